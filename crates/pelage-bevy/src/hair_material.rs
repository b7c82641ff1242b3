//! The material Bevy draws real-time strands with: a groom's hairs, as
//! the GPU grew them this frame (a points buffer, `xyz` and width a point,
//! point-major), pulled by `shaders/strands.wgsl` as camera-facing ribbons
//! (pelage-shaders' hair math: the same ribbons and hair model pelage-gpu
//! draws), lit by the scene's directional lights, alpha-to-coverage with
//! Bevy's MSAA so thin hairs thin out instead of shimmering.

use bevy::asset::uuid_handle;
use bevy::mesh::{MeshVertexAttribute, MeshVertexBufferLayoutRef};
use bevy::pbr::{MaterialPipeline, MaterialPipelineKey};
use bevy::prelude::*;
use bevy::render::render_resource::{
    AsBindGroup, RenderPipelineDescriptor, ShaderType, SpecializedMeshPipelineError, VertexFormat,
};
use bevy::render::storage::ShaderBuffer;
use bevy::shader::ShaderRef;

/// A ribbon vertex's own number (0, 1, 2, …), at shader location 0: which
/// hair, segment and corner it is (`ribbon_corner` in the hair math).
pub const ATTRIBUTE_RIBBON_CORNER: MeshVertexAttribute = MeshVertexAttribute::new(
    "PelageRibbonCorner",
    0x7065_6c61_6765_0002,
    VertexFormat::Uint32,
);

/// `strands.wgsl`.
pub(crate) const STRANDS_SHADER: Handle<Shader> =
    uuid_handle!("8c7d1c3e-5a4b-4f0e-9a57-6b1f0c2d9e03");
/// pelage's shared hair math, imported as `pelage::hair_math`.
pub(crate) const HAIR_MATH_SHADER: Handle<Shader> =
    uuid_handle!("8c7d1c3e-5a4b-4f0e-9a57-6b1f0c2d9e04");
/// pelage's GPU groom (compute), run by the render world's growth.
pub(crate) const GROOM_SHADER: Handle<Shader> =
    uuid_handle!("8c7d1c3e-5a4b-4f0e-9a57-6b1f0c2d9e05");

/// Puts the strand shaders in Bevy's shader assets: the math under its
/// import path, so the composer finds it.
pub(crate) fn register_shaders(app: &mut App) {
    let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
    let sources = [
        (
            &HAIR_MATH_SHADER,
            crate::material::importable(
                pelage_shaders::hair::MATH_IMPORT_PATH,
                pelage_shaders::hair::MATH_WGSL,
                "pelage/hair_math.wgsl",
            ),
        ),
        (
            &STRANDS_SHADER,
            Shader::from_wgsl(
                include_str!("shaders/strands.wgsl"),
                "pelage_bevy/strands.wgsl",
            ),
        ),
        (
            &GROOM_SHADER,
            Shader::from_wgsl(pelage_shaders::groom::GROOM_WGSL, "pelage/groom.wgsl"),
        ),
    ];
    for (handle, shader) in sources {
        shaders.insert(handle, shader).expect("a fixed handle");
    }
}

/// The strands' numbers as `strands.wgsl` reads them (`struct Strands`; a
/// test checks the two agree field by field and in size).
#[derive(Debug, Clone, Copy, ShaderType, PartialEq, Reflect)]
pub struct StrandUniform {
    /// Hairs in the points buffer (its rows' stride).
    pub stride: u32,
    /// Points a hair.
    pub points: u32,
    /// The first render hair in the points buffer.
    pub first: u32,
    /// Render hairs drawn, the first by arrival (a level of detail).
    pub drawn: u32,
    /// Every width's factor (a level of detail's 1/√F).
    pub width_scale: f32,
    /// The strands' opacity, 0 to 1 (less in the hand-over to shells).
    pub opacity: f32,
    /// R's strength.
    pub specular: f32,
    /// The highlights' shift (radians).
    pub shift: f32,
    /// Hairs without colours take this one (linear RGB).
    pub base_color: Vec3,
    /// The highlights' width (radians).
    pub roughness: f32,
    /// TRT's strength.
    pub trt: f32,
    /// TT's strength.
    pub transmission: f32,
    /// TT's azimuthal exponent.
    pub transmission_exponent: f32,
    /// Padding.
    pub pad: f32,
}

/// Real-time strands as Bevy draws them: one per furred mesh.
#[derive(Asset, TypePath, AsBindGroup, Debug, Clone)]
pub struct StrandMaterial {
    /// The strands' numbers.
    #[uniform(0)]
    pub strands: StrandUniform,
    /// Every hair's points as the GPU grew them this frame (written by the
    /// render world's growth pass before the main pass).
    #[storage(1, read_only, visibility(vertex))]
    pub points: Handle<ShaderBuffer>,
    /// Each render point's colour (`rgb`; negative: none) and opacity,
    /// hair after hair.
    #[storage(2, read_only, visibility(vertex))]
    pub colors: Handle<ShaderBuffer>,
}

impl Material for StrandMaterial {
    fn vertex_shader() -> ShaderRef {
        ShaderRef::Handle(STRANDS_SHADER)
    }

    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(STRANDS_SHADER)
    }

    fn alpha_mode(&self) -> AlphaMode {
        AlphaMode::AlphaToCoverage
    }

    // Hairs cast no shadow on the scene and are not in the prepasses.
    fn enable_prepass() -> bool {
        false
    }

    fn enable_shadows() -> bool {
        false
    }

    fn specialize(
        _pipeline: &MaterialPipeline,
        descriptor: &mut RenderPipelineDescriptor,
        layout: &MeshVertexBufferLayoutRef,
        _key: MaterialPipelineKey<Self>,
    ) -> Result<(), SpecializedMeshPipelineError> {
        descriptor.vertex.buffers = vec![
            layout
                .0
                .get_layout(&[ATTRIBUTE_RIBBON_CORNER.at_shader_location(0)])?,
        ];
        // A ribbon faces the camera; either winding is its front.
        descriptor.primitive.cull_mode = None;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::reflect::structs::Struct;

    /// The Rust block and the WGSL struct agree field by field and in
    /// size, so encase writes what the shader reads.
    #[test]
    fn the_uniform_block_matches_the_shader() {
        let (wgsl, span) =
            crate::material::tests::wgsl_struct(include_str!("shaders/strands.wgsl"), "Strands");
        let block = StrandUniform {
            stride: 0,
            points: 0,
            first: 0,
            drawn: 0,
            width_scale: 0.0,
            opacity: 0.0,
            specular: 0.0,
            shift: 0.0,
            base_color: Vec3::ZERO,
            roughness: 0.0,
            trt: 0.0,
            transmission: 0.0,
            transmission_exponent: 0.0,
            pad: 0.0,
        };
        let rust: Vec<String> = (0..block.field_len())
            .map(|i| block.name_at(i).unwrap().to_string())
            .collect();
        assert_eq!(rust, wgsl);
        assert_eq!(StrandUniform::min_size().get(), u64::from(span));
    }
}
