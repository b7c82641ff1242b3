//! Counter-based random streams: the random numbers of sample `i` depend on
//! `(seed, i)` alone, so any range of samples can be generated on its own,
//! on any number of threads, with identical results (docs/design.md,
//! "Deterministic by hair id").
//!
//! Two forms, both SplitMix64 (Steele et al. 2014, "Fast splittable
//! pseudorandom number generators"), whose output is a strong 64-bit mix of
//! a counter:
//!
//! - [`PairDraws`]: a sample that needs exactly two 64-bit draws takes
//!   outputs `2i` and `2i + 1` of the stream keyed by the seed: two mixes,
//!   no state. The density sampler uses it.
//! - [`SampleRng`]: a sample that needs an unknown number of draws (the
//!   rejection sampler) gets its own stream, started at a hash of
//!   `(seed, index)`; it draws a handful of numbers, far below the distance
//!   at which two hashed streams could overlap.

/// The random stream of one sample (or one hair).
#[derive(Debug, Clone)]
pub struct SampleRng {
    state: u64,
}

const GOLDEN_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's finaliser (Stafford's variant 13): a bijection on u64 with
/// full avalanche.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Exactly two 64-bit draws per sample index: SplitMix64's outputs `2i`
/// and `2i + 1` of the stream whose start the seed gives.
#[derive(Debug, Clone, Copy)]
pub struct PairDraws {
    start: u64,
}

impl PairDraws {
    /// The stream of `seed`.
    #[inline]
    pub fn new(seed: u64) -> Self {
        Self {
            start: mix64(seed ^ 0x243F_6A88_85A3_08D3),
        }
    }

    /// The two draws of sample `index`.
    #[inline]
    pub fn draws(&self, index: u64) -> [u64; 2] {
        let position = self
            .start
            .wrapping_add(index.wrapping_mul(2).wrapping_mul(GOLDEN_GAMMA));
        [
            mix64(position.wrapping_add(GOLDEN_GAMMA)),
            mix64(position.wrapping_add(GOLDEN_GAMMA.wrapping_mul(2))),
        ]
    }
}

/// Two uniform numbers in (0, 1) from one 64-bit draw (24 bits each).
#[inline]
pub fn open_unit_pair(bits: u64) -> [f32; 2] {
    [
        open_unit((bits >> 40) as u32),
        open_unit(((bits >> 8) & 0xFF_FFFF) as u32),
    ]
}

/// `(k + ½) / 2²⁴` for a 24-bit `k`; exact in f32.
#[inline]
fn open_unit(k: u32) -> f32 {
    (k as f32 + 0.5) * (1.0 / (1u32 << 24) as f32)
}

impl SampleRng {
    /// The stream of sample `index` under `seed`.
    #[inline]
    pub fn new(seed: u64, index: u64) -> Self {
        Self {
            state: mix64(seed.wrapping_mul(GOLDEN_GAMMA) ^ mix64(index ^ 0x6A09_E667_F3BC_C909)),
        }
    }

    /// The next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN_GAMMA);
        mix64(self.state)
    }

    /// A uniform number in the open interval (0, 1): the centre of one of
    /// 2²⁴ equal steps. Never 0 or 1, so warped samples never land exactly
    /// on a triangle's edge, where the triangle they belong to is ambiguous.
    #[inline]
    pub fn uniform_f32(&mut self) -> f32 {
        open_unit((self.next_u64() >> 40) as u32)
    }

    /// Two independent uniform numbers in (0, 1) from one 64-bit draw.
    #[inline]
    pub fn uniform_f32_pair(&mut self) -> [f32; 2] {
        open_unit_pair(self.next_u64())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_and_index_same_stream() {
        let mut a = SampleRng::new(7, 12345);
        let mut b = SampleRng::new(7, 12345);
        for _ in 0..10 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
        assert_ne!(
            SampleRng::new(7, 1).next_u64(),
            SampleRng::new(8, 1).next_u64()
        );
        assert_ne!(
            SampleRng::new(7, 1).next_u64(),
            SampleRng::new(7, 2).next_u64()
        );
    }

    #[test]
    fn pair_draws_do_not_repeat_across_neighbouring_samples() {
        let d = PairDraws::new(5);
        let mut seen = std::collections::HashSet::new();
        for i in 0..10_000 {
            for x in d.draws(i) {
                assert!(seen.insert(x), "draw repeated at sample {i}");
            }
        }
        assert_ne!(PairDraws::new(5).draws(0), PairDraws::new(6).draws(0));
    }

    #[test]
    fn uniforms_are_in_range_and_evenly_spread() {
        let mut bins = [0u32; 16];
        for i in 0..160_000 {
            let [a, b] = SampleRng::new(1, i).uniform_f32_pair();
            assert!(a > 0.0 && a < 1.0 && b > 0.0 && b < 1.0);
            bins[(a * 4.0) as usize * 4 + (b * 4.0) as usize] += 1;
        }
        // Chi-square with 15 degrees of freedom; 37.7 is the 0.001 quantile.
        let chi2: f64 = bins
            .iter()
            .map(|&c| (f64::from(c) - 10_000.0).powi(2) / 10_000.0)
            .sum();
        assert!(chi2 < 37.7, "chi2 {chi2}");
    }
}
