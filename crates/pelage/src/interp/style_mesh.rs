//! The style mesh of Furtility's Mesh Style GOP (Andrus & Manca, SIGGRAPH
//! 2015 talk), built from the surface as the talk describes:
//!
//! 1. Each guide marks the mesh vertex nearest its root.
//! 2. Every vertex is coloured with the nearest guide by distance along
//!    mesh edges: a multi-source Dijkstra from the marked vertices, where a
//!    colour passes to a neighbour only while it is the closest that
//!    neighbour has seen.
//! 3. Cells are the groups of identically coloured vertices; the style
//!    mesh has an edge between two guides whose cells share a border, and
//!    a triangle for every mesh triangle whose corners carry three
//!    different colours.
//! 4. A hair takes the barycentric coordinates of its closest point on the
//!    style mesh as weights over that triangle's three guides, so a hair at
//!    a guide's root reproduces the guide exactly.
//!
//! Which closest point: a hair on the skin looks only at the style
//! primitives incident to the guides colouring its skin triangle's corners
//! — its own cells. That keeps the search on the hair's side of the
//! surface (a thin part's other side can never win, however the style
//! mesh bends) and tests a handful of triangles instead of walking a tree.
//! Among those, the nearest triangle whose plane projection contains the
//! root wins (two dot products a triangle); only where none contains it
//! (near a fold) are closest points on edges and corners computed.
//! A root off the skin (or in a part no guide reaches) uses the closest
//! point on the whole style mesh (a BVH).
//!
//! Gaps: border edges that no three-colour triangle uses (two cells
//! meeting along a strip with no third cell at either end) join the
//! closest-point set as segments, and a guide whose cell touches no other
//! (alone on an island) as a point, so every guide and every adjacency can
//! be the closest feature. Closest points only need a "well-defined closest
//! point function" (the talk), so non-manifold and degenerate style
//! triangles are fine.
//!
//! Failure case, reported not hidden: two guides nearest the same vertex
//! (denser than the mesh, e.g. more than three guides in a triangle). The
//! farther one is listed in [`StyleMesh::lost`] with the vertex and the
//! guide that kept it. With [`StyleMeshOptions::split_shared`] (the talk's
//! suggested fix) the triangle under each such guide is split locally
//! (1 → 3 at the guide root), so every guide gets its own vertex.

use super::{GuideWeight, GuideWeights, HairRoot, normalise};
use crate::guides::Guides;
use crate::mesh::{EdgeGraph, EdgeList, Mesh, TriangleBvh, closest_on_triangle};
use glam::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::collections::HashSet;

/// Options of the style mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StyleMeshOptions {
    /// Split the mesh triangle under each guide that lost its vertex, so
    /// every guide gets a vertex of its own.
    pub split_shared: bool,
}

/// A guide the style mesh could not use.
#[derive(Debug, Clone, PartialEq)]
pub struct LostGuide {
    /// The guide.
    pub guide: u32,
    /// The vertex it was nearest.
    pub vertex: u32,
    /// The guide nearer that vertex, which kept it.
    pub kept_by: u32,
}

impl std::fmt::Display for LostGuide {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "guide {} is not used: vertex {} is nearest to it and to guide {}, which is nearer; \
             guides are denser than the mesh there (split_shared gives each guide its own vertex)",
            self.guide, self.vertex, self.kept_by
        )
    }
}

/// Furtility's style mesh over a set of guides.
pub struct StyleMesh {
    /// Guide root positions (the style mesh's vertices).
    positions: Vec<Vec3>,
    /// Style triangles (guide indices); segments and points are triangles
    /// with repeated corners.
    triangles: Vec<[u32; 3]>,
    /// How many of `triangles` are real (three distinct guides).
    real_triangles: usize,
    /// Guide pairs whose cells share a border.
    edges: Vec<[u32; 2]>,
    /// The colour (guide) of each vertex of the mesh the colouring ran on;
    /// `u32::MAX` where no guide reaches.
    colours: Vec<u32>,
    lost: Vec<LostGuide>,
    bvh: TriangleBvh,
    /// Corner positions of each primitive of `triangles`.
    corners: Vec<[Vec3; 3]>,
    /// Each primitive prepared for projecting a point onto its plane.
    projections: Vec<Projection>,
    /// Per guide, the primitives it is a corner of (CSR).
    incident_offsets: Vec<u32>,
    incident: Vec<u32>,
    /// Per skin triangle, the colours of its corners.
    triangle_colours: Vec<[u32; 3]>,
    /// Guides given their own vertex inside a skin triangle by the split.
    split_colours: HashMap<u32, Vec<u32>>,
}

