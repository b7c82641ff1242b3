//! Blue-noise samples: candidates drawn [`OVERSAMPLING`] times over and
//! thinned back by weighted sample elimination (Yuksel 2015, "Sample
//! Elimination for Generating Poisson Disk Sample Sets"), Sik's stated
//! future work ("better than random" placement). Each candidate weighs
//! `Σ (1 − d / 2r)^8` over its neighbours closer than `2r`, and the
//! heaviest (the most crowded) is removed until the count asked for is
//! left. The radius follows the density, `r = √(1 / (2√3 ρ))` with `ρ` the
//! samples a unit area expected there (Yuksel's `r_max` for hexagonal
//! packing), so crowding is judged against the local density and the
//! samples still follow the map while neighbours keep their distance.
//!
//! [`blue_noise_samples`] thins a whole mesh's candidates at once (no
//! seams anywhere); the groom thins each part's (`groom/blue_noise.rs`).
//! Where the time goes is timed in [`BlueNoiseTimes`]: drawing the
//! candidates is a random sample four times over, finding each one's
//! neighbours a radius query in a kd-tree (parallel; about 15 within `2r`
//! at four-fold oversampling, 4 · π · 2² / (2√3)), and the elimination a
//! priority queue that removes one candidate at a time (serial: each
//! removal changes the weights the next choice reads).

use super::{DensitySampler, SurfaceSampler, mix64, salts, sample_range};
use crate::mesh::{Mesh, SurfacePoint};
use crate::nearest::NearestPoints;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::time::Instant;

/// Candidates drawn for each sample kept.
pub const OVERSAMPLING: u64 = 4;

/// Seconds spent in each step of [`blue_noise_samples`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BlueNoiseTimes {
    /// Drawing the candidates, their positions and radii.
    pub candidates: f64,
    /// The kd-tree and each candidate's neighbours within `2r`.
    pub neighbours: f64,
    /// The weighted elimination itself.
    pub elimination: f64,
}

/// `n` points of `sampler` over `mesh`, thinned to blue noise from
/// [`OVERSAMPLING`]` · n` candidates of stream `seed`, in candidate order;
/// the same on any number of threads.
pub fn blue_noise_samples(
    sampler: &DensitySampler,
    mesh: &Mesh,
    seed: u64,
    n: u64,
) -> Vec<SurfacePoint> {
    blue_noise_samples_timed(sampler, mesh, seed, n).0
}

/// [`blue_noise_samples`] and where its time went.
pub fn blue_noise_samples_timed(
    sampler: &DensitySampler,
    mesh: &Mesh,
    seed: u64,
    n: u64,
) -> (Vec<SurfacePoint>, BlueNoiseTimes) {
    let mut times = BlueNoiseTimes::default();
    let started = Instant::now();
    let stream = mix64(seed ^ mix64(salts::BLUE_NOISE));
    let candidates = sample_range(sampler, stream, 0..OVERSAMPLING * n);
    let (positions, radii) = positions_and_radii(sampler, mesh, &candidates, n);
    times.candidates = started.elapsed().as_secs_f64();
    let kept = eliminate_timed(&positions, &radii, n as usize, &mut times);
    (kept.into_iter().map(|i| candidates[i]).collect(), times)
}

/// Each candidate's position, and the radius `√(1 / (2√3 ρ))` of the
/// density `ρ = n · pdf` of `n` kept samples there.
pub(crate) fn positions_and_radii(
    sampler: &impl SurfaceSampler,
    mesh: &Mesh,
    candidates: &[SurfacePoint],
    n: u64,
) -> (Vec<glam::Vec3>, Vec<f32>) {
    let positions = candidates.par_iter().map(|c| c.position(mesh)).collect();
    let radii = candidates
        .par_iter()
        .map(|c| {
            let density = n as f64 * sampler.pdf(*c);
            (1.0 / (2.0 * 3f64.sqrt() * density.max(1e-30))).sqrt() as f32
        })
        .collect();
    (positions, radii)
}

/// Weighted sample elimination: the indices of the `keep` candidates
/// left, ascending.
pub fn eliminate(positions: &[glam::Vec3], radii: &[f32], keep: usize) -> Vec<usize> {
    eliminate_timed(positions, radii, keep, &mut BlueNoiseTimes::default())
}

/// A chunk's neighbour counts (one a candidate) and its `(neighbour,
/// weight)` pairs, in candidate order.
type NeighbourChunk = (Vec<u32>, Vec<(u32, f32)>);

