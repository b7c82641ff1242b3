//! The viewer's shell-fur session: a scene uploaded once, the wetness mask
//! painted by clicks and rain and drying as time passes (Silva §3.1, Alg. 1),
//! the mass-spring fur stepped every frame (Banisch; the brush is his
//! "locally apply forces by user input"), and the panel of sliders that
//! changes all of it live.

use glam::Vec3;
use pelage::dynamics::{PushBrush, Solver, Topology, Wind};
use pelage::shell::math::{ClumpParams, Coupling, ShadingMode};
use pelage::shell::scene::DynamicsSettings;
use pelage::shell::wetness::{Droplet, DropletStyle, droplets_on_mesh, mask_coordinates};
use pelage::shell::{ShellScene, WetnessMask};
use pelage_gpu::{
    FinParams, FurMotion, GpuContext, GpuError, OrbitCamera, ShellFeatures, ShellLevel, ShellLod,
    ShellModel, ShellParams, ShellRenderer, ShellTarget, ShellView,
};
use std::time::Instant;

/// What a left click or drag does on the fur.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tool {
    /// Click: a droplet (Alg. 1) where the ray meets the skin.
    Water,
    /// Drag: a force on the fur under the pointer.
    Push,
}

/// The panel's settings that are not [`ShellParams`].
#[derive(Debug, Clone)]
pub struct ShellControls {
    /// Left-button tool.
    pub tool: Tool,
    /// Splash radius, mask units.
    pub drop_radius: f32,
    /// Radius of each droplet (one clump), mask units.
    pub clump_size: f32,
    /// ρ_drop.
    pub drop_wetness: f32,
    /// Wetness decay per second.
    pub drying_rate: f32,
    /// Droplets falling all over.
    pub rain: bool,
    /// Droplets per second while it rains.
    pub rain_rate: f32,
    /// Curl radius as a fraction of the shell length.
    pub curl_radius: f32,
    /// Curl turns over the shell length.
    pub curl_turns: f32,
    /// Clumping on.
    pub clump: bool,
    /// The light follows the camera (else azimuth/elevation below).
    pub light_follows_camera: bool,
    /// Light azimuth, degrees.
    pub light_azimuth: f32,
    /// Light elevation, degrees.
    pub light_elevation: f32,
    /// Layers wanted (the shell texture is regenerated to match).
    pub layers: u32,
    /// Simulate the fur.
    pub dynamics_on: bool,
    /// Wind speed along +x (world units per second).
    pub wind: f32,
    /// Gravity's strength (m/s² scale of −y).
    pub gravity: f32,
    /// Brush radius as a fraction of the mesh's diagonal.
    pub brush_radius: f32,
    /// Brush force per pixel dragged.
    pub brush_strength: f32,
    /// A skinned scene's clip plays (else it holds at `clip_time`).
    pub playing: bool,
    /// Seconds into the clip.
    pub clip_time: f32,
}

/// A shell scene being looked at.
pub struct ShellSession {
    scene: ShellScene,
    renderer: ShellRenderer,
    model: ShellModel,
    target: Option<ShellTarget>,
    /// What the shaders read.
    pub params: ShellParams,
    /// Everything else the panel sets.
    pub controls: ShellControls,
    mask: WetnessMask,
    mask_changed: bool,
    /// The dynamics settings the panel edits (the scene's, or defaults).
    pub dynamics: DynamicsSettings,
    motion: Option<FurMotion>,
    rain: Vec<Droplet>,
    rain_next: usize,
    rain_owed: f32,
    shake_since: Option<f32>,
    time: f32,
    brush: Option<PushBrush>,
    /// The scene's wind (direction, gusts, turbulence); the panel sets
    /// its speed.
    base_wind: Wind,
    /// Splashes so far (each gets its own jitter).
    splashes: u64,
    /// Milliseconds the last frame's simulation (dynamics + mask) took.
    pub last_simulation_ms: f64,
    /// The level of detail the last frame was drawn at.
    level: Option<ShellLevel>,
    /// The fins and level of detail the panel turns on (kept while off).
    fins: FinParams,
    lod: ShellLod,
}

