//! Real-time strands drawn: a [`GpuGroom`]'s hairs, straight from its
//! points buffer, as camera-facing ribbons with a real-time hair shading
//! model and the key light's opacity shadow map (`shaders/hair.wgsl` says
//! what each term is and where it comes from).
//!
//! Embedding follows [`crate::ShellRenderer::record`]'s contract: the host
//! owns the device, the render pass and its depth; pelage records into
//! them. A frame is two calls: [`StrandRenderer::prepare`] writes the
//! frame's uniforms and records the shadow map's pass into the host's
//! encoder (before its main pass), then [`StrandRenderer::record`] draws
//! the ribbons inside the host's pass, depth-tested against what the host
//! drew (the skin, other objects).

use crate::layout::{UniformRing, entry, gpu_struct, group};
use crate::renderer::{DEPTH_FORMAT, check_size};
use crate::shells::{
    ShellModel, ShellParams, ShellRenderer, ShellTarget, ShellTargetFormats, ShellView,
};
use crate::{GpuContext, GpuError, GpuGroom};
use glam::Vec3;

/// Texels along a side of the key light's shadow maps.
const SHADOW_SIZE: u32 = 1024;
/// The opacity layers' format: four layers, added up in half floats.
const OPACITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

gpu_struct! {
    /// The shader's `Strands` block.
    pub(crate) struct StrandUniforms {
        view_proj: [[f32; 4]; 4],
        light_view_proj: [[f32; 4]; 4],
        eye: [f32; 3],
        focal_length_px: f32,
        light_dir: [f32; 3],
        width_scale: f32,
        base_color: [f32; 3],
        specular: f32,
        viewport_px: [f32; 2],
        stride: u32,
        points: u32,
        first: u32,
        layer_depth: f32,
        shadow_range: f32,
        shadow_px_per_unit: f32,
        shift: f32,
        roughness: f32,
        trt: f32,
        ambient: f32,
        transmission: f32,
        transmission_exponent: f32,
        shadowed: u32,
        shadow_size: f32,
        hair_opacity: f32,
        opacity: f32,
        pad1: u32,
        pad2: u32,
    }
}

pub use pelage_shaders::hair::StrandLook;

/// What a frame of strands draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrandParams {
    /// The look.
    pub look: StrandLook,
    /// Render hairs drawn, the first of them (`None`: all).
    pub hairs: Option<u32>,
    /// Every width's factor.
    pub width_scale: f32,
    /// The strands' opacity, 0 to 1 (less where they hand over to shell
    /// fur; through alpha-to-coverage with MSAA).
    pub opacity: f32,
    /// Self-shadowing: world units below the first hair or skin the key
    /// light sees that the deep opacity map's first layer spans (the next
    /// end at 2×, 4× and 8× of it; `None`: no self-shadowing).
    pub shadow_layer: Option<f32>,
}

impl StrandParams {
    /// Defaults for hairs about `length` long: opacity layers ending a
    /// quarter, a half, one and two hairs below the top of the coat.
    pub fn for_length(length: f32) -> Self {
        Self {
            look: StrandLook::default(),
            hairs: None,
            width_scale: 1.0,
            opacity: 1.0,
            shadow_layer: Some(length / 4.0),
        }
    }
}

/// A [`GpuGroom`]'s buffers, bound for drawing.
#[derive(Debug)]
pub struct StrandBinding {
    group: wgpu::BindGroup,
    stride: u32,
    points: u32,
    /// The skin's triangle corners.
    skin_vertices: u32,
    render: std::ops::Range<u32>,
}

/// A frame [`StrandRenderer::prepare`]d: its uniforms' slot and what to draw.
#[derive(Debug, Clone, Copy)]
pub struct StrandFrame {
    offset: u32,
    vertices: u32,
}

/// What the key light's passes draw with: the skin's depth, the first
/// hair's depth, then the opacity layers below it.
#[derive(Debug)]
struct ShadowPipelines {
    hair_depth: wgpu::RenderPipeline,
    skin_depth: wgpu::RenderPipeline,
    hair_opacity: wgpu::RenderPipeline,
}

