//! A furry mesh on the GPU ([`ShellModel`]): one vertex per triangle
//! corner with its strand frame, the shell texture layers, the colour
//! texture and the wetness mask; and [`ShellTarget`], the images a frame
//! is drawn into.

use crate::renderer::check_size;
use crate::{GpuContext, GpuError};
use glam::Vec3;
use pelage::Mesh;

use super::ShellRenderer;
use super::{PoseVertex, SurfaceVertex, TipOffset};
use pelage::anim::SkinRig;
use pelage::shell::{ShellScene, ShellTextures, WetnessMask};
use wgpu::util::DeviceExt;

/// A furry mesh on the GPU: indexed skin vertices with their frames (posed
/// every frame by the skinning pass for a skinned mesh), the shell texture
/// layers with their mip chain, the colour texture, the wetness mask and
/// the fins on its edges.
#[derive(Debug)]
pub struct ShellModel {
    /// [`PoseVertex`] per vertex: written once, or by the skinning pass.
    pub(crate) pose: wgpu::Buffer,
    /// [`SurfaceVertex`] per vertex.
    pub(super) surface: wgpu::Buffer,
    /// p − p0 per vertex; `GpuMassSpring` writes it in place.
    pub(crate) tip_offsets: wgpu::Buffer,
    pub(super) indices: wgpu::Buffer,
    pub(super) index_count: u32,
    /// Vertices: triangle corners welded where the mesh vertex, its UV
    /// and the stick it follows agree.
    pub(crate) vertex_count: u32,
    /// Triangle corners of the mesh (3 × triangles).
    pub(crate) corner_count: u32,
    /// For each vertex, a triangle corner `3t + k` it stands for (CPU copy
    /// and GPU buffer, which the dynamics' coupling pass reads).
    pub(super) corners_of_vertices: Vec<u32>,
    pub(crate) vertex_corners: wgpu::Buffer,
    /// For each vertex, the mesh vertex it is.
    pub(super) mesh_vertices: Vec<u32>,
    /// Fins: their records and the bind group the fin pass reads them
    /// (and the pose, UVs and tips) through; none on a mesh without
    /// interior edges.
    pub(super) fins: Option<(wgpu::BindGroup, u32)>,
    /// The skinning pass's inputs, for a skinned mesh.
    pub(super) skin: Option<GpuSkin>,
    pub(super) wetness: wgpu::Texture,
    pub(super) wetness_size: (u32, u32),
    pub(super) textures: wgpu::BindGroup,
    pub(super) layers: u32,
    pub(super) texture_resolution: u32,
    pub(super) mip_levels: u32,
    pub(super) bounds: (Vec3, Vec3),
}

/// A skinned model's rest frames, influences and palette on the GPU, and
/// the bind group of the pass that poses it.
#[derive(Debug)]
pub(super) struct GpuSkin {
    pub(super) palette: wgpu::Buffer,
    pub(super) palette_len: usize,
    pub(super) bind: wgpu::BindGroup,
}

impl ShellModel {
    /// The skin's bounds: the mesh's as uploaded, or as set by
    /// [`Self::set_bounds`]. Objects outside the view are not drawn and
    /// the level of detail measures them by these.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// Sets the bounds (before `offset`) every pose stays within: a
    /// skinned model is uploaded in its bind pose, which may lie elsewhere
    /// (and at another scale) than where its animation takes it.
    pub fn set_bounds(&mut self, lo: Vec3, hi: Vec3) {
        self.bounds = (lo, hi);
    }

    /// The number of layers in the shell texture.
    pub fn texture_layers(&self) -> u32 {
        self.layers
    }

    /// Vertices drawn per layer (after welding triangle corners).
    pub fn vertex_count(&self) -> u32 {
        self.vertex_count
    }

    /// Triangle corners of the mesh.
    pub fn corner_count(&self) -> u32 {
        self.corner_count
    }

    /// Fins on the mesh's edges.
    pub fn fin_count(&self) -> u32 {
        self.fins.as_ref().map_or(0, |f| f.1)
    }

    /// Whether the model is posed by a skin ([`ShellRenderer::pose`]).
    pub fn is_skinned(&self) -> bool {
        self.skin.is_some()
    }

