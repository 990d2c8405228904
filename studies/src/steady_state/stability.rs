//! Stability of the digital loops: the `Bn T` limit and the slowest closed-loop pole.

use gpsrx_tracking::loop_analysis;
use gpsrx_tracking::loop_filter::LoopFilter;

use super::MAIN_T_COH_S;

/// The largest `Bn T` at which the order-`order` PLL of this implementation is stable
/// (bisection on [`loop_analysis::is_stable`] over `Bn T` in (0, 2]; the closed loop depends on
/// `omega0 T` only, so the limit does not depend on T).
pub fn stability_limit_bn_t(order: u8) -> f64 {
    let t = MAIN_T_COH_S;
    let stable = |bn_t: f64| {
        LoopFilter::pll(order, bn_t / t)
            .map(|f| loop_analysis::is_stable(&f, t))
            .unwrap_or(false)
    };
    let (mut lo, mut hi) = (0.0, 2.0);
    if stable(hi) {
        return hi;
    }
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Largest closed-loop pole radius of `filter` at `t_s` (bisection on the Schur-Cohn test of
/// the scaled characteristic polynomial `sum a_i r^-i z^-i`, stable iff all poles lie inside
/// radius `r`); `None` if unstable.
pub(super) fn spectral_radius(filter: &LoopFilter, t_s: f64) -> Option<f64> {
    let den = loop_analysis::closed_loop(filter, t_s).den;
    let inside = |r: f64| {
        let scaled: Vec<f64> = den
            .iter()
            .enumerate()
            .map(|(i, a)| a / r.powi(i as i32))
            .collect();
        loop_analysis::polynomial_is_stable(&scaled)
    };
    if !inside(1.0) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if inside(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}
