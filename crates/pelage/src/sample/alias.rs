//! Discrete selection in O(1) by Walker's alias method, built with Vose's
//! stable algorithm ("A linear algorithm for generating random numbers with
//! a given distribution", 1991).
//!
//! Each bin keeps a 32-bit fixed-point threshold and an alias: one draw
//! picks the bin from its high 32 bits and tosses the bin's coin with its
//! low 32 bits, so a selection costs one random number and one or two
//! memory reads, whatever the number of records.

/// A bin of the alias table: keep the bin when the coin is below
/// `threshold`, else take `alias`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C)]
pub struct AliasBin {
    /// Probability of keeping this bin, times 2³².
    pub threshold: u32,
    /// The record taken otherwise.
    pub alias: u32,
}

/// Walker's alias table.
#[derive(Debug, Clone)]
pub struct AliasTable {
    bins: Vec<AliasBin>,
}

/// Where an alias table's bins are written: the plain [`AliasBin`]s of an
/// [`AliasTable`], or a structure that keeps each bin beside its record
/// (the density sampler's fused entries).
pub trait AliasBins {
    /// Sets bin `i`: keep it when the coin is below `threshold`, else take
    /// `alias`. Bins never set keep themselves.
    fn set(&mut self, i: usize, threshold: u32, alias: u32);
}

impl AliasBins for [AliasBin] {
    fn set(&mut self, i: usize, threshold: u32, alias: u32) {
        self[i] = AliasBin { threshold, alias };
    }
}

/// Fills `bins` (one per weight, each initially keeping itself) with
/// Walker's alias table of `weights` (non-negative, not all zero).
pub fn build_alias_bins(
    weights: impl IntoIterator<Item = f64>,
    bins: &mut (impl AliasBins + ?Sized),
) {
    // Scaled in place so the average bin holds exactly 1.
    let mut scaled: Vec<f64> = weights.into_iter().collect();
    let n = scaled.len();
    let total: f64 = scaled.iter().sum();
    assert!(total > 0.0, "an alias table needs a positive total weight");
    let factor = n as f64 / total;
    scaled.iter_mut().for_each(|w| *w *= factor);

    // Vose's pairing done as a sweep: `small` and `large` scan forward
    // for the next bin below / at or above 1. Both only move forward,
    // so the 20 MB of bins and weights are read in order instead of at
    // random as with Vose's stacks, several times faster here.
    let next_small =
        |from: usize, scaled: &[f64]| (from..n).find(|&i| scaled[i] < 1.0).unwrap_or(n);
    let next_large =
        |from: usize, scaled: &[f64]| (from..n).find(|&i| scaled[i] >= 1.0).unwrap_or(n);
    let mut scan = next_small(0, &scaled);
    let mut s = scan;
    let mut large = next_large(0, &scaled);
    while s < n && large < n {
        let p = scaled[s];
        let threshold = (p * 4_294_967_296.0 + 0.5).min(u32::MAX as f64) as u32;
        bins.set(s, threshold, large as u32);
        scaled[large] -= 1.0 - p;
        // `s` was either the scan's entry (then the scan moves on) or
        // an earlier donor (then the scan's entry is still waiting).
        if s == scan {
            scan = next_small(scan + 1, &scaled);
        }
        s = scan;
        if scaled[large] < 1.0 {
            // The donor is now small itself. If the scan has passed it,
            // pair it next; otherwise the scan reaches it (or just did).
            let donor = large;
            large = next_large(large + 1, &scaled);
            if donor < scan {
                s = donor;
            }
        }
    }
    // What remains holds 1 up to rounding: it keeps itself always (a bin
    // never set has alias = itself, so the 2⁻³² coin case is harmless).
}

impl AliasTable {
    /// Builds the table of `weights` (non-negative, not all zero).
    pub fn new(weights: impl IntoIterator<Item = f64>) -> Self {
        let weights: Vec<f64> = weights.into_iter().collect();
        let mut bins: Vec<AliasBin> = (0..weights.len() as u32)
            .map(|i| AliasBin {
                threshold: u32::MAX,
                alias: i,
            })
            .collect();
        build_alias_bins(weights, bins.as_mut_slice());
        Self { bins }
    }

