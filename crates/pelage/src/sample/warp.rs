//! Small exact sampling functions, each with its density and inverse, in
//! the shape of pbrt-v4's `util/sampling.h`.

/// Uniform point in the reference triangle (0,0), (1,0), (0,1) from two
/// uniform numbers (Sik, Fig. 6 step 2): `u = 1 − √ξ1`, `v = ξ2 √ξ1`.
/// Returns `[u, v]`, the weights of corners 1 and 2.
#[inline]
pub fn sample_uniform_triangle([xi1, xi2]: [f32; 2]) -> [f32; 2] {
    let root = xi1.sqrt();
    [1.0 - root, xi2 * root]
}

/// Density of [`sample_uniform_triangle`] per unit area of the reference
/// triangle: constant, 1 / (area ½) = 2.
pub fn uniform_triangle_pdf() -> f32 {
    2.0
}

/// The numbers that [`sample_uniform_triangle`] maps to `[u, v]`:
/// `ξ1 = (1 − u)²`, `ξ2 = v / (1 − u)`.
pub fn invert_uniform_triangle_sample([u, v]: [f32; 2]) -> [f32; 2] {
    let root = 1.0 - u;
    let xi2 = if root > 0.0 { v / root } else { 0.0 };
    [root * root, xi2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::rng::SampleRng;

    #[test]
    fn triangle_samples_are_uniform() {
        use crate::sample::subtriangle::decode;
        // Level-2 sub-triangles (positions 4..20) each cover 1/16 of the
        // reference triangle, so each should get 1/16 of the samples.
        let cells: Vec<_> = (4..20).map(decode).collect();
        let n = 160_000;
        let mut bins = [0u32; 16];
        for i in 0..n {
            let [u, v] = sample_uniform_triangle(SampleRng::new(3, i).uniform_f32_pair());
            assert!(u >= 0.0 && v >= 0.0 && u + v <= 1.0 + 1e-6);
            let b = glam::Vec2::new(u, v);
            let k = cells.iter().position(|c| c.contains(b, 1e-6)).unwrap();
            bins[k] += 1;
        }
        let expected = n as f64 / 16.0;
        let chi2: f64 = bins
            .iter()
            .map(|&c| (f64::from(c) - expected).powi(2) / expected)
            .sum();
        // 37.7 is the 0.001 quantile of chi-square with 15 degrees of freedom.
        assert!(chi2 < 37.7, "chi2 {chi2}, bins {bins:?}");
        assert_eq!(uniform_triangle_pdf(), 2.0);
    }

    #[test]
    fn inverse_round_trips() {
        for i in 0..1000 {
            let xi = SampleRng::new(9, i).uniform_f32_pair();
            let back = invert_uniform_triangle_sample(sample_uniform_triangle(xi));
            assert!(
                (back[0] - xi[0]).abs() < 1e-5 && (back[1] - xi[1]).abs() < 1e-4,
                "{xi:?} {back:?}"
            );
        }
    }
}