    /// For each vertex, the mesh vertex it was welded from.
    pub fn mesh_vertices(&self) -> &[u32] {
        &self.mesh_vertices
    }

    /// Every vertex's position, normal and tangent as the GPU has them
    /// now (after the skinning pass of a skinned model), read back — in
    /// the model's vertex order ([`Self::mesh_vertices`] maps them).
    pub fn read_pose(&self, ctx: &GpuContext) -> Result<pelage::anim::PosedFrames, GpuError> {
        let size = self.pose.size();
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shell pose readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.pose, 0, &readback, 0, size);
        ctx.queue.submit([encoder.finish()]);
        crate::readback::map_read(ctx, &readback, |mapped| {
            let vertices: &[PoseVertex] = bytemuck::cast_slice(mapped);
            pelage::anim::PosedFrames {
                positions: vertices.iter().map(|v| Vec3::from(v.position)).collect(),
                normals: vertices.iter().map(|v| Vec3::from(v.normal)).collect(),
                tangents: vertices.iter().map(|v| Vec3::from(v.tangent)).collect(),
            }
        })
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
    /// of [`ShellRenderer::encode`]).
    pub fn resolve_view(&self) -> wgpu::TextureView {
        self.resolved.create_view(&Default::default())
    }
}

/// How a mesh is uploaded ([`ShellRenderer::upload_with`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct ShellUpload<'a> {
    /// Skinning: the mesh is then the rig's rest pose, and
    /// [`ShellRenderer::pose`] poses it each frame.
    pub rig: Option<&'a SkinRig>,
    /// One vertex per triangle corner, never welded: for fur whose
    /// sticks stand per corner or per triangle (the separable topologies,
    /// Silva strands), whose layers part at every edge.
    pub per_corner: bool,
}

impl ShellRenderer {
    /// Copies a furry mesh to the GPU ([`Self::upload_with`], still and
    /// welded).
    pub fn upload(
        &self,
        ctx: &GpuContext,
        mesh: &Mesh,
        color: &image::RgbaImage,
        textures: &ShellTextures,
        mask_size: u32,
    ) -> Result<ShellModel, GpuError> {
        self.upload_with(
            ctx,
            mesh,
            color,
            textures,
            mask_size,
            ShellUpload::default(),
        )
    }

