//! The preview renderer: the skin mesh (lit), points (discs) and curves
//! (Kajiya-Kay ribbons) into an image, multisampled, with depth.
//!
//! One file, past 600 lines: the three preview pipelines (skin, points,
//! curves) share one frame uniform and one pass.

use crate::layout::{UniformRing, entry, gpu_struct, gpu_vertex, group};
use crate::readback::{is_bgra, read_texture};
use crate::{Camera, GpuContext, GpuError};
use glam::Vec3;
use pelage::{Curves, Mesh};
use wgpu::util::DeviceExt;

/// Multisampling: 4 samples per pixel (every Vulkan device supports 4).
pub(crate) const SAMPLES: u32 = 4;
/// Stored sRGB-encoded; shaders work in linear light.
pub(crate) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// What to draw.
#[derive(Debug, Clone, Copy, Default)]
pub struct PreviewScene<'a> {
    /// The skin, if any.
    pub mesh: Option<&'a Mesh>,
    /// Points (hair roots, samples) in world space.
    pub points: &'a [Vec3],
    /// Hair curves, drawn as ribbons of their widths, in their own colours
    /// where they have them.
    pub curves: Option<&'a Curves>,
    /// A colour texture for the skin (sRGB), read at the mesh's UVs;
    /// ignored for meshes without UVs.
    pub skin_texture: Option<&'a image::RgbaImage>,
}

impl PreviewScene<'_> {
    /// Bounds of everything drawn, or `None` for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut bounds = self.mesh.map(Mesh::bounds);
        let curve_points = self.curves.map_or(&[][..], |c| c.points());
        for &p in self.points.iter().chain(curve_points) {
            bounds = Some(match bounds {
                Some((lo, hi)) => (lo.min(p), hi.max(p)),
                None => (p, p),
            });
        }
        bounds
    }
}

/// Colours (linear RGB) and sizes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreviewStyle {
    /// Where nothing is drawn.
    pub background: [f32; 3],
    /// The skin.
    pub skin: [f32; 3],
    /// Points.
    pub point: [f32; 3],
    /// Point radius in pixels.
    pub point_radius: f32,
    /// Hair.
    pub hair: [f32; 3],
    /// Strength of the hair's specular highlight.
    pub hair_specular: f32,
}

impl Default for PreviewStyle {
    fn default() -> Self {
        Self {
            background: [1.0, 1.0, 1.0],
            skin: [0.70, 0.60, 0.48],
            point: [0.30, 0.01, 0.005],
            point_radius: 1.5,
            hair: [0.35, 0.17, 0.07],
            hair_specular: 0.12,
        }
    }
}

gpu_vertex! {
    /// A skin vertex (`VertexIn` of `mesh.wgsl`).
    pub(crate) struct MeshVertex at location 0 {
        position: [f32; 3],
        normal: [f32; 3],
        /// Zero on untextured meshes.
        uv: [f32; 2],
    }
}

gpu_vertex! {
    /// A point disc's centre (`PointIn` of `points.wgsl`), one an instance.
    pub(crate) struct PointInstance at location 0 {
        center: [f32; 3],
    }
}

gpu_vertex! {
    /// A curve segment (`SegmentIn` of `curves.wgsl`), one an instance.
    pub(crate) struct SegmentInstance at location 0 {
        /// xyz: the first point, w: its width.
        a: [f32; 4],
        /// xyz: the second point, w: its width.
        b: [f32; 4],
        /// rgb: the first point's colour; a: 1 where the curves have
        /// colours, 0 to use the style's hair colour.
        color_a: [f32; 4],
        /// The second point's colour.
        color_b: [f32; 4],
    }
}

gpu_struct! {
    /// The uniform block every preview shader reads (`struct Frame` in
    /// `frame.wgsl`).
    pub(crate) struct FrameUniforms {
        view_proj: [[f32; 4]; 4],
        /// The camera's position.
        eye: [f32; 3],
        /// Point disc radius in pixels.
        point_radius: f32,
        /// Unit direction towards the light.
        light_dir: [f32; 3],
        /// How far points are pulled towards the camera, in clip w units.
        point_depth_pull: f32,
        skin_color: [f32; 3],
        /// Focal length in pixels: turns world widths into pixels.
        focal_length_px: f32,
        point_color: [f32; 3],
        /// Kajiya-Kay specular strength of the hair.
        hair_specular: f32,
        hair_color: [f32; 3],
        pad0: f32,
        /// Viewport size in pixels.
        viewport_px: [f32; 2],
        pad1: [f32; 2],
    }
}

