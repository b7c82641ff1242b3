//! The material Bevy draws shell fur with: pelage's shell texture and
//! colour, a uniform block of the fur's numbers, and `shell_fur.wgsl`
//! (which imports pelage's shared shell math). Blended over what Bevy's
//! opaque pass drew, depth-tested against it, layers in mesh order
//! (innermost first), lit by the view's directional lights.

use bevy::asset::uuid_handle;
use bevy::mesh::{MeshVertexAttribute, MeshVertexBufferLayoutRef};
use bevy::pbr::{MaterialPipeline, MaterialPipelineKey};
use bevy::prelude::*;
use bevy::render::render_resource::{
    AsBindGroup, Face, RenderPipelineDescriptor, ShaderType, SpecializedMeshPipelineError,
    VertexFormat,
};
use bevy::shader::ShaderRef;

/// Which layer a fur mesh's vertex belongs to (0: innermost), at shader
/// location 8.
pub const ATTRIBUTE_SHELL_LAYER: MeshVertexAttribute = MeshVertexAttribute::new(
    "PelageShellLayer",
    0x7065_6c61_6765_0001,
    VertexFormat::Uint32,
);

/// `shell_fur.wgsl`.
pub(crate) const SHELL_FUR_SHADER: Handle<Shader> =
    uuid_handle!("8c7d1c3e-5a4b-4f0e-9a57-6b1f0c2d9e01");
/// pelage's shared shell math, imported as `pelage::shell_math`.
pub(crate) const SHELL_MATH_SHADER: Handle<Shader> =
    uuid_handle!("8c7d1c3e-5a4b-4f0e-9a57-6b1f0c2d9e02");

/// Puts both shaders in Bevy's shader assets: the math under its import
/// path, so the composer finds it.
pub(crate) fn register_shaders(app: &mut App) {
    let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
    shaders
        .insert(
            &SHELL_MATH_SHADER,
            importable(
                pelage_shaders::shell::MATH_IMPORT_PATH,
                pelage_shaders::shell::MATH_WGSL,
                "pelage/shell_math.wgsl",
            ),
        )
        .expect("a fixed handle");
    shaders
        .insert(
            &SHELL_FUR_SHADER,
            Shader::from_wgsl(
                include_str!("shaders/shell_fur.wgsl"),
                "pelage_bevy/shell_fur.wgsl",
            ),
        )
        .expect("a fixed handle");
}

/// pelage-shaders' WGSL module `source` as a Bevy shader other shaders
/// `#import` under `import_path`.
pub(crate) fn importable(import_path: &str, source: &str, name: &'static str) -> Shader {
    Shader::from_wgsl(format!("#define_import_path {import_path}\n{source}"), name)
}

/// The fur's numbers as `shell_fur.wgsl` reads them (`struct ShellFur`;
/// a test checks the two have the same fields in the same order and the
/// same size).
#[derive(Debug, Clone, Copy, ShaderType, PartialEq, Reflect)]
pub struct ShellFurUniform {
    /// Where the dynamics pushed the strands' tips (world units).
    pub tip_offset: Vec3,
    /// The outermost layer's height above the skin (mesh units).
    pub length: f32,
    /// Kajiya-Kay's specular colour `K_s`.
    pub specular: Vec3,
    /// Kajiya-Kay's exponent `p_phong`.
    pub exponent: f32,
    /// Layers of this fur mesh.
    pub layers: u32,
    /// `Coupling::index`: 0 Bézier, 1 linear, 2 bent.
    pub coupling: u32,
    /// The bent coupling's `k`.
    pub coupling_exponent: f32,
    /// Shell texture repeats across the UV square.
    pub tiles: f32,
    /// `K_shadow`: darker towards the skin.
    pub k_shadow: f32,
    /// The layers' opacity, 0 to 1.
    pub opacity: f32,
    /// The colour texture's gain (1: as painted).
    pub color_gain: f32,
    /// Bit 0: curl (Eq. 4); bit 1: clumps (Alg. 2).
    pub effects: u32,
    /// The curl's radius at the tip of dry fur `K_α` (mesh units).
    pub curl_radius: f32,
    /// The curl's turn from root to tip `ω` (radians).
    pub curl_frequency: f32,
    /// The clump profile's `w`.
    pub clump_w: f32,
    /// The clump's strength.
    pub clump_strength: f32,
    /// The wetness mask's size in texels.
    pub wetness_size: Vec2,
}