impl StyleMesh {
    /// Builds the style mesh of `guides` on `mesh`.
    pub fn build(mesh: &Mesh, guides: &Guides, options: &StyleMeshOptions) -> Self {
        let positions: Vec<Vec3> = guides.roots().iter().map(|r| r.position(mesh)).collect();
        // 1. Each guide marks the corner of its root triangle nearest to it.
        let nearest_corner = |g: usize| {
            let tri = mesh.triangles()[guides.roots()[g].tri as usize];
            *tri.iter()
                .min_by(|&&a, &&b| {
                    let da = (mesh.positions()[a as usize] - positions[g]).length_squared();
                    let db = (mesh.positions()[b as usize] - positions[g]).length_squared();
                    da.total_cmp(&db).then(a.cmp(&b))
                })
                .expect("three corners")
        };
        let mut marks: Vec<(u32, u32)> = (0..guides.len())
            .map(|g| (nearest_corner(g), g as u32))
            .collect();
        let lost = conflicts(&marks, &positions, mesh.positions());

        // 2. The colouring, on the mesh itself or, with the split fix, on a
        // copy split under each lost guide (then no guide is lost).
        let mut split_colours: HashMap<u32, Vec<u32>> = HashMap::new();
        let (colours, split_triangles, lost) = if options.split_shared && !lost.is_empty() {
            for l in &lost {
                let tri = guides.roots()[l.guide as usize].tri;
                split_colours.entry(tri).or_default().push(l.guide);
            }
            let (vertices, triangles) = split_under(mesh, guides, &lost, &positions, &mut marks);
            let graph = EdgeGraph::new(&vertices, &EdgeList::build(&triangles));
            let colours = colour(&graph, &marks, &[]);
            (colours, Some(triangles), Vec::new())
        } else {
            let colours = colour(mesh.edge_graph(), &marks, &lost);
            (colours, None, lost)
        };

        // Per skin triangle, its corners' colours (what a hair's weights
        // start from); on the split copy, the border comes from its own.
        let triangle_colours: Vec<[u32; 3]> = mesh
            .triangles()
            .par_iter()
            .map(|t| t.map(|v| colours[v as usize]))
            .collect();
        let split_triangle_colours: Vec<[u32; 3]> = split_triangles
            .as_deref()
            .unwrap_or_default()
            .par_iter()
            .map(|t| t.map(|v| colours[v as usize]))
            .collect();
        let coloured = if split_triangles.is_some() {
            &split_triangle_colours
        } else {
            &triangle_colours
        };
        let (edges, mut triangles) = style_primitives(coloured);
        let real_triangles = triangles.len();

        close_gaps(&mut triangles, &edges, guides.len(), &lost);
        let bvh = TriangleBvh::new(&positions, &triangles);

        let corners: Vec<[Vec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|g| positions[g as usize]))
            .collect();
        let projections = corners.iter().map(|&c| Projection::new(c)).collect();
        let (incident_offsets, incident) = incidence(&triangles, guides.len());

        Self {
            positions,
            triangles,
            real_triangles,
            edges,
            colours,
            lost,
            bvh,
            corners,
            projections,
            incident_offsets,
            incident,
            triangle_colours,
            split_colours,
        }
    }

    /// Guides the style mesh could not use, with the reason.
    pub fn lost(&self) -> &[LostGuide] {
        &self.lost
    }

    /// Style triangles with three distinct guides.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles[..self.real_triangles]
    }

    /// Everything hairs can be closest to: the triangles, then segments
    /// (`[a, b, b]`) and points (`[g, g, g]`) that close gaps.
    pub fn closest_point_set(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Guide pairs whose cells share a border.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// The guide colouring each vertex of the mesh the colouring ran on
    /// (`u32::MAX`: no guide reaches it). With `split_shared` and lost
    /// guides, the split mesh has extra vertices at the end.
    pub fn colours(&self) -> &[u32] {
        &self.colours
    }

    /// The style mesh's vertices: the guide roots.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }
}

