//! Counter-based random streams: the random numbers of sample `i` depend on
//! `(seed, i)` alone, so any range of samples can be generated on its own,
//! on any number of threads, with identical results (DESIGN.md,
//! "Deterministic by hair id").
//!
//! Each `(seed, index)` pair is hashed into a SplitMix64 state; the stream
//! then steps SplitMix64 (Steele et al. 2014), whose output function is a
//! strong 64-bit mixer. A sample draws a handful of numbers, far below the
//! distance at which two hashed streams could overlap.

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
        let bits = self.next_u64();
        [
            open_unit((bits >> 40) as u32),
            open_unit(((bits >> 8) & 0xFF_FFFF) as u32),
        ]
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
