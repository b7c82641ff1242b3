//! Fins (Lengyel et al. 2001, §4): one quad standing on every edge of the
//! skin, drawn where the edge is seen edge-on. A fin record names the
//! edge's two vertices; the vertex shader (`vs_fin` in `shells.wgsl`)
//! reads their posed positions and normals, so it can tell every frame,
//! skinned or not, how close the edge is to the silhouette.
//!
//! The silhouette is that of the smooth surface the vertex normals
//! describe, not of the facets: on a low-poly character the facets' own
//! contour runs across the body wherever two faces fold away from each
//! other, and fins there draw creases of hair.

use super::prepare::WeldedCorners;
use pelage::Mesh;
use std::collections::HashSet;

/// One fin: the model vertices `[a, b]` of its edge.
pub(super) type FinRecord = [u32; 2];

/// Every edge's fin, once: edges are matched by mesh vertex (a UV seam
/// does not make two fins), in the order the triangles meet them.
pub(super) fn fin_records(mesh: &Mesh, welded: &WeldedCorners) -> Vec<FinRecord> {
    let mut seen: HashSet<(u32, u32)> = HashSet::with_capacity(mesh.triangle_count() * 3 / 2);
    let mut fins = Vec::with_capacity(mesh.triangle_count() * 3 / 2);
    for (t, tri) in mesh.triangles().iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (tri[k], tri[(k + 1) % 3]);
            if seen.insert((u.min(v), u.max(v))) {
                fins.push([
                    welded.indices[3 * t + k],
                    welded.indices[3 * t + (k + 1) % 3],
                ]);
            }
        }
    }
    fins
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_edge_has_one_fin() {
        let spot = pelage::assets::spot();
        let welded = WeldedCorners::new(&spot, false);
        let fins = fin_records(&spot, &welded);
        assert_eq!(fins.len(), spot.edges().edges.len());
        // Each fin's ends are the ends of a mesh edge.
        let edges: HashSet<[u32; 2]> = spot.edges().edges.iter().copied().collect();
        for [a, b] in fins {
            let (u, v) = (
                welded.mesh_vertices[a as usize],
                welded.mesh_vertices[b as usize],
            );
            assert!(edges.contains(&[u.min(v), u.max(v)]));
        }
    }
}