impl StyleMesh {
    /// The style primitives guide `g` is a corner of.
    fn incident_to(&self, g: u32) -> &[u32] {
        let (start, end) = (
            self.incident_offsets[g as usize],
            self.incident_offsets[g as usize + 1],
        );
        &self.incident[start as usize..end as usize]
    }

    /// The closest point among the primitives incident to the guides of
    /// the skin triangle's corners: (primitive, weights), or `None` when
    /// no guide colours them.
    fn closest_in_cells(&self, root: Vec3, triangle: u32) -> Option<(u32, [f32; 3])> {
        let colours = self.triangle_colours.get(triangle as usize)?;
        let extra = if self.split_colours.is_empty() {
            None
        } else {
            self.split_colours.get(&triangle)
        };
        // The primitives incident to the distinct guides of the corners
        // (and to any guide split inside), as a few slices: plain loops
        // over them keep this hot path tight.
        let mut lists: [&[u32]; 3] = [&[]; 3];
        for k in 0..3 {
            let g = colours[k];
            if g != u32::MAX && !colours[..k].contains(&g) {
                lists[k] = self.incident_to(g);
            }
        }
        let extra_lists: Vec<&[u32]> = extra
            .map(|gs| gs.iter().map(|&g| self.incident_to(g)).collect())
            .unwrap_or_default();
        // Fast path: the nearest candidate whose triangle contains the
        // root's projection onto its plane — the closest point whenever the
        // skin under the root is not folded over the style mesh.
        let mut best: Option<(f32, u32, [f32; 3])> = None;
        for list in lists.iter().chain(&extra_lists) {
            for &prim in *list {
                if let Some((d, weights)) = self.projections[prim as usize].inside(root)
                    && best.is_none_or(|(bd, bp, _)| d < bd || (d == bd && prim < bp))
                {
                    best = Some((d, prim, weights));
                }
            }
        }
        if best.is_none() {
            // Exact closest point among the candidates (edges, corners,
            // segments and points).
            for &prim in lists.iter().chain(&extra_lists).flat_map(|l| l.iter()) {
                let (point, weights) = closest_on_triangle(root, self.corners[prim as usize]);
                let d = (point - root).length_squared();
                if best.is_none_or(|(bd, bp, _)| d < bd || (d == bd && prim < bp)) {
                    best = Some((d, prim, weights));
                }
            }
        }
        best.map(|(_, prim, weights)| (prim, weights))
    }
}

/// A triangle prepared for barycentric projection (Ericson §3.4, with the
/// solve folded into two "dual" vectors): for a point `p`, with
/// `r = p − a`, the barycentric coordinates of its projection onto the
/// plane are `v = r·q₁`, `w = r·q₂`, `u = 1 − v − w`, where
/// `q₁ = (d₁₁ e₁ − d₀₁ e₂) / D` and `q₂ = (d₀₀ e₂ − d₀₁ e₁) / D`
/// (`dᵢⱼ = eᵢ·eⱼ`, `D = d₀₀ d₁₁ − d₀₁²`); the squared distance to the plane
/// is `(r·n̂)²`. Three dot products a candidate.
#[derive(Debug, Clone, Copy)]
struct Projection {
    a: Vec3,
    q1: Vec3,
    q2: Vec3,
    /// Unit normal of the plane.
    normal: Vec3,
}

