//! Where Bevy draws the fur's vertices, read back: the shell material's
//! own vertex stage (`shell_fur.wgsl`, Bevy's joint matrices, pelage's
//! coupled offset), drawn as points whose fragments store each vertex's
//! world position at its index in a buffer. For tests and tools that must
//! know the fur is where the skinned skin is, to the float, rather than
//! near it in a picture.
//!
//! A point covers the pixel its vertex falls in, so every vertex inside
//! the view is stored; the depth test is off, so hidden ones are too.
//! Fragment stages may write storage buffers on every native backend, so
//! the probe needs no optional device feature.

use crate::material::{SHELL_FUR_SHADER, ShellFurMaterial};
use bevy::asset::RenderAssetUsages;
use bevy::mesh::MeshVertexBufferLayoutRef;
use bevy::pbr::{
    ExtendedMaterial, MaterialExtension, MaterialExtensionKey, MaterialExtensionPipeline,
};
use bevy::prelude::*;
use bevy::render::render_resource::{
    AsBindGroup, CompareFunction, PrimitiveTopology, RenderPipelineDescriptor,
    SpecializedMeshPipelineError,
};
use bevy::render::storage::ShaderBuffer;
use bevy::shader::ShaderRef;

/// The shell material with a [`FurPositionProbe`]: put it on a fur entity
/// in place of its [`ShellFurMaterial`] (with the same `base`).
pub type ProbedShellFurMaterial = ExtendedMaterial<ShellFurMaterial, FurPositionProbe>;

/// The buffer a probed fur mesh writes its vertices' world positions to:
/// one `vec4` a vertex in the fur mesh's vertex order: xyz, and in w the
/// frame that stored it (Bevy's frame count plus 1, as a float).
#[derive(Asset, AsBindGroup, Reflect, Debug, Clone)]
pub struct FurPositionProbe {
    /// A [`ShaderBuffer`] of at least 16 bytes a vertex
    /// ([`FurPositionProbe::buffer`] makes one).
    #[storage(100, visibility(fragment))]
    pub positions: Handle<ShaderBuffer>,
}

impl FurPositionProbe {
    /// A buffer for `vertices` positions, each NaN until a frame stores it.
    pub fn buffer(vertices: usize) -> ShaderBuffer {
        let unwritten: Vec<u8> = std::iter::repeat_n(f32::NAN.to_le_bytes(), 4 * vertices)
            .flatten()
            .collect();
        ShaderBuffer::new(&unwritten, RenderAssetUsages::RENDER_WORLD)
    }

    /// A read-back buffer's positions as the latest frame in it drew
    /// them: `None` for a vertex that frame did not store (outside the
    /// view then; an earlier frame's position would be stale).
    pub fn positions(bytes: &[u8]) -> Vec<Option<Vec3>> {
        let stored: Vec<Vec4> = bytes
            .chunks_exact(16)
            .map(|v| {
                let f = |i: usize| f32::from_le_bytes(v[4 * i..4 * i + 4].try_into().unwrap());
                Vec4::new(f(0), f(1), f(2), f(3))
            })
            .collect();
        let latest = stored
            .iter()
            .map(|v| v.w)
            .filter(|w| !w.is_nan())
            .fold(f32::NAN, f32::max);
        stored
            .iter()
            .map(|v| (v.w == latest).then_some(v.truncate()))
            .collect()
    }
}

/// Adds the probed shell material to Bevy (after [`PelagePlugin`](crate::PelagePlugin)).
#[derive(Debug, Clone, Default)]
pub struct FurPositionProbePlugin;

impl Plugin for FurPositionProbePlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins(MaterialPlugin::<ProbedShellFurMaterial>::default());
    }
}

impl MaterialExtension for FurPositionProbe {
    fn vertex_shader() -> ShaderRef {
        ShaderRef::Handle(SHELL_FUR_SHADER)
    }

    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(SHELL_FUR_SHADER)
    }

    fn enable_prepass() -> bool {
        false
    }

    fn enable_shadows() -> bool {
        false
    }

    fn specialize(
        _pipeline: &MaterialExtensionPipeline,
        descriptor: &mut RenderPipelineDescriptor,
        _layout: &MeshVertexBufferLayoutRef,
        _key: MaterialExtensionKey<Self>,
    ) -> Result<(), SpecializedMeshPipelineError> {
        descriptor
            .vertex
            .shader_defs
            .push("FUR_POSITION_PROBE".into());
        if let Some(fragment) = descriptor.fragment.as_mut() {
            fragment.shader_defs.push("FUR_POSITION_PROBE".into());
        }
        // Each vertex its own primitive, so its fragment knows which
        // vertex it is; none culled, none hidden.
        descriptor.primitive.topology = PrimitiveTopology::PointList;
        descriptor.primitive.cull_mode = None;
        if let Some(depth) = descriptor.depth_stencil.as_mut() {
            depth.depth_compare = Some(CompareFunction::Always);
            depth.depth_write_enabled = Some(false);
        }
        Ok(())
    }
}
