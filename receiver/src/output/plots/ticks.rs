//! Axis ranges and tick labels: few, readable labels on logarithmic axes (1-2-5 steps) and
//! numbers without needless trailing zeros.

/// Axis range of the finite values (positive ones on a log axis), padded a little: 5 % of the
/// span on a linear axis, a factor 1.3 on a log axis; a flat or empty set gets a unit range.
pub fn padded_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        (lo / 1.3, hi * 1.3)
    } else if hi - lo < 1e-12 * hi.abs().max(1.0) {
        (lo - 1.0, hi + 1.0)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

/// Tick values for a logarithmic axis over `[lo, hi]` (`0 < lo < hi`): the powers of ten
/// when there are at least three of them, else the 1-2-5 sequence, else every integer
/// mantissa 1-9; at most about 8 labels so they never run into each other.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Vec::new();
    }
    let mantissas: [&[f64]; 3] = [
        &[1.0],
        &[1.0, 2.0, 5.0],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    ];
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let mut best = Vec::new();
    for m in mantissas {
        let ticks: Vec<f64> = (k0..=k1)
            .flat_map(|k| m.iter().map(move |mm| mm * 10f64.powi(k)))
            .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
            .collect();
        if ticks.len() > 8 && !best.is_empty() {
            break;
        }
        best = ticks;
        if best.len() >= 3 {
            break;
        }
    }
    best
}

/// A tick label: at most 4 significant digits, no trailing zeros (`0.5`, `10`, `2.25`),
/// powers-of-ten notation beyond 1e5 or below 1e-3 (`1e-4`, `2e6`).
pub fn tick_label(v: f64) -> String {
    if !v.is_finite() {
        return String::new();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.3e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        return format!("{}e{e}", trim_zeros(m));
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    trim_zeros(&format!("{v:.decimals$}"))
}

fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_are_few_and_readable() {
        // One decade and a half: 1-2-5 steps.
        assert_eq!(log_ticks(0.3, 12.0), vec![0.5, 1.0, 2.0, 5.0, 10.0]);
        // Six decades: the powers of ten only.
        let t = log_ticks(1e-4, 50.0);
        assert_eq!(t.len(), 6);
        assert!((t[0] - 1e-4).abs() < 1e-12 && (t[5] - 10.0).abs() < 1e-9);
        // Inside one decade: every mantissa.
        assert_eq!(log_ticks(3.0, 8.0), vec![3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
        assert!(log_ticks(-1.0, 8.0).is_empty());
    }

    #[test]
    fn tick_labels_have_no_needless_zeros() {
        assert_eq!(tick_label(10.0), "10");
        assert_eq!(tick_label(0.5), "0.5");
        assert_eq!(tick_label(0.1 + 0.2), "0.3");
        assert_eq!(tick_label(2.25), "2.25");
        assert_eq!(tick_label(-35.0), "-35");
        assert_eq!(tick_label(1e-4), "1e-4");
        assert_eq!(tick_label(2e6), "2e6");
        assert_eq!(tick_label(0.0), "0");
    }

    #[test]
    fn padded_range_pads_and_handles_degenerate_sets() {
        assert_eq!(padded_range([0.0, 10.0].into_iter(), false), (-0.5, 10.5));
        assert_eq!(padded_range([3.0, 3.0].into_iter(), false), (2.0, 4.0));
        assert_eq!(padded_range([f64::NAN].into_iter(), true), (0.1, 10.0));
        let (a, b) = padded_range([-1.0, 1.0, 13.0].into_iter(), true);
        assert!((a - 1.0 / 1.3).abs() < 1e-12 && (b - 13.0 * 1.3).abs() < 1e-9);
    }
}