impl Projection {
    fn new([a, b, c]: [Vec3; 3]) -> Self {
        let (e1, e2) = (b - a, c - a);
        let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let denominator = d00 * d11 - d01 * d01;
        // Degenerate primitives (segments, points, slivers) get NaN duals,
        // which fail every inside test below.
        let inverse = if denominator > 1e-12 * (d00 * d11).max(f32::MIN_POSITIVE) {
            1.0 / denominator
        } else {
            f32::NAN
        };
        Self {
            a,
            q1: (d11 * e1 - d01 * e2) * inverse,
            q2: (d00 * e2 - d01 * e1) * inverse,
            normal: e1.cross(e2).normalize_or_zero(),
        }
    }

    /// Squared distance to the plane and the barycentric weights, when the
    /// projection of `p` falls inside the triangle.
    #[inline]
    fn inside(&self, p: Vec3) -> Option<(f32, [f32; 3])> {
        let r = p - self.a;
        let v = r.dot(self.q1);
        let w = r.dot(self.q2);
        let u = 1.0 - v - w;
        // NaN (degenerate) fails these comparisons.
        if u >= 0.0 && v >= 0.0 && w >= 0.0 {
            let h = r.dot(self.normal);
            Some((h * h, [u, v, w]))
        } else {
            None
        }
    }
}

impl GuideWeights for StyleMesh {
    fn weights(&self, root: HairRoot, out: &mut Vec<GuideWeight>) {
        out.clear();
        let found = root
            .triangle
            .and_then(|t| self.closest_in_cells(root.position, t))
            .or_else(|| {
                let hit = self.bvh.closest(root.position)?;
                Some((hit.triangle, hit.weights))
            });
        let Some((prim, weights)) = found else {
            return;
        };
        let t = self.triangles[prim as usize];
        for (guide, weight) in t.into_iter().zip(weights) {
            let weight = weight.max(0.0);
            match out.iter_mut().find(|w| w.guide == guide) {
                Some(w) => w.weight += weight,
                None if weight > 0.0 => out.push(GuideWeight { guide, weight }),
                None => {}
            }
        }
        normalise(out);
    }

    fn lost_guides(&self) -> Vec<LostGuide> {
        self.lost.clone()
    }
}

/// Guides whose vertex a nearer guide also marks (ties: the lower index
/// keeps it). `marks` are (vertex, guide).
fn conflicts(marks: &[(u32, u32)], roots: &[Vec3], vertices: &[Vec3]) -> Vec<LostGuide> {
    let mut by_vertex = marks.to_vec();
    let d = |(v, g): (u32, u32)| (roots[g as usize] - vertices[v as usize]).length_squared();
    by_vertex.sort_by(|&a, &b| {
        a.0.cmp(&b.0)
            .then(d(a).total_cmp(&d(b)))
            .then(a.1.cmp(&b.1))
    });
    // In each run of one vertex the first (nearest) guide keeps it.
    let mut lost = Vec::new();
    let mut winner = by_vertex.first().copied();
    for &(vertex, guide) in by_vertex.iter().skip(1) {
        match winner {
            Some((v, kept_by)) if v == vertex => lost.push(LostGuide {
                guide,
                vertex,
                kept_by,
            }),
            _ => winner = Some((vertex, guide)),
        }
    }
    lost.sort_by_key(|l| l.guide);
    lost
}

