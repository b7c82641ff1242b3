//! The viewer's window: winit's event loop, a wgpu surface, egui on top.
//! Mouse and keys move the camera and drive the session's tools; a script
//! drives the same calls frame by frame, so the scripted run a test makes
//! is the run a person gets.
//!
//! One file, past 600 lines: one winit application (event loop, surface,
//! egui, input) whose handlers share its state.

use super::curves::{CurvesSession, CurvesSource};
use super::grooming::{GroomingSession, PALETTE};
use super::realtime::RealtimeSession;
use super::script::{Script, Step};
use super::shells::{ShellSession, Tool};
use anyhow::Context as _;
use glam::{Vec2, Vec3};
use pelage::shell::ShellScene;
use pelage_gpu::{GpuContext, OrbitCamera, wgpu};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// How the window is opened.
#[derive(Debug, Clone)]
pub struct WindowOptions {
    /// Inner size in pixels.
    pub size: (u32, u32),
    /// What the window's title says is shown.
    pub title: String,
    /// Steps to run; `None` for an interactive session.
    pub script: Option<Script>,
}

/// What a session measured, printed when the window closes.
#[derive(Debug, Default)]
pub struct Timings {
    /// The adapter drawn with.
    pub adapter: String,
    /// Seconds from one frame's start to the next's.
    pub frame_ms: Vec<f64>,
    /// Milliseconds of simulation (dynamics, drying, rain) per frame.
    pub simulation_ms: Vec<f64>,
    /// Screenshots written.
    pub screenshots: Vec<PathBuf>,
    /// Milliseconds each groom brush dab took (edit and regrowth).
    pub dab_ms: Vec<f64>,
}

/// The control panel's width in logical pixels (egui adds its margins).
const PANEL_WIDTH: f32 = 280.0;

/// What the window shows.
pub enum Content {
    /// Shell fur.
    Shells(Box<ShellScene>),
    /// A groom or curves file.
    Curves(CurvesSource),
    /// A groom file, groomed by hand.
    Groom(PathBuf),
    /// A groom file, played in real time on the GPU.
    Realtime(PathBuf),
}

/// A session in the window: shell fur, a groom to look at, or a groom to
/// groom.
enum Session {
    Shells(Box<ShellSession>),
    Curves(Box<CurvesSession>),
    Groom(Box<GroomingSession>),
    Realtime(Box<RealtimeSession>),
}

impl Session {
    fn initial_orbit(&self, aspect: f32) -> OrbitCamera {
        match self {
            Session::Shells(s) => s.initial_orbit(aspect),
            Session::Curves(c) => c.initial_orbit(aspect),
            Session::Groom(g) => g.initial_orbit(aspect),
            Session::Realtime(r) => r.initial_orbit(aspect),
        }
    }

    fn fps(&self) -> f32 {
        match self {
            Session::Shells(s) => s.scene().fps.max(1.0),
            Session::Curves(_) | Session::Groom(_) | Session::Realtime(_) => 24.0,
        }
    }

    fn shells(&mut self) -> Option<&mut ShellSession> {
        match self {
            Session::Shells(s) => Some(s),
            _ => None,
        }
    }

    fn grooming(&mut self) -> Option<&mut GroomingSession> {
        match self {
            Session::Groom(g) => Some(g),
            _ => None,
        }
    }

    fn update(&mut self, ctx: &GpuContext, dt: f32) -> anyhow::Result<f64> {
        match self {
            Session::Shells(s) => {
                s.apply_controls(ctx)?;
                s.advance(ctx, dt)?;
                Ok(s.last_simulation_ms)
            }
            Session::Curves(c) => {
                c.advance(dt);
                Ok(0.0)
            }
            Session::Groom(_) => Ok(0.0),
            Session::Realtime(r) => {
                r.advance(ctx)?;
                Ok(r.last_simulation_ms)
            }
        }
    }

