//! Discrete selection by the cumulative distribution function with a
//! uniform grid over its codomain (Sik §3.2–3.3, Fig. 7).
//!
//! `F(i)` is stored as 32-bit fixed point of the normalised CDF rather than
//! as f32: near 1 an f32 CDF resolves only 6·10⁻⁸ of the total, which would
//! shift a record holding 10⁻⁶ of the probability by several percent (a
//! chi-square test sees it). Fixed point resolves 2.3·10⁻¹⁰ everywhere, in
//! the same four bytes, and selection compares integers.
//!
//! The grid stores only each cell's first index (`C_begin`); the paper's
//! `C_end` of cell c is `C_begin` of cell c + 1, so one array serves both.

/// `F` of the last record: the fixed-point scale.
const FULL: u64 = u32::MAX as u64;

/// A discrete distribution sampled by bisection in the CDF, optionally
/// narrowed by a uniform grid over the CDF's codomain.
#[derive(Debug, Clone)]
pub struct CdfGrid {
    /// `F(i)`: the probability of records `0..=i`, times 2³² − 1, rounded.
    cdf: Vec<u32>,
    /// For each grid cell the first record it can select, plus one entry
    /// for the end; empty when there is no grid.
    cell_begin: Vec<u32>,
}

impl CdfGrid {
    /// Builds the CDF of `weights` (non-negative, not all zero) and a grid of
    /// `grid_percent` % as many cells as records (0 % = plain bisection; the
    /// paper's Table 1 explores 0–400 %).
    pub fn new(weights: impl IntoIterator<Item = f64>, grid_percent: u32) -> Self {
        let weights: Vec<f64> = weights.into_iter().collect();
        let total: f64 = weights.iter().sum();
        assert!(total > 0.0, "CdfGrid needs a positive total weight");
        let mut running = 0.0;
        let mut cdf: Vec<u32> = weights
            .iter()
            .map(|w| {
                running += w;
                ((running / total) * FULL as f64 + 0.5).min(FULL as f64) as u32
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = FULL as u32;
        }

        let cells = (cdf.len() as u64 * u64::from(grid_percent) / 100) as usize;
        let mut cell_begin = Vec::new();
        if cells > 0 {
            cell_begin.reserve(cells + 1);
            let mut i = 0usize;
            for c in 0..cells as u64 {
                // Smallest ξ in cell c: ceil(c·2³² / cells).
                let lo = (c << 32).div_ceil(cells as u64);
                while i + 1 < cdf.len() && u64::from(cdf[i]) <= lo {
                    i += 1;
                }
                cell_begin.push(i as u32);
            }
            cell_begin.push(cdf.len() as u32 - 1);
        }
        Self { cdf, cell_begin }
    }

    /// Number of records.
    pub fn len(&self) -> usize {
        self.cdf.len()
    }

    /// Whether there are no records.
    pub fn is_empty(&self) -> bool {
        self.cdf.is_empty()
    }

    /// Number of grid cells (0 without a grid).
    pub fn cell_count(&self) -> usize {
        self.cell_begin.len().saturating_sub(1)
    }

    /// Selects a record from 64 random bits (the high 32 are used):
    /// `argmin_i F(i) > ξ` with `ξ` uniform in [0, F(last)).
    #[inline]
    pub fn select(&self, bits: u64) -> usize {
        self.search(bits, self.range_of(bits))
    }

    /// The grid cell's entry that `bits` falls in (for prefetching), or the
    /// first CDF entry without a grid.
    #[inline]
    pub fn cell_entry(&self, bits: u64) -> &u32 {
        if self.cell_begin.is_empty() {
            &self.cdf[0]
        } else {
            &self.cell_begin[self.cell_of(Self::xi(bits))]
        }
    }

    /// The index range of the CDF that `bits` can select (first step).
    #[inline]
    pub fn range_of(&self, bits: u64) -> (usize, usize) {
        if self.cell_begin.is_empty() {
            (0, self.cdf.len() - 1)
        } else {
            let cell = self.cell_of(Self::xi(bits));
            (
                self.cell_begin[cell] as usize,
                self.cell_begin[cell + 1] as usize,
            )
        }
    }

    /// The CDF entry at `i`, for prefetching.
    #[inline]
    pub fn entry(&self, i: usize) -> &u32 {
        &self.cdf[i]
    }

    /// Bisection inside `(lo, hi)` (second step).
    #[inline]
    pub fn search(&self, bits: u64, (lo, hi): (usize, usize)) -> usize {
        let xi = Self::xi(bits);
        lo + self.cdf[lo..=hi].partition_point(|&f| u64::from(f) <= xi)
    }

    /// ξ uniform in [0, F(last)) from the high 32 bits.
    #[inline]
    fn xi(bits: u64) -> u64 {
        ((bits >> 32) * FULL) >> 32
    }

    #[inline]
    fn cell_of(&self, xi: u64) -> usize {
        ((xi * self.cell_count() as u64) >> 32) as usize
    }

    /// Probability of record `i` as the selector realises it.
    pub fn probability(&self, i: usize) -> f64 {
        let below = if i == 0 { 0 } else { self.cdf[i - 1] };
        f64::from(self.cdf[i] - below) / FULL as f64
    }

    /// Bytes the CDF and grid occupy.
    pub fn memory_bytes(&self) -> usize {
        (self.cdf.len() + self.cell_begin.len()) * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::rng::SampleRng;

    fn histogram(cdf: &CdfGrid, n: u64) -> Vec<u64> {
        let mut counts = vec![0u64; cdf.len()];
        for i in 0..n {
            counts[cdf.select(SampleRng::new(5, i).next_u64())] += 1;
        }
        counts
    }

    #[test]
    fn zero_weights_are_never_selected_and_grid_does_not_change_selection() {
        let weights = [0.0, 3.0, 0.0, 1.0, 0.0, 0.0, 4.0, 0.0];
        let plain = CdfGrid::new(weights, 0);
        for percent in [13, 100, 400] {
            let grid = CdfGrid::new(weights, percent);
            for i in 0..20_000 {
                let bits = SampleRng::new(1, i).next_u64();
                assert_eq!(plain.select(bits), grid.select(bits), "grid {percent}%");
            }
        }
        let counts = histogram(&plain, 80_000);
        for (w, c) in weights.iter().zip(&counts) {
            if *w == 0.0 {
                assert_eq!(*c, 0);
            } else {
                let expected = 80_000.0 * w / 8.0;
                assert!((*c as f64 - expected).abs() < 5.0 * expected.sqrt());
            }
        }
    }

    #[test]
    fn extremes_select_first_and_last_positive_records() {
        let cdf = CdfGrid::new([0.0, 1.0, 1.0, 0.0], 200);
        assert_eq!(cdf.select(0), 1);
        assert_eq!(cdf.select(u64::MAX), 2);
        assert!((cdf.probability(1) - 0.5).abs() < 1e-9);
    }

    #[test]
    fn tiny_weights_keep_their_share() {
        // A million records of weight 1 and one of weight 1000: f32 could
        // not tell the last record's F from its neighbour's within 1 %.
        let weights: Vec<f64> = (0..1_000_000)
            .map(|i| if i == 500_000 { 1000.0 } else { 1.0 })
            .collect();
        let cdf = CdfGrid::new(weights.iter().copied(), 100);
        let expected = 1.0 / 1_000_999.0;
        assert!((cdf.probability(10) - expected).abs() / expected < 1e-3);
    }
}
