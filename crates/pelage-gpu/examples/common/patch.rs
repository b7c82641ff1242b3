//! A furry test surface shared by the gallery examples.

use glam::{Vec2, Vec3};
use pelage::Mesh;
use pelage::mesh::Uvs;

/// A flat square of `n × n` quads in the XZ plane, normal +Y, with UVs.
pub fn patch(n: usize) -> Mesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            positions.push(Vec3::new(u - 0.5, 0.0, 0.5 - v));
            uvs.push(Vec2::new(u, v));
        }
    }
    let mut triangles = Vec::new();
    let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Mesh::new(
        "patch",
        positions,
        triangles,
        None,
        Some(Uvs::PerVertex(uvs)),
    )
    .expect("a valid patch")
}
