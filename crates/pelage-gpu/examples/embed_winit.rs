//! pelage's shell fur inside an app of its own: a minimal winit + wgpu
//! program that owns its instance, device, queue, surface, depth buffer,
//! camera and render pass — as a game engine would — and asks pelage only
//! to pose its skinned model and to record fur into its pass.
//! docs/embedding.md walks through it.
//!
//! ```sh
//! cargo run --release -p pelage-gpu --example embed_winit
//! cargo run --release -p pelage-gpu --example embed_winit -- --frames 30 --screenshot fox.png
//! ```
//!
//! Three foxes run side by side (one skinned model drawn three times, each
//! placed by its offset): two in shell fur with fins and the level of
//! detail, the middle one in real-time strands (a groom grown on the GPU
//! every frame and carried by the pose, recorded into the same pass;
//! docs/realtime.md).

use glam::{Mat4, Vec3};
use pelage::groom::{AnimatedGroom, Groom, GroomRecipe};
use pelage::shell::{ShellAnimation, ShellScene, ShellTextureParams, ShellTextures};
use pelage_gpu::{
    FinParams, GpuContext, GpuGroom, ShellFeatures, ShellLod, ShellModel, ShellParams,
    ShellRenderer, ShellTargetFormats, ShellUpload, ShellView, StrandBinding, StrandParams,
    StrandRenderer,
};
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

/// The app's own depth format and sample count: not pelage's.
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth24Plus;

struct Furry {
    renderer: ShellRenderer,
    fox: ShellAnimation,
    fox_model: ShellModel,
    fox_params: ShellParams,
    /// The middle fox's groom: carried by its pose, grown on the GPU.
    groom: AnimatedGroom,
    hairs: GpuGroom,
    rest_guides: Vec<Vec3>,
    strands: StrandRenderer,
    strand_binding: StrandBinding,
}

struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    adapter: wgpu::Adapter,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    depth: wgpu::TextureView,
    furry: Furry,
    started: Instant,
    frames: u32,
}

struct App {
    running: Option<Running>,
    stop_after: Option<u32>,
    screenshot: Option<std::path::PathBuf>,
}

fn depth_view(device: &wgpu::Device, width: u32, height: u32) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("app depth"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

impl Furry {
    /// What the app does once: pipelines for its targets, models uploaded
    /// with its device.
    fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        color: wgpu::TextureFormat,
    ) -> anyhow::Result<Self> {
        let renderer = ShellRenderer::for_targets(
            device,
            ShellTargetFormats {
                color,
                depth: DEPTH,
                samples: 1,
            },
            ShellFeatures {
                cull_back: true,
                ..ShellFeatures::PLAIN
            },
        );
        let ctx = GpuContext::wrap(adapter, device, queue);
        let assets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../pelage/assets/fox");
        let fox = ShellAnimation::load(&assets.join("Fox.gltf"), "Run", 1)?;
        let fox_color = image::open(assets.join("fox.png"))?.to_rgba8();
        let textures = ShellTextures::generate(&ShellTextureParams {
            layers: 24,
            ..Default::default()
        });
        let mut fox_model = renderer.upload_with(
            &ctx,
            fox.rest_mesh(),
            &fox_color,
            &textures,
            8,
            ShellUpload {
                rig: Some(fox.rig()),
                per_corner: false,
            },
        )?;
        let (lo, hi) = fox.bounds();
        fox_model.set_bounds(lo, hi);
        // A groom on the same Fox, grown on the GPU every frame.
        let text = format!(
            "[mesh]\npath = {:?}\n[roots]\ncount = 30000\n\
             [guides]\npoints = 8\ngenerate = {{ count = 300, length = 8, comb = [0, -0.2, -0.8] }}\n\
             [[ops]]\nclump = {{ count = 1500, rate = 0.35 }}\n\
             [finish]\npoints = 8\noutside_skin = false\nwidth = {{ root = 1.0, tip = 0.3 }}\n\
             [animation]\nframes = \"1-28\"\nclip = \"Run\"\n",
            assets.join("Fox.gltf")
        );
        let groom = Groom::from_text("fox.toml", &text)?
            .animated(None)?
            .expect("the groom is animated");
        let (roots, ids) = pelage::groom::roots_by_arrival(groom.generator());
        let recipe = GroomRecipe::new(groom.generator(), &roots, &ids)?;
        let hairs = GpuGroom::new(&ctx, &recipe, groom.binding())?;
        let strands = StrandRenderer::new(
            &ctx,
            ShellTargetFormats {
                color,
                depth: DEPTH,
                samples: 1,
            },
        );
        let strand_binding = strands.bind(&ctx, &hairs);
        Ok(Self {
            rest_guides: GroomRecipe::guide_offsets(groom.generator().guides()),
            groom,
            hairs,
            strands,
            strand_binding,
            renderer,
            fox_params: ShellParams {
                layers: 24,
                length: 4.0,
                tiles: 24.0,
                fins: Some(FinParams::default()),
                lod: Some(ShellLod::default()),
                // Shading and the rest as a scene file's defaults.
                ..ShellParams::from_scene(&ShellScene::spot())
            },
            fox,
            fox_model,
        })
    }
}