/// Step 2, colouring: each vertex gets the guide with the shortest edge
/// path to it (ties: the lower guide index).
///
/// Computed as one Dijkstra search per guide, all in parallel, over shared
/// `(distance, guide)` labels updated with an atomic minimum. A search
/// stops expanding wherever another guide is nearer: if a vertex `u` on
/// the path from guide `g` to `v` is nearer to `h`, then so is `v`
/// (`d_h(v) ≤ d_h(u) + d(u, v) < d_g(u) + d(u, v) = d_g(v)`), so nothing is
/// lost, and each search stays inside its own cell and its border (the
/// searches advance together, band by band of distance, so none runs ahead
/// into cells not yet claimed). The
/// result is the unique smallest label of every vertex, so it does not
/// depend on the number of threads or the order of work — and the local
/// searches are kinder to the cache than one global frontier.
fn colour(graph: &EdgeGraph, marks: &[(u32, u32)], lost: &[LostGuide]) -> Vec<u32> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
    let lost: HashSet<u32> = lost.iter().map(|l| l.guide).collect();
    // Label = distance bits (non-negative floats order like their bits)
    // above the guide index: the smallest label is the nearest guide, ties
    // to the lower index.
    let label = |d: f32, g: u32| (u64::from(d.to_bits()) << 32) | u64::from(g);
    let state: Vec<AtomicU64> = (0..graph.vertex_count())
        .into_par_iter()
        .map(|_| AtomicU64::new(u64::MAX))
        .collect();
    // Seeds in graph indices.
    let seeds: Vec<(u32, u32)> = marks
        .iter()
        .filter(|(_, g)| !lost.contains(g))
        .map(|&(v, g)| (graph.rank(v), g))
        .collect();
    for &(u, g) in &seeds {
        state[u as usize].fetch_min(label(0.0, g), Relaxed);
    }
    // The searches advance in lockstep, one distance band at a time: a
    // search that ran ahead alone would flood cells its neighbours have not
    // claimed yet. A band of two mean edge lengths keeps the overlap small
    // and the rounds few.
    let mean_edge = graph.mean_edge_length();
    let band = if mean_edge > 0.0 {
        2.0 * mean_edge
    } else {
        f32::INFINITY
    };
    let mut frontiers: Vec<BinaryHeap<Reverse<(u32, u32)>>> = seeds
        .iter()
        .map(|&(u, _)| BinaryHeap::from([Reverse((0u32, u))]))
        .collect();
    let mut limit = band;
    while frontiers.iter().any(|f| !f.is_empty()) {
        frontiers
            .par_iter_mut()
            .zip(&seeds)
            .for_each(|(heap, &(_, g))| {
                while let Some(&Reverse((d_bits, u))) = heap.peek() {
                    let d = f32::from_bits(d_bits);
                    if d >= limit {
                        break;
                    }
                    heap.pop();
                    if state[u as usize].load(Relaxed) != label(d, g) {
                        continue;
                    }
                    let (neighbors, lengths) = graph.edges_of(u);
                    for (&n, &length) in neighbors.iter().zip(lengths) {
                        let nd = d + length;
                        let key = label(nd, g);
                        // A plain load first: most relaxations lose, and
                        // an atomic read-modify-write costs far more.
                        let slot = &state[n as usize];
                        if key < slot.load(Relaxed) && key < slot.fetch_min(key, Relaxed) {
                            heap.push(Reverse((nd.to_bits(), n)));
                        }
                    }
                }
            });
        limit += band;
    }
    // Back to mesh vertex order.
    graph
        .ranks()
        .par_iter()
        .map(|&u| {
            let s = state[u as usize].load(Relaxed);
            if s == u64::MAX { u32::MAX } else { s as u32 }
        })
        .collect()
}

