//! A mesh prepared for the shell renderer, on the CPU and without wgpu:
//! triangle corners welded into indexed vertices ([`WeldedCorners`]) with
//! their pose, surface and skin vertices. Per-vertex tangents and the
//! shell texture's mip chain come from the layer the GPU hosts share
//! (`pelage_shaders::shell`). The uploads of `upload.rs` and the fins of
//! `fins.rs` read these.

use super::{PoseVertex, SurfaceVertex};
use pelage::Mesh;
use pelage::anim::SkinRig;
use pelage_shaders::shell::vertex_tangents;

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

impl WeldedCorners {
    /// Each vertex's rest position, normal and tangent (the strand frame
    /// the shells stand on).
    pub(super) fn pose_vertices(&self, mesh: &Mesh) -> Vec<PoseVertex> {
        let tangents = vertex_tangents(mesh);
        self.mesh_vertices
            .iter()
            .map(|&v| PoseVertex {
                position: mesh.positions()[v as usize].to_array(),
                normal: mesh.normals()[v as usize].to_array(),
                tangent: tangents[v as usize].to_array(),
            })
            .collect()
    }

    /// Each vertex's UV as the wetness mask reads it.
    pub(super) fn surface_vertices(&self) -> Vec<SurfaceVertex> {
        self.uvs
            .iter()
            .map(|&uv| SurfaceVertex {
                uv: pelage::shell::wetness::mask_coordinates(uv).to_array(),
            })
            .collect()
    }

    /// Each vertex's four joints and their weights (as bits), as the
    /// skinning pass reads them.
    pub(super) fn skin_influences(&self, rig: &SkinRig) -> Vec<[u32; 8]> {
        self.mesh_vertices
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
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec3};
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
}
