//! Least-squares polynomial fits of the error over the measurement window.

/// Least-squares polynomial of degree `deg` (<= 2) through `(t, y)`, in powers of `t - t_c`
/// with `t_c` the mean time ([`gpsrx_core::Polynomial::fit`]); NaN coefficients when there
/// are too few points.
pub(super) fn polyfit(pts: &[(f64, f64)], deg: usize) -> (Vec<f64>, f64) {
    gpsrx_core::Polynomial::fit(pts, deg).map_or_else(
        || (vec![f64::NAN; deg + 1], 0.0),
        |p| (p.coeffs, p.t_center),
    )
}

pub(super) fn eval_fit(fit: &(Vec<f64>, f64), t: f64) -> f64 {
    let x = t - fit.1;
    fit.0.iter().rev().fold(0.0, |acc, c| acc * x + c)
}
