//! A posed skin as a narrow-band signed-distance grid, for pushing
//! simulated strands out of the body.
//!
//! Distances are exact (closest point on a triangle, Ericson §5.1.5) at
//! the grid nodes within a band of the surface, signed by the skin's
//! vertex normal interpolated at the closest point (the side of the
//! surface the node is on: a pseudo-normal that tolerates open meshes,
//! which ray parity would not); each of those nodes also keeps its
//! closest triangle. Nodes farther away hold the band's depth: "clear of
//! the skin". A query interpolates the eight nodes around it (trilinear);
//! where that puts it within a cell of the skin, it measures the exact
//! distance to the eight nodes' closest triangles (the closest of them,
//! signed the same way) and takes the line to the closest point as the
//! way out. Interpolation alone would miss parts thinner than two cells
//! (a leg, an ear), whose nodes all lie outside them. Farther away the
//! gradient of the interpolation is the way out.
//!
//! Why a grid and not closest-point queries over a BVH: a simulation asks
//! for every point of every strand at every substep (10,000 guides × 16
//! points × 4 substeps a frame), and a skin has a few thousand triangles.
//! A grid query costs about a quarter of a BVH descent; its build costs
//! milliseconds, which the queries repay; `pelage bench dynamics
//! --strands` measures both in the same run.
//!
//! The band is the limit: a point deeper inside the skin than the band
//! reads as clear of it. GuideStrands enter the skin only from outside, by a
//! segment or by the skin's move between two checks, so
//! [`SkinSdf::new`] takes the depth the band must cover.

use crate::mesh::closest_on_triangle;
use glam::Vec3;
use rayon::prelude::*;

/// Within this many cells of the skin (by the interpolated distance), a
/// query measures the exact distance to the nearby triangles.
const EXACT_WITHIN: f32 = 1.0;

/// The signed distance to a posed skin on a uniform grid of nodes.
#[derive(Debug, Clone)]
pub struct SkinSdf {
    origin: Vec3,
    cell: f32,
    dims: [usize; 3],
    /// Signed distance at each node, x fastest.
    distances: Vec<f32>,
    /// The triangle closest to each node (`u32::MAX` outside the band).
    nearest: Vec<u32>,
    /// The posed skin, for exact distances near it.
    corners: Vec<[Vec3; 3]>,
    corner_normals: Vec<[Vec3; 3]>,
    /// What a node outside the band holds.
    far: f32,
}

