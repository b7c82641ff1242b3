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

use super::spec::HairIds;
use crate::mesh::{Mesh, SurfacePoint, morton};
use crate::sample::RootCells;
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

/// Hairs per part when the groom does not say.
pub const HAIRS_PER_PART: u64 = 100_000;

/// The number of parts of `count` hairs: `parts` if given, or one per
/// [`HAIRS_PER_PART`] hairs; at least one, at most one a triangle (a root
/// cell, with stable ids: a part is a run of cells).
pub(crate) fn part_count(mesh: &Mesh, count: u64, parts: Option<u32>, ids: HairIds) -> usize {
    let wanted = match parts {
        Some(p) => p.max(1) as usize,
        None => count.div_ceil(HAIRS_PER_PART).max(1) as usize,
    };
    let most = match ids {
        HairIds::Stable => RootCells::count_for(mesh.triangle_count()),
        HairIds::Sequential => mesh.triangle_count(),
    };
    wanted.min(most).max(1)
}

/// Orders one root cell's roots by (triangle, barycentrics, id). A part
/// with root cells grows its cells along their Morton curve, each cell's
/// roots in this order: a walk along the skin that keeps the neighbour
/// searches' candidate lists warmer than the triangles' own order (a
/// preview fraction's sparse roots most), with no sort of the whole part.
pub(crate) fn sort_cell_roots(roots: &mut [(SurfacePoint, u64)]) {
    roots.sort_unstable_by_key(|(r, id)| (r.tri, r.bary[0].to_bits(), r.bary[1].to_bits(), *id));
}

/// [`sorted_by_triangle`] carrying each root's id along (equal roots keep
/// ascending ids).
pub(crate) fn sorted_by_triangle_with_ids(
    roots: Vec<SurfacePoint>,
    ids: Vec<u64>,
) -> (Vec<SurfacePoint>, Vec<u64>) {
    sorted_by_triangle_with_payload(roots.into_iter().zip(ids).collect())
        .into_iter()
        .unzip()
}

/// `roots` ordered by (triangle, first barycentric, second barycentric),
/// the order [`Generator::part_roots`] grows hairs in without root cells
/// (sequential ids): the same order as
/// a comparison sort by that key, found faster. A counting sort by
/// triangle moves each root once; each triangle's few roots (a dozen or
/// two) are then sorted among themselves. A comparison sort of the whole
/// part took a tenth of a groom's time on one core.
pub(crate) fn sorted_by_triangle(roots: Vec<SurfacePoint>) -> Vec<SurfacePoint> {
    // A zero-sized payload: the pairs are the roots' own size.
    sorted_by_triangle_with_payload(roots.into_iter().map(|r| (r, ())).collect())
        .into_iter()
        .map(|(r, ())| r)
        .collect()
}

/// Roots with a payload each, sorted by (triangle, barycentrics, payload)
/// ([`sorted_by_triangle`]'s counting sort).
pub(crate) fn sorted_by_triangle_with_payload<T: Copy + Default + Ord>(
    roots: Vec<(SurfacePoint, T)>,
) -> Vec<(SurfacePoint, T)> {
    let (Some(lo), Some(hi)) = (
        roots.iter().map(|r| r.0.tri).min(),
        roots.iter().map(|r| r.0.tri).max(),
    ) else {
        return roots;
    };
    // starts[t − lo] .. starts[t − lo + 1]: where triangle t's roots go.
    let mut starts = vec![0u32; (hi - lo) as usize + 2];
    for r in &roots {
        starts[(r.0.tri - lo) as usize + 1] += 1;
    }
    for t in 1..starts.len() {
        starts[t] += starts[t - 1];
    }
    let mut next = starts.clone();
    let mut sorted = vec![(SurfacePoint::default(), T::default()); roots.len()];
    for r in &roots {
        let slot = &mut next[(r.0.tri - lo) as usize];
        sorted[*slot as usize] = *r;
        *slot += 1;
    }
    for range in starts.windows(2) {
        let triangle = &mut sorted[range[0] as usize..range[1] as usize];
        if triangle.len() > 1 {
            triangle.sort_unstable_by_key(|(r, payload)| {
                (r.bary[0].to_bits(), r.bary[1].to_bits(), *payload)
            });
        }
    }
    sorted
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::mix64;

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

    #[test]
    fn roots_sorted_by_triangle_match_a_comparison_sort() {
        // Random roots over a few hundred triangles, with repeated
        // triangles and first barycentrics (ties broken by the second),
        // exact duplicates, and a negative zero.
        let mut roots: Vec<SurfacePoint> = (0..5000u64)
            .map(|i| {
                let h = mix64(i);
                let unit = |h: u64| (h >> 40) as f32 / (1u64 << 24) as f32;
                let b0 = if i % 7 == 0 { 0.25 } else { unit(h) };
                SurfacePoint::new((h % 300) as u32 * 77, [b0, unit(mix64(h))])
            })
            .collect();
        roots.extend_from_within(..50);
        roots.push(SurfacePoint::new(3, [-0.0, 0.5]));
        roots.push(SurfacePoint::new(3, [0.0, 0.5]));
        let mut expected = roots.clone();
        expected.sort_unstable_by_key(|r| (r.tri, r.bary[0].to_bits(), r.bary[1].to_bits()));
        let got = sorted_by_triangle(roots);
        let bits = |r: &SurfacePoint| (r.tri, r.bary.map(f32::to_bits));
        assert_eq!(
            got.iter().map(bits).collect::<Vec<_>>(),
            expected.iter().map(bits).collect::<Vec<_>>()
        );
        assert!(sorted_by_triangle(Vec::new()).is_empty());
    }
}
