//! The shell-fur renderer (Silva §4, Lengyel et al.): the skin once with
//! depth write, then the N layers in one instanced draw — depth test on,
//! depth write off, blended in layer order. Layer displacement (Eq. 1,
//! curl Eq. 4) runs in the vertex shader, clumping (Alg. 2) and shading
//! (Eq. 6) in the fragment shader; `shaders/shells.wgsl` mirrors
//! `pelage::shell::math` function by function.
//!
//! Pipelines are specialised with WGSL override constants — plain shells,
//! with curl, with curl and clumps ([`ShellFeatures`]) — so the benchmark
//! compares like with like.

use crate::layout::gpu_struct;
use crate::renderer::{COLOR_FORMAT, DEPTH_FORMAT, SAMPLES, check_size};
use crate::{Camera, FurMotion, GpuContext, GpuError};
use glam::{Mat4, Vec3};
use pelage::Mesh;

use pelage::shell::math::{ClumpParams, Coupling, CurlParams, KajiyaKay, ShadingMode};
use pelage::shell::{ShellScene, ShellTextures, WetnessMask};
use wgpu::util::DeviceExt;

/// Which effects a pipeline computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ShellFeatures {
    /// Curl (Eq. 4) in the vertex shader: reads the wetness mask per vertex.
    pub curl: bool,
    /// Clumping (Alg. 2) in the fragment shader: reads the mask per fragment.
    pub clump: bool,
}

impl ShellFeatures {
    /// Plain shells: layers along the strand, no curl, no clumps.
    pub const PLAIN: Self = Self {
        curl: false,
        clump: false,
    };
    /// Curl and clumps.
    pub const ALL: Self = Self {
        curl: true,
        clump: true,
    };
}

/// How to draw the fur: everything the shaders read besides textures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellParams {
    /// Number of layers N.
    pub layers: u32,
    /// Shell length L0 (world units).
    pub length: f32,
    /// Shell texture repeats across the UV square.
    pub tiles: f32,
    /// Curl (Eq. 4).
    pub curl: CurlParams,
    /// How the strands' tips bend the layers (Silva's Bézier, Banisch's
    /// linear or bent layers).
    pub coupling: Coupling,
    /// The whole skin moved by this (an object being shaken).
    pub offset: Vec3,
    /// Clumping (Eq. 5).
    pub clump: ClumpParams,
    /// Shading stage.
    pub mode: ShadingMode,
    /// Specular colour, exponent and `K_shadow`.
    pub kajiya_kay: KajiyaKay,
    /// Behind the fur (linear RGB).
    pub background: [f32; 3],
}

/// Where the fur is seen from, and lit from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellView {
    /// Clip from world (wgpu depth 0..1).
    pub clip_from_world: Mat4,
    /// The eye, for `E` in Eq. 6.
    pub eye: Vec3,
    /// Unit direction towards the light.
    pub light: Vec3,
}

impl ShellView {
    /// A perspective view through `camera` (framed on the mesh's bounds
    /// grown by the shell length when `None`), with a key light above and
    /// beside the camera unless `light` is given.
    pub fn new(
        camera: Option<Camera>,
        bounds: (Vec3, Vec3),
        length: f32,
        aspect: f32,
        light: Option<Vec3>,
    ) -> Self {
        let (lo, hi) = (
            bounds.0 - Vec3::splat(length),
            bounds.1 + Vec3::splat(length),
        );
        let camera = camera.unwrap_or_else(|| Camera::framing(lo, hi, aspect));
        let radius =
            (0.5 * (hi - lo)).length().max(1e-6) + (0.5 * (lo + hi) - camera.target).length();
        let view = (camera.eye - camera.target).normalize();
        let side = view.cross(Vec3::Y).normalize_or_zero();
        Self {
            clip_from_world: camera.clip_from_world(aspect, radius),
            eye: camera.eye,
            light: light.unwrap_or((view + 0.9 * Vec3::Y + 0.6 * side).normalize()),
        }
    }
}