/// A scene's geometry on the GPU (see [`Renderer::upload`]).
#[derive(Debug)]
pub struct GpuScene {
    /// Vertices, and indices with their count (none: draw unindexed).
    mesh: Option<(wgpu::Buffer, Option<wgpu::Buffer>, u32)>,
    skin_texture: wgpu::BindGroup,
    /// Whether the skin is coloured by a texture (then the style's skin
    /// colour is not applied on top).
    textured: bool,
    points: Option<(wgpu::Buffer, u32)>,
    segments: Option<(wgpu::Buffer, u32)>,
    bounds: Option<(Vec3, Vec3)>,
}

/// Draws preview scenes into images. Build once, render many times.
#[derive(Debug)]
pub struct Renderer {
    /// The frame's uniforms, made once, rewritten for each frame.
    frame: UniformRing<FrameUniforms>,
    texture_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    mesh_pipeline: wgpu::RenderPipeline,
    points_pipeline: wgpu::RenderPipeline,
    curves_pipeline: wgpu::RenderPipeline,
    format: wgpu::TextureFormat,
}

impl Renderer {
    /// Compiles the shaders and builds the pipelines for offscreen images
    /// ([`render`](Self::render), [`render_uploaded`](Self::render_uploaded)).
    pub fn new(ctx: &GpuContext) -> Self {
        Self::for_format(ctx, COLOR_FORMAT)
    }

    /// Builds the pipelines for targets of `format`, e.g. a window
    /// surface's preferred format (`Bgra8UnormSrgb` on most platforms); draw
    /// with [`encode`](Self::encode). Use an sRGB format: the shaders write
    /// linear colour.
    pub fn for_format(ctx: &GpuContext, format: wgpu::TextureFormat) -> Self {
        let device = &ctx.device;
        let frame_layout = UniformRing::<FrameUniforms>::layout(
            device,
            "frame",
            wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
        );
        let frame = UniformRing::new(device, "frame", &frame_layout);
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("skin texture"),
            entries: &[
                entry::texture(
                    0,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::TextureViewDimension::D2,
                    true,
                ),
                entry::sampler(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("skin"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        // One layout for all pipelines; points and curves ignore group 1.
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("preview"),
            bind_group_layouts: &[Some(&frame_layout), Some(&texture_layout)],
            immediate_size: 0,
        });
        let shader = |name: &str, source: &str| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        };
        let mesh_shader = shader("mesh.wgsl", &crate::shader_source("mesh.wgsl"));
        let points_shader = shader("points.wgsl", &crate::shader_source("points.wgsl"));
        let curves_shader = shader("curves.wgsl", &crate::shader_source("curves.wgsl"));
        let pipeline = |module: &wgpu::ShaderModule,
                        buffers: &[Option<wgpu::VertexBufferLayout>],
                        alpha_to_coverage: bool| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("preview"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: SAMPLES,
                    mask: !0,
                    alpha_to_coverage_enabled: alpha_to_coverage,
                },
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let mesh_pipeline = pipeline(
            &mesh_shader,
            &[Some(MeshVertex::layout(wgpu::VertexStepMode::Vertex))],
            false,
        );
        let points_pipeline = pipeline(
            &points_shader,
            &[Some(PointInstance::layout(wgpu::VertexStepMode::Instance))],
            true,
        );
        let curves_pipeline = pipeline(
            &curves_shader,
            &[Some(SegmentInstance::layout(
                wgpu::VertexStepMode::Instance,
            ))],
            true,
        );
        Self {
            frame,
            texture_layout,
            sampler,
            mesh_pipeline,
            points_pipeline,
            curves_pipeline,
            format,
        }
    }

    /// The colour format the pipelines draw into.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Renders `scene` into a `width × height` image. Without a camera the
    /// scene is framed automatically.
    pub fn render(
        &self,
        ctx: &GpuContext,
        scene: &PreviewScene,
        style: &PreviewStyle,
        camera: Option<Camera>,
        width: u32,
        height: u32,
    ) -> Result<image::RgbaImage, GpuError> {
        let uploaded = self.upload(ctx, scene);
        self.render_uploaded(ctx, &uploaded, style, camera, width, height)
    }

