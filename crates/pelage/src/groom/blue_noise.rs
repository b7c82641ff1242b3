//! Blue-noise roots (Sik's stated future work: "better than random"
//! placement): a part's roots drawn four times over and thinned back by
//! weighted sample elimination (Yuksel 2015, "Sample Elimination for
//! Generating Poisson Disk Sample Sets"). Each candidate weighs
//! `Σ (1 − d / 2r)^8` over its neighbours closer than `2r`, and the
//! heaviest (the most crowded) is removed until the part's count is left.
//! The radius follows the density, `r = √(1 / (2√3 ρ))` with `ρ` the
//! hairs a unit area expected there (Yuksel's `r_max` for hexagonal
//! packing), so crowding is judged against the local density and the
//! roots still follow the map while neighbours keep their distance.
//!
//! The candidates are the part's own roots and three times as many more
//! from its own stream; hairs keep the part's ids (a survivor that was a
//! root keeps its id, the others take the ids of the roots removed, in
//! order), so ids stay unique and the same on every run. The elimination
//! runs inside one part, so neighbours across a part border are not
//! thinned against each other.

use super::generator::Generator;
use super::grow::sorted_by_triangle_with_ids;
use crate::interp::{NearestPoints, Neighbour};
use crate::mesh::SurfacePoint;
use crate::sample::{SurfaceSampler, mix64, salts, sample_range};
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Candidates drawn for each root kept.
const OVERSAMPLING: u64 = 4;
/// Neighbours each candidate looks at (enough to cover `2r` at
/// four-fold oversampling: about 4 · π · 2² / (2√3) ≈ 15 on average).
const NEIGHBOURS: usize = 24;

/// Part `p`'s roots thinned to blue noise, ordered by triangle, with ids.
pub(super) fn part_roots(generator: &Generator, p: usize) -> (Vec<SurfacePoint>, Vec<u64>) {
    let part = &generator.layout.parts()[p];
    let (roots, ids) = generator.regular_part_roots(p);
    let n = roots.len() as u64;
    if n < 2 {
        return (roots, ids);
    }
    let Some(sampler) = generator.sampler.restricted(&part.triangles) else {
        return (roots, ids);
    };
    let mesh = generator.mesh();
    let stream = mix64(generator.seed() ^ mix64(salts::BLUE_NOISE + p as u64));
    let mut candidates = roots.clone();
    candidates.extend(sample_range(&sampler, stream, 0..(OVERSAMPLING - 1) * n));
    let positions: Vec<glam::Vec3> = candidates.par_iter().map(|c| c.position(mesh)).collect();
    // Expected kept roots a unit area at each candidate, and its radius.
    let radii: Vec<f32> = candidates
        .par_iter()
        .map(|c| {
            let density = n as f64 * sampler.pdf(*c);
            (1.0 / (2.0 * 3f64.sqrt() * density.max(1e-30))).sqrt() as f32
        })
        .collect();
    let kept = eliminate(&positions, &radii, n as usize);
    // Survivors that were roots keep their ids; the others take the ids
    // of the roots removed, in order.
    let mut is_kept = vec![false; candidates.len()];
    for &i in &kept {
        is_kept[i] = true;
    }
    let mut free = (0..roots.len()).filter(|&i| !is_kept[i]).map(|i| ids[i]);
    let mut out_roots = Vec::with_capacity(kept.len());
    let mut out_ids = Vec::with_capacity(kept.len());
    for i in kept {
        out_roots.push(candidates[i]);
        out_ids.push(if i < roots.len() {
            ids[i]
        } else {
            free.next().expect("as many free ids as new survivors")
        });
    }
    sorted_by_triangle_with_ids(out_roots, out_ids)
}

/// Weighted sample elimination: the indices of the `keep` candidates
/// left, ascending.
pub fn eliminate(positions: &[glam::Vec3], radii: &[f32], keep: usize) -> Vec<usize> {
    let m = positions.len();
    if keep >= m {
        return (0..m).collect();
    }
    let tree = NearestPoints::new(positions.to_vec());
    // Each candidate's neighbours within 2r, and what each adds to its weight.
    let neighbours: Vec<Vec<(u32, f32)>> = (0..m)
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let mut found: Vec<Neighbour> = Vec::with_capacity(NEIGHBOURS + 1);
            tree.nearest(positions[i], NEIGHBOURS + 1, &mut found);
            let reach = 2.0 * radii[i];
            found
                .into_iter()
                .filter(|n| n.index as usize != i)
                .filter_map(|n| {
                    let d = n.distance_squared.sqrt();
                    (d < reach).then(|| (n.index, (1.0 - d / reach).powi(8)))
                })
                .collect()
        })
        .collect();
    // Who counts each candidate among its neighbours: removing it lightens them.
    let mut counted_by: Vec<Vec<(u32, f32)>> = vec![Vec::new(); m];
    for (i, list) in neighbours.iter().enumerate() {
        for &(j, w) in list {
            counted_by[j as usize].push((i as u32, w));
        }
    }
    let mut weight: Vec<f32> = neighbours
        .iter()
        .map(|l| l.iter().map(|&(_, w)| w).sum())
        .collect();
    let mut alive = vec![true; m];
    let mut heap: BinaryHeap<Heaviest> = (0..m).map(|i| Heaviest(weight[i], i as u32)).collect();
    let mut left = m;
    while left > keep {
        let Some(Heaviest(w, i)) = heap.pop() else {
            break;
        };
        let i = i as usize;
        if !alive[i] || w != weight[i] {
            continue; // removed already, or a stale weight
        }
        alive[i] = false;
        left -= 1;
        for &(j, contribution) in &counted_by[i] {
            let j = j as usize;
            if alive[j] {
                weight[j] -= contribution;
                heap.push(Heaviest(weight[j], j as u32));
            }
        }
    }
    (0..m).filter(|&i| alive[i]).collect()
}

/// A candidate by weight, heaviest first (ties: the higher index).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Heaviest(f32, u32);

impl Eq for Heaviest {}

impl PartialOrd for Heaviest {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Heaviest {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn elimination_keeps_the_count_and_spreads_the_points() {
        // 4,000 random points on the unit square, thinned to 1,000.
        let points: Vec<Vec3> = (0..4000u64)
            .map(|i| {
                let h = mix64(i);
                Vec3::new(
                    (h >> 40) as f32 / 16_777_216.0,
                    (h & 0xFF_FFFF) as f32 / 16_777_216.0,
                    0.0,
                )
            })
            .collect();
        let r = (1.0 / (2.0 * 3f32.sqrt() * 1000.0)).sqrt();
        let kept = eliminate(&points, &vec![r; points.len()], 1000);
        assert_eq!(kept.len(), 1000);
        let min_distance = |set: &[Vec3]| {
            let tree = NearestPoints::new(set.to_vec());
            let mut out = Vec::new();
            set.iter()
                .map(|p| {
                    tree.nearest(*p, 2, &mut out);
                    out[1].distance_squared.sqrt()
                })
                .fold(f32::INFINITY, f32::min)
        };
        let thinned: Vec<Vec3> = kept.iter().map(|&i| points[i]).collect();
        let random = &points[..1000];
        assert!(min_distance(&thinned) > 3.0 * min_distance(random));
    }
}