gpu_struct! {
    /// The uniform block of `shells.wgsl` (`struct Shell`).
    pub(crate) struct ShellUniforms {
        view_proj: [[f32; 4]; 4],
        eye: [f32; 3],
        /// L0: the outermost layer's height above the skin.
        shell_length: f32,
        /// Unit direction towards the light.
        light_dir: [f32; 3],
        /// N: layers drawn.
        layers: u32,
        /// Kajiya-Kay's K_s.
        specular: [f32; 3],
        /// p_phong.
        specular_exponent: f32,
        /// The whole skin moved by this (a shaken object).
        motion: [f32; 3],
        /// Eq. 4's k, for the bent coupling.
        coupling_exponent: f32,
        /// Shell texture repeats across the UV square.
        tiles: f32,
        k_shadow: f32,
        /// K_α and ω of the curl.
        curl_radius: f32,
        curl_frequency: f32,
        /// [`ShadingMode::index`](pelage::shell::math::ShadingMode::index).
        shading_mode: u32,
        /// [`Coupling::index`](pelage::shell::Coupling::index).
        coupling: u32,
        clump_w: f32,
        clump_strength: f32,
        /// The wetness mask's size in texels.
        wetness_size: [f32; 2],
        pad0: [f32; 2],
    }
}

/// A furry mesh on the GPU: skin vertices with their frames, the shell
/// texture layers, the colour texture and the wetness mask.
#[derive(Debug)]
pub struct ShellModel {
    vertices: wgpu::Buffer,
    /// p − p0 per triangle corner; `GpuMassSpring` writes it in place.
    pub(crate) tip_offsets: wgpu::Buffer,
    pub(crate) vertex_count: u32,
    wetness: wgpu::Texture,
    wetness_size: (u32, u32),
    textures: wgpu::BindGroup,
    layers: u32,
    bounds: (Vec3, Vec3),
}

impl ShellModel {
    /// The skin's bounds.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// The number of layers in the shell texture.
    pub fn texture_layers(&self) -> u32 {
        self.layers
    }
}

/// Colour, depth and resolve targets of one size, reused frame to frame.
#[derive(Debug)]
pub struct ShellTarget {
    color: wgpu::TextureView,
    depth: wgpu::TextureView,
    resolved: wgpu::Texture,
    size: (u32, u32),
}