    /// The panel; a groom's panel answers with the actions asked for.
    fn panel(&mut self, ui: &mut egui::Ui) -> Option<super::grooming::PanelActions> {
        match self {
            Session::Shells(s) => s.panel(ui),
            Session::Curves(c) => c.panel(ui),
            Session::Realtime(r) => r.panel(ui),
            Session::Groom(g) => return Some(g.panel(ui)),
        }
        None
    }

    #[allow(clippy::too_many_arguments)]
    fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        orbit: &OrbitCamera,
        view: &wgpu::TextureView,
        width: u32,
        height: u32,
    ) -> anyhow::Result<()> {
        match self {
            Session::Shells(s) => Ok(s.encode(ctx, encoder, orbit, view, width, height)?),
            Session::Curves(c) => c.encode(ctx, encoder, orbit, view, width, height),
            Session::Groom(g) => g.encode(ctx, encoder, orbit, view, width, height),
            Session::Realtime(r) => r.encode(ctx, encoder, orbit, view, width, height),
        }
    }
}

/// Opens the window on `content` and runs until it is closed (or the
/// script ends).
pub fn run(content: Content, options: WindowOptions) -> anyhow::Result<Timings> {
    let event_loop = EventLoop::new().context(
        "cannot open a window: no display (set DISPLAY, or run under `xvfb-run` on a machine without one)",
    )?;
    let mut app = App {
        options,
        content: Some(content),
        state: None,
        error: None,
        timings: Timings::default(),
    };
    event_loop
        .run_app(&mut app)
        .context("the window's event loop failed")?;
    match app.error {
        Some(err) => Err(err),
        None => Ok(app.timings),
    }
}

struct App {
    options: WindowOptions,
    content: Option<Content>,
    state: Option<WindowState>,
    error: Option<anyhow::Error>,
    timings: Timings,
}

struct WindowState {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    ctx: GpuContext,
    egui: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    session: Session,
    orbit: OrbitCamera,
    home: OrbitCamera,
    pointer: Pointer,
    script: Option<ScriptRun>,
    show_ui: bool,
    last_frame: Option<Instant>,
    screenshot_requests: Vec<PathBuf>,
    screenshots_taken: u32,
    /// A scripted step that failed (a save that could not be written).
    script_error: Option<anyhow::Error>,
}

#[derive(Debug, Default)]
struct Pointer {
    position: Vec2,
    pressed_at: Option<Vec2>,
    button: Option<MouseButton>,
    dragged: bool,
    shift: bool,
    ctrl: bool,
}

struct ScriptRun {
    steps: Vec<Step>,
    next: usize,
    wait: u32,
    push: Option<(super::script::PushStep, u32)>,
    finished: bool,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        let Some(content) = self.content.take() else {
            return;
        };
        match WindowState::open(event_loop, content, &self.options) {
            Ok(state) => {
                self.timings.adapter = state.ctx.adapter_name();
                state.window.request_redraw();
                self.state = Some(state);
            }
            Err(err) => {
                self.error = Some(err);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(state) = self.state.as_mut() else {
            return;
        };
        let consumed = state.egui.on_window_event(&state.window, &event).consumed;
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => state.resize(size.width, size.height),
            WindowEvent::RedrawRequested => match state.frame(&mut self.timings) {
                Ok(true) => state.window.request_redraw(),
                Ok(false) => event_loop.exit(),
                Err(err) => {
                    self.error = Some(err);
                    event_loop.exit();
                }
            },
            WindowEvent::ModifiersChanged(m) => {
                state.pointer.shift = m.state().shift_key();
                state.pointer.ctrl = m.state().control_key();
            }
            _ if consumed => {}
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if let Err(err) = state.groom_key(event.logical_key.as_ref()) {
                    self.error = Some(err);
                    event_loop.exit();
                    return;
                }
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) | Key::Character("q") => event_loop.exit(),
                    Key::Named(NamedKey::F12) | Key::Character("p") => {
                        let n = state.screenshots_taken + 1;
                        state
                            .screenshot_requests
                            .push(PathBuf::from(format!("pelage-view-{n:03}.png")));
                    }
                    Key::Character("h") if !state.pointer.ctrl => state.show_ui = !state.show_ui,
                    Key::Character("r") => state.orbit = state.home,
                    Key::Character("s") => {
                        if let Some(s) = state.session.shells() {
                            s.shake();
                        }
                    }
                    _ => {}
                }
            }
            WindowEvent::MouseInput {
                state: pressed,
                button,
                ..
            } => state.mouse_button(button, pressed == ElementState::Pressed),
            WindowEvent::CursorMoved { position, .. } => {
                state.mouse_moved(Vec2::new(position.x as f32, position.y as f32));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                state.orbit.zoom(0.9f32.powf(lines));
            }
            _ => {}
        }
    }
}