impl ShellSession {
    /// Uploads `scene` for drawing into targets of `format`.
    pub fn new(
        ctx: &GpuContext,
        scene: ShellScene,
        format: pelage_gpu::wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        // Curl and clumps are always compiled in, so the sliders can turn
        // them on; at zero they cost little (see `pelage bench shells`).
        let renderer = ShellRenderer::for_format(ctx, format, ShellFeatures::ALL);
        let model = renderer.upload_scene(ctx, &scene)?;
        let mut params = ShellParams::from_scene(&scene);
        let clump = scene.clump.is_some();
        if !clump {
            params.clump = ClumpParams {
                w: 0.6,
                strength: 4.0,
            };
        }
        let length = scene.fur.length.max(1e-9);
        let dynamics = scene.dynamics.clone().unwrap_or_default();
        let controls = ShellControls {
            tool: Tool::Water,
            drop_radius: 0.05,
            clump_size: 0.012,
            drop_wetness: 1.0,
            drying_rate: scene.drying_rate,
            rain: false,
            rain_rate: 40.0,
            curl_radius: scene.curl.radius / length,
            curl_turns: scene.curl.frequency / std::f32::consts::TAU,
            clump,
            light_follows_camera: scene.light.is_none(),
            light_azimuth: scene.light.map_or(40.0, |l| l.x.atan2(l.z).to_degrees()),
            light_elevation: scene
                .light
                .map_or(45.0, |l| l.normalize_or(Vec3::Y).y.asin().to_degrees()),
            layers: scene.fur.layers,
            dynamics_on: scene.dynamics.is_some(),
            wind: dynamics
                .params
                .wind
                .as_ref()
                .map_or(0.0, |w| w.velocity.length()),
            gravity: -dynamics.params.gravity.y,
            brush_radius: 0.12,
            brush_strength: 0.4,
            playing: true,
            clip_time: 0.0,
        };
        let base_wind = dynamics
            .params
            .wind
            .clone()
            .unwrap_or_else(|| Wind::new(Vec3::X, 0.5, 0.5, 0.5, 4.0, 1));
        let mask = WetnessMask::dry_mask(scene.wetness_resolution, scene.wetness_resolution);
        let mut session = Self {
            scene,
            renderer,
            model,
            target: None,
            params,
            controls,
            mask,
            mask_changed: true,
            dynamics,
            motion: None,
            rain: Vec::new(),
            rain_next: 0,
            rain_owed: 0.0,
            shake_since: None,
            time: 0.0,
            brush: None,
            last_simulation_ms: 0.0,
            base_wind,
            splashes: 0,
            level: None,
            fins: params.fins.unwrap_or_default(),
            lod: params.lod.unwrap_or_default(),
        };
        // The scene's own droplets at time 0 are the starting mask.
        let mut timeline = session.scene.wetness_timeline();
        session.mask = timeline.advance_to(0.0).clone();
        Ok(session)
    }

    /// The scene.
    pub fn scene(&self) -> &ShellScene {
        &self.scene
    }

    /// The orbit that frames the scene (its camera, or an automatic one).
    pub fn initial_orbit(&self, aspect: f32) -> OrbitCamera {
        let camera = self.scene.camera.map_or_else(
            || {
                let l = Vec3::splat(self.scene.fur.length);
                let (lo, hi) = self.scene.mesh.bounds();
                pelage_gpu::Camera::framing(lo - l, hi + l, aspect)
            },
            |c| {
                let l = Vec3::splat(self.scene.fur.length);
                let (lo, hi) = self.scene.mesh.bounds();
                pelage_gpu::Camera::from_scene(&c, lo - l, hi + l, aspect)
            },
        );
        OrbitCamera::from_camera(camera)
    }