/// [`eliminate`], adding its steps' seconds to `times`.
fn eliminate_timed(
    positions: &[glam::Vec3],
    radii: &[f32],
    keep: usize,
    times: &mut BlueNoiseTimes,
) -> Vec<usize> {
    let started = Instant::now();
    let m = positions.len();
    if keep >= m {
        return (0..m).collect();
    }
    // The candidates in Morton order: neighbours in space are neighbours
    // in memory, for the tree's queries and the heap's updates (a random
    // order costs a cache miss a neighbour: 1 M samples took 2.5 times
    // as long a sample as 100 k).
    let order = morton_order(positions);
    let positions: Vec<glam::Vec3> = order.iter().map(|&i| positions[i as usize]).collect();
    let radii: Vec<f32> = order.iter().map(|&i| radii[i as usize]).collect();
    let positions = &positions[..];
    let tree = NearestPoints::new(positions.to_vec());
    // Each candidate's neighbours within 2r and what each adds to its
    // weight, as one flat list (chunks found in parallel, joined in order).
    let found: Vec<NeighbourChunk> = (0..m)
        .into_par_iter()
        .chunks(4096)
        .map(|chunk| {
            let mut counts = Vec::with_capacity(chunk.len());
            let mut pairs = Vec::with_capacity(chunk.len() * 16);
            for i in chunk {
                let (p, reach) = (positions[i], 2.0 * radii[i]);
                let before = pairs.len();
                tree.visit_within(p, reach * reach, |j| {
                    if j as usize != i {
                        let d = positions[j as usize].distance(p);
                        if d < reach {
                            pairs.push((j, (1.0 - d / reach).powi(8)));
                        }
                    }
                });
                // The tree's order depends on nothing but the points; by
                // index, the sums below add in one order everywhere.
                pairs[before..].sort_unstable_by_key(|&(j, _)| j);
                counts.push((pairs.len() - before) as u32);
            }
            (counts, pairs)
        })
        .collect();
    let mut start = Vec::with_capacity(m + 1);
    start.push(0u32);
    let mut pairs = Vec::new();
    for (counts, chunk_pairs) in found {
        for c in counts {
            let last = *start.last().expect("starts at 0");
            start.push(last + c);
        }
        pairs.extend(chunk_pairs);
    }
    let mut weight: Vec<f32> = (0..m)
        .map(|i| {
            pairs[start[i] as usize..start[i + 1] as usize]
                .iter()
                .map(|&(_, w)| w)
                .sum()
        })
        .collect();
    // Who counts each candidate among its neighbours (removing it lightens
    // them), by a counting sort of the pairs on their neighbour.
    let mut by_start = vec![0u32; m + 1];
    for &(j, _) in &pairs {
        by_start[j as usize + 1] += 1;
    }
    for k in 0..m {
        by_start[k + 1] += by_start[k];
    }
    let mut fill = by_start.clone();
    let mut counted_by = vec![(0u32, 0f32); pairs.len()];
    for i in 0..m {
        for &(j, w) in &pairs[start[i] as usize..start[i + 1] as usize] {
            let slot = &mut fill[j as usize];
            counted_by[*slot as usize] = (i as u32, w);
            *slot += 1;
        }
    }
    drop(pairs);
    times.neighbours += started.elapsed().as_secs_f64();
    let started = Instant::now();
    let mut heap = WeightHeap::new(&weight);
    let mut alive = vec![true; m];
    for _ in keep..m {
        let i = heap.pop_heaviest(&weight) as usize;
        alive[i] = false;
        for &(j, contribution) in &counted_by[by_start[i] as usize..by_start[i + 1] as usize] {
            let j = j as usize;
            if alive[j] {
                weight[j] -= contribution;
                heap.lightened(j, &weight);
            }
        }
    }
    let mut kept: Vec<usize> = (0..m)
        .filter(|&i| alive[i])
        .map(|i| order[i] as usize)
        .collect();
    kept.sort_unstable();
    times.elimination += started.elapsed().as_secs_f64();
    kept
}

