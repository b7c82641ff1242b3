//! [`ShellRenderer`]: the pipelines (specialised per [`ShellFeatures`]) and
//! what they record: the skinning pass of a skinned model, then the skin
//! once with depth write, the layers in one instanced indexed draw and the
//! fins. [`ShellRenderer::record`] records into a render pass of the
//! caller's (docs/embedding.md); [`ShellRenderer::draw`] and
//! [`ShellRenderer::render`] into pelage's own [`ShellTarget`].

use crate::layout::{UniformRing, compute_pipeline, entry};
use crate::renderer::{COLOR_FORMAT, DEPTH_FORMAT, SAMPLES, check_size, target_texture};
use crate::{GpuContext, GpuError};
use glam::Mat4;

use super::model::ShellModel;
use super::{
    PoseVertex, ShellFeatures, ShellLevel, ShellParams, ShellUniforms, ShellView, SurfaceVertex,
    TipOffset,
};

/// The render targets a [`ShellRenderer`]'s pipelines draw into: the
/// caller's colour format (use an sRGB one: the shaders write linear
/// colour), depth format and sample count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShellTargetFormats {
    /// Colour attachment format.
    pub color: wgpu::TextureFormat,
    /// Depth attachment format (the skin writes depth, the fur tests it).
    pub depth: wgpu::TextureFormat,
    /// Samples per pixel of both.
    pub samples: u32,
}

impl ShellTargetFormats {
    /// pelage's own targets ([`ShellTarget`]): sRGB RGBA8, 32-bit float
    /// depth, 4× multisampling.
    pub fn own() -> Self {
        Self::pelage(COLOR_FORMAT)
    }

    /// pelage's own: `format`, 32-bit float depth, 4× multisampling.
    pub fn pelage(color: wgpu::TextureFormat) -> Self {
        Self {
            color,
            depth: DEPTH_FORMAT,
            samples: SAMPLES,
        }
    }
}

/// Draws shell fur. Build once per feature set, draw many frames.
#[derive(Debug)]
pub struct ShellRenderer {
    /// The frame's [`ShellUniforms`], made once, rewritten for each draw.
    pub(super) uniforms: UniformRing<ShellUniforms>,
    pub(super) texture_layout: wgpu::BindGroupLayout,
    pub(super) fin_layout: wgpu::BindGroupLayout,
    pub(super) skin_layout: wgpu::BindGroupLayout,
    pub(super) fur_sampler: wgpu::Sampler,
    pub(super) color_sampler: wgpu::Sampler,
    pub(super) skin_pipeline: wgpu::RenderPipeline,
    pub(super) layer_pipeline: wgpu::RenderPipeline,
    pub(super) fin_pipeline: wgpu::RenderPipeline,
    pub(super) skinning: wgpu::ComputePipeline,
    pub(super) formats: ShellTargetFormats,
    pub(super) features: ShellFeatures,
}

impl ShellRenderer {
    /// Pipelines for offscreen images.
    pub fn new(ctx: &GpuContext, features: ShellFeatures) -> Self {
        Self::for_format(ctx, COLOR_FORMAT, features)
    }

    /// Pipelines for targets of `format` (use an sRGB format) with
    /// pelage's depth format and multisampling ([`ShellTarget`]).
    pub fn for_format(
        ctx: &GpuContext,
        format: wgpu::TextureFormat,
        features: ShellFeatures,
    ) -> Self {
        Self::for_targets(&ctx.device, ShellTargetFormats::pelage(format), features)
    }