impl WindowState {
    fn open(
        event_loop: &ActiveEventLoop,
        content: Content,
        options: &WindowOptions,
    ) -> anyhow::Result<Self> {
        let (width, height) = options.size;
        let window = Arc::new(
            event_loop
                .create_window(
                    Window::default_attributes()
                        .with_title(&options.title)
                        .with_inner_size(winit::dpi::PhysicalSize::new(width, height)),
                )
                .context("cannot open a window")?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance
            .create_surface(window.clone())
            .context("cannot draw into the window")?;
        let ctx = GpuContext::for_surface(&instance, &surface)?;
        let caps = surface.get_capabilities(ctx.adapter());
        // Shading is written for an sRGB target, as the headless images.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| f.is_srgb())
            .or_else(|| caps.formats.first().copied())
            .context("the window's surface offers no format")?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&ctx.device, &config);
        let session = match content {
            Content::Shells(scene) => {
                Session::Shells(Box::new(ShellSession::new(&ctx, *scene, format)?))
            }
            Content::Curves(source) => {
                Session::Curves(Box::new(CurvesSession::new(&ctx, source, format)?))
            }
            Content::Groom(path) => {
                Session::Groom(Box::new(GroomingSession::new(&ctx, &path, format)?))
            }
            Content::Realtime(path) => {
                Session::Realtime(Box::new(RealtimeSession::new(&ctx, &path, format)?))
            }
        };
        let show_ui = options.script.as_ref().is_none_or(|s| s.ui);
        // Framed in the part of the window the panel leaves free.
        let panel = if show_ui {
            (PANEL_WIDTH * window.scale_factor() as f32).min(0.5 * config.width as f32)
        } else {
            0.0
        };
        let height = config.height as f32;
        let mut orbit = session.initial_orbit((config.width as f32 - panel) / height);
        orbit.pan(-0.5 * panel / height, 0.0);
        let egui_ctx = egui::Context::default();
        let egui = egui_winit::State::new(
            egui_ctx,
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(&ctx.device, format, Default::default());
        let script = options.script.clone().map(|s| ScriptRun {
            steps: s.steps,
            next: 0,
            wait: 0,
            push: None,
            finished: false,
        });
        Ok(Self {
            window,
            surface,
            config,
            ctx,
            egui,
            egui_renderer,
            session,
            orbit,
            home: orbit,
            pointer: Pointer::default(),
            script,
            show_ui,
            last_frame: None,
            screenshot_requests: Vec::new(),
            screenshots_taken: 0,
            script_error: None,
        })
    }

    fn resize(&mut self, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(&self.ctx.device, &self.config);
        }
    }

    fn aspect(&self) -> f32 {
        self.config.width as f32 / self.config.height.max(1) as f32
    }

