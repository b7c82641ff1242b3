//! Copying a furry mesh to the GPU: [`ShellRenderer::upload_with`] builds
//! a [`ShellModel`] from a mesh prepared in `prepare.rs` (welded corners,
//! tangents, the mip chain) and the fins of `fins.rs`, with the bind
//! groups of the renderer's layouts; and what changes a model later (tip
//! offsets, the wetness mask). It stands above both the model and the
//! renderer, which therefore never use each other in a circle.

use super::fins::fin_records;
use super::model::{GpuSkin, ShellModel, ShellUpload};
use super::prepare::WeldedCorners;
use super::renderer::ShellRenderer;
use super::{PoseVertex, TipOffset};
use crate::layout::group;
use crate::{GpuContext, GpuError};
use glam::Vec3;
use pelage::Mesh;
use pelage::anim::SkinRig;
use pelage::shell::{ShellScene, ShellTextures, WetnessMask};
use pelage_shaders::shell::fur_mip_chain;
use wgpu::util::DeviceExt;

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
        let pose = welded.pose_vertices(mesh);
        let surface = welded.surface_vertices();
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

        let mask_size = mask_size.max(1);
        let shell_textures = self.texture_group(ctx, textures, color, mask_size);
        let fins = self.fin_group(
            ctx,
            mesh,
            &welded,
            [&pose_buffer, &surface_buffer, &tip_offsets],
        );
        let skin = options
            .rig
            .map(|rig| self.skin_group(ctx, rig, &welded, &pose, &pose_buffer));
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
            wetness: shell_textures.wetness,
            wetness_size: (mask_size, mask_size),
            textures: shell_textures.bind,
            layers: textures.layers(),
            texture_resolution: textures.resolution(),
            mip_levels: shell_textures.mip_levels,
            bounds: mesh.bounds(),
        })
    }

    /// The model's textures on the GPU and the bind group the shell pass
    /// reads them through: the shell layers with their mips, the colour
    /// (sRGB) and a dry wetness mask of `mask_size`².
    fn texture_group(
        &self,
        ctx: &GpuContext,
        textures: &ShellTextures,
        color: &image::RgbaImage,
        mask_size: u32,
    ) -> ShellTextureGroup {
        let device = &ctx.device;
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
            entries: &group::sequential([
                wgpu::BindingResource::TextureView(&fur_view),
                wgpu::BindingResource::Sampler(&self.fur_sampler),
                wgpu::BindingResource::TextureView(&color_view),
                wgpu::BindingResource::Sampler(&self.color_sampler),
                wgpu::BindingResource::TextureView(&wetness_view),
            ]),
        });
        ShellTextureGroup {
            bind,
            wetness,
            mip_levels,
        }
    }

    /// The fins' records on the GPU and the bind group the fin pass reads
    /// them (and the pose, UVs and tips: `buffers`) through, with their
    /// count; none on a mesh without interior edges.
    fn fin_group(
        &self,
        ctx: &GpuContext,
        mesh: &Mesh,
        welded: &WeldedCorners,
        buffers: [&wgpu::Buffer; 3],
    ) -> Option<(wgpu::BindGroup, u32)> {
        let device = &ctx.device;
        let [pose_buffer, surface_buffer, tip_offsets] = buffers;
        let fin_records = fin_records(mesh, welded);
        (!fin_records.is_empty()).then(|| {
            let records = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shell fins"),
                contents: bytemuck::cast_slice(&fin_records),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shell fins"),
                layout: &self.fin_layout,
                entries: &group::buffers([&records, pose_buffer, surface_buffer, tip_offsets]),
            });
            (group, fin_records.len() as u32)
        })
    }

    /// What the skinning pass reads for a rigged model: the rest pose,
    /// each vertex's four joints and weights, the palette (written each
    /// frame), and the bind group over them and the pose it writes.
    fn skin_group(
        &self,
        ctx: &GpuContext,
        rig: &SkinRig,
        welded: &WeldedCorners,
        pose: &[PoseVertex],
        pose_buffer: &wgpu::Buffer,
    ) -> GpuSkin {
        let device = &ctx.device;
        let storage = wgpu::BufferUsages::STORAGE;
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let rest = buffer("shell rest pose", bytemuck::cast_slice(pose), storage);
        let influences = welded.skin_influences(rig);
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
            entries: &group::buffers([&palette, &rest, &influences, pose_buffer]),
        });
        GpuSkin {
            palette,
            palette_len: rig.palette_len(),
            bind,
        }
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

/// A model's textures ([`ShellRenderer::texture_group`]): the bind group
/// of the shell pass, the wetness mask (rewritten when painted) and the
/// shell layers' mip count.
struct ShellTextureGroup {
    bind: wgpu::BindGroup,
    wetness: wgpu::Texture,
    mip_levels: u32,
}