impl SkinSdf {
    /// The grid of the skin `positions` / `triangles` (with per-vertex
    /// `normals` giving each side), nodes `cell` apart, exact within
    /// `depth` of the surface (at least two cells deep).
    pub fn new(
        positions: &[Vec3],
        normals: &[Vec3],
        triangles: &[[u32; 3]],
        cell: f32,
        depth: f32,
    ) -> Self {
        assert!(cell > 0.0 && cell.is_finite(), "a positive cell size");
        let band = (depth / cell).ceil().max(2.0) as usize;
        let far = band as f32 * cell;
        let (lo, hi) = if positions.is_empty() {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            crate::mesh::bounds_of(positions)
        };
        let margin = (band + 1) as f32 * cell;
        let origin = lo - Vec3::splat(margin);
        let extent = hi + Vec3::splat(margin) - origin;
        let dims = [0, 1, 2].map(|a| (extent[a] / cell).ceil() as usize + 1);
        let (nx, ny, nz) = (dims[0], dims[1], dims[2]);
        // Which triangles touch each z slab of nodes: slabs are filled in
        // parallel, each from its own list, so the result does not depend
        // on the thread count.
        let mut by_slab: Vec<Vec<u32>> = vec![Vec::new(); nz];
        let node_range = |v: f32, a: usize, dim: usize| -> (usize, usize) {
            let first = ((v - origin[a]) / cell - band as f32).floor().max(0.0) as usize;
            let last = (((v - origin[a]) / cell + band as f32).ceil() as usize).min(dim - 1);
            (first, last)
        };
        let corners_of = |t: [u32; 3]| t.map(|i| positions[i as usize]);
        for (ti, &t) in triangles.iter().enumerate() {
            let c = corners_of(t);
            let (z0, _) = node_range(c[0].z.min(c[1].z).min(c[2].z), 2, nz);
            let (_, z1) = node_range(c[0].z.max(c[1].z).max(c[2].z), 2, nz);
            for slab in &mut by_slab[z0..=z1] {
                slab.push(ti as u32);
            }
        }
        let mut distances = vec![far; nx * ny * nz];
        let mut nearest = vec![u32::MAX; nx * ny * nz];
        distances
            .par_chunks_mut(nx * ny)
            .zip(nearest.par_chunks_mut(nx * ny))
            .zip(by_slab.par_iter())
            .enumerate()
            .for_each(|(z, ((slab, slab_nearest), tris))| {
                // Unsigned distance, the nearest triangle's normal side,
                // the triangle.
                let mut best = vec![(f32::INFINITY, 0.0f32, u32::MAX); nx * ny];
                let pz = origin.z + z as f32 * cell;
                for &ti in tris {
                    let t = triangles[ti as usize];
                    let c = corners_of(t);
                    let (lo, hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
                    let (x0, _) = node_range(lo.x, 0, nx);
                    let (_, x1) = node_range(hi.x, 0, nx);
                    let (y0, _) = node_range(lo.y, 1, ny);
                    let (_, y1) = node_range(hi.y, 1, ny);
                    let face = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
                    let centre = (c[0] + c[1] + c[2]) / 3.0;
                    let radius = c.iter().map(|&v| (v - centre).length()).fold(0.0, f32::max);
                    for y in y0..=y1 {
                        let py = origin.y + y as f32 * cell;
                        for x in x0..=x1 {
                            let p = Vec3::new(origin.x + x as f32 * cell, py, pz);
                            // The distance to the plane and to the
                            // bounding sphere are both at most the
                            // distance to the triangle: nodes beyond the
                            // band by either, or already nearer another
                            // triangle, need no closest point.
                            let slot = &mut best[y * nx + x];
                            let plane = (p - c[0]).dot(face).abs();
                            let sphere = (p - centre).length() - radius;
                            let bound = plane.max(sphere);
                            if bound > far || bound >= slot.0 {
                                continue;
                            }
                            let (q, w) = closest_on_triangle(p, c);
                            let d = (p - q).length();
                            if d < slot.0 {
                                let n = w[0] * normals[t[0] as usize]
                                    + w[1] * normals[t[1] as usize]
                                    + w[2] * normals[t[2] as usize];
                                let n = if n.length_squared() > 1e-12 { n } else { face };
                                let side = (p - q).dot(n);
                                *slot = (d, if side < 0.0 { -1.0 } else { 1.0 }, ti);
                            }
                        }
                    }
                }
                for ((out, out_nearest), &(d, sign, ti)) in
                    slab.iter_mut().zip(slab_nearest.iter_mut()).zip(&best)
                {
                    if d < far {
                        *out = sign * d;
                        *out_nearest = ti;
                    }
                }
            });
        let corners = triangles.iter().map(|&t| corners_of(t)).collect();
        let corner_normals = triangles
            .iter()
            .map(|t| t.map(|i| normals[i as usize]))
            .collect();
        Self {
            origin,
            cell,
            dims,
            distances,
            nearest,
            corners,
            corner_normals,
            far,
        }
    }

    /// The posed skin's triangles, as corner positions, and their
    /// corners' vertex normals (for a GPU port).
    pub fn triangles(&self) -> (&[[Vec3; 3]], &[[Vec3; 3]]) {
        (&self.corners, &self.corner_normals)
    }

    /// The triangle closest to each node (`u32::MAX` for nodes outside
    /// the band), x fastest.
    pub fn nearest_triangles(&self) -> &[u32] {
        &self.nearest
    }

    /// The grid's first node, node spacing and node counts (x, y, z).
    pub fn layout(&self) -> (Vec3, f32, [usize; 3]) {
        (self.origin, self.cell, self.dims)
    }

    /// The node values, x fastest, then y, then z.
    pub fn distances(&self) -> &[f32] {
        &self.distances
    }

    /// How deep the exact band reaches: nodes beyond it hold this value.
    pub fn band_depth(&self) -> f32 {
        self.far
    }

    /// The signed distance at `p` (negative inside the skin) and the unit
    /// direction in which it grows (zero where it is flat), trilinear
    /// between the grid's nodes; `far` outside the grid.
    pub fn sample(&self, p: Vec3) -> (f32, Vec3) {
        let Some((base, f)) = self.cell_of(p) else {
            return (self.far, Vec3::ZERO);
        };
        let [nx, ny, _] = self.dims;
        // The eight corner nodes, in the order c000, c100, c010, c110,
        // c001, c101, c011, c111 (x fastest).
        let corners = [
            0,
            1,
            nx,
            nx + 1,
            nx * ny,
            nx * ny + 1,
            nx * ny + nx,
            nx * ny + nx + 1,
        ]
        .map(|o| base + o);
        let [c000, c100, c010, c110, c001, c101, c011, c111] = corners.map(|i| self.distances[i]);
        let x00 = c000 + f.x * (c100 - c000);
        let x10 = c010 + f.x * (c110 - c010);
        let x01 = c001 + f.x * (c101 - c001);
        let x11 = c011 + f.x * (c111 - c011);
        let y0 = x00 + f.y * (x10 - x00);
        let y1 = x01 + f.y * (x11 - x01);
        let d = y0 + f.z * (y1 - y0);
        // The trilinear interpolation's own gradient.
        let dx0 = (c100 - c000) + f.y * ((c110 - c010) - (c100 - c000));
        let dx1 = (c101 - c001) + f.y * ((c111 - c011) - (c101 - c001));
        let dy0 = x10 - x00;
        let dy1 = x11 - x01;
        if d < EXACT_WITHIN * self.cell {
            // Near the skin: the exact distance to the nearest of the
            // corners' closest triangles. Interpolation alone cannot see
            // a part thinner than two cells (a leg, an ear): the nodes on
            // both sides of it are outside, and so would be every point
            // between them.
            let ids = corners.map(|i| self.nearest[i]);
            if let Some(exact) = self.exact(p, &ids) {
                return exact;
            }
        }
        let grad = Vec3::new(dx0 + f.z * (dx1 - dx0), dy0 + f.z * (dy1 - dy0), y1 - y0);
        (d, grad.normalize_or_zero())
    }

    /// The grid cell holding `p`: its first node's index and where `p`
    /// lies in it (0 to 1 on each axis); `None` outside the grid.
    #[inline]
    fn cell_of(&self, p: Vec3) -> Option<(usize, Vec3)> {
        let g = (p - self.origin) / self.cell;
        let [nx, ny, nz] = self.dims;
        if !(g.x >= 0.0 && g.y >= 0.0 && g.z >= 0.0) {
            return None;
        }
        let (ix, iy, iz) = (g.x as usize, g.y as usize, g.z as usize);
        if ix + 1 >= nx || iy + 1 >= ny || iz + 1 >= nz {
            return None;
        }
        let f = g - Vec3::new(ix as f32, iy as f32, iz as f32);
        Some(((iz * ny + iy) * nx + ix, f))
    }

    /// Whether `p` is certainly `gap` or more outside the skin, read from
    /// the grid's nodes alone, without the exact path: the distance to
    /// the skin changes no faster than the point moves, so a node `d`
    /// outside keeps every point `r` from it at least `d - r` outside
    /// (a path from the node to the point that met the skin would be
    /// longer than `d`). Only nodes inside the exact band count: beyond
    /// it a node holds `far` on either side. False when unsure, and
    /// always for a gap wider than the exact band's cell (where
    /// [`Self::sample`] reads the interpolation, which may say less), so
    /// that a point it calls clear is one [`Self::sample`] finds `gap` or
    /// more outside.
    #[inline]
    pub fn clear_of(&self, p: Vec3, gap: f32) -> bool {
        if gap > EXACT_WITHIN * self.cell {
            return false;
        }
        // Beyond the grid (more than the band from the skin's bounds):
        // outside.
        let Some((base, f)) = self.cell_of(p) else {
            return true;
        };
        let [nx, ny, _] = self.dims;
        // The corner nearest the point first: it gives the best bound.
        let near = [
            usize::from(f.x >= 0.5),
            usize::from(f.y >= 0.5),
            usize::from(f.z >= 0.5),
        ];
        for k in 0..8 {
            let o = [
                near[0] ^ (k & 1),
                near[1] ^ ((k >> 1) & 1),
                near[2] ^ ((k >> 2) & 1),
            ];
            let d = self.distances[base + (o[2] * ny + o[1]) * nx + o[0]];
            // Nodes beyond the band hold `far` on either side of the
            // skin: they say nothing.
            if d < gap || d >= self.far {
                continue;
            }
            let r = (f - Vec3::new(o[0] as f32, o[1] as f32, o[2] as f32)).length() * self.cell;
            if d - r >= gap {
                return true;
            }
        }
        false
    }

    /// The signed distance to the closest of `triangles` (each tried
    /// once) and the direction out; `None` when none is in the band.
    fn exact(&self, p: Vec3, triangles: &[u32; 8]) -> Option<(f32, Vec3)> {
        let mut best: Option<(f32, Vec3, usize, [f32; 3])> = None;
        for (k, &t) in triangles.iter().enumerate() {
            if t == u32::MAX || triangles[..k].contains(&t) {
                continue;
            }
            let (q, w) = closest_on_triangle(p, self.corners[t as usize]);
            let d2 = (p - q).length_squared();
            if best.is_none_or(|b| d2 < b.0) {
                best = Some((d2, q, t as usize, w));
            }
        }
        let (d2, q, t, w) = best?;
        let [n0, n1, n2] = self.corner_normals[t];
        let c = self.corners[t];
        let n = (w[0] * n0 + w[1] * n1 + w[2] * n2)
            .try_normalize()
            .or_else(|| (c[1] - c[0]).cross(c[2] - c[0]).try_normalize())
            .unwrap_or(Vec3::Y);
        let away = p - q;
        let sign = if away.dot(n) < 0.0 { -1.0 } else { 1.0 };
        let d = d2.sqrt();
        // The line to the closest point is the way out; on the surface
        // itself, the normal.
        let out = if d > 1e-6 * self.cell {
            sign * away / d
        } else {
            n
        };
        Some((sign * d, out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Spot, its grid (cells 0.02, exact 0.06 deep) and a BVH to check it.
    fn spot_grid() -> (crate::Mesh, SkinSdf, crate::mesh::TriangleBvh) {
        let spot = crate::assets::spot();
        let sdf = SkinSdf::new(
            spot.positions(),
            spot.normals(),
            spot.triangles(),
            0.02,
            0.06,
        );
        let bvh = crate::mesh::TriangleBvh::new(spot.positions(), spot.triangles());
        (spot, sdf, bvh)
    }

    #[test]
    fn distances_to_spot_match_closest_points_inside_the_band() {
        let (spot, sdf, bvh) = spot_grid();
        let (lo, hi) = spot.bounds();
        let mut checked = 0;
        for i in 0..2000u32 {
            // A low-discrepancy walk through the bounds.
            let t = Vec3::new(
                (i as f32 * 0.618_034).fract(),
                (i as f32 * 0.754_878).fract(),
                (i as f32 * 0.569_840).fract(),
            );
            let p = lo + t * (hi - lo);
            let exact = bvh.closest(p).unwrap().distance_squared.sqrt();
            if exact > 0.04 {
                continue;
            }
            let (d, _) = sdf.sample(p);
            // Trilinear interpolation of a distance field is within half a
            // cell diagonal of the exact distance.
            assert!(
                (d.abs() - exact).abs() < 0.5 * 0.02 * 3f32.sqrt(),
                "{p}: grid {d}, exact {exact}"
            );
            checked += 1;
        }
        assert!(checked > 50, "only {checked} points near the skin");
        // Outside is positive, a point pushed inward along a normal is
        // negative, and the gradient points out.
        let (v, n) = (spot.positions()[100], spot.normals()[100]);
        let (outside, out_dir) = sdf.sample(v + 0.03 * n);
        let (inside, in_dir) = sdf.sample(v - 0.03 * n);
        assert!(outside > 0.015 && inside < -0.015, "{outside} {inside}");
        assert!(out_dir.dot(n) > 0.7 && in_dir.dot(n) > 0.7);
    }

    #[test]
    fn a_point_the_nodes_call_clear_is_outside_that_far_by_the_exact_path_and_the_mesh() {
        let (spot, sdf, bvh) = spot_grid();
        // Inside or outside by the mesh's winding number (its triangles'
        // solid angles seen from `p`, over 4π).
        let winding = |p: Vec3| {
            let mut w = 0.0f64;
            for t in spot.triangles() {
                let [a, b, c] = t.map(|i| (spot.positions()[i as usize] - p).as_dvec3());
                let (la, lb, lc) = (a.length(), b.length(), c.length());
                let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
                w += 2.0 * a.dot(b.cross(c)).atan2(den);
            }
            w / (4.0 * std::f64::consts::PI)
        };
        let (lo, hi) = spot.bounds();
        let mut clear = 0;
        for gap in [0.002f32, 0.01, 0.02] {
            for i in 0..4000u32 {
                let t = Vec3::new(
                    (i as f32 * 0.618_034).fract(),
                    (i as f32 * 0.754_878).fract(),
                    (i as f32 * 0.569_840).fract(),
                );
                let p = lo - Vec3::splat(0.05) + t * (hi - lo + Vec3::splat(0.1));
                if !sdf.clear_of(p, gap) {
                    continue;
                }
                clear += 1;
                let (d, _) = sdf.sample(p);
                assert!(d >= gap, "{p}: clear of {gap}, but sampled {d}");
                let from_mesh = bvh.closest(p).unwrap().distance_squared.sqrt();
                assert!(
                    from_mesh >= gap,
                    "{p}: clear of {gap}, {from_mesh} from the mesh"
                );
                assert!(winding(p) < 0.5, "{p}: clear of {gap}, but inside the mesh");
            }
        }
        // A shortcut often taken: over a thousand of these points.
        assert!(clear > 1000, "{clear} clear");
        // Wider than a cell, it never answers (the interpolation decides).
        assert!(!sdf.clear_of(hi + Vec3::splat(0.5), 0.03));
    }
}
