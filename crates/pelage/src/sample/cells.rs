//! Root cells: hair roots whose ids and places survive a change of the
//! hair count or a local change of the density.
//!
//! The mesh's triangles are cut, along a Morton curve through their
//! centroids, into cells of about equal area (about
//! [`RootCells::TRIANGLES_PER_CELL`] triangles each; the cut depends on
//! the mesh alone). Each cell `c` is a Poisson process in a "time" `t`
//! with rate `p_c`, the probability that a root lands in it: its `k`-th
//! hair arrives at `T_{c,k} = (E_0 + … + E_k) / p_c`, the `E_i`
//! exponential variates from the cell's own stream. A groom of `N` hairs
//! takes the `N` earliest arrivals over all cells. Since the cell of each
//! successive arrival of superposed Poisson processes is independently
//! distributed as `p_c`, the counts are exactly those of `N` independent
//! roots, yet:
//!
//! - raising `N` to `M` only adds later arrivals, so every hair of the
//!   `N` keeps its cell and its number `k` in it; lowering it removes the
//!   latest ones;
//! - hair `k` of cell `c` is sample `k` of the cell's own stream (the
//!   cell's restricted density), with id `k · C + c` (`C` cells): a
//!   density edit moves only the roots of the cells it touches, plus a
//!   few hairs added or removed at the margin elsewhere as the total
//!   shifts.
//!
//! The `N` earliest arrivals are found by counting the arrivals before a
//! time just short of `N` in every cell (in parallel), then taking the
//! few missing ones from a heap of the cells' next arrivals. Every step
//! uses only IEEE-exact arithmetic in a fixed order (the logarithm of the
//! exponential variates is computed here, from a table and a short
//! series, not by the platform's libm), so the result is the same on
//! every machine.

use super::{DensitySampler, SurfaceSampler, mix64, salts};
use crate::mesh::{Mesh, SurfacePoint, morton};
use glam::Vec3;
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The cells of a mesh with each one's root probability.
#[derive(Debug, Clone)]
pub struct RootCells {
    /// Each cell's triangles, ascending; cells in Morton order.
    cells: Vec<Vec<u32>>,
    /// Each cell's share of the roots (sums to 1).
    rates: Vec<f64>,
}

impl RootCells {
    /// About how many triangles a cell holds.
    pub const TRIANGLES_PER_CELL: usize = 16;
    /// The most cells a mesh is cut into.
    pub const MAX_CELLS: usize = 1 << 16;

    /// Cuts `mesh` into cells and weighs each by `sampler` (a density
    /// sampler over the whole mesh).
    pub fn new(mesh: &Mesh, sampler: &DensitySampler) -> Self {
        let count = Self::count_for(mesh.triangle_count());
        let (lo, hi) = mesh.bounds();
        let extent = (hi - lo).max(Vec3::splat(1e-30));
        let mut order: Vec<(u64, u32)> = (0..mesh.triangle_count())
            .map(|t| {
                let [a, b, c] = mesh.triangle_positions(t);
                (morton(((a + b + c) / 3.0 - lo) / extent), t as u32)
            })
            .collect();
        order.sort_unstable();
        let areas = mesh.triangle_areas();
        let total: f64 = order
            .iter()
            .map(|&(_, t)| f64::from(areas[t as usize]))
            .sum();
        let mut cells = Vec::with_capacity(count);
        let mut current = Vec::new();
        let mut cumulative = 0.0;
        for (i, &(_, t)) in order.iter().enumerate() {
            current.push(t);
            cumulative += f64::from(areas[t as usize]);
            let left = order.len() - i - 1;
            let cells_left = count - cells.len() - 1;
            let target = total * (cells.len() + 1) as f64 / count as f64;
            // Cut at equal area, keeping a triangle for each cell to come.
            if cells_left > 0 && (cumulative >= target || left == cells_left) {
                current.sort_unstable();
                cells.push(std::mem::take(&mut current));
            }
        }
        current.sort_unstable();
        cells.push(current);
        let rates = cells
            .par_iter()
            .map(|c| sampler.probability_of(c))
            .collect();
        Self { cells, rates }
    }