    /// A key of the groom mode: brushes, radius, strength, mirror, undo,
    /// redo, save. Other sessions ignore it.
    fn groom_key(&mut self, key: Key<&str>) -> anyhow::Result<()> {
        let ctrl = self.pointer.ctrl;
        let shift = self.pointer.shift;
        let Some(g) = self.session.grooming() else {
            return Ok(());
        };
        let Key::Character(ch) = key else {
            return Ok(());
        };
        let ch = ch.to_ascii_lowercase();
        let c = &mut g.controls;
        match ch.as_str() {
            "z" if ctrl && shift => g.redo()?,
            "z" if ctrl => g.undo()?,
            "s" if ctrl => {
                let path = g.default_save_path();
                if let Err(e) = g.save(&path) {
                    g.status = crate::one_line(&e);
                }
            }
            _ if ctrl => {}
            "[" => c.radius /= 1.25,
            "]" => c.radius *= 1.25,
            "," => c.strength = (c.strength - 0.1).max(-1.0),
            "." => c.strength = (c.strength + 0.1).min(1.0),
            "m" => c.mirror_x = !c.mirror_x,
            "-" => c.brush = PALETTE.len() - 1,
            "0" => c.brush = 9,
            d if d.len() == 1 && ("1"..="9").contains(&d) => {
                c.brush = d.parse::<usize>().expect("a digit") - 1;
            }
            _ => {}
        }
        Ok(())
    }

    /// A scripted stroke: dabs along the pixels from `from` to `to`. A dab
    /// the brush refuses (a bad radius, a layer name) fails the script.
    fn scripted_stroke(&mut self, step: &super::script::BrushStep) -> anyhow::Result<()> {
        let pixels: Vec<Vec2> = {
            let (from, to) = (
                Vec2::from(step.from),
                Vec2::from(step.to.unwrap_or(step.from)),
            );
            let dabs = step.dabs.max(1);
            (0..=dabs)
                .map(|k| from.lerp(to, k as f32 / dabs as f32))
                .collect()
        };
        let rays: Vec<(Vec3, Vec3)> = pixels.iter().map(|p| self.ray(*p)).collect();
        let Some(g) = self.session.grooming() else {
            eprintln!("warning: `brush` is for `--groom`; ignored");
            return Ok(());
        };
        let c = &mut g.controls;
        c.brush = PALETTE
            .iter()
            .position(|n| *n == step.name)
            .expect("checked when the script was read");
        c.radius = step.radius.unwrap_or(c.radius);
        c.strength = step.strength.unwrap_or(c.strength);
        c.mirror_x = step.mirror.unwrap_or(c.mirror_x);
        if let Some(layer) = &step.layer {
            c.layer = layer.clone();
        }
        c.value = step.value.unwrap_or(c.value);
        c.region = step.region.unwrap_or(c.region);
        c.add_count = step.count.unwrap_or(c.add_count);
        if let Some(f) = step
            .falloff
            .as_deref()
            .and_then(pelage::groom::brush::Falloff::parse)
        {
            c.falloff = f;
        }
        g.begin_stroke();
        let mut missed = true;
        let mut refused = None;
        for (origin, direction) in rays {
            match g.stroke_to(origin, direction) {
                Ok(hit) => missed &= !hit,
                Err(e) => {
                    refused = Some(e);
                    break;
                }
            }
        }
        let edits = g.end_stroke();
        if let Some(e) = refused {
            return Err(e.context(format!("the {} stroke at pixel {:?}", step.name, step.from)));
        }
        if missed {
            eprintln!(
                "warning: the {} stroke at pixel {:?} missed the mesh",
                step.name, step.from
            );
        } else if edits == 0 {
            // The dab's own words: no guide within reach, and how far.
            eprintln!(
                "warning: the {} stroke at pixel {:?} changed nothing: {}",
                step.name, step.from, g.status
            );
        }
        Ok(())
    }

    /// The ray through a window pixel (x right, y down).
    fn ray(&self, pixel: Vec2) -> (Vec3, Vec3) {
        let ndc_x = 2.0 * pixel.x / self.config.width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * pixel.y / self.config.height as f32;
        self.orbit.ray(ndc_x, ndc_y, self.aspect())
    }