impl ShellFurUniform {
    /// `effects`' bit for curl.
    pub const CURL: u32 = 1;
    /// `effects`' bit for clumps.
    pub const CLUMP: u32 = 2;
}

/// Shell fur as Bevy draws it: one per furred mesh and level of detail.
#[derive(Asset, TypePath, AsBindGroup, Debug, Clone)]
pub struct ShellFurMaterial {
    /// The fur's numbers.
    #[uniform(0)]
    pub fur: ShellFurUniform,
    /// pelage's shell texture: one slice a layer, with mips.
    #[texture(1, dimension = "2d_array")]
    #[sampler(2)]
    pub layers: Handle<Image>,
    /// The fur's colour, read at the mesh's UVs.
    #[texture(3)]
    #[sampler(4)]
    pub color: Handle<Image>,
    /// pelage's wetness mask (clump centre, radius, wetness; 32-bit
    /// floats, read texel by texel).
    #[texture(5, sample_type = "float", filterable = false)]
    pub wetness: Handle<Image>,
}

impl Material for ShellFurMaterial {
    fn vertex_shader() -> ShaderRef {
        ShaderRef::Handle(SHELL_FUR_SHADER)
    }

    fn fragment_shader() -> ShaderRef {
        ShaderRef::Handle(SHELL_FUR_SHADER)
    }

    fn alpha_mode(&self) -> AlphaMode {
        AlphaMode::Blend
    }

    // Fur is drawn after the opaque pass and casts nothing: its shadow
    // on the skin is the shells' own K_shadow term.
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
        let mut attributes = vec![
            Mesh::ATTRIBUTE_POSITION.at_shader_location(0),
            Mesh::ATTRIBUTE_NORMAL.at_shader_location(1),
            Mesh::ATTRIBUTE_UV_0.at_shader_location(2),
            Mesh::ATTRIBUTE_TANGENT.at_shader_location(4),
        ];
        if layout.0.contains(Mesh::ATTRIBUTE_JOINT_INDEX) {
            attributes.push(Mesh::ATTRIBUTE_JOINT_INDEX.at_shader_location(6));
            attributes.push(Mesh::ATTRIBUTE_JOINT_WEIGHT.at_shader_location(7));
        }
        attributes.push(ATTRIBUTE_SHELL_LAYER.at_shader_location(8));
        descriptor.vertex.buffers = vec![layout.0.get_layout(&attributes)?];
        // A closed skin's far side is behind its near side anyway.
        descriptor.primitive.cull_mode = Some(Face::Back);
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use bevy::reflect::structs::Struct;

    /// `struct name` of a shader's `source`, as naga lays it out: its
    /// field names in order, and its size (the uniform-block tests of both
    /// materials).
    pub(crate) fn wgsl_struct(source: &str, name: &str) -> (Vec<String>, u32) {
        let start = source
            .find(&format!("struct {name} {{"))
            .expect("the struct");
        let end = start + source[start..].find("};").expect("its end") + 2;
        let module = naga::front::wgsl::parse_str(&source[start..end]).expect("WGSL");
        let ty = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .expect("the struct's type")
            .1;
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            panic!("a struct");
        };
        let names = members.iter().map(|m| m.name.clone().unwrap()).collect();
        (names, *span)
    }

    /// The Rust block and the WGSL struct agree field by field and in
    /// size, so encase writes what the shader reads.
    #[test]
    fn the_uniform_block_matches_the_shader() {
        let block = ShellFurUniform {
            tip_offset: Vec3::ZERO,
            length: 0.0,
            specular: Vec3::ZERO,
            exponent: 0.0,
            layers: 0,
            coupling: 0,
            coupling_exponent: 0.0,
            tiles: 0.0,
            k_shadow: 0.0,
            opacity: 0.0,
            color_gain: 0.0,
            effects: 0,
            curl_radius: 0.0,
            curl_frequency: 0.0,
            clump_w: 0.0,
            clump_strength: 0.0,
            wetness_size: Vec2::ZERO,
        };
        let rust: Vec<String> = (0..block.field_len())
            .map(|i| block.name_at(i).unwrap().to_string())
            .collect();
        let (wgsl, size) = wgsl_struct(include_str!("shaders/shell_fur.wgsl"), "ShellFur");
        assert_eq!(rust, wgsl);
        assert_eq!(ShellFurUniform::min_size().get(), u64::from(size));
    }
}
