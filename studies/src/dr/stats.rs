//! Means, variances and RMS over time windows of per-epoch series (NaN entries skipped).

/// Mean and (population) variance of the finite values of `v` whose time is in `[a, b)`.
pub fn mean_var(t: &[f64], v: &[f64], a: f64, b: f64) -> (f64, f64) {
    let xs: Vec<f64> = t
        .iter()
        .zip(v)
        .filter(|(&t, x)| t >= a && t < b && x.is_finite())
        .map(|(_, &x)| x)
        .collect();
    if xs.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = xs.len() as f64;
    let m = xs.iter().sum::<f64>() / n;
    (m, xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n)
}

/// Root mean square of a slice.
pub fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_statistics_match_hand_values() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let v = [1.0, 2.0, f64::NAN, 4.0, 100.0];
        let (m, var) = mean_var(&t, &v, 0.0, 4.0);
        // {1, 2, 4}: mean 7/3, variance ((4/3)^2 + (1/3)^2 + (5/3)^2) / 3 = 14/9.
        assert!((m - 7.0 / 3.0).abs() < 1e-12 && (var - 14.0 / 9.0).abs() < 1e-12);
        assert!(mean_var(&t, &v, 10.0, 11.0).0.is_nan());
        assert!((rms(&[3.0, 4.0]) - 12.5f64.sqrt()).abs() < 1e-12);
    }
}