    /// A splash of water where the ray meets the skin: the disk of
    /// `radius` (mask units) around the hit filled with droplets of the
    /// clump size, each one clump (Alg. 1), on a jittered grid. Returns
    /// whether the ray hit.
    pub fn drop_water(
        &mut self,
        origin: Vec3,
        direction: Vec3,
        radius: f32,
        wetness: f32,
        clump: f32,
    ) -> bool {
        let origin = origin - self.params.offset;
        let mesh = self.posed_mesh();
        let Some(hit) = pelage::mesh::first_hit(&mesh, origin, direction) else {
            return false;
        };
        let Some(uv) = hit.point.uv(&mesh) else {
            return false;
        };
        self.splashes += 1;
        for drop in splash(mask_coordinates(uv), radius, clump, wetness, self.splashes) {
            self.mask.add_droplet(drop);
        }
        self.mask_changed = true;
        true
    }

    /// Pushes the fur under the ray with `force` (world units), until
    /// [`Self::release`]; turns the dynamics on if they were off.
    pub fn push(&mut self, origin: Vec3, direction: Vec3, force: Vec3) -> bool {
        let origin = origin - self.params.offset;
        let mesh = self.posed_mesh();
        let Some(hit) = pelage::mesh::first_hit(&mesh, origin, direction) else {
            self.brush = None;
            return false;
        };
        let (lo, hi) = mesh.bounds();
        let brush = PushBrush {
            centre: hit.point.position(&mesh),
            radius: self.controls.brush_radius * (hi - lo).length(),
            force,
        };
        drop(mesh);
        self.controls.dynamics_on = true;
        self.brush = Some(brush);
        true
    }