    fn drop_at(
        &mut self,
        pixel: Vec2,
        radius: Option<f32>,
        wetness: Option<f32>,
        clump: Option<f32>,
    ) -> bool {
        let (origin, direction) = self.ray(pixel);
        let Session::Shells(session) = &mut self.session else {
            return false;
        };
        let c = &session.controls;
        let (radius, wetness, clump) = (
            radius.unwrap_or(c.drop_radius),
            wetness.unwrap_or(c.drop_wetness),
            clump.unwrap_or(c.clump_size),
        );
        session.drop_water(origin, direction, radius, wetness, clump)
    }

    /// A push from where the drag started towards where the pointer is.
    fn push_at(&mut self, from: Vec2, to: Vec2) {
        let (origin, direction) = self.ray(to);
        let camera = self.orbit.camera();
        let forward = (camera.target - camera.eye).normalize();
        let side = forward.cross(Vec3::Y).normalize_or_zero();
        let above = side.cross(forward);
        let drag = to - from;
        // Up to full strength over a tenth of the window's height.
        let amount = (drag.length() / (0.1 * self.config.height as f32)).min(1.0);
        let along = (side * drag.x - above * drag.y).normalize_or_zero() * amount;
        if let Some(session) = self.session.shells() {
            session.push(origin, direction, along);
        }
    }

    fn mouse_button(&mut self, button: MouseButton, pressed: bool) {
        if button == MouseButton::Left && matches!(self.session, Session::Groom(_)) {
            let position = self.pointer.position;
            let (origin, direction) = self.ray(position);
            if let Some(g) = self.session.grooming() {
                if pressed {
                    g.begin_stroke();
                    if let Err(e) = g.stroke_to(origin, direction) {
                        g.status = crate::one_line(&e);
                    }
                } else {
                    g.end_stroke();
                }
            }
        }
        let p = &mut self.pointer;
        if pressed {
            p.pressed_at = Some(p.position);
            p.button = Some(button);
            p.dragged = false;
            return;
        }
        let clicked = p.button == Some(button) && !p.dragged;
        let position = p.position;
        let tool = match &self.session {
            Session::Shells(s) => s.controls.tool,
            Session::Curves(_) | Session::Groom(_) | Session::Realtime(_) => return,
        };
        p.button = None;
        p.pressed_at = None;
        if button == MouseButton::Left {
            match tool {
                Tool::Water if clicked => {
                    self.drop_at(position, None, None, None);
                }
                Tool::Push => {
                    if let Some(s) = self.session.shells() {
                        s.release();
                    }
                }
                Tool::Water => {}
            }
        }
    }

    fn mouse_moved(&mut self, position: Vec2) {
        let delta = position - self.pointer.position;
        self.pointer.position = position;
        let Some(start) = self.pointer.pressed_at else {
            if matches!(&self.session, Session::Groom(_)) {
                let (origin, direction) = self.ray(position);
                if let Some(g) = self.session.grooming() {
                    g.hover(origin, direction);
                }
            }
            return;
        };
        if (position - start).length() > 3.0 {
            self.pointer.dragged = true;
        }
        let height = self.config.height.max(1) as f32;
        match self.pointer.button {
            Some(MouseButton::Left) if matches!(&self.session, Session::Shells(s) if s.controls.tool == Tool::Push) =>
            {
                self.push_at(start, position);
            }
            Some(MouseButton::Left) if matches!(&self.session, Session::Groom(_)) => {
                let (origin, direction) = self.ray(position);
                if let Some(g) = self.session.grooming()
                    && let Err(e) = g.stroke_to(origin, direction)
                {
                    g.status = crate::one_line(&e);
                }
            }
            Some(MouseButton::Right) if !self.pointer.shift => {
                self.orbit.orbit(-delta.x * 0.01, delta.y * 0.01);
            }
            Some(MouseButton::Right | MouseButton::Middle) => {
                self.orbit.pan(-delta.x / height, delta.y / height);
            }
            _ => {}
        }
    }