impl ShellTarget {
    /// Targets for `width × height` images.
    pub fn new(
        ctx: &GpuContext,
        renderer: &ShellRenderer,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        check_size(ctx, width, height)?;
        let texture = |samples: u32, format: wgpu::TextureFormat, usage: wgpu::TextureUsages| {
            ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("shell target"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        Ok(Self {
            color: texture(SAMPLES, renderer.format, attach).create_view(&Default::default()),
            depth: texture(SAMPLES, DEPTH_FORMAT, attach).create_view(&Default::default()),
            resolved: texture(1, renderer.format, attach | wgpu::TextureUsages::COPY_SRC),
            size: (width, height),
        })
    }

    /// The image size.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }
}

/// Draws shell fur. Build once per feature set, draw many frames.
#[derive(Debug)]
pub struct ShellRenderer {
    /// The frame's [`ShellUniforms`], rewritten (`write_buffer`) for each
    /// frame, and their bind group, both made once.
    uniforms: wgpu::Buffer,
    uniform_group: wgpu::BindGroup,
    texture_layout: wgpu::BindGroupLayout,
    fur_sampler: wgpu::Sampler,
    color_sampler: wgpu::Sampler,
    skin_pipeline: wgpu::RenderPipeline,
    layer_pipeline: wgpu::RenderPipeline,
    format: wgpu::TextureFormat,
    features: ShellFeatures,
}

/// Vertex layout: position, normal, mask uv, dP/du; tip offsets come from
/// a second buffer, rewritten as the fur moves.
const VERTEX_FLOATS: usize = 11;

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
        let uniform_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shell uniforms"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
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
        let vertex_attributes = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Float32x3
        ];
        let tip_attributes = wgpu::vertex_attr_array![4 => Float32x3];
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
                        Some(wgpu::VertexBufferLayout {
                            array_stride: (VERTEX_FLOATS * 4) as u64,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &vertex_attributes,
                        }),
                        Some(wgpu::VertexBufferLayout {
                            array_stride: 12,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &tip_attributes,
                        }),
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
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shell uniforms"),
            size: std::mem::size_of::<ShellUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let uniform_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shell uniforms"),
            layout: &uniform_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        Self {
            skin_pipeline: pipeline("vs_skin", "fs_skin", false),
            layer_pipeline: pipeline("vs_layer", "fs_layer", true),
            uniforms,
            uniform_group,
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

    /// Copies a furry mesh to the GPU: one vertex per triangle corner (UVs
    /// may be per corner) with its strand frame, the shell layers, the
    /// colour texture (sRGB) and a dry wetness mask of `mask_size`².
    /// Meshes without UVs are refused: the fur is textured by UV.
    pub fn upload(
        &self,
        ctx: &GpuContext,
        mesh: &Mesh,
        color: &image::RgbaImage,
        textures: &ShellTextures,
        mask_size: u32,
    ) -> Result<ShellModel, GpuError> {
        if !mesh.has_uvs() {
            return Err(GpuError::NoUvs(mesh.name().to_string()));
        }
        let device = &ctx.device;
        let tangents = vertex_tangents(mesh);
        let mut vertices: Vec<f32> = Vec::with_capacity(mesh.triangle_count() * 3 * VERTEX_FLOATS);
        for t in 0..mesh.triangle_count() {
            let uvs = mesh.triangle_uvs(t).expect("checked: the mesh has UVs");
            for (k, &v) in mesh.triangles()[t].iter().enumerate() {
                let (p, n, u) = (
                    mesh.positions()[v as usize],
                    mesh.normals()[v as usize],
                    tangents[v as usize],
                );
                let uv = pelage::shell::wetness::mask_coordinates(uvs[k]);
                vertices
                    .extend_from_slice(&[p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y, u.x, u.y, u.z]);
            }
        }
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shell skin"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let tip_offsets = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shell tip offsets"),
            contents: bytemuck::cast_slice(&vec![0.0f32; mesh.triangle_count() * 9]),
            usage: wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::STORAGE,
        });
        let size = |w, h, layers| wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: layers,
        };
        let texture = |label, extent, format, data: &[u8]| {
            device.create_texture_with_data(
                &ctx.queue,
                &wgpu::TextureDescriptor {
                    label: Some(label),
                    size: extent,
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                data,
            )
        };
        let r = textures.resolution();
        let fur = texture(
            "shell layers",
            size(r, r, textures.layers()),
            wgpu::TextureFormat::Rgba8Unorm,
            bytemuck::cast_slice(textures.texels()),
        );
        let color_texture = texture(
            "fur colour",
            size(color.width(), color.height(), 1),
            wgpu::TextureFormat::Rgba8UnormSrgb,
            color.as_raw(),
        );
        let mask_size = mask_size.max(1);
        let dry = WetnessMask::dry_mask(mask_size, mask_size);
        let wetness = texture(
            "wetness mask",
            size(mask_size, mask_size, 1),
            wgpu::TextureFormat::Rgba32Float,
            bytemuck::cast_slice(&dry.to_rgba()),
        );
        let fur_view = fur.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let color_view = color_texture.create_view(&Default::default());
        let wetness_view = wetness.create_view(&Default::default());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shell textures"),
            layout: &self.texture_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&fur_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.fur_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&color_view),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(&self.color_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&wetness_view),
                },
            ],
        });
        Ok(ShellModel {
            vertices: vertex_buffer,
            tip_offsets,
            vertex_count: (mesh.triangle_count() * 3) as u32,
            wetness,
            wetness_size: (mask_size, mask_size),
            textures: bind,
            layers: textures.layers(),
            bounds: mesh.bounds(),
        })
    }

    /// Generates a scene's shell texture and uploads the scene
    /// ([`Self::upload`] with the scene's mesh, colour and mask size).
    pub fn upload_scene(
        &self,
        ctx: &GpuContext,
        scene: &ShellScene,
    ) -> Result<ShellModel, GpuError> {
        let textures = ShellTextures::generate(&scene.texture);
        self.upload(
            ctx,
            &scene.mesh,
            &scene.color,
            &textures,
            scene.wetness_resolution,
        )
    }

    /// Moves the strands' tips: one offset `p − p0` per triangle corner
    /// (`3t + k`), as [`pelage::dynamics::MassSpringSystem::corner_tip_offsets`]
    /// gives them.
    pub fn set_tip_offsets(
        &self,
        ctx: &GpuContext,
        model: &ShellModel,
        offsets: &[Vec3],
    ) -> Result<(), GpuError> {
        if offsets.len() != model.vertex_count as usize {
            return Err(GpuError::Mismatch(format!(
                "{} tip offsets for a model with {} triangle corners",
                offsets.len(),
                model.vertex_count
            )));
        }
        let flat: Vec<f32> = offsets.iter().flat_map(|o| o.to_array()).collect();
        ctx.queue
            .write_buffer(&model.tip_offsets, 0, bytemuck::cast_slice(&flat));
        Ok(())
    }

    /// Replaces the model's wetness mask (same size as uploaded).
    pub fn set_wetness(
        &self,
        ctx: &GpuContext,
        model: &ShellModel,
        mask: &WetnessMask,
    ) -> Result<(), GpuError> {
        if (mask.width(), mask.height()) != model.wetness_size {
            return Err(GpuError::Mismatch(format!(
                "a {}×{} wetness mask for a model uploaded with {}×{}",
                mask.width(),
                mask.height(),
                model.wetness_size.0,
                model.wetness_size.1
            )));
        }
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &model.wetness,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&mask.to_rgba()),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(16 * mask.width()),
                rows_per_image: Some(mask.height()),
            },
            wgpu::Extent3d {
                width: mask.width(),
                height: mask.height(),
                depth_or_array_layers: 1,
            },
        );
        Ok(())
    }

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
        crate::renderer::read_texture(ctx, encoder, &target.resolved)
    }

    /// Records a frame: the skin, then the layers, resolved into
    /// `resolve` (a view of `target`'s size: the target's own resolve
    /// texture, or a window's surface texture). Submit it before encoding
    /// the next frame: the frame's settings live in one uniform buffer
    /// that each `encode` rewrites.
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
        // Written before the encoder's commands run (write_buffer is queued
        // ahead of the next submission): one frame per submission.
        ctx.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
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
        pass.set_bind_group(0, &self.uniform_group, &[]);
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