    /// The skin where it is now: a skinned scene posed at the clip's
    /// time, else the scene's mesh.
    fn posed_mesh(&self) -> std::borrow::Cow<'_, pelage::Mesh> {
        match &self.scene.animation {
            Some(a) => a.mesh_at(self.controls.clip_time).map_or(
                std::borrow::Cow::Borrowed(&self.scene.mesh),
                std::borrow::Cow::Owned,
            ),
            None => std::borrow::Cow::Borrowed(&self.scene.mesh),
        }
    }

    /// Sets the clip's clock (seconds) and holds it there.
    pub fn set_clip_time(&mut self, seconds: f32) {
        self.controls.clip_time = seconds.max(0.0);
        self.controls.playing = false;
    }

    /// Ends a push.
    pub fn release(&mut self) {
        self.brush = None;
    }

    /// Starts shaking the object (the scene's shake, or a default one).
    pub fn shake(&mut self) {
        self.controls.dynamics_on = true;
        self.shake_since = Some(self.time);
    }

    /// Advances time by `dt` seconds: rain falls, the fur dries, the fur
    /// moves.
    pub fn advance(&mut self, ctx: &GpuContext, dt: f32) -> Result<(), GpuError> {
        let started = Instant::now();
        let dt = dt.clamp(0.0, 0.1);
        self.time += dt;
        if let Some(animation) = &self.scene.animation
            && self.controls.playing
        {
            let duration = animation.clip().1.max(1e-3);
            self.controls.clip_time = (self.controls.clip_time + dt).rem_euclid(duration);
        }
        if self.controls.rain {
            self.rain_owed += self.controls.rain_rate.max(0.0) * dt;
            while self.rain_owed >= 1.0 {
                self.rain_owed -= 1.0;
                if let Some(mut drop) = self.next_raindrop() {
                    drop.wetness = self.controls.drop_wetness;
                    self.mask.add_droplet(drop);
                    self.mask_changed = true;
                }
            }
        }
        if self.controls.drying_rate > 0.0 && self.mask.wet_fraction() > 0.0 {
            self.mask.dry(dt, self.controls.drying_rate);
            self.mask_changed = true;
        }
        if self.mask_changed {
            self.renderer.set_wetness(ctx, &self.model, &self.mask)?;
            self.mask_changed = false;
        }
        self.step_dynamics(ctx, dt)?;
        self.last_simulation_ms = started.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }

    fn next_raindrop(&mut self) -> Option<Droplet> {
        if self.rain.is_empty() {
            let style = DropletStyle {
                radius_min: 0.01,
                radius_max: 0.03,
                wetness: 1.0,
            };
            self.rain = droplets_on_mesh(&self.scene.mesh, 4096, style, 7).ok()?;
        }
        let drop = *self.rain.get(self.rain_next % self.rain.len().max(1))?;
        self.rain_next += 1;
        Some(drop)
    }

    fn shake_offset(&self) -> Vec3 {
        let Some(since) = self.shake_since else {
            return Vec3::ZERO;
        };
        let (lo, hi) = self.scene.mesh.bounds();
        let shake = self.dynamics.shake.unwrap_or(pelage::shell::scene::Shake {
            amplitude: Vec3::new(0.04 * (hi - lo).length(), 0.0, 0.0),
            frequency: 3.0,
            duration: 1.0,
        });
        shake.offset(self.time - since)
    }

    fn step_dynamics(&mut self, ctx: &GpuContext, dt: f32) -> Result<(), GpuError> {
        if !self.controls.dynamics_on {
            if self.motion.take().is_some() {
                // Back at rest: no offsets.
                let zero = vec![Vec3::ZERO; self.scene.mesh.triangle_count() * 3];
                self.renderer.set_tip_offsets(ctx, &self.model, &zero)?;
            }
            self.params.offset = Vec3::ZERO;
            self.params.coupling = Coupling::Bezier;
            return Ok(());
        }
        let offset = self.shake_offset();
        let settings = &mut self.dynamics;
        settings.params.gravity = Vec3::new(0.0, -self.controls.gravity, 0.0);
        settings.params.wind = (self.controls.wind > 0.0).then(|| {
            let mut wind = self.base_wind.clone();
            wind.velocity = wind.velocity.normalize_or(Vec3::X) * self.controls.wind;
            wind
        });
        settings.params.brush = self.brush;
        let topology = settings.topology;
        let steps = settings.steps_per_frame.max(1);
        let h = dt / steps as f32;
        let motion = match &mut self.motion {
            Some(m) if m.topology() == topology => m,
            slot => {
                let motion = FurMotion::new(&self.scene.mesh, topology, self.scene.fur.length);
                // Said once a system, as `pelage shells` says it.
                if h > 0.0
                    && let Some(warning) = motion.substeps_warning(h, settings)
                {
                    eprintln!("warning: {warning}");
                }
                slot.insert(motion)
            }
        };
        if h > 0.0 {
            for k in 0..steps {
                // The clip's clock has moved on by dt already.
                let t = self.controls.clip_time - dt + (k + 1) as f32 * h;
                let animation = self.scene.animation.as_ref();
                motion.step_scene(ctx, h, animation, t, offset, settings)?;
            }
        }
        self.params.coupling = settings.coupling;
        self.params.offset = offset;
        motion.show(ctx, &self.renderer, &self.model)
    }

    /// Applies the panel's settings that need work (a new shell texture
    /// when the layer count changed) and the cheap ones.
    pub fn apply_controls(&mut self, ctx: &GpuContext) -> Result<(), GpuError> {
        let c = &self.controls;
        self.params.curl.radius = c.curl_radius * self.scene.fur.length;
        self.params.curl.frequency = c.curl_turns * std::f32::consts::TAU;
        if c.layers != self.model.texture_layers() {
            self.scene.texture.layers = c.layers;
            self.scene.fur.layers = c.layers;
            self.model = self.renderer.upload_scene(ctx, &self.scene)?;
            self.params.layers = c.layers;
            self.mask_changed = true;
            self.motion = None;
        }
        Ok(())
    }

    /// The parameters to draw with (clumping off means strength 0).
    fn draw_params(&self) -> ShellParams {
        let mut params = self.params;
        if !self.controls.clump {
            params.clump.strength = 0.0;
        }
        params
    }

    /// The view from `orbit` for an image of `aspect`.
    pub fn view(&self, orbit: &OrbitCamera, aspect: f32) -> ShellView {
        let light = (!self.controls.light_follows_camera).then(|| {
            let (az, el) = (
                self.controls.light_azimuth.to_radians(),
                self.controls.light_elevation.to_radians(),
            );
            Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos())
        });
        ShellView::new(
            Some(orbit.camera()),
            self.scene.mesh.bounds(),
            self.scene.fur.length,
            aspect,
            light,
        )
    }

    /// Records the fur into `resolve` (`width × height`, the format given
    /// at [`Self::new`]).
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut pelage_gpu::wgpu::CommandEncoder,
        orbit: &OrbitCamera,
        resolve: &pelage_gpu::wgpu::TextureView,
        width: u32,
        height: u32,
    ) -> Result<(), GpuError> {
        if self
            .target
            .as_ref()
            .is_none_or(|t| t.size() != (width, height))
        {
            self.target = Some(ShellTarget::new(ctx, &self.renderer, width, height)?);
        }
        let view = self.view(orbit, width as f32 / height.max(1) as f32);
        let params = self.draw_params();
        let target = self.target.as_ref().expect("made above");
        if let Some(animation) = &self.scene.animation {
            let palette = animation.palette_at(self.controls.clip_time);
            self.renderer
                .pose(&ctx.queue, encoder, &self.model, &palette)?;
        }
        let level =
            self.renderer
                .encode(ctx, encoder, &self.model, &params, &view, target, resolve)?;
        self.level = Some(level);
        Ok(())
    }

    /// The control panel.
    pub fn panel(&mut self, ui: &mut egui::Ui) {
        let c = &mut self.controls;
        ui.heading("Fur");
        ui.add(egui::Slider::new(&mut c.layers, 1..=64).text("layers"));
        let length = &mut self.scene.fur.length;
        let (lo, hi) = self.scene.mesh.bounds();
        let diagonal = (hi - lo).length();
        ui.add(egui::Slider::new(length, 0.001 * diagonal..=0.15 * diagonal).text("shell length"));
        self.params.length = *length;
        ui.add(egui::Slider::new(&mut c.curl_radius, 0.0..=1.0).text("curl Kα (× length)"));
        ui.add(egui::Slider::new(&mut c.curl_turns, 0.0..=8.0).text("curl turns (ω / 2π)"));
        ui.checkbox(&mut c.clump, "wet clumps");
        ui.add(egui::Slider::new(&mut self.params.clump.w, 0.0..=1.0).text("clump w"));
        ui.add(egui::Slider::new(&mut self.params.clump.strength, 0.0..=8.0).text("clump squeeze"));
        let mut fins = self.params.fins.is_some();
        ui.horizontal(|ui| {
            ui.checkbox(&mut fins, "fins");
            ui.add_enabled(
                fins,
                egui::Slider::new(&mut self.fins.width, 0.02..=0.6).text("edge-on |n·e| <"),
            );
        });
        self.params.fins = fins.then_some(self.fins);
        let mut lod = self.params.lod.is_some();
        ui.horizontal(|ui| {
            ui.checkbox(&mut lod, "level of detail");
            ui.add_enabled(
                lod,
                egui::Slider::new(&mut self.lod.max_gap_px, 0.25..=4.0)
                    .logarithmic(true)
                    .text("px between layers"),
            );
        });
        self.params.lod = lod.then_some(self.lod);

        if let Some(animation) = &self.scene.animation {
            let (clip, duration) = animation.clip();
            ui.separator();
            ui.heading(format!("Animation: {clip}"));
            ui.horizontal(|ui| {
                let label = if c.playing { "Pause" } else { "Play" };
                if ui.button(label).clicked() {
                    c.playing = !c.playing;
                }
                let slider = ui.add(
                    egui::Slider::new(&mut c.clip_time, 0.0..=duration)
                        .text("s")
                        .fixed_decimals(2),
                );
                if slider.dragged() {
                    c.playing = false;
                }
            });
        }

        ui.separator();
        ui.heading("Water");
        ui.horizontal(|ui| {
            ui.label("left button:");
            ui.radio_value(&mut c.tool, Tool::Water, "drop water");
            ui.radio_value(&mut c.tool, Tool::Push, "push fur");
        });
        ui.add(egui::Slider::new(&mut c.drop_radius, 0.005..=0.25).text("splash radius"));
        ui.add(egui::Slider::new(&mut c.clump_size, 0.003..=0.05).text("clump size"));
        ui.add(egui::Slider::new(&mut c.drop_wetness, 0.0..=1.0).text("drop wetness ρ"));
        ui.add(egui::Slider::new(&mut c.drying_rate, 0.0..=2.0).text("drying rate /s"));
        ui.horizontal(|ui| {
            ui.checkbox(&mut c.rain, "rain");
            ui.add(egui::Slider::new(&mut c.rain_rate, 1.0..=400.0).text("drops/s"));
        });
        ui.label(format!(
            "wet: {:.1} % of the mask",
            100.0 * self.mask.wet_fraction()
        ));
        if ui.button("Dry everything").clicked() {
            self.mask = WetnessMask::dry_mask(self.mask.width(), self.mask.height());
            self.mask_changed = true;
        }

        ui.separator();
        ui.heading("Shading");
        egui::ComboBox::from_label("mode")
            .selected_text(format!("{:?}", self.params.mode))
            .show_ui(ui, |ui| {
                for mode in [
                    ShadingMode::Structure,
                    ShadingMode::Color,
                    ShadingMode::Shadow,
                    ShadingMode::Lambert,
                    ShadingMode::KajiyaKay,
                ] {
                    ui.selectable_value(&mut self.params.mode, mode, format!("{mode:?}"));
                }
            });
        let k = &mut self.params.kajiya_kay;
        ui.add(egui::Slider::new(&mut k.k_shadow, 1.0..=8.0).text("K_shadow"));
        ui.add(egui::Slider::new(&mut k.exponent, 1.0..=200.0).text("specular exponent"));
        ui.checkbox(&mut c.light_follows_camera, "light follows the camera");
        ui.add_enabled(
            !c.light_follows_camera,
            egui::Slider::new(&mut c.light_azimuth, -180.0..=180.0).text("light azimuth °"),
        );
        ui.add_enabled(
            !c.light_follows_camera,
            egui::Slider::new(&mut c.light_elevation, -90.0..=90.0).text("light elevation °"),
        );

        ui.separator();
        ui.heading("Dynamics");
        ui.checkbox(&mut c.dynamics_on, "simulate");
        let d = &mut self.dynamics;
        egui::ComboBox::from_label("topology")
            .selected_text(d.topology.name())
            .show_ui(ui, |ui| {
                for t in Topology::ALL {
                    ui.selectable_value(&mut d.topology, t, t.name());
                }
            });
        let mut implicit = matches!(d.solver, Solver::Implicit { .. });
        ui.horizontal(|ui| {
            ui.label("solver:");
            ui.radio_value(&mut implicit, true, "implicit");
            ui.radio_value(&mut implicit, false, "explicit");
        });
        d.solver = match (implicit, d.solver) {
            (true, Solver::Explicit { .. }) => Solver::Implicit { iterations: 30 },
            // As many substeps as the stiffness slider asks for stability.
            (false, Solver::Implicit { .. }) => Solver::Explicit { substeps: 0 },
            (_, s) => s,
        };
        if implicit && d.topology.joins_tips() {
            // FurMotion steps prisms' implicit solve (CG over all tips) on
            // the CPU whatever the box says.
            ui.add_enabled(false, egui::Checkbox::new(&mut d.gpu, "on the GPU"))
                .on_disabled_hover_text("the prisms' implicit step runs on the CPU; choose explicit to step them on the GPU");
        } else {
            ui.checkbox(&mut d.gpu, "on the GPU").on_hover_text(
                "step the solver in a compute shader; the fur is drawn from the GPU's state",
            );
        }
        ui.add(
            egui::Slider::new(&mut d.params.stiffness, 0.05..=50.0)
                .logarithmic(true)
                .text("stiffness"),
        );
        ui.add(egui::Slider::new(&mut d.params.damping, 0.0..=0.5).text("damping"));
        ui.add(egui::Slider::new(&mut d.params.restoring, 0.0..=0.5).text("restoring w (Eq. 5)"));
        ui.add(egui::Slider::new(&mut c.gravity, 0.0..=20.0).text("gravity"));
        ui.add(egui::Slider::new(&mut c.wind, 0.0..=10.0).text("wind"));
        ui.add(egui::Slider::new(&mut c.brush_radius, 0.01..=0.5).text("push radius"));
        ui.add(egui::Slider::new(&mut c.brush_strength, 0.0..=4.0).text("push strength"));
        if ui.button("Shake").clicked() {
            self.shake();
        }
        self.level_overlay(ui.ctx());
    }
}