/// The key light's three maps (the hairs' first depth, the skin's depth,
/// the opacity layers) and how the passes bind them.
struct ShadowMaps {
    shadow_view: wgpu::TextureView,
    skin_shadow_view: wgpu::TextureView,
    opacity_view: wgpu::TextureView,
    /// The opacity pass reads the first depth…
    first_depth_layout: wgpu::BindGroupLayout,
    first_depth_group: wgpu::BindGroup,
    /// … the frame reads all three.
    shadow_layout: wgpu::BindGroupLayout,
    shadow_group: wgpu::BindGroup,
}

impl ShadowMaps {
    fn new(device: &wgpu::Device) -> Self {
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let depth_entry = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: fragment,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let first_depth_layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("strand first depth"),
                entries: &[depth_entry],
            });
        let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("strand shadow map"),
            entries: &[
                depth_entry,
                entry::texture(1, fragment, wgpu::TextureViewDimension::D2, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    ..depth_entry
                },
            ],
        });
        let shadow_texture = |label, format, usage| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width: SHADOW_SIZE,
                        height: SHADOW_SIZE,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        let sampled = wgpu::TextureUsages::TEXTURE_BINDING;
        let shadow_view = shadow_texture("strand shadow depth", DEPTH_FORMAT, sampled);
        let skin_shadow_view = shadow_texture("skin shadow depth", DEPTH_FORMAT, sampled);
        let opacity_view = shadow_texture("strand opacity layers", OPACITY_FORMAT, sampled);
        let first_depth_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("strand first depth"),
            layout: &first_depth_layout,
            entries: &group::sequential([wgpu::BindingResource::TextureView(&shadow_view)]),
        });
        let shadow_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("strand shadow map"),
            layout: &shadow_layout,
            entries: &group::sequential([
                wgpu::BindingResource::TextureView(&shadow_view),
                wgpu::BindingResource::TextureView(&opacity_view),
                wgpu::BindingResource::TextureView(&skin_shadow_view),
            ]),
        });
        Self {
            shadow_view,
            skin_shadow_view,
            opacity_view,
            first_depth_layout,
            first_depth_group,
            shadow_layout,
            shadow_group,
        }
    }
}

/// Ribbons are triangle lists, both sides drawn.
const PRIMITIVE: wgpu::PrimitiveState = wgpu::PrimitiveState {
    topology: wgpu::PrimitiveTopology::TriangleList,
    strip_index_format: None,
    front_face: wgpu::FrontFace::Ccw,
    cull_mode: None,
    unclipped_depth: false,
    polygon_mode: wgpu::PolygonMode::Fill,
    conservative: false,
};

/// Depth tested and written.
fn depth_state(format: wgpu::TextureFormat) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: Default::default(),
    })
}

/// A pipeline drawing the ribbons (or the skin) pulled by vertex index:
/// no vertex buffers, both sides, `entry_point` and `fragment` of `module`.
fn pulled_pipeline(
    device: &wgpu::Device,
    (label, layout): (&str, &wgpu::PipelineLayout),
    (module, entry_point): (&wgpu::ShaderModule, &str),
    depth_stencil: Option<wgpu::DepthStencilState>,
    multisample: wgpu::MultisampleState,
    fragment: Option<wgpu::FragmentState<'_>>,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(entry_point),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: PRIMITIVE,
        depth_stencil,
        multisample,
        fragment,
        multiview_mask: None,
        cache: None,
    })
}

