//! The mesh as a weighted graph for shortest paths along its edges — what
//! the style mesh's geodesic colouring walks (Furtility talk, step 2).
//!
//! Vertices are renumbered along a Morton (Z-order) curve through their
//! positions. A search that grows a region of the surface then reads and
//! writes a few contiguous stretches of memory instead of vertices spread
//! over the whole file order (subdivision, for one, appends every new
//! vertex at the end), which is what limits such searches on large meshes.
//! Edge lengths are stored beside the neighbours, in the same order.

use super::EdgeList;
use glam::Vec3;
use rayon::prelude::*;

/// Vertex adjacency with edge lengths, in a locality-preserving vertex
/// order. "Graph index" below means a vertex's index in that order.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeGraph {
    /// For each mesh vertex, its graph index.
    rank: Vec<u32>,
    /// `vertex_count + 1` offsets into `neighbors` and `lengths`, by graph
    /// index.
    offsets: Vec<u32>,
    /// Neighbours' graph indices.
    neighbors: Vec<u32>,
    /// Length of the edge to each neighbour.
    lengths: Vec<f32>,
}

impl EdgeGraph {
    /// Builds the graph of the vertices `positions` joined by `edges`.
    pub fn new(positions: &[Vec3], edges: &EdgeList) -> Self {
        let n = positions.len();
        let (lo, hi) = positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let extent = (hi - lo).max(Vec3::splat(1e-30));
        let mut order: Vec<(u64, u32)> = positions
            .par_iter()
            .enumerate()
            .map(|(v, &p)| (morton((p - lo) / extent), v as u32))
            .collect();
        order.par_sort_unstable();
        let mut rank = vec![0u32; n];
        for (new, &(_, old)) in order.iter().enumerate() {
            rank[old as usize] = new as u32;
        }
        let mut offsets = vec![0u32; n + 1];
        for &[a, b] in &edges.edges {
            offsets[rank[a as usize] as usize + 1] += 1;
            offsets[rank[b as usize] as usize + 1] += 1;
        }
        for v in 0..n {
            offsets[v + 1] += offsets[v];
        }
        let mut cursor: Vec<u32> = offsets[..n].to_vec();
        let mut neighbors = vec![0u32; edges.edges.len() * 2];
        for &[a, b] in &edges.edges {
            let (a, b) = (rank[a as usize], rank[b as usize]);
            neighbors[cursor[a as usize] as usize] = b;
            cursor[a as usize] += 1;
            neighbors[cursor[b as usize] as usize] = a;
            cursor[b as usize] += 1;
        }
        // Lengths from the positions in graph order, so both ends of most
        // edges are read from nearby memory.
        let local: Vec<Vec3> = order
            .par_iter()
            .map(|&(_, v)| positions[v as usize])
            .collect();
        let (offsets_ref, neighbors_ref, local) = (&offsets, &neighbors, &local);
        let lengths = (0..n)
            .into_par_iter()
            .flat_map_iter(|u| {
                let p = local[u];
                let range = offsets_ref[u] as usize..offsets_ref[u + 1] as usize;
                neighbors_ref[range]
                    .iter()
                    .map(move |&w| (local[w as usize] - p).length())
            })
            .collect();
        Self {
            rank,
            offsets,
            neighbors,
            lengths,
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.rank.len()
    }

    /// The graph index of mesh vertex `v`.
    pub fn rank(&self, v: u32) -> u32 {
        self.rank[v as usize]
    }

    /// The graph index of every mesh vertex.
    pub fn ranks(&self) -> &[u32] {
        &self.rank
    }

    /// The neighbours (graph indices) of graph vertex `u` and the lengths
    /// of the edges to them.
    #[inline]
    pub fn edges_of(&self, u: u32) -> (&[u32], &[f32]) {
        let range = self.offsets[u as usize] as usize..self.offsets[u as usize + 1] as usize;
        (&self.neighbors[range.clone()], &self.lengths[range])
    }

    /// The mean edge length (each edge counted from both ends).
    pub fn mean_edge_length(&self) -> f32 {
        if self.lengths.is_empty() {
            0.0
        } else {
            (self.lengths.par_iter().map(|&l| f64::from(l)).sum::<f64>()
                / self.lengths.len() as f64) as f32
        }
    }
}

/// 63-bit Morton code of a point of the unit cube (21 bits an axis).
pub(crate) fn morton(p: Vec3) -> u64 {
    let scale = ((1u32 << 21) - 1) as f32;
    let q = |x: f32| spread((x.clamp(0.0, 1.0) * scale) as u64);
    q(p.x) | (q(p.y) << 1) | (q(p.z) << 2)
}

/// Spreads the low 21 bits of `x` to every third bit.
fn spread(mut x: u64) -> u64 {
    x &= 0x1F_FFFF;
    x = (x | (x << 32)) & 0x001F_0000_0000_FFFF;
    x = (x | (x << 16)) & 0x001F_0000_FF00_00FF;
    x = (x | (x << 8)) & 0x100F_00F0_0F00_F00F;
    x = (x | (x << 4)) & 0x10C3_0C30_C30C_30C3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_axes() {
        assert_eq!(spread(0b111), 0b1001001);
        assert!(morton(Vec3::ZERO) < morton(Vec3::splat(0.5)));
        assert!(morton(Vec3::splat(0.5)) < morton(Vec3::ONE));
    }

    #[test]
    fn graph_has_the_mesh_edges_and_lengths_in_its_own_order() {
        let mesh = crate::assets::spot().subdivided(1);
        let graph = mesh.edge_graph();
        let adjacency = mesh.vertex_adjacency();
        let p = mesh.positions();
        // The renumbering is a permutation.
        let mut seen = vec![false; mesh.vertex_count()];
        for &r in graph.ranks() {
            assert!(!std::mem::replace(&mut seen[r as usize], true));
        }
        let mut old_of = vec![0u32; mesh.vertex_count()];
        for v in 0..mesh.vertex_count() as u32 {
            old_of[graph.rank(v) as usize] = v;
        }
        for v in 0..mesh.vertex_count() {
            let (neighbors, lengths) = graph.edges_of(graph.rank(v as u32));
            let mut got: Vec<(u32, f32)> = neighbors
                .iter()
                .map(|&u| old_of[u as usize])
                .zip(lengths.iter().copied())
                .collect();
            got.sort_by_key(|g| g.0);
            let expected: Vec<(u32, f32)> = adjacency
                .neighbors(v)
                .iter()
                .map(|&u| (u, (p[u as usize] - p[v]).length()))
                .collect();
            assert_eq!(got, expected, "vertex {v}");
        }
    }

    #[test]
    fn neighbouring_vertices_are_near_in_the_new_order() {
        // The point of the renumbering: after subdivision appends the new
        // vertices at the end, edges span far less of the index range.
        let mesh = crate::assets::spot().subdivided(3);
        let graph = mesh.edge_graph();
        let span = |rank: &dyn Fn(u32) -> u32| {
            let mut spans: Vec<u32> = mesh
                .edges()
                .edges
                .iter()
                .map(|&[a, b]| rank(a).abs_diff(rank(b)))
                .collect();
            spans.sort_unstable();
            spans[spans.len() / 2]
        };
        let file_order = span(&|v| v);
        let graph_order = span(&|v| graph.rank(v));
        assert!(
            graph_order * 20 < file_order,
            "median edge span {graph_order} (graph order) vs {file_order} (file order)"
        );
    }
}
