//! Statistics over the per-channel series: pooled standard deviation, mean and slope.

/// Fewest samples for a per-channel statistic.
pub(super) const MIN_SAMPLES: usize = 100;

/// Mean and sum of squared deviations.
fn mean_ss(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (m, v.iter().map(|x| (x - m).powi(2)).sum())
}

/// Pooled standard deviation of several series, each about its own mean:
/// `sqrt(sum_i sum_k (x_ik - mean_i)^2 / sum_i (n_i - 1))`; series shorter than
/// [`MIN_SAMPLES`] are left out; NaN when none is left.
pub(super) fn pooled_std<'a>(series: impl Iterator<Item = &'a [f64]>) -> f64 {
    let (mut ss, mut dof) = (0.0, 0.0);
    for v in series.filter(|v| v.len() >= MIN_SAMPLES) {
        ss += mean_ss(v).1;
        dof += v.len() as f64 - 1.0;
    }
    if dof > 0.0 {
        (ss / dof).sqrt()
    } else {
        f64::NAN
    }
}

/// Least-squares line `y = a + s t`: returns (mean of y, slope s).
pub(super) fn mean_and_slope(t: &[f64], y: &[f64]) -> (f64, f64) {
    let n = t.len() as f64;
    let (tm, ym) = (t.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sty, mut stt) = (0.0, 0.0);
    for (ti, yi) in t.iter().zip(y) {
        sty += (ti - tm) * (yi - ym);
        stt += (ti - tm) * (ti - tm);
    }
    (ym, if stt > 0.0 { sty / stt } else { f64::NAN })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooled_std_and_slope() {
        // Two series with their own means: the pooled std ignores the means.
        let a: Vec<f64> = (0..200)
            .map(|k| 1.0 + if k % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        let b: Vec<f64> = a.iter().map(|x| x + 5.0).collect();
        let s = pooled_std([a.as_slice(), b.as_slice()].into_iter());
        assert!((s - 0.1 * (200.0f64 / 199.0).sqrt()).abs() < 1e-12, "{s}");
        assert!(pooled_std([&a[..10]].into_iter()).is_nan());
        let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 - 0.5 * t).collect();
        let (m, slope) = mean_and_slope(&t, &y);
        assert!((slope + 0.5).abs() < 1e-12 && (m - (2.0 - 0.5 * 2.45)).abs() < 1e-12);
    }
}