/// The indices of `positions` sorted by the Morton code of each position
/// in their bounding box (21 bits an axis), ties by index.
fn morton_order(positions: &[glam::Vec3]) -> Vec<u32> {
    let (lo, hi) = positions.iter().fold(
        (
            glam::Vec3::splat(f32::INFINITY),
            glam::Vec3::splat(f32::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let scale = ((1u32 << 21) - 1) as f32 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let spread = |v: f32| -> u64 {
        // Spreads 21 bits to every third bit of 63.
        let mut x = (v.clamp(0.0, ((1u32 << 21) - 1) as f32) as u64) & 0x1f_ffff;
        x = (x | x << 32) & 0x1f_0000_0000_ffff;
        x = (x | x << 16) & 0x1f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    };
    let mut keyed: Vec<(u64, u32)> = positions
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let q = (*p - lo) * scale;
            (spread(q.x) | spread(q.y) << 1 | spread(q.z) << 2, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// A max-heap (four-ary) of candidates by weight that knows where each candidate
/// sits, so a weight that drops moves its candidate down in place (no
/// stale entries to skip, as a heap of copies has). Ties go to the higher
/// index.
struct WeightHeap {
    /// Candidates, heaviest at 0.
    order: Vec<u32>,
    /// Each candidate's place in `order` (`u32::MAX`: removed).
    place: Vec<u32>,
}

impl WeightHeap {
    fn new(weight: &[f32]) -> Self {
        let m = weight.len();
        let mut heap = Self {
            order: (0..m as u32).collect(),
            place: (0..m as u32).collect(),
        };
        for k in (0..m.div_ceil(4)).rev() {
            heap.sift_down(k, weight);
        }
        heap
    }

    /// Whether candidate `a` goes above `b`.
    #[inline(always)]
    fn above(a: u32, b: u32, weight: &[f32]) -> bool {
        match weight[a as usize].total_cmp(&weight[b as usize]) {
            Ordering::Equal => a > b,
            o => o == Ordering::Greater,
        }
    }

    fn swap(&mut self, x: usize, y: usize) {
        self.order.swap(x, y);
        self.place[self.order[x] as usize] = x as u32;
        self.place[self.order[y] as usize] = y as u32;
    }

    /// Moves the candidate at `k` down past heavier children. Four
    /// children a node: half the levels of a binary heap, and the
    /// children side by side in memory.
    fn sift_down(&mut self, mut k: usize, weight: &[f32]) {
        let n = self.order.len();
        loop {
            let first = 4 * k + 1;
            let mut top = k;
            for c in first..(first + 4).min(n) {
                if Self::above(self.order[c], self.order[top], weight) {
                    top = c;
                }
            }
            if top == k {
                return;
            }
            self.swap(k, top);
            k = top;
        }
    }

    /// Removes and returns the heaviest candidate.
    fn pop_heaviest(&mut self, weight: &[f32]) -> u32 {
        let top = self.order[0];
        let last = self.order.len() - 1;
        self.swap(0, last);
        self.order.pop();
        self.place[top as usize] = u32::MAX;
        if !self.order.is_empty() {
            self.sift_down(0, weight);
        }
        top
    }

    /// Candidate `i`'s weight went down: it moves down to its place.
    fn lightened(&mut self, i: usize, weight: &[f32]) {
        let k = self.place[i];
        if k != u32::MAX {
            self.sift_down(k as usize, weight);
        }
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

    /// A whole mesh's blue noise: the count asked for, spread further than
    /// random points, and the same on one thread and on two.
    #[test]
    fn whole_mesh_blue_noise_is_spread_and_deterministic() {
        let mesh = crate::assets::spot();
        let sampler = DensitySampler::new(
            &mesh,
            &crate::Map::Constant(1.0),
            super::super::DensitySamplerOptions::default(),
        )
        .unwrap();
        let on = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| blue_noise_samples(&sampler, &mesh, 7, 3000))
        };
        let points = on(1);
        assert_eq!(points.len(), 3000);
        assert!(points == on(2), "one thread and two differ");
        let nearest = |set: &[SurfacePoint]| {
            let positions: Vec<Vec3> = set.iter().map(|p| p.position(&mesh)).collect();
            let tree = NearestPoints::new(positions.clone());
            let mut out = Vec::new();
            let mut d: Vec<f32> = positions
                .iter()
                .map(|p| {
                    tree.nearest(*p, 2, &mut out);
                    out[1].distance_squared.sqrt()
                })
                .collect();
            d.sort_by(f32::total_cmp);
            d[d.len() / 100] // the closest 1 %
        };
        let random = sample_range(&sampler, 7, 0..3000);
        assert!(
            nearest(&points) > 2.0 * nearest(&random),
            "blue noise {} vs random {}",
            nearest(&points),
            nearest(&random)
        );
    }
}