impl Running {
    /// Draws a frame; with `screenshot`, reads it back and writes it there.
    fn frame(&mut self, screenshot: Option<&std::path::Path>) -> anyhow::Result<()> {
        let texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            _ => {
                self.surface.configure(&self.device, &self.config);
                return Ok(());
            }
        };
        let view = texture.texture.create_view(&Default::default());
        let (width, height) = (self.config.width as f32, self.config.height as f32);
        // The app's camera.
        let eye = Vec3::new(300.0, 90.0, 260.0);
        let clip_from_world: Mat4 =
            glam::camera::rh::proj::directx::perspective(0.6, width / height, 1.0, 2000.0)
                * glam::camera::rh::view::look_at_mat4(eye, Vec3::new(0.0, 40.0, 40.0), Vec3::Y);
        let camera = ShellView {
            clip_from_world,
            eye,
            light: Vec3::new(0.4, 1.0, 0.6).normalize(),
        };
        let furry = &mut self.furry;
        let seconds = self.started.elapsed().as_secs_f32();
        let mut encoder = self.device.create_command_encoder(&Default::default());
        // 1. pelage poses the skinned model in the app's encoder.
        furry.renderer.pose(
            &self.queue,
            &mut encoder,
            &furry.fox_model,
            &furry.fox.palette_at(seconds),
        )?;
        // pelage grows the middle fox's hairs on its pose (frame 1 is the
        // clip's start, 24 frames a second), then draws the key light's
        // shadow maps: passes of their own, before the app's.
        let pose = furry.groom.pose(1.0 + 24.0 * f64::from(seconds))?;
        let ctx = GpuContext::wrap(&self.adapter, &self.device, &self.queue);
        furry
            .hairs
            .record(&ctx, &mut encoder, &furry.rest_guides, Some(&pose))?;
        let (lo, hi) = furry.fox.bounds();
        let grown = (lo - Vec3::splat(16.0), hi + Vec3::splat(16.0));
        let strand_frame = furry.strands.prepare(
            &self.queue,
            &mut encoder,
            &furry.strand_binding,
            &StrandParams::for_length(8.0),
            &camera,
            (grown, (self.config.width, self.config.height)),
        );
        {
            // 2. The app's own pass: its clear colour, its depth buffer.
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("app pass"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: 0.35,
                            g: 0.45,
                            b: 0.3,
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // 3. pelage records fur into it: three foxes, the middle one's
            // skin bare under its strands.
            for x in [-90.0, 0.0, 90.0] {
                let params = ShellParams {
                    offset: Vec3::new(x, 0.0, -x),
                    layers: if x == 0.0 { 0 } else { furry.fox_params.layers },
                    fins: furry.fox_params.fins.filter(|_| x != 0.0),
                    ..furry.fox_params
                };
                furry.renderer.record(
                    &self.queue,
                    &mut pass,
                    &furry.fox_model,
                    &params,
                    &camera,
                    height,
                )?;
            }
            furry
                .strands
                .record(&mut pass, &furry.strand_binding, &strand_frame);
        }
        match screenshot {
            Some(path) => {
                let ctx = GpuContext::wrap(&self.adapter, &self.device, &self.queue);
                pelage_gpu::read_texture(&ctx, encoder, &texture.texture)?.save(path)?;
                println!("wrote {}", path.display());
            }
            None => {
                self.queue.submit([encoder.finish()]);
            }
        }
        self.window.pre_present_notify();
        self.queue.present(texture);
        self.frames += 1;
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        let start = || -> anyhow::Result<Running> {
            let window = Arc::new(
                event_loop.create_window(
                    Window::default_attributes()
                        .with_title("pelage shells in an app of its own")
                        .with_inner_size(winit::dpi::PhysicalSize::new(960, 540)),
                )?,
            );
            let instance =
                wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                    Box::new(event_loop.owned_display_handle()),
                ));
            let surface = instance.create_surface(window.clone())?;
            let adapter =
                pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                    compatible_surface: Some(&surface),
                    ..Default::default()
                }))?;
            let (device, queue) =
                pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))?;
            let caps = surface.get_capabilities(&adapter);
            let format = caps
                .formats
                .iter()
                .copied()
                .find(|f| f.is_srgb())
                .unwrap_or(caps.formats[0]);
            let size = window.inner_size();
            let config = wgpu::SurfaceConfiguration {
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                format,
                width: size.width.max(1),
                height: size.height.max(1),
                present_mode: wgpu::PresentMode::AutoVsync,
                desired_maximum_frame_latency: 2,
                alpha_mode: caps.alpha_modes[0],
                view_formats: vec![],
                color_space: wgpu::SurfaceColorSpace::Auto,
            };
            surface.configure(&device, &config);
            let furry = Furry::new(&adapter, &device, &queue, format)?;
            println!(
                "{}: pelage's shells and strands in the app's pass",
                adapter.get_info().name
            );
            Ok(Running {
                depth: depth_view(&device, config.width, config.height),
                window,
                surface,
                adapter,
                device,
                queue,
                config,
                furry,
                started: Instant::now(),
                frames: 0,
            })
        };
        match start() {
            Ok(running) => {
                running.window.request_redraw();
                self.running = Some(running);
            }
            Err(e) => {
                eprintln!("error: {e:#}");
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(running) = &mut self.running else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                running.config.width = size.width.max(1);
                running.config.height = size.height.max(1);
                running.surface.configure(&running.device, &running.config);
                running.depth =
                    depth_view(&running.device, running.config.width, running.config.height);
            }
            WindowEvent::RedrawRequested => {
                let last = self.stop_after.is_some_and(|n| running.frames + 1 >= n);
                let shot = self.screenshot.as_deref().filter(|_| last);
                if let Err(e) = running.frame(shot) {
                    eprintln!("error: {e:#}");
                    event_loop.exit();
                    return;
                }
                if self.stop_after.is_some_and(|n| running.frames >= n) {
                    println!("{} frames drawn", running.frames);
                    event_loop.exit();
                    return;
                }
                running.window.request_redraw();
            }
            _ => {}
        }
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let mut app = App {
        running: None,
        stop_after: None,
        screenshot: None,
    };
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--frames" => app.stop_after = args.next().and_then(|n| n.parse().ok()),
            "--screenshot" => app.screenshot = args.next().map(Into::into),
            other => anyhow::bail!("unknown argument {other}: use --frames N, --screenshot FILE"),
        }
    }
    EventLoop::new()?.run_app(&mut app)?;
    Ok(())
}