/// Per-vertex `dP/du` (the texture's x direction on the surface), averaged
/// over the triangles around each vertex and made perpendicular to its
/// normal, so neighbouring triangles curl the same way and layers do not
/// tear. Vertices where UVs give no direction get any tangent.
pub fn vertex_tangents(mesh: &Mesh) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; mesh.vertex_count()];
    for t in 0..mesh.triangle_count() {
        let Some([t0, t1, t2]) = mesh.triangle_uvs(t) else {
            break;
        };
        let [p0, p1, p2] = mesh.triangle_positions(t);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let (d1, d2) = (t1 - t0, t2 - t0);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() <= f32::EPSILON {
            continue;
        }
        // Area-weighted: the cross product's length is twice the area.
        let dp_du = ((e1 * d2.y - e2 * d1.y) / det).normalize_or_zero() * e1.cross(e2).length();
        for &v in &mesh.triangles()[t] {
            sum[v as usize] += dp_du;
        }
    }
    sum.iter()
        .zip(mesh.normals())
        .map(|(&s, &n)| {
            (s - n * n.dot(s))
                .try_normalize()
                .unwrap_or_else(|| n.any_orthonormal_vector())
        })
        .collect()
}

impl ShellParams {
    /// The parameters a scene file sets, on the grey-blue background of
    /// the groom previews (white fur on white would vanish).
    pub fn from_scene(scene: &ShellScene) -> Self {
        Self {
            layers: scene.fur.layers,
            length: scene.fur.length,
            tiles: scene.fur.tiles,
            curl: scene.curl,
            clump: scene.clump.unwrap_or(ClumpParams {
                w: 0.0,
                strength: 0.0,
            }),
            coupling: Coupling::Bezier,
            offset: Vec3::ZERO,
            mode: scene.shading.mode,
            kajiya_kay: scene.shading.kajiya_kay,
            background: [0.62, 0.66, 0.72],
        }
    }
}

