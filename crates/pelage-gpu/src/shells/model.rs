//! A furry mesh on the GPU ([`ShellModel`]): one vertex per triangle
//! corner with its strand frame, the shell texture layers, the colour
//! texture and the wetness mask. The images a frame is drawn into
//! ([`ShellTarget`](super::ShellTarget)) are the renderer's.

use crate::{GpuContext, GpuError};
use glam::Vec3;

use super::PoseVertex;
use pelage::anim::SkinRig;

/// A furry mesh on the GPU: indexed skin vertices with their frames (posed
/// every frame by the skinning pass for a skinned mesh), the shell texture
/// layers with their mip chain, the colour texture, the wetness mask and
/// the fins on its edges.
#[derive(Debug)]
pub struct ShellModel {
    /// [`PoseVertex`] per vertex: written once, or by the skinning pass.
    pub(crate) pose: wgpu::Buffer,
    /// [`SurfaceVertex`](super::SurfaceVertex) per vertex.
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

    /// Whether the model is posed by a skin ([`ShellRenderer::pose`](super::ShellRenderer::pose)).
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

/// How a mesh is uploaded ([`ShellRenderer::upload_with`](super::ShellRenderer::upload_with)).
#[derive(Debug, Clone, Copy, Default)]
pub struct ShellUpload<'a> {
    /// Skinning: the mesh is then the rig's rest pose, and
    /// [`ShellRenderer::pose`](super::ShellRenderer::pose) poses it each frame.
    pub rig: Option<&'a SkinRig>,
    /// One vertex per triangle corner, never welded: for fur whose
    /// sticks stand per corner or per triangle (the separable topologies,
    /// Silva strands), whose layers part at every edge.
    pub per_corner: bool,
}
