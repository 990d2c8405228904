//! The detection statistic under H0 (noise only) and its threshold.
//!
//! One coherent correlation of complex circular Gaussian noise is `y ~ CN(0, sigma^2)`, so
//! `|y|^2 / sigma^2` is exponential with mean 1; the non-coherent sum of `n` independent blocks,
//! `S / sigma^2`, is Gamma(n, 1) (= chi-square with 2n degrees of freedom, halved). Its tail is
//! the regularised upper incomplete gamma function, which for an integer shape is the Poisson sum
//! (Abramowitz & Stegun 6.5.13 with 26.4.21):
//!
//! `P(S/sigma^2 > x) = Q(n, x) = exp(-x) * sum_{k=0}^{n-1} x^k / k!`

/// Natural log of `Q(n, x) = P(Gamma(n, 1) > x)` for integer `n >= 1`, `x >= 0`, accurate far
/// into the tail (it works in logs, so 1e-300 is no problem).
pub fn gamma_upper_tail_ln(n: u32, x: f64) -> f64 {
    if x <= 0.0 || x.is_nan() {
        return 0.0;
    }
    let n = n.max(1);
    let lnx = x.ln();
    // Terms t_k = k ln x - ln k!; log-sum-exp around the largest one.
    let mut terms_max = f64::NEG_INFINITY;
    let mut ln_fact = 0.0;
    for k in 0..n {
        if k > 0 {
            ln_fact += f64::from(k).ln();
        }
        terms_max = terms_max.max(f64::from(k) * lnx - ln_fact);
    }
    let mut sum = 0.0;
    ln_fact = 0.0;
    for k in 0..n {
        if k > 0 {
            ln_fact += f64::from(k).ln();
        }
        sum += (f64::from(k) * lnx - ln_fact - terms_max).exp();
    }
    (-x + terms_max + sum.ln()).min(0.0)
}

/// The `x` with `P(Gamma(n, 1) > x) = p` (the detection threshold on `S / sigma^2`), for
/// `p` in (0, 1). Bisection on [`gamma_upper_tail_ln`], relative accuracy 1e-10.
pub fn gamma_upper_quantile(n: u32, p: f64) -> f64 {
    let p = p.clamp(f64::MIN_POSITIVE, 1.0 - 1e-16);
    let target = p.ln();
    let mut lo = 0.0_f64;
    let mut hi = f64::from(n.max(1)) + 10.0;
    while gamma_upper_tail_ln(n, hi) > target {
        lo = hi;
        hi *= 2.0;
        if hi > 1e12 {
            return hi;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if gamma_upper_tail_ln(n, mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-10 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Threshold on the normalised cell `S / sigma^2` for a per-PRN-search false-alarm probability
/// `pfa` over `cells` cells: each cell gets `pfa / cells` (union bound; neighbouring lags and
/// Doppler bins share noise, but far in the tail their exceedances are nearly independent, so the
/// bound is close to the real rate).
pub fn detection_threshold(noncoherent: u32, pfa: f64, cells: usize) -> f64 {
    gamma_upper_quantile(noncoherent, pfa / cells.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_block_is_exponential() {
        for &x in &[0.1, 1.0, 7.5, 30.0, 200.0] {
            assert!((gamma_upper_tail_ln(1, x) + x).abs() < 1e-12);
        }
        let p = 1e-9_f64;
        assert!((gamma_upper_quantile(1, p) + p.ln()).abs() < 1e-8);
    }

    #[test]
    fn matches_chi_square_tables() {
        // chi-square 95 % points (2n dof): 20 dof 31.410, 40 dof 55.758, 4 dof 9.488; x = chi2/2.
        assert!((gamma_upper_quantile(10, 0.05) - 31.410 / 2.0).abs() < 2e-3);
        assert!((gamma_upper_quantile(20, 0.05) - 55.758 / 2.0).abs() < 2e-3);
        assert!((gamma_upper_quantile(2, 0.05) - 9.488 / 2.0).abs() < 2e-3);
        // Two blocks: Q(2, x) = exp(-x)(1 + x), exact.
        let x = 23.0_f64;
        assert!((gamma_upper_tail_ln(2, x) - (-x + (1.0 + x).ln())).abs() < 1e-12);
    }

    #[test]
    fn deep_tail_and_large_n_are_finite_and_monotone() {
        let mut prev = 0.0;
        for &p in &[1e-3, 1e-6, 1e-9, 1e-12, 1e-15] {
            let x = gamma_upper_quantile(100, p);
            assert!(x.is_finite() && x > prev);
            assert!((gamma_upper_tail_ln(100, x) - p.ln()).abs() < 1e-6);
            prev = x;
        }
        assert!(gamma_upper_quantile(5000, 1e-10) > 5000.0);
    }
}
