//! A fur mesh made from a Bevy mesh: its vertices once per shell layer,
//! each copy tagged with its layer ([`ATTRIBUTE_SHELL_LAYER`]), with the
//! same positions, normals, UVs and joint influences, so Bevy's skinning
//! carries every layer's root exactly where it carries the skin. The
//! strand frame's tangent is pelage's (`pelage_shaders::shell`).

use crate::material::ATTRIBUTE_SHELL_LAYER;
use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;

/// Why a mesh cannot wear shell fur.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FurMeshError {
    /// Shells stand on triangles.
    #[error("the mesh is not a triangle list")]
    NotTriangles,
    /// A required attribute is missing or of an unexpected type.
    #[error("the mesh has no {0} (shell fur needs positions, normals and UVs)")]
    Missing(&'static str),
    /// pelage could not read the mesh (empty, bad indices).
    #[error("{0}")]
    Mesh(String),
    /// The mesh's vertices are on the GPU only.
    #[error(
        "the mesh's vertices went to the GPU only (its RenderAssetUsages lack MAIN_WORLD): fur is grown from them on the CPU"
    )]
    RenderWorldOnly,
}

/// The fur mesh of `skin` with `layers` layers (layer 0 innermost, drawn
/// first).
pub fn fur_mesh(skin: &Mesh, layers: u32) -> Result<Mesh, FurMeshError> {
    if skin.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err(FurMeshError::NotTriangles);
    }
    if skin.try_attributes().is_err() {
        return Err(FurMeshError::RenderWorldOnly);
    }
    let positions = float3(skin, Mesh::ATTRIBUTE_POSITION, "positions")?;
    let normals = float3(skin, Mesh::ATTRIBUTE_NORMAL, "normals")?;
    let uvs = match skin.attribute(Mesh::ATTRIBUTE_UV_0) {
        Some(VertexAttributeValues::Float32x2(v)) => v.clone(),
        _ => return Err(FurMeshError::Missing("UVs")),
    };
    let n = positions.len();
    let triangles: Vec<[u32; 3]> = match skin.indices() {
        Some(indices) => {
            let all: Vec<u32> = indices.iter().map(|i| i as u32).collect();
            all.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
        None => (0..n as u32 / 3)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect(),
    };
    let tangents = strand_tangents(&positions, &normals, &uvs, &triangles)?;

    let mut fur = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::RENDER_WORLD,
    );
    let repeat = |v: &VertexAttributeValues| repeat_values(v, layers as usize);
    for (attribute, values) in skin.attributes() {
        let id = attribute.id;
        let copied = [
            Mesh::ATTRIBUTE_POSITION.id,
            Mesh::ATTRIBUTE_NORMAL.id,
            Mesh::ATTRIBUTE_UV_0.id,
            Mesh::ATTRIBUTE_JOINT_INDEX.id,
            Mesh::ATTRIBUTE_JOINT_WEIGHT.id,
        ]
        .contains(&id);
        if copied && let Some(values) = repeat(values) {
            fur.insert_attribute(*attribute, values);
        }
    }
    let tangents: Vec<[f32; 4]> = tangents.iter().map(|t| [t.x, t.y, t.z, 1.0]).collect();
    fur.insert_attribute(
        Mesh::ATTRIBUTE_TANGENT,
        repeat_values(&VertexAttributeValues::Float32x4(tangents), layers as usize)
            .expect("Float32x4 repeats"),
    );
    let layer_of: Vec<u32> = (0..layers)
        .flat_map(|l| std::iter::repeat_n(l, n))
        .collect();
    fur.insert_attribute(ATTRIBUTE_SHELL_LAYER, layer_of);
    let mut indices = Vec::with_capacity(triangles.len() * 3 * layers as usize);
    for l in 0..layers {
        let base = l * n as u32;
        indices.extend(triangles.iter().flatten().map(|&i| base + i));
    }
    fur.insert_indices(Indices::U32(indices));
    Ok(fur)
}

fn float3(
    mesh: &Mesh,
    attribute: bevy::mesh::MeshVertexAttribute,
    what: &'static str,
) -> Result<Vec<Vec3>, FurMeshError> {
    match mesh.attribute(attribute) {
        Some(VertexAttributeValues::Float32x3(v)) => Ok(v.iter().map(|&p| Vec3::from(p)).collect()),
        _ => Err(FurMeshError::Missing(what)),
    }
}

