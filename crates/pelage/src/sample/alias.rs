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

impl AliasTable {
    /// Builds the table of `weights` (non-negative, not all zero).
    pub fn new(weights: impl IntoIterator<Item = f64>) -> Self {
        // Scaled in place so the average bin holds exactly 1.
        let mut scaled: Vec<f64> = weights.into_iter().collect();
        let n = scaled.len();
        let total: f64 = scaled.iter().sum();
        assert!(total > 0.0, "AliasTable needs a positive total weight");
        let factor = n as f64 / total;
        scaled.iter_mut().for_each(|w| *w *= factor);

        let mut bins: Vec<AliasBin> = (0..n as u32)
            .map(|i| AliasBin {
                threshold: u32::MAX,
                alias: i,
            })
            .collect();
        // Vose's two work lists share one buffer: "small" (< 1) grows up
        // from the front, "large" (≥ 1) down from the back. Together they
        // never hold more than n entries, so nothing reallocates.
        let mut work = vec![0u32; n];
        let (mut small, mut large) = (0usize, n);
        for (i, &p) in scaled.iter().enumerate() {
            if p < 1.0 {
                work[small] = i as u32;
                small += 1;
            } else {
                large -= 1;
                work[large] = i as u32;
            }
        }
        while small > 0 && large < n {
            small -= 1;
            let s = work[small] as usize;
            let l = work[large];
            let p = scaled[s];
            bins[s] = AliasBin {
                threshold: (p * 4_294_967_296.0 + 0.5).min(u32::MAX as f64) as u32,
                alias: l,
            };
            scaled[l as usize] -= 1.0 - p;
            if scaled[l as usize] < 1.0 {
                large += 1;
                work[small] = l;
                small += 1;
            }
        }
        // What remains holds 1 up to rounding: it keeps itself always (the
        // default bin has alias = itself, so the 2⁻³² coin case is harmless).
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

    #[test]
    fn single_record_is_always_selected() {
        let t = AliasTable::new([3.0]);
        assert_eq!(t.select(0), 0);
        assert_eq!(t.select(u64::MAX), 0);
    }
}