    /// How many cells a mesh of `triangles` triangles is cut into.
    pub fn count_for(triangles: usize) -> usize {
        (triangles / Self::TRIANGLES_PER_CELL).clamp(1, Self::MAX_CELLS)
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Whether there are none (never: a mesh has at least one triangle).
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Cell `c`'s triangles, ascending.
    pub fn triangles(&self, c: usize) -> &[u32] {
        &self.cells[c]
    }

    /// Cell `c`'s share of the roots.
    pub fn rate(&self, c: usize) -> f64 {
        self.rates[c]
    }

    /// The id of hair `k` of cell `c`.
    pub fn id(&self, c: usize, k: u64) -> u64 {
        k * self.cells.len() as u64 + c as u64
    }

    /// How many of `hairs` hairs each cell grows, for the groom's `seed`:
    /// the cells of the `hairs` earliest arrivals. Raising `hairs` never
    /// lowers a count.
    pub fn counts(&self, seed: u64, hairs: u64) -> Vec<u64> {
        let n = hairs as f64;
        // Just short of the time by which `hairs` arrivals are expected
        // (the rates sum to 1): four standard deviations, so that the
        // count below it almost never passes `hairs`.
        let mut before = (n - 4.0 * n.sqrt() - 16.0).max(0.0);
        let (mut states, mut total) = loop {
            let states: Vec<Arrivals> = (0..self.cells.len())
                .into_par_iter()
                .with_min_len(64)
                .map(|c| Arrivals::until(self.stream(seed, c), self.rates[c], before))
                .collect();
            let total: u64 = states.iter().map(|s| s.count).sum();
            if total <= hairs {
                break (states, total);
            }
            before *= 0.5;
        };
        let mut next: BinaryHeap<Reverse<(u64, usize)>> = states
            .iter()
            .enumerate()
            .filter(|(_, s)| s.next.is_finite())
            .map(|(c, s)| Reverse((s.next.to_bits(), c)))
            .collect();
        while total < hairs {
            let Some(Reverse((_, c))) = next.pop() else {
                break;
            };
            let s = &mut states[c];
            s.advance(self.stream(seed, c), 1.0 / self.rates[c]);
            total += 1;
            next.push(Reverse((s.next.to_bits(), c)));
        }
        states.into_iter().map(|s| s.count).collect()
    }

    /// When each of the first `count` hairs of cell `c` arrives, for the
    /// groom's `seed`: `T_{c,k}`, summed as [`Self::counts`] sums it, so a
    /// groom of `N` hairs is exactly the `N` earliest (a preview fraction
    /// is the hairs before a time). Empty in a cell of rate 0.
    pub fn arrivals(&self, seed: u64, c: usize, count: u64) -> Vec<f64> {
        let rate = self.rates[c];
        if rate <= 0.0 || count == 0 {
            return Vec::new();
        }
        let stream = self.stream(seed, c);
        let mean_gap = 1.0 / rate;
        let mut s = Arrivals {
            count: 0,
            next: exponential(stream, 0) * mean_gap,
        };
        let mut out = Vec::with_capacity(count as usize);
        while (out.len() as u64) < count {
            out.push(s.next);
            s.advance(stream, mean_gap);
        }
        out
    }

    /// The cell and place in it of hair `id` ([`Self::id`]'s inverse).
    pub fn cell_of(&self, id: u64) -> (usize, u64) {
        let cells = self.cells.len() as u64;
        ((id % cells) as usize, id / cells)
    }

    /// The first `count` roots of cell `c` (hair `k` is sample `k` of the
    /// cell's stream), or none when the density is zero there.
    pub fn roots(
        &self,
        sampler: &DensitySampler,
        seed: u64,
        c: usize,
        count: u64,
    ) -> Vec<SurfacePoint> {
        let Some(cell) = sampler.cell_sampler(&self.cells[c]) else {
            return Vec::new();
        };
        let stream = mix64(seed ^ mix64(salts::CELL_ROOTS + c as u64));
        let mut out = vec![SurfacePoint::default(); count as usize];
        cell.sample_block(stream, 0, &mut out);
        out
    }

    fn stream(&self, seed: u64, c: usize) -> u64 {
        mix64(seed ^ mix64(salts::CELL_ARRIVALS + c as u64))
    }
}

/// A cell's arrivals so far: `count` before the time asked for, and the
/// time of the next.
#[derive(Debug, Clone, Copy)]
struct Arrivals {
    count: u64,
    next: f64,
}

impl Arrivals {
    /// The arrivals of a cell of `rate` before time `before`.
    fn until(stream: u64, rate: f64, before: f64) -> Self {
        if rate <= 0.0 {
            return Self {
                count: 0,
                next: f64::INFINITY,
            };
        }
        let mean_gap = 1.0 / rate;
        let mut s = Self {
            count: 0,
            next: exponential(stream, 0) * mean_gap,
        };
        while s.next < before {
            s.advance(stream, mean_gap);
        }
        s
    }

