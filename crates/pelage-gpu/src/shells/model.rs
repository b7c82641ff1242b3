//! A furry mesh on the GPU ([`ShellModel`]): one vertex per triangle
//! corner with its strand frame, the shell texture layers, the colour
//! texture and the wetness mask; and [`ShellTarget`], the images a frame
//! is drawn into.

use crate::renderer::{DEPTH_FORMAT, SAMPLES, check_size};
use crate::{GpuContext, GpuError};
use glam::Vec3;
use pelage::Mesh;

use super::ShellRenderer;
use super::{ShellVertex, TipOffset};
use pelage::shell::{ShellScene, ShellTextures, WetnessMask};
use wgpu::util::DeviceExt;

/// A furry mesh on the GPU: skin vertices with their frames, the shell
/// texture layers, the colour texture and the wetness mask.
#[derive(Debug)]
pub struct ShellModel {
    pub(super) vertices: wgpu::Buffer,
    /// p − p0 per triangle corner; `GpuMassSpring` writes it in place.
    pub(crate) tip_offsets: wgpu::Buffer,
    pub(crate) vertex_count: u32,
    pub(super) wetness: wgpu::Texture,
    pub(super) wetness_size: (u32, u32),
    pub(super) textures: wgpu::BindGroup,
    pub(super) layers: u32,
    pub(super) bounds: (Vec3, Vec3),
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
    pub(super) color: wgpu::TextureView,
    pub(super) depth: wgpu::TextureView,
    pub(super) resolved: wgpu::Texture,
    pub(super) size: (u32, u32),
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

impl ShellRenderer {
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
        let mut vertices = Vec::with_capacity(mesh.triangle_count() * 3);
        for t in 0..mesh.triangle_count() {
            let uvs = mesh.triangle_uvs(t).expect("checked: the mesh has UVs");
            for (k, &v) in mesh.triangles()[t].iter().enumerate() {
                let (p, n, u) = (
                    mesh.positions()[v as usize],
                    mesh.normals()[v as usize],
                    tangents[v as usize],
                );
                let uv = pelage::shell::wetness::mask_coordinates(uvs[k]);
                vertices.push(ShellVertex {
                    position: p.to_array(),
                    normal: n.to_array(),
                    uv: uv.to_array(),
                    tangent: u.to_array(),
                });
            }
        }
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shell skin"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let tip_offsets = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shell tip offsets"),
            contents: bytemuck::cast_slice(&vec![TipOffset::default(); mesh.triangle_count() * 3]),
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
        let tips: Vec<TipOffset> = offsets
            .iter()
            .map(|o| TipOffset {
                tip_offset: o.to_array(),
            })
            .collect();
        ctx.queue
            .write_buffer(&model.tip_offsets, 0, bytemuck::cast_slice(&tips));
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