/// A scene file drawn frame by frame: the model uploaded once, the
/// wetness mask advanced in time (droplets falling, fur drying) and
/// re-uploaded each frame.
#[derive(Debug)]
pub struct ShellScenePlayer<'s> {
    scene: &'s ShellScene,
    renderer: ShellRenderer,
    model: ShellModel,
    target: ShellTarget,
    /// What is drawn; change it between frames.
    pub params: ShellParams,
    /// From where; change it between frames.
    pub view: ShellView,
    timeline: pelage::shell::scene::WetnessTimeline<'s>,
    motion: Option<FurMotion>,
}

impl<'s> ShellScenePlayer<'s> {
    /// Generates the shell texture, uploads the scene and sets up
    /// `width × height` targets. Curl and clumping are computed when the
    /// scene asks for them.
    pub fn new(
        ctx: &GpuContext,
        scene: &'s ShellScene,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        let features = ShellFeatures {
            curl: scene.curl.radius != 0.0,
            clump: scene.clump.is_some(),
        };
        let renderer = ShellRenderer::new(ctx, features);
        let model = renderer.upload_scene(ctx, scene)?;
        let target = ShellTarget::new(ctx, &renderer, width, height)?;
        let camera = scene.camera.map(|c| Camera {
            eye: c.eye,
            target: c.target,
            fov_y_degrees: c.fov_y_degrees,
        });
        let view = ShellView::new(
            camera,
            scene.mesh.bounds(),
            scene.fur.length,
            width as f32 / height as f32,
            scene.light,
        );
        Ok(Self {
            scene,
            renderer,
            model,
            target,
            params: ShellParams::from_scene(scene),
            view,
            timeline: scene.wetness_timeline(),
            motion: scene
                .dynamics
                .as_ref()
                .map(|d| FurMotion::new(&scene.mesh, d.topology, scene.fur.length)),
        })
    }

    /// Runs the scene's mass-spring system up to `time`, in steps of
    /// `1 / (fps · steps_per_frame)`, moving the skin as the shake says.
    fn simulate_to(&mut self, ctx: &GpuContext, time: f32) -> Result<(), GpuError> {
        let (Some(motion), Some(settings)) = (&mut self.motion, &self.scene.dynamics) else {
            return Ok(());
        };
        let dt = 1.0 / (self.scene.fps * settings.steps_per_frame as f32);
        let shake = |t: f32| settings.shake.map_or(Vec3::ZERO, |s| s.offset(t));
        while motion.time() + 0.5 * dt < time {
            let offset = shake(motion.time() + dt);
            motion.step(ctx, dt, offset, settings)?;
        }
        self.params.coupling = settings.coupling;
        self.params.offset = shake(motion.time());
        motion.show(ctx, &self.renderer, &self.model)
    }

    /// The frame at `time` seconds (not before the last one drawn).
    pub fn render_at(&mut self, ctx: &GpuContext, time: f32) -> Result<image::RgbaImage, GpuError> {
        self.simulate_to(ctx, time)?;
        let mask = self.timeline.advance_to(time);
        self.renderer.set_wetness(ctx, &self.model, mask)?;
        self.renderer
            .render(ctx, &self.model, &self.params, &self.view, &self.target)
    }

    /// The wetness mask as of the last frame.
    pub fn wetness(&self) -> &WetnessMask {
        self.timeline.mask()
    }

    /// The scene.
    pub fn scene(&self) -> &'s ShellScene {
        self.scene
    }
}