impl ShadowPipelines {
    /// The key light's pipelines over `[uniforms, points, first depth]`.
    fn new(
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        [uniform_layout, points_layout, first_depth_layout]: [&wgpu::BindGroupLayout; 3],
    ) -> Self {
        let layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("strand shadows"),
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let shadow_layout = layout(&[Some(uniform_layout), Some(points_layout)]);
        let depth_only = |label, entry_point| {
            pulled_pipeline(
                device,
                (label, &shadow_layout),
                (module, entry_point),
                depth_state(DEPTH_FORMAT),
                Default::default(),
                None,
            )
        };
        let opacity_layout = layout(&[
            Some(uniform_layout),
            Some(points_layout),
            Some(first_depth_layout),
        ]);
        let adding = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let targets = [Some(wgpu::ColorTargetState {
            format: OPACITY_FORMAT,
            blend: Some(wgpu::BlendState {
                color: adding,
                alpha: adding,
            }),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let hair_opacity = pulled_pipeline(
            device,
            ("strand opacity", &opacity_layout),
            (module, "vs_shadow"),
            None,
            Default::default(),
            Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_opacity"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
        );
        Self {
            hair_depth: depth_only("strand shadow depth", "vs_shadow"),
            skin_depth: depth_only("skin shadow depth", "vs_occluder"),
            hair_opacity,
        }
    }
}

/// Draws real-time strands. Build once, draw many frames.
#[derive(Debug)]
pub struct StrandRenderer {
    formats: ShellTargetFormats,
    uniforms: UniformRing<StrandUniforms>,
    points_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    shadow_pipelines: ShadowPipelines,
    shadow_view: wgpu::TextureView,
    skin_shadow_view: wgpu::TextureView,
    opacity_view: wgpu::TextureView,
    first_depth_group: wgpu::BindGroup,
    shadow_group: wgpu::BindGroup,
}

impl StrandRenderer {
    /// The pipelines, drawing into targets of `formats`.
    pub fn new(ctx: &GpuContext, formats: ShellTargetFormats) -> Self {
        let device = &ctx.device;
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let uniform_layout = UniformRing::<StrandUniforms>::layout(device, "strands", both);
        let uniforms = UniformRing::new(device, "strands", &uniform_layout);
        let vertex = wgpu::ShaderStages::VERTEX;
        let points_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("strand points"),
            entries: &(0..4)
                .map(|b| entry::storage(b, vertex, true))
                .collect::<Vec<_>>(),
        });
        let maps = ShadowMaps::new(device);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("hair.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::shader_source("hair.wgsl")),
        });
        let layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("strands"),
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let main_layout = layout(&[
            Some(&uniform_layout),
            Some(&points_layout),
            Some(&maps.shadow_layout),
        ]);
        let targets = [Some(wgpu::ColorTargetState {
            format: formats.color,
            // Without MSAA, coverage blends.
            blend: (formats.samples == 1).then_some(wgpu::BlendState::ALPHA_BLENDING),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let pipeline = pulled_pipeline(
            device,
            ("strands", &main_layout),
            (&module, "vs_main"),
            depth_state(formats.depth),
            wgpu::MultisampleState {
                count: formats.samples,
                mask: !0,
                alpha_to_coverage_enabled: formats.samples > 1,
            },
            Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
        );
        let shadow_pipelines = ShadowPipelines::new(
            device,
            &module,
            [&uniform_layout, &points_layout, &maps.first_depth_layout],
        );
        Self {
            formats,
            uniforms,
            points_layout,
            pipeline,
            shadow_pipelines,
            shadow_view: maps.shadow_view,
            skin_shadow_view: maps.skin_shadow_view,
            opacity_view: maps.opacity_view,
            first_depth_group: maps.first_depth_group,
            shadow_group: maps.shadow_group,
        }
    }

    /// The targets its pipelines draw into.
    pub fn target_formats(&self) -> ShellTargetFormats {
        self.formats
    }

    /// `groom`'s points and colours bound for drawing (again after a new
    /// upload; the same binding serves every frame it grows).
    pub fn bind(&self, ctx: &GpuContext, groom: &GpuGroom) -> StrandBinding {
        let (skin, triangles, triangle_count) = groom.skin();
        let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("strand points"),
            layout: &self.points_layout,
            entries: &group::buffers([groom.points(), groom.colors(), skin, triangles]),
        });
        let (stride, points) = groom.layout();
        StrandBinding {
            group,
            stride,
            points,
            skin_vertices: 3 * triangle_count,
            render: groom.render_hairs(),
        }
    }

    /// Starts a frame: writes its uniforms through `queue` and, with
    /// shadows, records the key light's shadow map into `encoder` (a pass
    /// of its own: call before the pass [`Self::record`] draws into).
    /// `bounds` hold the hairs (the skin's grown by the hairs' length);
    /// `viewport` is the target's size in pixels.
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        binding: &StrandBinding,
        params: &StrandParams,
        view: &ShellView,
        (bounds, viewport): ((Vec3, Vec3), (u32, u32)),
    ) -> StrandFrame {
        let (lo, hi) = bounds;
        let centre = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo)).length().max(1e-6);
        let light = view.light.normalize_or(Vec3::Y);
        let up = if light.y.abs() > 0.9 {
            Vec3::X
        } else {
            Vec3::Y
        };
        let light_view =
            glam::camera::rh::view::look_at_mat4(centre + 2.0 * radius * light, centre, up);
        let light_proj = glam::camera::rh::proj::directx::orthographic(
            -radius,
            radius,
            -radius,
            radius,
            0.0,
            4.0 * radius,
        );
        // The focal length in pixels from the projection's y scale.
        let m = view.clip_from_world;
        let focal = 0.5 * viewport.1 as f32 * m.row(1).truncate().length();
        let look = params.look;
        let hairs = params.hairs.map_or(binding.render.len() as u32, |h| {
            h.min(binding.render.len() as u32)
        });
        let uniforms = StrandUniforms {
            view_proj: m.to_cols_array_2d(),
            light_view_proj: (light_proj * light_view).to_cols_array_2d(),
            eye: view.eye.to_array(),
            focal_length_px: focal,
            light_dir: light.to_array(),
            width_scale: params.width_scale,
            base_color: look.color.to_array(),
            specular: look.specular,
            viewport_px: [viewport.0 as f32, viewport.1 as f32],
            stride: binding.stride,
            points: binding.points,
            first: binding.render.start,
            layer_depth: params.shadow_layer.unwrap_or(1.0).max(1e-9),
            shadow_range: 4.0 * radius,
            shadow_px_per_unit: SHADOW_SIZE as f32 / (2.0 * radius),
            shift: StrandLook::SHIFT,
            roughness: look.roughness,
            trt: StrandLook::TRT,
            ambient: StrandLook::AMBIENT,
            transmission: look.transmission,
            transmission_exponent: StrandLook::TRANSMISSION_EXPONENT,
            shadowed: u32::from(params.shadow_layer.is_some()),
            shadow_size: SHADOW_SIZE as f32,
            hair_opacity: look.opacity,
            opacity: params.opacity.clamp(0.0, 1.0),
            pad1: 0,
            pad2: 0,
        };
        let offset = self.uniforms.write(queue, &uniforms);
        let vertices = hairs * pelage_shaders::hair::ribbon_vertices(binding.points);
        let frame = StrandFrame { offset, vertices };
        if params.shadow_layer.is_some() {
            self.record_shadows(encoder, binding, offset, vertices);
        }
        frame
    }

    /// The key light's passes: the skin's depth, the first hair's depth,
    /// then the opacity layers below it.
    fn record_shadows(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        binding: &StrandBinding,
        offset: u32,
        vertices: u32,
    ) {
        let pipelines = &self.shadow_pipelines;
        for (label, view, pipeline, count) in [
            (
                "skin shadow depth",
                &self.skin_shadow_view,
                &pipelines.skin_depth,
                binding.skin_vertices,
            ),
            (
                "strand shadow depth",
                &self.shadow_view,
                &pipelines.hair_depth,
                vertices,
            ),
        ] {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view,
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
            pass.set_bind_group(0, self.uniforms.group(), &[offset]);
            pass.set_bind_group(1, &binding.group, &[]);
            pass.set_pipeline(pipeline);
            pass.draw(0..count, 0..1);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("strand opacity layers"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.opacity_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, self.uniforms.group(), &[offset]);
        pass.set_bind_group(1, &binding.group, &[]);
        pass.set_bind_group(2, &self.first_depth_group, &[]);
        pass.set_pipeline(&pipelines.hair_opacity);
        pass.draw(0..vertices, 0..1);
    }

    /// Draws the frame's ribbons into the caller's pass (targets of
    /// [`Self::target_formats`], with depth).
    pub fn record(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        binding: &StrandBinding,
        frame: &StrandFrame,
    ) {
        if frame.vertices == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, self.uniforms.group(), &[frame.offset]);
        pass.set_bind_group(1, &binding.group, &[]);
        pass.set_bind_group(2, &self.shadow_group, &[]);
        pass.draw(0..frame.vertices, 0..1);
    }

    /// Records a frame into pelage's own `target`: the key light's maps,
    /// then one pass cleared to the background with `skin` (a shell
    /// renderer drawing the skin, and its shells when their layers are
    /// not 0) and the strands, resolved into the target.
    ///
    /// # Errors
    /// When the skin cannot be drawn.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        binding: &StrandBinding,
        params: &StrandParams,
        view: &ShellView,
        bounds: (Vec3, Vec3),
        skin: Option<(&ShellRenderer, &ShellModel, &ShellParams)>,
        target: &ShellTarget,
    ) -> Result<(), GpuError> {
        let resolve = target.resolved.create_view(&Default::default());
        let skin_and_target = (skin, target, &resolve);
        self.encode_to(ctx, encoder, binding, params, view, bounds, skin_and_target)
    }

    /// [`Self::encode`] resolved into `resolve` (a view of `target`'s
    /// size: its own resolve texture, or a window's surface texture).
    #[allow(clippy::too_many_arguments)]
    pub fn encode_to(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        binding: &StrandBinding,
        params: &StrandParams,
        view: &ShellView,
        bounds: (Vec3, Vec3),
        (skin, target, resolve): (
            Option<(&ShellRenderer, &ShellModel, &ShellParams)>,
            &ShellTarget,
            &wgpu::TextureView,
        ),
    ) -> Result<(), GpuError> {
        let frame = self.prepare(
            &ctx.queue,
            encoder,
            binding,
            params,
            view,
            (bounds, target.size),
        );
        let background = skin.map_or([0.0; 3], |(_, _, p)| p.background);
        let mut pass = target.begin_pass(encoder, "strands", resolve, background);
        if let Some((shells, model, shell_params)) = skin {
            shells.record(
                &ctx.queue,
                &mut pass,
                model,
                shell_params,
                view,
                target.size.1 as f32,
            )?;
        }
        self.record(&mut pass, binding, &frame);
        Ok(())
    }

    /// [`Self::encode`] submitted, waiting for the GPU to finish (a
    /// frame's cost, for benchmarks).
    ///
    /// # Errors
    /// When the GPU fails.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &self,
        ctx: &GpuContext,
        binding: &StrandBinding,
        params: &StrandParams,
        view: &ShellView,
        bounds: (Vec3, Vec3),
        skin: Option<(&ShellRenderer, &ShellModel, &ShellParams)>,
        target: &ShellTarget,
    ) -> Result<(), GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.encode(
            ctx,
            &mut encoder,
            binding,
            params,
            view,
            bounds,
            skin,
            target,
        )?;
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()
    }

    /// [`Self::encode`], read back: a picture.
    ///
    /// # Errors
    /// When the GPU fails or the read-back does.
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &self,
        ctx: &GpuContext,
        binding: &StrandBinding,
        params: &StrandParams,
        view: &ShellView,
        bounds: (Vec3, Vec3),
        skin: Option<(&ShellRenderer, &ShellModel, &ShellParams)>,
        target: &ShellTarget,
    ) -> Result<image::RgbaImage, GpuError> {
        check_size(ctx, target.size.0, target.size.1)?;
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.encode(
            ctx,
            &mut encoder,
            binding,
            params,
            view,
            bounds,
            skin,
            target,
        )?;
        crate::readback::read_texture(ctx, encoder, &target.resolved)
    }
}
