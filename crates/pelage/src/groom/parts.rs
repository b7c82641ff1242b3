//! Parts: the mesh split into spatially compact groups of triangles, each
//! generated on its own (Sik §4.2.1: "each of these calls is responsible
//! for generating hair on one selected part of a triangular mesh"; docs/design.md,
//! "Parts").
//!
//! Triangles are ordered along a Morton (Z-order) curve through their
//! centroids and cut into runs of equal root probability, so parts are
//! compact and balanced. The layout depends only on the mesh, the density
//! and the part count — never on threads or machines — and part `p`'s
//! hairs are numbered from `⌊N·C(p)⌋` to `⌊N·C(p+1)⌋`, `C` the cumulative
//! probability at the part boundaries, so the parts' hair ids tile
//! `0..N` exactly. With stable ids ([`PartLayout::from_cells`]) parts are
//! runs of root cells ([`crate::sample::RootCells`]) of about equal hair
//! counts, and each cell numbers its own hairs.

use crate::mesh::{Mesh, morton};
use glam::Vec3;

/// One part of the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// Its triangles, ascending.
    pub triangles: Vec<u32>,
    /// Id of its first hair.
    pub first_hair: u64,
    /// Number of hairs it grows.
    pub hair_count: u64,
    /// With stable ids: its root cells and each one's hair count
    /// (empty: hairs `first_hair..first_hair + hair_count`).
    pub cells: Vec<(u32, u64)>,
}

/// The parts of a groom.
#[derive(Debug, Clone, PartialEq)]
pub struct PartLayout {
    parts: Vec<Part>,
}

impl PartLayout {
    /// Splits `mesh` into `part_count` parts of about equal weight
    /// (`triangle_weight(t)`: the probability that a root lands in `t`) and
    /// shares `hairs` among them.
    pub fn new(
        mesh: &Mesh,
        triangle_weight: impl Fn(usize) -> f64,
        hairs: u64,
        part_count: usize,
    ) -> Self {
        let part_count = part_count.max(1);
        let (lo, hi) = mesh.bounds();
        let extent = (hi - lo).max(Vec3::splat(1e-30));
        let mut order: Vec<(u64, u32)> = (0..mesh.triangle_count())
            .map(|t| {
                let [a, b, c] = mesh.triangle_positions(t);
                let centroid = ((a + b + c) / 3.0 - lo) / extent;
                (morton(centroid), t as u32)
            })
            .collect();
        order.sort_unstable();
        let weights: Vec<f64> = order
            .iter()
            .map(|&(_, t)| triangle_weight(t as usize))
            .collect();
        let total: f64 = weights.iter().sum();

        let mut parts = Vec::with_capacity(part_count);
        let mut start = 0usize;
        let mut cumulative = 0.0f64;
        let mut first_hair = 0u64;
        for p in 0..part_count {
            let target = total * (p + 1) as f64 / part_count as f64;
            let mut end = start;
            if p + 1 == part_count {
                end = order.len();
                cumulative = total;
            } else {
                while end < order.len() && cumulative + weights[end] * 0.5 < target {
                    cumulative += weights[end];
                    end += 1;
                }
            }
            let fraction = if total > 0.0 { cumulative / total } else { 1.0 };
            let last_hair = if p + 1 == part_count {
                hairs
            } else {
                ((hairs as f64 * fraction).floor() as u64).min(hairs)
            };
            let mut triangles: Vec<u32> = order[start..end].iter().map(|&(_, t)| t).collect();
            triangles.sort_unstable();
            parts.push(Part {
                triangles,
                first_hair,
                hair_count: last_hair - first_hair,
                cells: Vec::new(),
            });
            first_hair = last_hair;
            start = end;
        }
        Self { parts }
    }

    /// Parts as runs of root cells (in their Morton order) with about
    /// equal hair counts: `counts[c]` hairs grow in cell `c`. `first_hair`
    /// counts the hairs of the parts before (hair ids are the cells' own).
    pub fn from_cells(cells: &crate::sample::RootCells, counts: &[u64], part_count: usize) -> Self {
        let part_count = part_count.clamp(1, cells.len());
        let total: u64 = counts.iter().sum();
        let mut parts = Vec::with_capacity(part_count);
        let mut start = 0usize;
        let mut cumulative = 0u64;
        for p in 0..part_count {
            let target = (total as u128 * (p + 1) as u128 / part_count as u128) as u64;
            let first_hair = cumulative;
            // Leave a cell for each part to come.
            let last_end = cells.len() - (part_count - p - 1);
            let mut end = start;
            if p + 1 == part_count {
                end = cells.len();
            } else {
                while end < last_end && (end == start || cumulative + counts[end] / 2 < target) {
                    cumulative += counts[end];
                    end += 1;
                }
            }
            let part_cells: Vec<(u32, u64)> = (start..end).map(|c| (c as u32, counts[c])).collect();
            let hair_count = part_cells.iter().map(|&(_, n)| n).sum();
            cumulative = first_hair + hair_count;
            let mut triangles: Vec<u32> = (start..end)
                .flat_map(|c| cells.triangles(c).iter().copied())
                .collect();
            triangles.sort_unstable();
            parts.push(Part {
                triangles,
                first_hair,
                hair_count,
                cells: part_cells,
            });
            start = end;
        }
        Self { parts }
    }

    /// The parts, in order.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// Number of parts.
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    /// Whether there are no parts (never: a layout has at least one).
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_every_triangle_and_tile_the_hair_ids() {
        let mesh = crate::assets::spot();
        let areas = mesh.triangle_areas().to_vec();
        let total: f64 = areas.iter().map(|&a| f64::from(a)).sum();
        let layout = PartLayout::new(&mesh, |t| f64::from(areas[t]) / total, 100_003, 7);
        assert_eq!(layout.len(), 7);
        let mut all: Vec<u32> = layout
            .parts()
            .iter()
            .flat_map(|p| p.triangles.clone())
            .collect();
        all.sort_unstable();
        assert_eq!(all, (0..mesh.triangle_count() as u32).collect::<Vec<_>>());
        let mut next = 0;
        for part in layout.parts() {
            assert_eq!(part.first_hair, next);
            next += part.hair_count;
            // Balanced by area: within a few percent of a seventh each.
            let share = part.hair_count as f64 / 100_003.0;
            assert!((share - 1.0 / 7.0).abs() < 0.01, "{share}");
        }
        assert_eq!(next, 100_003);
        // Compact: each part's box is far smaller than the mesh's.
        let (lo, hi) = mesh.bounds();
        for part in layout.parts() {
            let mut b = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
            for &t in &part.triangles {
                for p in mesh.triangle_positions(t as usize) {
                    b = (b.0.min(p), b.1.max(p));
                }
            }
            let volume = |l: Vec3, h: Vec3| (h - l).x * (h - l).y * (h - l).z;
            assert!(volume(b.0, b.1) < 0.6 * volume(lo, hi));
        }
    }
}