    /// Takes the next arrival (`mean_gap`: one over the cell's rate).
    #[inline]
    fn advance(&mut self, stream: u64, mean_gap: f64) {
        self.count += 1;
        self.next += exponential(stream, self.count) * mean_gap;
    }
}

/// Variate `i` of an exponential distribution of mean 1 from `stream`:
/// `−ln u`, `u` uniform in (0, 1).
#[inline]
fn exponential(stream: u64, i: u64) -> f64 {
    let bits = mix64(stream.wrapping_add(i.wrapping_mul(0x9E37_79B9_7F4A_7C15)));
    let u = ((bits >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64);
    -ln(u)
}

/// The natural logarithm of a positive, finite `x` with only IEEE-exact
/// operations in a fixed order (so every machine gets the same bits), and
/// no division: `x = m · 2^e`, `m` in [1, 2) split as `c · (1 + r)` with
/// `c = 1 + i/128` from a table (`i` the top seven bits of the mantissa)
/// and `0 ≤ r < 1/128`, `ln(1 + r)` to `r⁵` (error below 1e-13).
#[inline]
fn ln(x: f64) -> f64 {
    let table = ln_table();
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7FF) as i64 - 1023;
    let m = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
    let i = ((bits >> 45) & 127) as usize;
    let r = m * table.inverse[i] - 1.0;
    let series = r * (1.0 + r * (-0.5 + r * (1.0 / 3.0 + r * (-0.25 + r * 0.2))));
    exponent as f64 * std::f64::consts::LN_2 + table.ln[i] + series
}

/// `ln(1 + i/128)` and `1 / (1 + i/128)` for `i` in 0..128.
struct LnTable {
    ln: [f64; 128],
    inverse: [f64; 128],
}

fn ln_table() -> &'static LnTable {
    static TABLE: std::sync::OnceLock<LnTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let c = |i: usize| 1.0 + i as f64 / 128.0;
        LnTable {
            ln: std::array::from_fn(|i| ln_series(c(i))),
            inverse: std::array::from_fn(|i| 1.0 / c(i)),
        }
    })
}

/// `ln m` for `m` in [1, 2] by `2 atanh(s)`, `s = (m − 1)/(m + 1)`, summed
/// to `s⁴⁷` (|s| ≤ 1/3: the terms left are below 1e-23): the table's
/// entries, built once from IEEE operations only.
fn ln_series(m: f64) -> f64 {
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let mut term = s;
    let mut sum = 0.0;
    for k in 0..24 {
        sum += term / (2 * k + 1) as f64;
        term *= s2;
    }
    2.0 * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_logarithm_matches_the_platform_one() {
        for x in [1e-16, 1e-3, 0.25, 0.5, 0.7, 0.999_999, 1.0 - 1e-16] {
            assert!((ln(x) - x.ln()).abs() < 1e-14, "{x}: {} {}", ln(x), x.ln());
        }
    }

    #[test]
    fn more_hairs_keep_every_cell_count_and_counts_follow_the_rates() {
        let spot = crate::assets::spot();
        let density = crate::map::Map::Image(crate::assets::spot_texture(crate::map::Channel::R));
        let sampler = DensitySampler::new(&spot, &density, Default::default()).unwrap();
        let cells = RootCells::new(&spot, &sampler);
        assert!(cells.len() > 300, "{}", cells.len());
        let mut all: Vec<u32> = (0..cells.len())
            .flat_map(|c| cells.triangles(c).to_vec())
            .collect();
        all.sort_unstable();
        assert_eq!(all, (0..spot.triangle_count() as u32).collect::<Vec<_>>());
        let mut before = vec![0; cells.len()];
        for n in [0, 1, 10, 1000, 1001, 50_000] {
            let counts = cells.counts(3, n);
            assert_eq!(counts.iter().sum::<u64>(), n);
            assert!(counts.iter().zip(&before).all(|(a, b)| a >= b), "{n}");
            before = counts;
        }
        // 50,000 hairs: each cell near its expected share (Poisson spread).
        let bad = (0..cells.len())
            .filter(|&c| {
                let expected = 50_000.0 * cells.rate(c);
                (before[c] as f64 - expected).abs() > 5.0 * expected.sqrt() + 2.0
            })
            .count();
        assert_eq!(bad, 0);
    }
}