    /// Pipelines for the caller's render targets, on the caller's device:
    /// what an engine embedding pelage's shells builds once
    /// (docs/embedding.md).
    pub fn for_targets(
        device: &wgpu::Device,
        formats: ShellTargetFormats,
        features: ShellFeatures,
    ) -> Self {
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let uniform_layout = UniformRing::<ShellUniforms>::layout(device, "shell uniforms", both);
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shell textures"),
            entries: &[
                entry::texture(0, both, wgpu::TextureViewDimension::D2Array, true),
                entry::sampler(1, both),
                entry::texture(2, both, wgpu::TextureViewDimension::D2, true),
                entry::sampler(3, both),
                entry::texture(4, both, wgpu::TextureViewDimension::D2, false),
            ],
        });
        let vertex = wgpu::ShaderStages::VERTEX;
        let fin_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shell fins"),
            entries: &[0, 1, 2, 3].map(|b| entry::storage(b, vertex, true)),
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let skin_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shell skinning"),
            entries: &[
                entry::storage(0, compute, true),
                entry::storage(1, compute, true),
                entry::storage(2, compute, true),
                entry::storage(3, compute, false),
            ],
        });
        let sampler = |mode, mips| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shell"),
                address_mode_u: mode,
                address_mode_v: mode,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: mips,
                ..Default::default()
            })
        };
        let fur_sampler = sampler(wgpu::AddressMode::Repeat, wgpu::MipmapFilterMode::Linear);
        let color_sampler = sampler(
            wgpu::AddressMode::ClampToEdge,
            wgpu::MipmapFilterMode::Nearest,
        );
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shells"),
            bind_group_layouts: &[Some(&uniform_layout), Some(&texture_layout)],
            immediate_size: 0,
        });
        let fin_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shell fins"),
            bind_group_layouts: &[
                Some(&uniform_layout),
                Some(&texture_layout),
                Some(&fin_layout),
            ],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shells.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::shader_source("shells.wgsl")),
        });
        let pass_pipeline = |kind| {
            let layout = match kind {
                PassKind::Fins => &fin_pipeline_layout,
                _ => &layout,
            };
            shell_pipeline(device, kind, &module, layout, formats, features)
        };
        let skin_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("skin.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::shader_source("skin.wgsl")),
        });
        let skinning = compute_pipeline(
            device,
            "shell skinning",
            &skin_module,
            "skin",
            &[&skin_layout],
        );
        let uniforms = UniformRing::new(device, "shell uniforms", &uniform_layout);
        Self {
            skin_pipeline: pass_pipeline(PassKind::Skin),
            layer_pipeline: pass_pipeline(PassKind::Layers),
            fin_pipeline: pass_pipeline(PassKind::Fins),
            skinning,
            uniforms,
            texture_layout,
            fin_layout,
            skin_layout,
            fur_sampler,
            color_sampler,
            formats,
            features,
        }
    }

    /// The effects this renderer computes.
    pub fn features(&self) -> ShellFeatures {
        self.features
    }

    /// The colour format it draws into.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.formats.color
    }

    /// The targets it draws into.
    pub fn target_formats(&self) -> ShellTargetFormats {
        self.formats
    }
}

