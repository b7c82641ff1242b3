//! [`ShellRenderer`]: the pipelines (specialised per [`ShellFeatures`]) and
//! the frame they record: the skin once with depth write, then the N
//! layers in one instanced draw.

use crate::layout::UniformRing;
use crate::renderer::{COLOR_FORMAT, DEPTH_FORMAT, SAMPLES};
use crate::{GpuContext, GpuError};

use super::model::{ShellModel, ShellTarget};
use super::{ShellFeatures, ShellParams, ShellUniforms, ShellVertex, ShellView, TipOffset};

/// Draws shell fur. Build once per feature set, draw many frames.
#[derive(Debug)]
pub struct ShellRenderer {
    /// The frame's [`ShellUniforms`], made once, rewritten for each frame.
    pub(super) uniforms: UniformRing<ShellUniforms>,
    pub(super) texture_layout: wgpu::BindGroupLayout,
    pub(super) fur_sampler: wgpu::Sampler,
    pub(super) color_sampler: wgpu::Sampler,
    pub(super) skin_pipeline: wgpu::RenderPipeline,
    pub(super) layer_pipeline: wgpu::RenderPipeline,
    pub(super) format: wgpu::TextureFormat,
    pub(super) features: ShellFeatures,
}

impl ShellRenderer {
    /// Pipelines for offscreen images.
    pub fn new(ctx: &GpuContext, features: ShellFeatures) -> Self {
        Self::for_format(ctx, COLOR_FORMAT, features)
    }

    /// Pipelines for targets of `format` (use an sRGB format).
    pub fn for_format(
        ctx: &GpuContext,
        format: wgpu::TextureFormat,
        features: ShellFeatures,
    ) -> Self {
        let device = &ctx.device;
        let uniform_layout = UniformRing::<ShellUniforms>::layout(
            device,
            "shell uniforms",
            wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
        );
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let texture_entry = |binding, dimension, filterable| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: both,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable },
                view_dimension: dimension,
                multisampled: false,
            },
            count: None,
        };
        let sampler_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: both,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        };
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shell textures"),
            entries: &[
                texture_entry(0, wgpu::TextureViewDimension::D2Array, true),
                sampler_entry(1),
                texture_entry(2, wgpu::TextureViewDimension::D2, true),
                sampler_entry(3),
                texture_entry(4, wgpu::TextureViewDimension::D2, false),
            ],
        });
        let sampler = |mode| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shell"),
                address_mode_u: mode,
                address_mode_v: mode,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            })
        };
        let fur_sampler = sampler(wgpu::AddressMode::Repeat);
        let color_sampler = sampler(wgpu::AddressMode::ClampToEdge);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shells"),
            bind_group_layouts: &[Some(&uniform_layout), Some(&texture_layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shells.wgsl"),
            source: wgpu::ShaderSource::Wgsl(crate::shader_source("shells.wgsl").into()),
        });
        let constants = [
            ("CURL", f64::from(u8::from(features.curl))),
            ("CLUMP", f64::from(u8::from(features.clump))),
        ];
        let pipeline = |vs: &str, fs: &str, layers: bool| {
            let compilation_options = wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            };
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(if layers { "shell layers" } else { "shell skin" }),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: compilation_options.clone(),
                    buffers: &[
                        Some(ShellVertex::layout(wgpu::VertexStepMode::Vertex)),
                        Some(TipOffset::layout(wgpu::VertexStepMode::Vertex)),
                    ],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(!layers),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: SAMPLES,
                    mask: !0,
                    alpha_to_coverage_enabled: false,
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options,
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: layers.then_some(wgpu::BlendState::ALPHA_BLENDING),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let uniforms = UniformRing::new(device, "shell uniforms", &uniform_layout);
        Self {
            skin_pipeline: pipeline("vs_skin", "fs_skin", false),
            layer_pipeline: pipeline("vs_layer", "fs_layer", true),
            uniforms,
            texture_layout,
            fur_sampler,
            color_sampler,
            format,
            features,
        }
    }

    /// The effects this renderer computes.
    pub fn features(&self) -> ShellFeatures {
        self.features
    }

    /// The colour format it draws into.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }
}

impl ShellRenderer {
    /// Draws one frame into `target` and waits for the GPU to finish (the
    /// benchmark times this); read the image with [`read`](Self::read).
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
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        Ok(())
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

    /// Records a frame: the skin, then the layers, resolved into
    /// `resolve` (a view of `target`'s size: the target's own resolve
    /// texture, or a window's surface texture).
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
    ) -> Result<(), GpuError> {
        if params.layers > model.layers {
            return Err(GpuError::Mismatch(format!(
                "{} layers drawn from a shell texture of {}",
                params.layers, model.layers
            )));
        }
        let k = params.kajiya_kay;
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
            pad0: [0.0; 2],
        };
        let uniform_offset = self.uniforms.write(&ctx.queue, &uniforms);
        let [r, g, b] = params.background.map(f64::from);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shells"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.color,
                depth_slice: None,
                resolve_target: Some(resolve),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                    store: wgpu::StoreOp::Discard,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, self.uniforms.group(), &[uniform_offset]);
        pass.set_bind_group(1, &model.textures, &[]);
        pass.set_vertex_buffer(0, model.vertices.slice(..));
        pass.set_vertex_buffer(1, model.tip_offsets.slice(..));
        pass.set_pipeline(&self.skin_pipeline);
        pass.draw(0..model.vertex_count, 0..1);
        pass.set_pipeline(&self.layer_pipeline);
        pass.draw(0..model.vertex_count, 0..params.layers);
        Ok(())
    }
}
