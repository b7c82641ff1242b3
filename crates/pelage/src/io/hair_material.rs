//! The hair material written beside curves that carry hair-shading
//! values ([`crate::curves::HairShading`]): a `UsdShade` `Material` whose
//! `mtlx:surface` output is a MaterialX network, `chiang_hair_bsdf` (the
//! Chiang et al. 2016 hair model of MaterialX 1.39's pbrlib) fed by
//! `geompropvalue` readers of the curves' primvars. The USD and MaterialX
//! names are the nodedefs' own (`ND_chiang_hair_bsdf`, its `tint_TT`, …),
//! so a renderer with MaterialX support (Karma, RenderMan's MaterialX
//! path, Omniverse, Storm) shades the fur with no set-up.
//!
//! Melanin is written on Cycles' 0–1 scale (`hair_melanin`). The network
//! turns it into the pigment concentration Cycles uses, `−ln(1 − m)`
//! (floored at 10⁻⁴ as Cycles does), and gives `deon_hair_absorption_from_
//! melanin` Cycles' pigment absorptions (`exp(−σ)` of eumelanin
//! (0.506, 0.841, 1.653) and pheomelanin (0.343, 0.733, 1.924)), so the
//! same primvars give the same absorption in Cycles and in MaterialX.
//! The tint colours the transmitted lobes (`tint_TT`, `tint_TRT`), where
//! Cycles adds it to the absorption: close, not equal.

use crate::curves::HairShading;
use glam::Vec3;

/// The material prim's name, under the file's default prim.
pub const MATERIAL_NAME: &str = "hair_material";

/// A prim of the network: its name, type, attributes and children.
pub(crate) struct NetworkPrim {
    pub name: &'static str,
    pub type_name: &'static str,
    pub attributes: Vec<NetworkAttribute>,
    pub children: Vec<NetworkPrim>,
}

/// An attribute of a network prim.
pub(crate) struct NetworkAttribute {
    /// `info:id`, `inputs:geomprop`, `outputs:out`.
    pub name: &'static str,
    /// The USD value type (`token`, `string`, `float`, `color3f`, …).
    pub type_name: &'static str,
    /// `uniform` variability (a shader's `info:id`).
    pub uniform: bool,
    pub value: NetworkValue,
}