/// The talk's fix for guides denser than the mesh: a copy of the mesh in
/// which the triangle under each lost guide is split 1 → 3 at the guide's
/// root, which becomes that guide's own vertex. Guides in the same
/// triangle split the sub-triangle they fall in, in turn.
fn split_under(
    mesh: &Mesh,
    guides: &Guides,
    lost: &[LostGuide],
    roots: &[Vec3],
    marks: &mut [(u32, u32)],
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut vertices = mesh.positions().to_vec();
    let mut triangles = mesh.triangles().to_vec();
    // Sub-triangles of each split original triangle.
    let mut pieces: std::collections::HashMap<u32, Vec<usize>> = Default::default();
    for l in lost {
        let g = l.guide as usize;
        let tri = guides.roots()[g].tri;
        let candidates = pieces.entry(tri).or_insert_with(|| vec![tri as usize]);
        // The piece containing the root: the one it is closest to.
        let &piece = candidates
            .iter()
            .min_by(|&&a, &&b| {
                let d = |t: usize| {
                    let c = triangles[t].map(|v| vertices[v as usize]);
                    (crate::mesh::closest_on_triangle(roots[g], c).0 - roots[g]).length_squared()
                };
                d(a).total_cmp(&d(b)).then(a.cmp(&b))
            })
            .expect("at least the triangle itself");
        let [a, b, c] = triangles[piece];
        let v = vertices.len() as u32;
        vertices.push(roots[g]);
        triangles[piece] = [a, b, v];
        triangles.push([b, c, v]);
        triangles.push([c, a, v]);
        let n = triangles.len();
        candidates.extend([n - 2, n - 1]);
        marks[g] = (v, l.guide);
    }
    (vertices, triangles)
}
/// Style edges and triangles from a colouring (each skin triangle's corner
/// colours): only triangles on cell borders matter. Sorting, not hashing,
/// dedups them (the same result, in parallel); a style triangle keeps the
/// corner order of the first mesh triangle of its guide triple.
fn style_primitives(coloured: &[[u32; 3]]) -> (Vec<[u32; 2]>, Vec<[u32; 3]>) {
    let border: Vec<u32> = (0..coloured.len() as u32)
        .into_par_iter()
        .filter(|&t| {
            let c = coloured[t as usize];
            !c.contains(&u32::MAX) && (c[0] != c[1] || c[1] != c[2])
        })
        .collect();
    let mut edges: Vec<[u32; 2]> = border
        .par_iter()
        .flat_map_iter(|&t| {
            let c = coloured[t as usize];
            [(c[0], c[1]), (c[1], c[2]), (c[2], c[0])]
                .into_iter()
                .filter(|(a, b)| a != b)
                .map(|(a, b)| [a.min(b), a.max(b)])
        })
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    let mut firsts: Vec<([u32; 3], u32)> = border
        .par_iter()
        .filter_map(|&t| {
            let mut key = coloured[t as usize];
            key.sort_unstable();
            (key[0] != key[1] && key[1] != key[2]).then_some((key, t))
        })
        .collect();
    firsts.par_sort_unstable();
    firsts.dedup_by_key(|(key, _)| *key);
    firsts.par_sort_unstable_by_key(|&(_, t)| t);
    let triangles: Vec<[u32; 3]> = firsts.iter().map(|&(_, t)| coloured[t as usize]).collect();
    (edges, triangles)
}

/// Closes the style mesh's gaps: edges in no triangle become segments
/// (`[a, b, b]`), guides in none (and not lost) points (`[g, g, g]`).
fn close_gaps(
    triangles: &mut Vec<[u32; 3]>,
    edges: &[[u32; 2]],
    guides: usize,
    lost: &[LostGuide],
) {
    let mut covered_edges = HashSet::new();
    let mut touched = vec![false; guides];
    for t in triangles.iter() {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            covered_edges.insert([a.min(b), a.max(b)]);
        }
        t.iter().for_each(|&g| touched[g as usize] = true);
    }
    for e in edges {
        if !covered_edges.contains(e) {
            triangles.push([e[0], e[1], e[1]]);
            touched[e[0] as usize] = true;
            touched[e[1] as usize] = true;
        }
    }
    let lost_set: HashSet<u32> = lost.iter().map(|l| l.guide).collect();
    for (g, &t) in touched.iter().enumerate() {
        if !t && !lost_set.contains(&(g as u32)) {
            triangles.push([g as u32; 3]);
        }
    }
}

/// Per guide, the primitives it is a corner of, in compressed rows.
fn incidence(triangles: &[[u32; 3]], guides: usize) -> (Vec<u32>, Vec<u32>) {
    let mut incident_offsets = vec![0u32; guides + 1];
    for t in triangles {
        for (k, &g) in t.iter().enumerate() {
            if !t[..k].contains(&g) {
                incident_offsets[g as usize + 1] += 1;
            }
        }
    }
    for g in 0..guides {
        incident_offsets[g + 1] += incident_offsets[g];
    }
    let mut fill = incident_offsets.clone();
    let mut incident = vec![0u32; *incident_offsets.last().unwrap() as usize];
    for (i, t) in triangles.iter().enumerate() {
        for (k, &g) in t.iter().enumerate() {
            if !t[..k].contains(&g) {
                incident[fill[g as usize] as usize] = i as u32;
                fill[g as usize] += 1;
            }
        }
    }
    (incident_offsets, incident)
}