impl ShellSession {
    /// The level of detail of the last frame, in the top right corner of
    /// the window: layers drawn of the scene's, the fur's length on screen
    /// and the texture's mip level.
    fn level_overlay(&self, ctx: &egui::Context) {
        let (Some(level), Some(_)) = (self.level, self.params.lod) else {
            return;
        };
        egui::Area::new(egui::Id::unique("level of detail"))
            .anchor(egui::Align2::RIGHT_TOP, egui::vec2(-10.0, 10.0))
            .interactable(false)
            .show(ctx, |ui| {
                egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.label(format!(
                        "level of detail: {:.1} of {} layers\nfur {:.1} px on screen · mip {:.1}",
                        level.layers, self.params.layers, level.fur_px, level.mip
                    ));
                });
            });
    }
}

/// Droplets of radius `clump` covering the disk of `radius` around
/// `centre` (mask units): a grid of spacing 1.2 · clump, each point moved
/// by up to a quarter of the spacing (a hash of the point and `salt`), so
/// neighbouring clumps touch without lining up. A splash no wider than a
/// clump is one droplet.
fn splash(centre: glam::Vec2, radius: f32, clump: f32, wetness: f32, salt: u64) -> Vec<Droplet> {
    let clump = clump.max(1e-4);
    if radius <= clump {
        return vec![Droplet {
            centre,
            radius: radius.max(1e-4),
            wetness,
        }];
    }
    let spacing = 1.2 * clump;
    let n = (radius / spacing).ceil() as i32;
    let mut drops = Vec::new();
    for j in -n..=n {
        for i in -n..=n {
            let mut h =
                pelage::sample::SampleRng::new(salt, ((j + n) * (2 * n + 1) + i + n) as u64);
            let jitter = glam::Vec2::new(h.uniform_f32() - 0.5, h.uniform_f32() - 0.5);
            let offset = (glam::Vec2::new(i as f32, j as f32) + jitter * 0.5) * spacing;
            if offset.length() <= radius {
                drops.push(Droplet {
                    centre: centre + offset,
                    radius: clump,
                    wetness,
                });
            }
        }
    }
    drops
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    #[test]
    fn a_splash_covers_its_disk_with_clump_sized_drops() {
        let centre = Vec2::new(0.5, 0.5);
        let drops = splash(centre, 0.1, 0.01, 0.8, 3);
        // About the disk's area over a grid cell's.
        let expected = std::f32::consts::PI * 0.01 / (0.012f32 * 0.012);
        assert!(
            (drops.len() as f32 - expected).abs() < 0.15 * expected,
            "{}",
            drops.len()
        );
        assert!(drops.iter().all(|d| d.radius == 0.01 && d.wetness == 0.8));
        assert!(drops.iter().all(|d| d.centre.distance(centre) <= 0.1));
        // The inner disk is wet but for small gaps between clumps.
        let mut mask = WetnessMask::dry_mask(512, 512);
        drops.iter().for_each(|&d| mask.add_droplet(d));
        let wet = (0..400)
            .filter(|&k| {
                let a = k as f32 * 2.399_963; // golden angle: a sunflower of points
                let p = centre + 0.09 * (k as f32 / 400.0).sqrt() * Vec2::new(a.cos(), a.sin());
                mask.at(p).wetness > 0.0
            })
            .count();
        assert!(wet >= 380, "{wet} of 400 points wet");
        // Small splashes are one drop; the same salt gives the same drops.
        assert_eq!(splash(centre, 0.005, 0.01, 1.0, 1).len(), 1);
        assert_eq!(drops, splash(centre, 0.1, 0.01, 0.8, 3));
    }
}
