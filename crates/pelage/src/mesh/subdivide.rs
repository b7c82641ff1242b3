//! Midpoint subdivision: every triangle becomes four by splitting its edges
//! at their midpoints. The surface does not move (same area, same shape),
//! UVs are interpolated linearly (seams stay seams), and vertices on shared
//! edges are welded, so a closed mesh stays closed.
//!
//! The benchmark meshes of the papers' tables are made with it from the
//! shared meshes: blub ×1 = 56,832 triangles, spot ×2 = 93,696, spot ×4 =
//! 1,499,136.

use super::topology::EdgeList;
use super::{Mesh, Uvs};
use glam::{Vec2, Vec3};

impl Mesh {
    /// The mesh subdivided `levels` times (×4 triangles per level). Child
    /// triangles of parent `t` are `4t..4t+4`: the three corner triangles
    /// (at corners 0, 1, 2) and the middle one, all with the parent's
    /// orientation.
    pub fn subdivided(&self, levels: u32) -> Mesh {
        let mut mesh = self.clone();
        for _ in 0..levels {
            mesh = mesh.subdivide_once();
        }
        mesh
    }

    /// [`Self::subdivided`], refused when the result would pass
    /// [`crate::limits::MAX_TRIANGLES`] (`subdivide` multiplies the count
    /// by 4 a level: a typo such as `subdivide = 20` would otherwise run
    /// the machine out of memory).
    pub fn subdivided_within_limits(&self, levels: u32) -> Result<Mesh, super::MeshError> {
        let limit = crate::limits::MAX_TRIANGLES;
        let triangles = (self.triangle_count() as u64).saturating_mul(4u64.saturating_pow(levels));
        if triangles > limit {
            return Err(super::MeshError::whole(
                self.name(),
                super::MeshErrorKind::Unsupported(format!(
                    "subdivide = {levels} would make {} triangles of its {}; pelage's limit is {} (docs/limits.md)",
                    crate::limits::grouped(triangles as f64),
                    crate::limits::grouped(self.triangle_count() as f64),
                    crate::limits::grouped(limit as f64),
                )),
            ));
        }
        Ok(self.subdivided(levels))
    }

    fn subdivide_once(&self) -> Mesh {
        let edges = self.edges();
        let n = self.vertex_count() as u32;
        let midpoint_vertex = |a: u32, b: u32| -> u32 {
            n + edges
                .find(a, b)
                .expect("every triangle side is in the edge list") as u32
        };

        let mut positions = self.positions().to_vec();
        positions.extend(
            edges
                .edges
                .iter()
                .map(|&[a, b]| 0.5 * (self.positions()[a as usize] + self.positions()[b as usize])),
        );
        // Normals of new vertices interpolate their edge's ends, so shading
        // (and the hair directions that follow it) is what the parent had.
        let mut normals = self.normals().to_vec();
        normals.extend(edges.edges.iter().map(|&[a, b]| {
            (self.normals()[a as usize] + self.normals()[b as usize])
                .try_normalize()
                .unwrap_or(Vec3::Z)
        }));

        let triangles = split_all(self.triangles(), midpoint_vertex);
        let uvs = self.uvs().map(|uvs| match uvs {
            Uvs::PerVertex(values) => {
                let mut new_values = values.clone();
                new_values.extend(
                    edges
                        .edges
                        .iter()
                        .map(|&[a, b]| midpoint2(values[a as usize], values[b as usize])),
                );
                Uvs::PerVertex(new_values)
            }
            Uvs::PerCorner { values, indices } => {
                // UV corners are welded along UV edges, not position edges:
                // across a seam the two sides keep their own midpoints.
                let uv_edges = EdgeList::build(indices);
                let m = values.len() as u32;
                let mut new_values = values.clone();
                new_values.extend(
                    uv_edges
                        .edges
                        .iter()
                        .map(|&[a, b]| midpoint2(values[a as usize], values[b as usize])),
                );
                let new_indices = split_all(indices, |a, b| {
                    m + uv_edges
                        .find(a, b)
                        .expect("every UV side is in the UV edge list")
                        as u32
                });
                Uvs::PerCorner {
                    values: new_values,
                    indices: new_indices,
                }
            }
        });

        let mut mesh = Mesh::new(self.name(), positions, triangles, Some(normals), uvs)
            .expect("subdividing a valid mesh gives a valid mesh");
        // Per-vertex scalars interpolate linearly, as the UVs do; a child
        // triangle is in its parent's face set.
        for attribute in self.vertex_attributes() {
            let mut values = attribute.values.to_vec();
            values.extend(edges.edges.iter().map(|&[a, b]| {
                0.5 * (attribute.values[a as usize] + attribute.values[b as usize])
            }));
            mesh = mesh
                .with_vertex_attribute(attribute.name.clone(), values)
                .expect("midpoints of finite values are finite");
        }
        for groups in &self.face_groups {
            let mut children = groups.clone();
            children.of_triangle = groups.of_triangle.iter().flat_map(|&g| [g; 4]).collect();
            mesh = mesh
                .with_face_groups(children)
                .expect("four children a triangle");
        }
        mesh
    }
}

fn midpoint2(a: Vec2, b: Vec2) -> Vec2 {
    0.5 * (a + b)
}

/// Splits each triangle into four, given the index of the vertex at the
/// midpoint of any side.
fn split_all(triangles: &[[u32; 3]], midpoint: impl Fn(u32, u32) -> u32) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(triangles.len() * 4);
    for &[a, b, c] in triangles {
        // A degenerate side (a == b) has no edge; its "midpoint" is the vertex.
        let mid = |u: u32, v: u32| if u == v { u } else { midpoint(u, v) };
        let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
        out.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::mesh::tests::{tetrahedron, unit_square};

    #[test]
    fn subdivision_keeps_closed_meshes_closed() {
        let m = tetrahedron().subdivided(2);
        assert_eq!(m.triangle_count(), 64);
        // Euler: V − E + F = 2 for a sphere.
        let r = m.topology_report();
        assert_eq!(m.vertex_count() as i64 - r.edges as i64 + 64, 2);
        assert_eq!(r.boundary_edges, 0);
        assert!((m.surface_area() - tetrahedron().surface_area()).abs() < 1e-5);
    }

    #[test]
    fn subdivided_square_uvs_stay_equal_to_xy() {
        let m = unit_square().subdivided(3);
        assert_eq!(m.triangle_count(), 2 * 64);
        for t in 0..m.triangle_count() {
            let ps = m.triangle_positions(t);
            let uvs = m.triangle_uvs(t).unwrap();
            for (p, uv) in ps.iter().zip(uvs) {
                assert!((p.truncate() - uv).length() < 1e-6);
            }
        }
    }
}