    /// Number of records.
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Whether there are no records.
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }

    /// Selects a record from 64 random bits.
    #[inline]
    pub fn select(&self, bits: u64) -> usize {
        self.resolve(self.bin_of(bits), bits)
    }

    /// The bin that `bits` draws (the first of the two steps of `select`).
    #[inline]
    pub fn bin_of(&self, bits: u64) -> usize {
        (((bits >> 32) * self.bins.len() as u64) >> 32) as usize
    }

    /// The bin itself, for prefetching.
    #[inline]
    pub fn bin(&self, bin: usize) -> &AliasBin {
        &self.bins[bin]
    }

    /// The record that `bits` selects in `bin` (the second step).
    #[inline]
    pub fn resolve(&self, bin: usize, bits: u64) -> usize {
        let b = self.bins[bin];
        if (bits as u32) < b.threshold {
            bin
        } else {
            b.alias as usize
        }
    }

    /// The bins, in record order.
    pub fn bins(&self) -> &[AliasBin] {
        &self.bins
    }

    /// Bytes the table occupies.
    pub fn memory_bytes(&self) -> usize {
        self.bins.len() * std::mem::size_of::<AliasBin>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::rng::SampleRng;

    #[test]
    fn histogram_matches_weights_and_zeros_stay_empty() {
        let weights = [0.0, 5.0, 1.0, 0.0, 2.0, 0.5, 0.0, 1.5];
        let total: f64 = weights.iter().sum();
        let table = AliasTable::new(weights);
        let n = 400_000;
        let mut counts = [0u64; 8];
        for i in 0..n {
            counts[table.select(SampleRng::new(2, i).next_u64())] += 1;
        }
        let mut chi2 = 0.0;
        for (w, c) in weights.iter().zip(counts) {
            if *w == 0.0 {
                assert_eq!(c, 0);
            } else {
                let e = n as f64 * w / total;
                chi2 += (c as f64 - e).powi(2) / e;
            }
        }
        // 5 positive bins: 4 degrees of freedom, 0.001 quantile 18.5.
        assert!(chi2 < 18.5, "chi2 {chi2} counts {counts:?}");
    }

    /// The probability each record receives, read off the table: its own
    /// bin's keep share plus every share aliased to it.
    fn realised(table: &AliasTable) -> Vec<f64> {
        let n = table.len() as f64;
        let mut p = vec![0.0; table.len()];
        for (i, b) in table.bins().iter().enumerate() {
            let keep = f64::from(b.threshold) / 4_294_967_296.0;
            p[i] += keep / n;
            p[b.alias as usize] += (1.0 - keep) / n;
        }
        p
    }

    #[test]
    fn table_realises_the_weights_exactly() {
        for seed in 0..20u64 {
            let n = 1 + (seed * 977 % 5000) as usize;
            let weights: Vec<f64> = (0..n as u64)
                .map(|i| {
                    let r = SampleRng::new(seed, i).uniform_f32() as f64;
                    // Many zeros and a wide range of sizes.
                    if r < 0.2 { 0.0 } else { r.powi(6) * 1000.0 }
                })
                .collect();
            let total: f64 = weights.iter().sum();
            if total == 0.0 {
                continue;
            }
            let table = AliasTable::new(weights.iter().copied());
            for (k, (w, p)) in weights.iter().zip(realised(&table)).enumerate() {
                assert!(
                    (p - w / total).abs() < 1e-8,
                    "seed {seed}, n {n}, record {k}: {p} vs {}",
                    w / total
                );
            }
        }
    }

    #[test]
    fn single_record_is_always_selected() {
        let t = AliasTable::new([3.0]);
        assert_eq!(t.select(0), 0);
        assert_eq!(t.select(u64::MAX), 0);
    }
}