/// What an attribute holds.
pub(crate) enum NetworkValue {
    /// A declaration only (a shader's output).
    Declared,
    /// A token.
    Token(&'static str),
    /// A string.
    Text(&'static str),
    /// A float.
    Float(f32),
    /// A colour (`color3f`).
    Color(Vec3),
    /// A connection to the output `.1` of the material's child shader `.0`.
    Connect(&'static str, &'static str),
}

impl NetworkAttribute {
    fn new(name: &'static str, type_name: &'static str, value: NetworkValue) -> Self {
        Self {
            name,
            type_name,
            uniform: false,
            value,
        }
    }
}

/// A shader: `info:id`, its inputs, its outputs.
fn shader(
    name: &'static str,
    id: &'static str,
    inputs: Vec<NetworkAttribute>,
    outputs: &[(&'static str, &'static str)],
) -> NetworkPrim {
    let mut attributes = vec![NetworkAttribute {
        uniform: true,
        ..NetworkAttribute::new("info:id", "token", NetworkValue::Token(id))
    }];
    attributes.extend(inputs);
    attributes.extend(
        outputs
            .iter()
            .map(|&(name, ty)| NetworkAttribute::new(name, ty, NetworkValue::Declared)),
    );
    NetworkPrim {
        name,
        type_name: "Shader",
        attributes,
        children: Vec::new(),
    }
}

/// An input fed by another shader's output.
fn wired(
    name: &'static str,
    ty: &'static str,
    from: &'static str,
    output: &'static str,
) -> NetworkAttribute {
    NetworkAttribute::new(name, ty, NetworkValue::Connect(from, output))
}

/// A `geompropvalue` reader of the primvar `primvar` with a default.
fn reader(name: &'static str, primvar: &'static str, default: f32) -> NetworkPrim {
    shader(
        name,
        "ND_geompropvalue_float",
        vec![
            NetworkAttribute::new("inputs:geomprop", "string", NetworkValue::Text(primvar)),
            NetworkAttribute::new("inputs:default", "float", NetworkValue::Float(default)),
        ],
        &[("outputs:out", "float")],
    )
}

/// `exp(−σ)` of Cycles' pigment absorption coefficients, as the colours
/// `deon_hair_absorption_from_melanin` takes.
fn pigment_color(sigma: [f32; 3]) -> Vec3 {
    Vec3::from(sigma.map(|s| (-s).exp()))
}

/// The hair material: a `Material` with the MaterialX network as its
/// children: the melanin concentration, the absorption it gives, the tint
/// and roughnesses, and the Chiang BSDF they feed.
pub(crate) fn hair_material() -> NetworkPrim {
    let mut children = melanin_concentration();
    children.extend(absorption());
    children.extend(tint_and_roughness());
    children.extend(bsdf());
    NetworkPrim {
        name: MATERIAL_NAME,
        type_name: "Material",
        attributes: vec![NetworkAttribute::new(
            "outputs:mtlx:surface",
            "token",
            NetworkValue::Connect("surface", "outputs:out"),
        )],
        children,
    }
}

/// `hair_melanin` (0–1, as Blender's Principled Hair takes it) made a
/// concentration: `−ln(max(1 − m, 1e-4))`.
fn melanin_concentration() -> Vec<NetworkPrim> {
    use NetworkValue::Float;
    let float = "float";
    let out = &[("outputs:out", "float")][..];
    vec![
        reader("melanin", "hair_melanin", HairShading::DEFAULTS[0]),
        shader(
            "melanin_remaining",
            "ND_subtract_float",
            vec![
                NetworkAttribute::new("inputs:in1", float, Float(1.0)),
                wired("inputs:in2", float, "melanin", "outputs:out"),
            ],
            out,
        ),
        shader(
            "melanin_floor",
            "ND_max_float",
            vec![
                wired("inputs:in1", float, "melanin_remaining", "outputs:out"),
                NetworkAttribute::new("inputs:in2", float, Float(1e-4)),
            ],
            out,
        ),
        shader(
            "melanin_log",
            "ND_ln_float",
            vec![wired("inputs:in", float, "melanin_floor", "outputs:out")],
            out,
        ),
        shader(
            "melanin_concentration",
            "ND_multiply_float",
            vec![
                wired("inputs:in1", float, "melanin_log", "outputs:out"),
                NetworkAttribute::new("inputs:in2", float, Float(-1.0)),
            ],
            out,
        ),
    ]
}

/// The absorption coefficient from the melanin concentration and
/// `hair_melanin_redness`, with Cycles' pigment colours.
fn absorption() -> Vec<NetworkPrim> {
    let float = "float";
    vec![
        reader(
            "melanin_redness",
            "hair_melanin_redness",
            HairShading::DEFAULTS[1],
        ),
        shader(
            "absorption",
            "ND_deon_hair_absorption_from_melanin",
            vec![
                wired(
                    "inputs:melanin_concentration",
                    float,
                    "melanin_concentration",
                    "outputs:out",
                ),
                wired(
                    "inputs:melanin_redness",
                    float,
                    "melanin_redness",
                    "outputs:out",
                ),
                NetworkAttribute::new(
                    "inputs:eumelanin_color",
                    "color3f",
                    NetworkValue::Color(pigment_color([0.506, 0.841, 1.653])),
                ),
                NetworkAttribute::new(
                    "inputs:pheomelanin_color",
                    "color3f",
                    NetworkValue::Color(pigment_color([0.343, 0.733, 1.924])),
                ),
            ],
            &[("outputs:absorption", "float3")],
        ),
    ]
}

/// `hair_tint` and the Chiang roughnesses from `hair_roughness` and
/// `hair_radial_roughness`.
fn tint_and_roughness() -> Vec<NetworkPrim> {
    let float = "float";
    vec![
        shader(
            "tint",
            "ND_geompropvalue_color3",
            vec![
                NetworkAttribute::new("inputs:geomprop", "string", NetworkValue::Text("hair_tint")),
                NetworkAttribute::new("inputs:default", "color3f", NetworkValue::Color(Vec3::ONE)),
            ],
            &[("outputs:out", "color3f")],
        ),
        reader(
            "longitudinal_roughness",
            "hair_roughness",
            HairShading::DEFAULTS[2],
        ),
        reader(
            "azimuthal_roughness",
            "hair_radial_roughness",
            HairShading::DEFAULTS[3],
        ),
        shader(
            "roughness",
            "ND_chiang_hair_roughness",
            vec![
                wired(
                    "inputs:longitudinal",
                    float,
                    "longitudinal_roughness",
                    "outputs:out",
                ),
                wired(
                    "inputs:azimuthal",
                    float,
                    "azimuthal_roughness",
                    "outputs:out",
                ),
            ],
            &[
                ("outputs:roughness_R", "float2"),
                ("outputs:roughness_TT", "float2"),
                ("outputs:roughness_TRT", "float2"),
            ],
        ),
    ]
}

/// The Chiang hair BSDF over them, and the surface shader.
fn bsdf() -> Vec<NetworkPrim> {
    vec![
        shader(
            "hair_bsdf",
            "ND_chiang_hair_bsdf",
            vec![
                wired("inputs:tint_TT", "color3f", "tint", "outputs:out"),
                wired("inputs:tint_TRT", "color3f", "tint", "outputs:out"),
                wired(
                    "inputs:roughness_R",
                    "float2",
                    "roughness",
                    "outputs:roughness_R",
                ),
                wired(
                    "inputs:roughness_TT",
                    "float2",
                    "roughness",
                    "outputs:roughness_TT",
                ),
                wired(
                    "inputs:roughness_TRT",
                    "float2",
                    "roughness",
                    "outputs:roughness_TRT",
                ),
                wired(
                    "inputs:absorption_coefficient",
                    "float3",
                    "absorption",
                    "outputs:absorption",
                ),
            ],
            &[("outputs:out", "token")],
        ),
        shader(
            "surface",
            "ND_surface",
            vec![wired("inputs:bsdf", "token", "hair_bsdf", "outputs:out")],
            &[("outputs:out", "token")],
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every connection names a shader of the network and an output it
    /// declares with the input's type.
    #[test]
    fn every_connection_reaches_a_declared_output_of_its_type() {
        let material = hair_material();
        let mut inputs = material.attributes.iter().collect::<Vec<_>>();
        for child in &material.children {
            inputs.extend(&child.attributes);
        }
        let mut connections = 0;
        for input in inputs {
            let NetworkValue::Connect(prim, output) = input.value else {
                continue;
            };
            let source = material
                .children
                .iter()
                .find(|c| c.name == prim)
                .unwrap_or_else(|| panic!("{} connects to a missing {prim}", input.name));
            let declared = source
                .attributes
                .iter()
                .find(|a| a.name == output && matches!(a.value, NetworkValue::Declared))
                .unwrap_or_else(|| panic!("{prim} declares no {output}"));
            assert_eq!(declared.type_name, input.type_name, "{}", input.name);
            connections += 1;
        }
        assert!(connections >= 15, "{connections}");
    }
}