/// pelage's per-vertex dP/du, through a pelage mesh of the same vertices.
fn strand_tangents(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[[f32; 2]],
    triangles: &[[u32; 3]],
) -> Result<Vec<Vec3>, FurMeshError> {
    // pelage's glam is not Bevy's: the values cross as arrays.
    let mesh = pelage::Mesh::new(
        "bevy mesh",
        positions
            .iter()
            .map(|p| glam::Vec3::from_array(p.to_array()))
            .collect(),
        triangles.to_vec(),
        Some(
            normals
                .iter()
                .map(|n| glam::Vec3::from_array(n.normalize_or(Vec3::Y).to_array()))
                .collect(),
        ),
        Some(pelage::mesh::Uvs::PerVertex(
            uvs.iter().map(|&uv| glam::Vec2::from_array(uv)).collect(),
        )),
    )
    .map_err(|e| FurMeshError::Mesh(e.to_string()))?;
    Ok(pelage_shaders::shell::vertex_tangents(&mesh)
        .iter()
        .map(|t| Vec3::from_array(t.to_array()))
        .collect())
}

/// `values` once per layer, for the attribute types a glTF skin has.
fn repeat_values(values: &VertexAttributeValues, layers: usize) -> Option<VertexAttributeValues> {
    fn rep<T: Clone>(v: &[T], layers: usize) -> Vec<T> {
        let mut out = Vec::with_capacity(v.len() * layers);
        for _ in 0..layers {
            out.extend_from_slice(v);
        }
        out
    }
    use VertexAttributeValues as V;
    Some(match values {
        V::Float32x2(v) => V::Float32x2(rep(v, layers)),
        V::Float32x3(v) => V::Float32x3(rep(v, layers)),
        V::Float32x4(v) => V::Float32x4(rep(v, layers)),
        V::Uint16x4(v) => V::Uint16x4(rep(v, layers)),
        V::Unorm16x4(v) => V::Unorm16x4(rep(v, layers)),
        V::Uint8x4(v) => V::Uint8x4(rep(v, layers)),
        V::Unorm8x4(v) => V::Unorm8x4(rep(v, layers)),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A skinned quad: two triangles, two joints.
    fn quad() -> Mesh {
        Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::default(),
        )
        .with_inserted_attribute(
            Mesh::ATTRIBUTE_POSITION,
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
        )
        .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0, 0.0, 1.0]; 4])
        .with_inserted_attribute(
            Mesh::ATTRIBUTE_UV_0,
            vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]],
        )
        .with_inserted_attribute(
            Mesh::ATTRIBUTE_JOINT_INDEX,
            VertexAttributeValues::Uint16x4(vec![[0, 1, 0, 0]; 4]),
        )
        .with_inserted_attribute(
            Mesh::ATTRIBUTE_JOINT_WEIGHT,
            vec![
                [0.25, 0.75, 0.0, 0.0],
                [1.0, 0.0, 0.0, 0.0],
                [0.5, 0.5, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
            ],
        )
        .with_inserted_indices(Indices::U32(vec![0, 1, 2, 0, 2, 3]))
    }

    /// Every layer's vertex is the skin's vertex with its own joints and
    /// weights, so Bevy's skinning puts each layer's root on the skin.
    #[test]
    fn each_layer_repeats_the_skin_with_its_influences() {
        let skin = quad();
        let fur = fur_mesh(&skin, 3).unwrap();
        assert_eq!(fur.count_vertices(), 12);
        for attribute in [
            Mesh::ATTRIBUTE_POSITION,
            Mesh::ATTRIBUTE_NORMAL,
            Mesh::ATTRIBUTE_UV_0,
            Mesh::ATTRIBUTE_JOINT_INDEX,
            Mesh::ATTRIBUTE_JOINT_WEIGHT,
        ] {
            let a = skin.attribute(attribute).unwrap();
            let b = fur.attribute(attribute).unwrap();
            let (a, b) = (a.get_bytes(), b.get_bytes());
            for layer in 0..3 {
                assert_eq!(
                    &b[layer * a.len()..(layer + 1) * a.len()],
                    a,
                    "{}",
                    attribute.name
                );
            }
        }
        let Some(VertexAttributeValues::Uint32(layer)) = fur.attribute(ATTRIBUTE_SHELL_LAYER)
        else {
            panic!("a layer attribute");
        };
        assert_eq!(layer, &vec![0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2]);
        // Layer by layer, innermost first: blending draws them in order.
        let indices: Vec<usize> = fur.indices().unwrap().iter().collect();
        assert_eq!(&indices[..6], &[0, 1, 2, 0, 2, 3]);
        assert_eq!(&indices[12..], &[8, 9, 10, 8, 10, 11]);
        // dP/du along +x, perpendicular to the normal.
        let Some(VertexAttributeValues::Float32x4(t)) = fur.attribute(Mesh::ATTRIBUTE_TANGENT)
        else {
            panic!("tangents");
        };
        assert!((Vec3::new(t[0][0], t[0][1], t[0][2]) - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn a_mesh_without_uvs_is_refused_by_name() {
        let mut skin = quad();
        skin.remove_attribute(Mesh::ATTRIBUTE_UV_0);
        assert_eq!(
            fur_mesh(&skin, 2).unwrap_err(),
            FurMeshError::Missing("UVs")
        );
    }
}