    /// Runs the script's steps due this frame. Returns false when the
    /// window should close.
    fn script_steps(&mut self) -> bool {
        let Some(mut run) = self.script.take() else {
            return true;
        };
        let mut open = true;
        if let Some((push, k)) = run.push.as_mut() {
            let t = (*k as f32 / push.frames.max(1) as f32).min(1.0);
            let (from, to) = (Vec2::from(push.from), Vec2::from(push.to));
            let (push_from, frames) = (from, push.frames);
            *k += 1;
            let done = *k > frames;
            self.push_at(push_from, from.lerp(to, t));
            if done {
                if let Some(s) = self.session.shells() {
                    s.release();
                }
                run.push = None;
            }
        } else if run.wait > 0 {
            run.wait -= 1;
        } else {
            while let Some(step) = run.steps.get(run.next).cloned() {
                run.next += 1;
                match step {
                    Step::Wait(frames) => {
                        run.wait = frames.saturating_sub(1);
                        break;
                    }
                    Step::Screenshot(path) => {
                        self.screenshot_requests.push(path);
                        break;
                    }
                    Step::Drop(d) => {
                        if !self.drop_at(Vec2::from(d.at), d.radius, d.wetness, d.clump) {
                            eprintln!("warning: the drop at pixel {:?} missed the mesh", d.at);
                        }
                    }
                    Step::Orbit([right, up]) => {
                        self.orbit.orbit(-right.to_radians(), up.to_radians());
                    }
                    Step::Zoom(factor) => self.orbit.zoom(factor),
                    Step::Push(push) => {
                        run.push = Some((push, 0));
                        break;
                    }
                    Step::Shake(on) => {
                        if let (true, Some(s)) = (on, self.session.shells()) {
                            s.shake();
                        }
                    }
                    Step::Time(seconds) => match &mut self.session {
                        Session::Shells(s) => s.set_clip_time(seconds),
                        Session::Curves(c) => {
                            if !c.hold_at(seconds) {
                                eprintln!(
                                    "warning: `time`: the curves file has no time samples; ignored"
                                );
                            }
                        }
                        Session::Realtime(r) => r.hold_at(seconds),
                        Session::Groom(_) => {
                            eprintln!(
                                "warning: `time` is for skinned scenes and animated curves files; ignored"
                            );
                        }
                    },
                    Step::Show(show) => match &mut self.session {
                        Session::Curves(c) => {
                            let t = &mut c.controls;
                            t.skin = show.skin.unwrap_or(t.skin);
                            t.hairs = show.hairs.unwrap_or(t.hairs);
                            t.guides = show.guides.unwrap_or(t.guides);
                            t.roots = show.roots.unwrap_or(t.roots);
                            if show.layer.is_some() {
                                eprintln!("warning: `show.layer` is for `--groom`; ignored");
                            }
                            t.percent = show.percent.map_or(t.percent, |p| p.clamp(0.1, 100.0));
                        }
                        Session::Groom(g) => {
                            let t = &mut g.controls;
                            t.skin = show.skin.unwrap_or(t.skin);
                            t.hairs = show.hairs.unwrap_or(t.hairs);
                            t.guides = show.guides.unwrap_or(t.guides);
                            t.show_layer = show.layer.unwrap_or(t.show_layer);
                        }
                        Session::Shells(_) | Session::Realtime(_) => {
                            eprintln!("warning: `show` is for groom and curves views; ignored");
                        }
                    },
                    Step::Pointer(at) => self.mouse_moved(Vec2::from(at)),
                    Step::Brush(b) => {
                        if let Err(e) = self.scripted_stroke(&b) {
                            self.script_error = Some(e);
                            open = false;
                            break;
                        }
                    }
                    Step::Undo(n) | Step::Redo(n) => {
                        let undo = matches!(step, Step::Undo(_));
                        if let Some(g) = self.session.grooming() {
                            for _ in 0..n {
                                let done = if undo { g.undo() } else { g.redo() };
                                if let Err(e) = done {
                                    g.status = crate::one_line(&e);
                                }
                            }
                        } else {
                            eprintln!("warning: undo and redo are for `--groom`; ignored");
                        }
                    }
                    Step::Save(ref path) | Step::Export(ref path) => {
                        let save = matches!(step, Step::Save(_));
                        match self.session.grooming() {
                            Some(g) => {
                                let done = if save { g.save(path) } else { g.export(path) };
                                if let Err(e) = done {
                                    self.script_error = Some(e);
                                    open = false;
                                    break;
                                }
                            }
                            None => {
                                eprintln!("warning: save and export are for `--groom`; ignored")
                            }
                        }
                    }
                    Step::Fraction(percent) => {
                        if let Some(g) = self.session.grooming()
                            && let Err(e) = g.set_percent(percent)
                        {
                            self.script_error = Some(e);
                            open = false;
                            break;
                        }
                    }
                    Step::Quit(true) => {
                        open = false;
                        break;
                    }
                    Step::Quit(false) => {}
                }
            }
            if run.next >= run.steps.len() && run.wait == 0 && run.push.is_none() && open {
                if run.finished {
                    open = false;
                } else {
                    // One more frame for the last screenshot, then close.
                    run.finished = true;
                }
            }
        }
        self.script = Some(run);
        open
    }

