//! Pearson's chi-square goodness of fit, for tests that check sampled
//! counts against the probabilities they should follow.

/// Pearson's chi-square of `counts` against `probabilities`. Bins expected
/// to hold fewer than 5 samples are pooled. A bin of probability zero that
/// received a sample fails at once (returned as infinity).
pub fn chi_square(counts: &[u64], probabilities: &[f64]) -> (f64, usize) {
    let n: u64 = counts.iter().sum();
    let (mut chi2, mut bins) = (0.0, 0usize);
    let (mut pooled_count, mut pooled_expected) = (0.0, 0.0);
    for (&c, &p) in counts.iter().zip(probabilities) {
        let e = p * n as f64;
        if p == 0.0 {
            if c > 0 {
                return (f64::INFINITY, bins);
            }
            continue;
        }
        if e < 5.0 {
            pooled_count += c as f64;
            pooled_expected += e;
            continue;
        }
        chi2 += (c as f64 - e).powi(2) / e;
        bins += 1;
    }
    if pooled_expected > 0.0 {
        chi2 += (pooled_count - pooled_expected).powi(2) / pooled_expected;
        bins += 1;
    }
    (chi2, bins.saturating_sub(1))
}

/// The 0.999 quantile of chi-square with `dof` degrees of freedom
/// (Wilson–Hilferty).
pub fn chi_square_limit(dof: usize) -> f64 {
    let k = dof as f64;
    let z = 3.0902;
    k * (1.0 - 2.0 / (9.0 * k) + z * (2.0 / (9.0 * k)).sqrt()).powi(3)
}

pub fn assert_fits(what: &str, counts: &[u64], probabilities: &[f64]) {
    let (chi2, dof) = chi_square(counts, probabilities);
    let limit = chi_square_limit(dof);
    assert!(
        chi2 < limit,
        "{what}: chi-square {chi2:.1} ≥ {limit:.1} ({dof} degrees of freedom)"
    );
}