    /// Copies a furry mesh to the GPU: its triangle corners welded into
    /// indexed vertices wherever vertex and UV agree (a UV seam keeps two),
    /// each with its strand frame; the shell layers with a mip chain; the
    /// colour texture (sRGB); a dry wetness mask of `mask_size`²; the fins
    /// on its edges; and, with a rig, what the skinning pass reads.
    /// Meshes without UVs are refused: the fur is textured by UV.
    pub fn upload_with(
        &self,
        ctx: &GpuContext,
        mesh: &Mesh,
        color: &image::RgbaImage,
        textures: &ShellTextures,
        mask_size: u32,
        options: ShellUpload<'_>,
    ) -> Result<ShellModel, GpuError> {
        if !mesh.has_uvs() {
            return Err(GpuError::NoUvs(mesh.name().to_string()));
        }
        if let Some(rig) = options.rig
            && rig.vertex_count() != mesh.vertex_count()
        {
            return Err(GpuError::Mismatch(format!(
                "a rig of {} vertices for a mesh of {}",
                rig.vertex_count(),
                mesh.vertex_count()
            )));
        }
        let device = &ctx.device;
        let welded = WeldedCorners::new(mesh, options.per_corner);
        let tangents = vertex_tangents(mesh);
        let pose: Vec<PoseVertex> = welded
            .mesh_vertices
            .iter()
            .map(|&v| PoseVertex {
                position: mesh.positions()[v as usize].to_array(),
                normal: mesh.normals()[v as usize].to_array(),
                tangent: tangents[v as usize].to_array(),
            })
            .collect();
        let surface: Vec<SurfaceVertex> = welded
            .uvs
            .iter()
            .map(|&uv| SurfaceVertex {
                uv: pelage::shell::wetness::mask_coordinates(uv).to_array(),
            })
            .collect();
        let storage = wgpu::BufferUsages::STORAGE;
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let pose_usage = wgpu::BufferUsages::VERTEX
            | storage
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC;
        let pose_buffer = buffer("shell pose", bytemuck::cast_slice(&pose), pose_usage);
        let surface_buffer = buffer(
            "shell surface",
            bytemuck::cast_slice(&surface),
            wgpu::BufferUsages::VERTEX | storage,
        );
        let vertex_count = welded.mesh_vertices.len();
        let tip_offsets = buffer(
            "shell tip offsets",
            bytemuck::cast_slice(&vec![TipOffset::default(); vertex_count]),
            wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST | storage,
        );
        let indices = buffer(
            "shell indices",
            bytemuck::cast_slice(&welded.indices),
            wgpu::BufferUsages::INDEX,
        );
        let vertex_corners = buffer(
            "shell vertex corners",
            bytemuck::cast_slice(&welded.corners),
            storage,
        );

        let size = |w, h, layers| wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: layers,
        };
        let texture = |label, extent, format, data: &[u8], mips: u32| {
            device.create_texture_with_data(
                &ctx.queue,
                &wgpu::TextureDescriptor {
                    label: Some(label),
                    size: extent,
                    mip_level_count: mips,
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
        let (mip_data, mip_levels) = fur_mip_chain(textures);
        let fur = texture(
            "shell layers",
            size(r, r, textures.layers()),
            wgpu::TextureFormat::Rgba8Unorm,
            &mip_data,
            mip_levels,
        );
        let color_texture = texture(
            "fur colour",
            size(color.width(), color.height(), 1),
            wgpu::TextureFormat::Rgba8UnormSrgb,
            color.as_raw(),
            1,
        );
        let mask_size = mask_size.max(1);
        let dry = WetnessMask::dry_mask(mask_size, mask_size);
        let wetness = texture(
            "wetness mask",
            size(mask_size, mask_size, 1),
            wgpu::TextureFormat::Rgba32Float,
            bytemuck::cast_slice(&dry.to_rgba()),
            1,
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

        let fin_records = super::fins::fin_records(mesh, &welded);
        let fins = (!fin_records.is_empty()).then(|| {
            let records = buffer("shell fins", bytemuck::cast_slice(&fin_records), storage);
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shell fins"),
                layout: &self.fin_layout,
                entries: &[
                    (0, &records),
                    (1, &pose_buffer),
                    (2, &surface_buffer),
                    (3, &tip_offsets),
                ]
                .map(|(binding, buffer)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                }),
            });
            (group, fin_records.len() as u32)
        });

        let skin = options.rig.map(|rig| {
            let rest = buffer("shell rest pose", bytemuck::cast_slice(&pose), storage);
            let influences: Vec<[u32; 8]> = welded
                .mesh_vertices
                .iter()
                .map(|&v| {
                    let i = rig.influences()[v as usize];
                    let w = i.weights.map(f32::to_bits);
                    [
                        i.joints[0],
                        i.joints[1],
                        i.joints[2],
                        i.joints[3],
                        w[0],
                        w[1],
                        w[2],
                        w[3],
                    ]
                })
                .collect();
            let influences = buffer(
                "shell skin influences",
                bytemuck::cast_slice(&influences),
                storage,
            );
            let palette = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("shell skin palette"),
                size: (64 * rig.palette_len().max(1)) as u64,
                usage: storage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shell skinning"),
                layout: &self.skin_layout,
                entries: &[
                    (0, &palette),
                    (1, &rest),
                    (2, &influences),
                    (3, &pose_buffer),
                ]
                .map(|(binding, buffer)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                }),
            });
            GpuSkin {
                palette,
                palette_len: rig.palette_len(),
                bind,
            }
        });

        Ok(ShellModel {
            pose: pose_buffer,
            surface: surface_buffer,
            tip_offsets,
            indices,
            index_count: welded.indices.len() as u32,
            vertex_count: vertex_count as u32,
            corner_count: (mesh.triangle_count() * 3) as u32,
            corners_of_vertices: welded.corners,
            mesh_vertices: welded.mesh_vertices,
            vertex_corners,
            fins,
            skin,
            wetness,
            wetness_size: (mask_size, mask_size),
            textures: bind,
            layers: textures.layers(),
            texture_resolution: r,
            mip_levels,
            bounds: mesh.bounds(),
        })
    }

    /// Generates a scene's shell texture and uploads the scene
    /// ([`Self::upload_with`] with the scene's mesh — its rest pose and
    /// rig when skinned, with the bounds of its whole clip —, colour and
    /// mask size; per corner when its dynamics' sticks are).
    pub fn upload_scene(
        &self,
        ctx: &GpuContext,
        scene: &ShellScene,
    ) -> Result<ShellModel, GpuError> {
        let textures = ShellTextures::generate(&scene.texture);
        let per_corner = scene.dynamics.as_ref().is_some_and(|d| {
            d.topology.is_per_corner() || d.topology == pelage::dynamics::Topology::SilvaStrands
        });
        let (mesh, rig) = match &scene.animation {
            Some(a) => (a.rest_mesh(), Some(a.rig())),
            None => (&scene.mesh, None),
        };
        let mut model = self.upload_with(
            ctx,
            mesh,
            &scene.color,
            &textures,
            scene.wetness_resolution,
            ShellUpload { rig, per_corner },
        )?;
        if let Some(animation) = &scene.animation {
            let (lo, hi) = animation.bounds();
            model.set_bounds(lo, hi);
        }
        Ok(model)
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
        if offsets.len() != model.corner_count as usize {
            return Err(GpuError::Mismatch(format!(
                "{} tip offsets for a model with {} triangle corners",
                offsets.len(),
                model.corner_count
            )));
        }
        let tips: Vec<TipOffset> = model
            .corners_of_vertices
            .iter()
            .map(|&c| TipOffset {
                tip_offset: offsets[c as usize].to_array(),
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

/// A mesh's triangle corners welded into indexed vertices.
#[derive(Debug)]
pub(super) struct WeldedCorners {
    /// Per vertex: the mesh vertex, its UV and a corner `3t + k` it
    /// stands for.
    pub(super) mesh_vertices: Vec<u32>,
    pub(super) uvs: Vec<glam::Vec2>,
    pub(super) corners: Vec<u32>,
    /// Three per triangle.
    pub(super) indices: Vec<u32>,
}

impl WeldedCorners {
    /// Corners that share a mesh vertex and a UV become one vertex (all of
    /// them, on a mesh with UVs per vertex); `per_corner` keeps every
    /// corner its own.
    pub(super) fn new(mesh: &Mesh, per_corner: bool) -> Self {
        let corners = mesh.triangle_count() * 3;
        let mut out = Self {
            mesh_vertices: Vec::new(),
            uvs: Vec::new(),
            corners: Vec::new(),
            indices: Vec::with_capacity(corners),
        };
        let mut index: std::collections::HashMap<(u32, [u32; 2]), u32> =
            std::collections::HashMap::with_capacity(if per_corner { 0 } else { corners / 2 });
        for t in 0..mesh.triangle_count() {
            let uvs = mesh.triangle_uvs(t).expect("checked: the mesh has UVs");
            for (k, &v) in mesh.triangles()[t].iter().enumerate() {
                let corner = (3 * t + k) as u32;
                let add = |out: &mut Self| {
                    out.mesh_vertices.push(v);
                    out.uvs.push(uvs[k]);
                    out.corners.push(corner);
                    out.mesh_vertices.len() as u32 - 1
                };
                let i = if per_corner {
                    add(&mut out)
                } else {
                    let key = (v, uvs[k].to_array().map(f32::to_bits));
                    match index.get(&key) {
                        Some(&i) => i,
                        None => {
                            let i = add(&mut out);
                            index.insert(key, i);
                            i
                        }
                    }
                };
                out.indices.push(i);
            }
        }
        out
    }
}

/// The shell texture's layers with a mip chain, layer by layer, each
/// layer's levels in turn (wgpu's layer-major order): each
/// level a box filter of the one above, colour weighted by alpha (a
/// transparent texel's direction must not leak into its neighbours).
fn fur_mip_chain(textures: &ShellTextures) -> (Vec<u8>, u32) {
    let r = textures.resolution() as usize;
    let texels: &[u8] = bytemuck::cast_slice(textures.texels());
    // Halving to one texel: a texture that is not a power of two gets
    // wgpu's sizes, max(1, r >> level).
    let levels = usize::BITS - r.leading_zeros();
    let mut data = Vec::with_capacity(texels.len() * 4 / 3 + 4 * textures.layers() as usize);
    for layer in texels.chunks_exact(r * r * 4) {
        data.extend_from_slice(layer);
        let mut above = layer.to_vec();
        let mut size = r;
        while size > 1 {
            let half = size / 2;
            let mut next = vec![0u8; half * half * 4];
            for y in 0..half {
                for x in 0..half {
                    let mut rgb = [0.0f32; 3];
                    let mut alpha = 0.0f32;
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let i = ((2 * y + dy) * size + 2 * x + dx) * 4;
                        let a = f32::from(above[i + 3]);
                        for c in 0..3 {
                            rgb[c] += a * f32::from(above[i + c]);
                        }
                        alpha += a;
                    }
                    let o = (y * half + x) * 4;
                    for c in 0..3 {
                        next[o + c] = if alpha > 0.0 {
                            (rgb[c] / alpha).round() as u8
                        } else {
                            128
                        };
                    }
                    next[o + 3] = (alpha / 4.0).round() as u8;
                }
            }
            data.extend_from_slice(&next);
            above = next;
            size = half;
        }
    }
    (data, levels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;
    use pelage::mesh::Uvs;

    /// Two triangles over a square sharing the diagonal 0–2; vertex 2's
    /// UV differs between them when `seam` (a UV seam along the diagonal's
    /// end).
    fn square(seam: bool) -> Mesh {
        let values = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(0.5, 0.5),
        ];
        let second = if seam { [0, 4, 3] } else { [0, 2, 3] };
        Mesh::new(
            "square",
            vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
            None,
            Some(Uvs::PerCorner {
                values,
                indices: vec![[0, 1, 2], second],
            }),
        )
        .unwrap()
    }

    #[test]
    fn corners_weld_where_vertex_and_uv_agree_and_a_seam_keeps_two() {
        let welded = WeldedCorners::new(&square(false), false);
        assert_eq!(welded.mesh_vertices.len(), 4);
        assert_eq!(welded.indices, vec![0, 1, 2, 0, 2, 3]);
        let seam = WeldedCorners::new(&square(true), false);
        assert_eq!(seam.mesh_vertices.len(), 5);
        assert_eq!(
            seam.mesh_vertices[3], 2,
            "vertex 2 again, with its other UV"
        );
        assert_eq!(seam.uvs[3], Vec2::new(0.5, 0.5));
        assert_eq!(seam.indices, vec![0, 1, 2, 0, 3, 4]);
        let corners = WeldedCorners::new(&square(false), true);
        assert_eq!(corners.mesh_vertices.len(), 6);
        // Every vertex stands for a corner of its own mesh vertex.
        for (i, &c) in seam.corners.iter().enumerate() {
            let (t, k) = (c as usize / 3, c as usize % 3);
            assert_eq!(square(true).triangles()[t][k], seam.mesh_vertices[i]);
        }
    }

    #[test]
    fn the_mip_chain_halves_to_one_texel_and_keeps_coverage() {
        let textures = ShellTextures::generate(&pelage::shell::ShellTextureParams {
            resolution: 16,
            layers: 2,
            ..Default::default()
        });
        let (data, levels) = fur_mip_chain(&textures);
        assert_eq!(levels, 5, "16, 8, 4, 2, 1");
        let per_layer: usize = [16, 8, 4, 2, 1].iter().map(|s| s * s * 4).sum();
        assert_eq!(data.len(), 2 * per_layer);
        // The last level of layer 0 is the mean alpha of its 256 texels.
        let texels: &[u8] = bytemuck::cast_slice(textures.texels());
        let mean: f32 = texels[..16 * 16 * 4]
            .chunks(4)
            .map(|t| f32::from(t[3]))
            .sum::<f32>()
            / 256.0;
        let last = data[per_layer - 1];
        assert!((f32::from(last) - mean).abs() <= 2.0, "{last} vs {mean}");
    }
}