impl ShellRenderer {
    /// Draws one frame into `target` and waits for the GPU to finish (the
    /// benchmark times this); read the image with [`render`](Self::render).
    pub fn draw(
        &self,
        ctx: &GpuContext,
        model: &ShellModel,
        params: &ShellParams,
        view: &ShellView,
        target: &ShellTarget,
    ) -> Result<(), GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let resolved = target.resolved.create_view(&Default::default());
        self.encode(ctx, &mut encoder, model, params, view, target, &resolved)?;
        ctx.queue.submit([encoder.finish()]);
        ctx.wait()
    }

    /// Draws one frame and reads it back.
    pub fn render(
        &self,
        ctx: &GpuContext,
        model: &ShellModel,
        params: &ShellParams,
        view: &ShellView,
        target: &ShellTarget,
    ) -> Result<image::RgbaImage, GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let resolved = target.resolved.create_view(&Default::default());
        self.encode(ctx, &mut encoder, model, params, view, target, &resolved)?;
        crate::readback::read_texture(ctx, encoder, &target.resolved)
    }

    /// Records a frame into pelage's own `target`: a pass cleared to the
    /// background with [`Self::record`] in it, resolved into `resolve` (a
    /// view of `target`'s size: the target's own resolve texture, or a
    /// window's surface texture).
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        model: &ShellModel,
        params: &ShellParams,
        view: &ShellView,
        target: &ShellTarget,
        resolve: &wgpu::TextureView,
    ) -> Result<ShellLevel, GpuError> {
        let levels = self.encode_all(ctx, encoder, &[(model, *params)], view, target, resolve)?;
        Ok(levels[0])
    }

    /// [`Self::encode`] for several objects (a crowd) in one pass, each
    /// with its own parameters (its `offset` places it; the first's
    /// background clears the image); the level of detail each was drawn
    /// at.
    pub fn encode_all(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        objects: &[(&ShellModel, ShellParams)],
        view: &ShellView,
        target: &ShellTarget,
        resolve: &wgpu::TextureView,
    ) -> Result<Vec<ShellLevel>, GpuError> {
        let background = objects.first().map_or([0.0; 3], |(_, p)| p.background);
        let mut pass = target.begin_pass(encoder, "shells", resolve, background);
        let height = target.size.1 as f32;
        objects
            .iter()
            .map(|(model, params)| self.record(&ctx.queue, &mut pass, model, params, view, height))
            .collect()
    }

    /// The level of detail `model` is drawn at with `params` from `view`,
    /// in an image `height` pixels high.
    pub fn level(
        &self,
        model: &ShellModel,
        params: &ShellParams,
        view: &ShellView,
        height: f32,
    ) -> ShellLevel {
        let Some(lod) = params.lod else {
            return ShellLevel::full(params.layers);
        };
        let (lo, hi) = model.bounds;
        let centre = 0.5 * (lo + hi) + params.offset;
        let fur_px = view.projected_length(centre, params.length, height);
        let object_px = view.projected_length(centre, (hi - lo).length(), height);
        let mut level = lod.level(
            params.layers,
            fur_px,
            model.texture_resolution,
            params.tiles,
            object_px,
        );
        level.mip = level.mip.min(model.mip_levels.saturating_sub(1) as f32);
        level
    }

    /// Records one furry object into the caller's render pass, which must
    /// draw into targets of [`Self::target_formats`] with a depth
    /// attachment: the skin (writing depth), the layers of its level of
    /// detail, and its fins — or nothing, when its bounds
    /// ([`ShellModel::set_bounds`]) grown by the fur are outside the view. `height` is the target's height in pixels
    /// (for the level of detail). The uniforms are written through
    /// `queue`, so submit after this call; up to 1,024 objects a
    /// submission.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        pass: &mut wgpu::RenderPass<'_>,
        model: &ShellModel,
        params: &ShellParams,
        view: &ShellView,
        height: f32,
    ) -> Result<ShellLevel, GpuError> {
        if params.layers > model.layers {
            return Err(GpuError::Mismatch(format!(
                "{} layers drawn from a shell texture of {}",
                params.layers, model.layers
            )));
        }
        let (lo, hi) = model.bounds;
        let radius = 0.5 * (hi - lo).length() + params.length;
        if !view.sees_sphere(0.5 * (lo + hi) + params.offset, radius) {
            return Ok(ShellLevel::CULLED);
        }
        let level = self.level(model, params, view, height);
        let k = params.kajiya_kay;
        let fins = params.fins.filter(|f| f.opacity > 0.0);
        let uniforms = ShellUniforms {
            view_proj: view.clip_from_world.to_cols_array_2d(),
            eye: view.eye.to_array(),
            shell_length: params.length,
            light_dir: view.light.normalize().to_array(),
            layers: params.layers,
            specular: k.specular.to_array(),
            specular_exponent: k.exponent,
            motion: params.offset.to_array(),
            coupling_exponent: params.coupling.exponent(),
            tiles: params.tiles,
            k_shadow: k.k_shadow,
            curl_radius: params.curl.radius,
            curl_frequency: params.curl.frequency,
            shading_mode: params.mode.index(),
            coupling: params.coupling.index(),
            clump_w: params.clump.w,
            clump_strength: params.clump.strength,
            wetness_size: [model.wetness_size.0 as f32, model.wetness_size.1 as f32],
            lod_layers: level.layers,
            fur_mip: level.mip,
            fin_opacity: fins.map_or(0.0, |f| f.opacity),
            fin_width: fins.map_or(1.0, |f| f.width.max(1e-3)),
            fur_opacity: params.opacity.clamp(0.0, 1.0),
            pad0: 0.0,
        };
        let uniform_offset = self.uniforms.write(queue, &uniforms);
        pass.set_bind_group(0, self.uniforms.group(), &[uniform_offset]);
        pass.set_bind_group(1, &model.textures, &[]);
        pass.set_vertex_buffer(0, model.pose.slice(..));
        pass.set_vertex_buffer(1, model.surface.slice(..));
        pass.set_vertex_buffer(2, model.tip_offsets.slice(..));
        pass.set_index_buffer(model.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_pipeline(&self.skin_pipeline);
        pass.draw_indexed(0..model.index_count, 0, 0..1);
        pass.set_pipeline(&self.layer_pipeline);
        pass.draw_indexed(0..model.index_count, 0, 0..level.drawn());
        if let (Some(_), Some((group, count))) = (fins, &model.fins) {
            pass.set_pipeline(&self.fin_pipeline);
            pass.set_bind_group(2, group, &[]);
            pass.draw(0..6 * count, 0..1);
        }
        Ok(level)
    }

    /// Records the skinning pass of a skinned `model` into the caller's
    /// encoder: every vertex posed by `palette` (the rig's, e.g.
    /// [`pelage::shell::ShellAnimation::palette_at`]). Record it before the
    /// frame that draws the model.
    pub fn pose(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        model: &ShellModel,
        palette: &[Mat4],
    ) -> Result<(), GpuError> {
        let Some(skin) = &model.skin else {
            return Err(GpuError::Mismatch(
                "a palette for a model uploaded without a rig".into(),
            ));
        };
        if palette.len() != skin.palette_len {
            return Err(GpuError::Mismatch(format!(
                "a palette of {} matrices for a rig of {}",
                palette.len(),
                skin.palette_len
            )));
        }
        let columns: Vec<[f32; 16]> = palette.iter().map(Mat4::to_cols_array).collect();
        queue.write_buffer(&skin.palette, 0, bytemuck::cast_slice(&columns));
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("shell skinning"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.skinning);
        pass.set_bind_group(0, &skin.bind, &[]);
        let (x, y) = crate::workgroups(model.vertex_count);
        pass.dispatch_workgroups(x, y, 1);
        Ok(())
    }

    /// [`Self::pose`] submitted on its own.
    pub fn pose_now(
        &self,
        ctx: &GpuContext,
        model: &ShellModel,
        palette: &[Mat4],
    ) -> Result<(), GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.pose(&ctx.queue, &mut encoder, model, palette)?;
        ctx.queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// The three draws of a shell frame.
#[derive(Clone, Copy, PartialEq)]
enum PassKind {
    /// The skin, with depth write.
    Skin,
    /// The instanced layers, blended in order.
    Layers,
    /// The fins on the edges seen edge-on.
    Fins,
}

/// The render pipeline of one draw, specialised by `features` (override
/// constants) for `formats`.
fn shell_pipeline(
    device: &wgpu::Device,
    kind: PassKind,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    formats: ShellTargetFormats,
    features: ShellFeatures,
) -> wgpu::RenderPipeline {
    let constants = [
        ("CURL", f64::from(u8::from(features.curl))),
        ("CLUMP", f64::from(u8::from(features.clump))),
    ];
    let vertex_buffers = [
        Some(PoseVertex::layout(wgpu::VertexStepMode::Vertex)),
        Some(SurfaceVertex::layout(wgpu::VertexStepMode::Vertex)),
        Some(TipOffset::layout(wgpu::VertexStepMode::Vertex)),
    ];
    let compilation_options = wgpu::PipelineCompilationOptions {
        constants: &constants,
        ..Default::default()
    };
    let (label, vs, fs, buffers): (_, _, _, &[_]) = match kind {
        PassKind::Skin => ("shell skin", "vs_skin", "fs_skin", &vertex_buffers),
        PassKind::Layers => ("shell layers", "vs_layer", "fs_layer", &vertex_buffers),
        PassKind::Fins => ("shell fins", "vs_fin", "fs_fin", &[]),
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vs),
            compilation_options: compilation_options.clone(),
            buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: (features.cull_back && kind != PassKind::Fins).then_some(wgpu::Face::Back),
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: formats.depth,
            depth_write_enabled: Some(kind == PassKind::Skin),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: formats.samples,
            mask: !0,
            alpha_to_coverage_enabled: false,
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fs),
            compilation_options,
            targets: &[Some(wgpu::ColorTargetState {
                format: formats.color,
                blend: (kind != PassKind::Skin).then_some(wgpu::BlendState::ALPHA_BLENDING),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Colour, depth and resolve targets of one size, reused frame to frame.
#[derive(Debug)]
pub struct ShellTarget {
    pub(crate) color: wgpu::TextureView,
    pub(crate) depth: wgpu::TextureView,
    pub(crate) resolved: wgpu::Texture,
    pub(crate) size: (u32, u32),
}

impl ShellTarget {
    /// A pass into this target, cleared to `background` (linear RGB) and
    /// the far depth, resolved into `resolve` (a view of its size: its own
    /// resolve texture, or a window's surface texture).
    pub(crate) fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        resolve: &wgpu::TextureView,
        background: [f32; 3],
    ) -> wgpu::RenderPass<'e> {
        let [r, g, b] = background.map(f64::from);
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.color,
                depth_slice: None,
                resolve_target: Some(resolve),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                    store: wgpu::StoreOp::Discard,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// Targets for `width × height` images.
    pub fn new(
        ctx: &GpuContext,
        renderer: &ShellRenderer,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        check_size(ctx, width, height)?;
        let texture = |samples, format, usage| {
            target_texture(
                &ctx.device,
                "shell target",
                (width, height),
                samples,
                format,
                usage,
            )
        };
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let formats = renderer.formats;
        Ok(Self {
            color: texture(formats.samples, formats.color, attach).create_view(&Default::default()),
            depth: texture(formats.samples, formats.depth, attach).create_view(&Default::default()),
            resolved: texture(1, formats.color, attach | wgpu::TextureUsages::COPY_SRC),
            size: (width, height),
        })
    }

    /// The image size.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The resolved (single-sample) image, e.g. to read back.
    pub fn resolved(&self) -> &wgpu::Texture {
        &self.resolved
    }

    /// A view of the resolved image, to resolve a pass into (the `resolve`
    /// of [`ShellRenderer::encode`](super::ShellRenderer::encode)).
    pub fn resolve_view(&self) -> wgpu::TextureView {
        self.resolved.create_view(&Default::default())
    }
}