    /// Copies a scene's geometry to the GPU, to be drawn any number of
    /// times by [`Renderer::render_uploaded`].
    pub fn upload(&self, ctx: &GpuContext, scene: &PreviewScene) -> GpuScene {
        let device = &ctx.device;
        // Textured meshes are drawn one vertex per triangle corner, since
        // their UVs may be per corner; untextured ones stay indexed.
        let textured = scene.skin_texture.is_some() && scene.mesh.is_some_and(Mesh::has_uvs);
        let mesh_buffers = scene.mesh.map(|mesh| {
            let mut vertices: Vec<MeshVertex> = Vec::new();
            let indices: Option<Vec<u32>> = if textured {
                vertices.reserve(mesh.triangle_count() * 3);
                for t in 0..mesh.triangle_count() {
                    let uvs = mesh.triangle_uvs(t).expect("textured meshes have UVs");
                    for (k, &v) in mesh.triangles()[t].iter().enumerate() {
                        vertices.push(MeshVertex {
                            position: mesh.positions()[v as usize].to_array(),
                            normal: mesh.normals()[v as usize].to_array(),
                            uv: uvs[k].to_array(),
                        });
                    }
                }
                None
            } else {
                vertices.extend(mesh.positions().iter().zip(mesh.normals()).map(|(p, n)| {
                    MeshVertex {
                        position: p.to_array(),
                        normal: n.to_array(),
                        uv: [0.0; 2],
                    }
                }));
                Some(mesh.triangles().iter().flatten().copied().collect())
            };
            let vertex = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("mesh vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            });
            let count = indices
                .as_ref()
                .map_or(mesh.triangle_count() as u32 * 3, |i| i.len() as u32);
            let index = indices.map(|indices| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("mesh indices"),
                    contents: bytemuck::cast_slice(&indices),
                    usage: wgpu::BufferUsages::INDEX,
                })
            });
            (vertex, index, count)
        });
        let white = image::RgbaImage::from_pixel(1, 1, image::Rgba([255; 4]));
        let texture_image = scene.skin_texture.filter(|_| textured).unwrap_or(&white);
        let texture = device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("skin texture"),
                size: wgpu::Extent3d {
                    width: texture_image.width(),
                    height: texture_image.height(),
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8UnormSrgb,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            texture_image.as_raw(),
        );
        let view = texture.create_view(&Default::default());
        let skin_texture = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("skin texture"),
            layout: &self.texture_layout,
            entries: &group::sequential([
                wgpu::BindingResource::TextureView(&view),
                wgpu::BindingResource::Sampler(&self.sampler),
            ]),
        });
        let point_buffer = (!scene.points.is_empty()).then(|| {
            let centres: Vec<PointInstance> = scene
                .points
                .iter()
                .map(|p| PointInstance {
                    center: p.to_array(),
                })
                .collect();
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("points"),
                contents: bytemuck::cast_slice(&centres),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });

        let segment_buffer = scene
            .curves
            .filter(|c| c.segment_count() > 0)
            .map(|curves| {
                let (points, widths) = (curves.points(), curves.widths());
                // Per-point colours where the curves have them; alpha 0
                // selects the style's hair colour in the shader.
                let color = |k: usize| match curves.colors() {
                    Some(c) => [c[k].x, c[k].y, c[k].z, 1.0],
                    None => [0.0; 4],
                };
                let mut segments = Vec::with_capacity(curves.segment_count());
                for i in 0..curves.curve_count() {
                    let range = curves.range(i);
                    for k in range.start..range.end.saturating_sub(1) {
                        segments.push(SegmentInstance {
                            a: points[k].extend(widths[k]).to_array(),
                            b: points[k + 1].extend(widths[k + 1]).to_array(),
                            color_a: color(k),
                            color_b: color(k + 1),
                        });
                    }
                }
                let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("curve segments"),
                    contents: bytemuck::cast_slice(&segments),
                    usage: wgpu::BufferUsages::VERTEX,
                });
                (buffer, segments.len() as u32)
            });

        GpuScene {
            mesh: mesh_buffers,
            skin_texture,
            textured,
            points: point_buffer.map(|b| (b, scene.points.len() as u32)),
            segments: segment_buffer,
            bounds: scene.bounds(),
        }
    }

    /// Draws an uploaded scene into a `width × height` image and reads it
    /// back. Without a camera the scene is framed automatically.
    pub fn render_uploaded(
        &self,
        ctx: &GpuContext,
        scene: &GpuScene,
        style: &PreviewStyle,
        camera: Option<Camera>,
        width: u32,
        height: u32,
    ) -> Result<image::RgbaImage, GpuError> {
        check_size(ctx, width, height)?;
        // Refused before any drawing: only 8-bit RGBA and BGRA read back.
        is_bgra(self.format)?;
        let resolved = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("preview image"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let view = resolved.create_view(&Default::default());
        self.encode(
            ctx,
            &mut encoder,
            scene,
            style,
            camera,
            &view,
            width,
            height,
        )?;
        read_texture(ctx, encoder, &resolved)
    }

    /// Records the drawing of an uploaded scene into `target`, a
    /// single-sampled view of this renderer's [`format`](Self::format) and
    /// `width × height` — an offscreen texture or a window surface's
    /// current texture. The renderer draws into its own multisampled colour
    /// and depth targets and resolves into `target`; submit the encoder
    /// (and present the surface texture) afterwards.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        style: &PreviewStyle,
        camera: Option<Camera>,
        target: &wgpu::TextureView,
        width: u32,
        height: u32,
    ) -> Result<(), GpuError> {
        check_size(ctx, width, height)?;
        let device = &ctx.device;
        let aspect = width as f32 / height as f32;
        let (lo, hi) = scene
            .bounds
            .unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)));
        let camera = camera.unwrap_or_else(|| Camera::framing(lo, hi, aspect));
        let radius =
            (0.5 * (hi - lo)).length().max(1e-6) + (0.5 * (lo + hi) - camera.target).length();
        let clip_from_world = camera.clip_from_world(aspect, radius);
        // Key light above and to the left of the camera, so form reads.
        let view = (camera.eye - camera.target).normalize();
        let side = view.cross(Vec3::Y).normalize_or_zero();
        let light = view + 0.9 * Vec3::Y + 0.6 * side;
        let uniforms = FrameUniforms {
            view_proj: clip_from_world.to_cols_array_2d(),
            eye: camera.eye.to_array(),
            point_radius: style.point_radius,
            light_dir: light.normalize().to_array(),
            // Points are pulled towards the camera by 0.2 % of clip w.
            point_depth_pull: 0.002,
            skin_color: if scene.textured { [1.0; 3] } else { style.skin },
            focal_length_px: camera.focal_length_px(height),
            point_color: style.point,
            hair_specular: style.hair_specular,
            hair_color: style.hair,
            viewport_px: [width as f32, height as f32],
            ..Default::default()
        };
        let frame_offset = self.frame.write(&ctx.queue, &uniforms);

        let target_texture = |samples, format, usage| {
            target_texture(
                device,
                "preview target",
                (width, height),
                samples,
                format,
                usage,
            )
        };
        let multisampled =
            target_texture(SAMPLES, self.format, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let depth = target_texture(
            SAMPLES,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let views = [&multisampled, &depth].map(|t| t.create_view(&Default::default()));
        {
            let [r, g, b] = style.background.map(f64::from);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("preview"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &views[0],
                    depth_slice: None,
                    resolve_target: Some(target),
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                        store: wgpu::StoreOp::Discard,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &views[1],
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
            pass.set_bind_group(0, self.frame.group(), &[frame_offset]);
            pass.set_bind_group(1, &scene.skin_texture, &[]);
            if let Some((vertex, index, count)) = &scene.mesh {
                pass.set_pipeline(&self.mesh_pipeline);
                pass.set_vertex_buffer(0, vertex.slice(..));
                match index {
                    Some(index) => {
                        pass.set_index_buffer(index.slice(..), wgpu::IndexFormat::Uint32);
                        pass.draw_indexed(0..*count, 0, 0..1);
                    }
                    None => pass.draw(0..*count, 0..1),
                }
            }
            if let Some((segments, count)) = &scene.segments {
                pass.set_pipeline(&self.curves_pipeline);
                pass.set_vertex_buffer(0, segments.slice(..));
                pass.draw(0..6, 0..*count);
            }
            if let Some((points, count)) = &scene.points {
                pass.set_pipeline(&self.points_pipeline);
                pass.set_vertex_buffer(0, points.slice(..));
                pass.draw(0..6, 0..*count);
            }
        }
        Ok(())
    }
}

/// A 2-D texture of `size` to draw into (a colour or depth attachment,
/// multisampled with `samples`, or the resolved image).
pub(crate) fn target_texture(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    samples: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
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
}

pub(crate) fn check_size(ctx: &GpuContext, width: u32, height: u32) -> Result<(), GpuError> {
    let max = ctx.device.limits().max_texture_dimension_2d;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(GpuError::Size { width, height, max });
    }
    Ok(())
}