    /// Draws one frame. Returns false when the window should close.
    fn frame(&mut self, timings: &mut Timings) -> anyhow::Result<bool> {
        let now = Instant::now();
        let scripted = self.script.is_some();
        // Scripts advance by the scene's frame time, so their runs repeat
        // exactly; a person gets the wall clock.
        let dt = match self.last_frame {
            _ if scripted => 1.0 / self.session.fps(),
            Some(last) => now.duration_since(last).as_secs_f32(),
            None => 0.0,
        };
        if let Some(last) = self.last_frame {
            timings
                .frame_ms
                .push(now.duration_since(last).as_secs_f64() * 1e3);
        }
        self.last_frame = Some(now);
        let open = self.script_steps();
        // A failed step ends the script with its error (it closed the
        // window, and a closed window's run would exit 0).
        if let Some(err) = self.script_error.take() {
            return Err(err);
        }
        if !open && self.screenshot_requests.is_empty() {
            return Ok(false);
        }

        // The panel.
        let input = self.egui.take_egui_input(&self.window);
        let frame_ms = timings.frame_ms.last().copied().unwrap_or(0.0);
        let simulation_ms = timings.simulation_ms.last().copied().unwrap_or(0.0);
        let show_ui = self.show_ui;
        let session = &mut self.session;
        let mut actions = None;
        let mut output = self.egui.egui_ctx().run_ui(input, |ui| {
            if !show_ui {
                return;
            }
            egui::Panel::left("controls")
                .default_size(PANEL_WIDTH - 10.0)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        ui.label(format!(
                            "frame {frame_ms:.1} ms ({:.1} fps) · simulation {simulation_ms:.2} ms",
                            1e3 / frame_ms.max(1e-3),
                        ));
                        ui.small("left: tool · right drag: orbit · shift/middle: pan · wheel: zoom · P: screenshot · H: hide · R: reset · S: shake");
                        ui.separator();
                        actions = session.panel(ui);
                    });
                });
        });
        self.egui
            .handle_platform_output(&self.window, output.platform_output);
        let pixels_per_point = output.pixels_per_point;
        let paint = self
            .egui
            .egui_ctx()
            .tessellate(output.shapes, pixels_per_point);

        // Uploaded now and emptied, so no error below leaves deltas behind.
        let mut textures = std::mem::take(&mut output.textures_delta);
        for (id, deltas) in &textures.set {
            for delta in deltas {
                self.egui_renderer
                    .update_texture(&self.ctx.device, &self.ctx.queue, *id, delta);
            }
        }
        let freed: Vec<egui::TextureId> = textures.free.iter().copied().collect();
        textures.clear();

        if let (Some(a), Some(g)) = (actions, self.session.grooming()) {
            if a.undo {
                g.undo()?;
            }
            if a.redo {
                g.redo()?;
            }
            if a.save {
                let path = g.default_save_path();
                if let Err(e) = g.save(&path) {
                    g.status = crate::one_line(&e);
                }
            }
            if let Some(percent) = a.percent {
                g.set_percent(percent)?;
            }
        }
        if let Some(err) = self.script_error.take() {
            return Err(err);
        }
        if let Some(g) = self.session.grooming()
            && g.dab_ms.len() != timings.dab_ms.len()
        {
            timings.dab_ms = g.dab_ms.clone();
        }
        let simulation = self.session.update(&self.ctx, dt)?;
        timings.simulation_ms.push(simulation);

        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point,
        };

        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.ctx.device, &self.config);
                None
            }
            _ => None,
        };
        if let Some(frame) = frame {
            let view = frame.texture.create_view(&Default::default());
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            self.draw(&mut encoder, &view, &paint, &screen)?;
            self.ctx.queue.submit([encoder.finish()]);
            self.window.pre_present_notify();
            self.ctx.queue.present(frame);
        }
        for path in std::mem::take(&mut self.screenshot_requests) {
            self.screenshot(&path, &paint, &screen)?;
            println!("wrote {}", path.display());
            timings.screenshots.push(path);
            self.screenshots_taken += 1;
        }
        for id in &freed {
            self.egui_renderer.free_texture(id);
        }
        Ok(open)
    }

    /// The fur, then the panel over it, into `view`.
    fn draw(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        paint: &[egui::ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) -> anyhow::Result<()> {
        let (w, h) = (self.config.width, self.config.height);
        self.session
            .encode(&self.ctx, encoder, &self.orbit, view, w, h)?;
        let extra = self.egui_renderer.update_buffers(
            &self.ctx.device,
            &self.ctx.queue,
            encoder,
            paint,
            screen,
        );
        if !extra.is_empty() {
            self.ctx.queue.submit(extra);
        }
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("panel"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        self.egui_renderer
            .render(&mut pass.forget_lifetime(), paint, screen);
        Ok(())
    }

    /// The frame drawn again into a texture of the window's size and
    /// format, read back and written as a PNG (atomically): what the window
    /// shows, on any platform, whether or not its surface can be read.
    fn screenshot(
        &mut self,
        path: &std::path::Path,
        paint: &[egui::ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) -> anyhow::Result<()> {
        let texture = self.ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("screenshot"),
            size: wgpu::Extent3d {
                width: self.config.width,
                height: self.config.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.config.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        self.draw(&mut encoder, &view, paint, screen)?;
        let mut image = pelage_gpu::read_texture(&self.ctx, encoder, &texture)?;
        // An opaque window shows the colours and ignores alpha (which the
        // curve ribbons' blending leaves below 1): so does the screenshot.
        if self.config.alpha_mode == wgpu::CompositeAlphaMode::Opaque {
            image.pixels_mut().for_each(|p| p.0[3] = 255);
        }
        if let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) {
            std::fs::create_dir_all(folder)
                .with_context(|| format!("cannot create {}", folder.display()))?;
        }
        pelage::io::write_atomically(path, |out| {
            image
                .write_to(out, image::ImageFormat::Png)
                .map_err(std::io::Error::other)
        })
        .with_context(|| format!("cannot write the screenshot {}", path.display()))?;
        Ok(())
    }
}
