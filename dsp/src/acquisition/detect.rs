//! Reading a search grid: peak, noise floor, peak-to-second-peak ratio and sub-cell
//! interpolation of the peak in code phase and Doppler; the cross-correlation check.

use super::wide::first_max;
use super::AcqResult;
use crate::Prn;

/// What one PRN's grid (one pass) says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Peak {
    /// Doppler row of the largest cell.
    pub row: usize,
    /// Code lag (samples) of the largest cell.
    pub lag: usize,
    /// Largest cell over its row's noise floor.
    pub metric: f64,
    /// Peak over the largest normalised cell more than one chip away (any Doppler).
    pub peak_ratio: f64,
    /// Mean of the peak's Doppler row more than one chip from the peak: `noncoherent * sigma^2`.
    pub noise_mean: f64,
    /// Interpolated code phase, samples (triangle fit to the amplitudes around the peak).
    pub lag_frac: f64,
    /// Interpolated Doppler offset from the peak row, in bins (parabola through amplitudes).
    pub row_frac: f64,
}

/// Analyses a grid of `rows` Doppler bins x `lags` code lags (row-major, non-coherent power
/// sums). `exclusion` is the half-width (lags) of the window around the peak that is left out of
/// the noise floors and of the second-peak search: one chip.
///
/// The noise floor is estimated per Doppler row (the mean of the row outside the window): a
/// narrowband interferer or a DC offset correlated with the code gives a whole row a raised,
/// flat level (the tone's correlation with a periodic code has the same magnitude at every lag),
/// which a single floor for the grid would take for a signal. Each row's mean comes from
/// thousands of cells, so its error is a fraction of a percent. The peak is the largest cell
/// relative to its row's floor.
pub(crate) fn analyse(
    grid: &[f32],
    rows: usize,
    lags: usize,
    exclusion: usize,
    floors: &mut Vec<f64>,
) -> Peak {
    // The window starts around the raw maximum; if a cell elsewhere is larger relative to its
    // row's floor (the raw maximum sat on a raised row), the window moves there once.
    let raw_max = first_max(grid).1;
    let lags = lags.max(1);
    let mut centre = raw_max % lags;
    let window = (2 * exclusion + 1).min(lags);
    let kept = (lags - window).max(1) as f64;
    let (mut peak, mut row, mut lag) = (0.0f64, 0usize, centre);
    for _ in 0..2 {
        floors.clear();
        for cells in grid.chunks_exact(lags).take(rows) {
            let total: f64 = cells.iter().map(|&v| f64::from(v)).sum();
            let inside: f64 = if window == lags {
                total
            } else {
                circular(cells, centre + lags - exclusion, window)
                    .map(|&v| f64::from(v))
                    .sum()
            };
            floors.push(((total - inside) / kept).max(f64::MIN_POSITIVE));
        }
        (peak, row, lag) = (0.0, 0, centre);
        for (r, (cells, &floor)) in grid.chunks_exact(lags).zip(floors.iter()).enumerate() {
            // The row's largest cell (the first of equals), then its ratio to the floor.
            let (v, l) = first_max(cells);
            let x = f64::from(v) / floor;
            if x > peak {
                (peak, row, lag) = (x, r, l);
            }
        }
        if circular_distance(lag, centre, lags) <= exclusion {
            break;
        }
        centre = lag;
    }
    // The largest cell more than `exclusion` lags from the peak, relative to its row's floor.
    let mut second = 0.0f64;
    if window < lags {
        for (cells, &floor) in grid.chunks_exact(lags).zip(floors.iter()) {
            let (_, v) = row_max(
                circular(cells, lag + exclusion + 1, lags - window)
                    .copied()
                    .enumerate(),
            );
            second = second.max(f64::from(v) / floor);
        }
    }
    finish(grid, lags, rows, floors, row, lag, peak, second)
}

/// `n` cells of `cells` from index `from` on, wrapping around (`from` taken modulo the length).
fn circular(cells: &[f32], from: usize, n: usize) -> impl Iterator<Item = &f32> {
    let len = cells.len();
    let from = from % len.max(1);
    let first = n.min(len - from);
    cells[from..from + first]
        .iter()
        .chain(cells[..n - first].iter())
}

/// The circular distance between lags `a` and `b` of a `lags`-long code period.
fn circular_distance(a: usize, b: usize, lags: usize) -> usize {
    let d = a.abs_diff(b);
    d.min(lags - d)
}

/// The largest value and its index (the first of equals; `(0, -inf)` when empty).
fn row_max(cells: impl Iterator<Item = (usize, f32)>) -> (usize, f32) {
    cells.fold(
        (0, f32::NEG_INFINITY),
        |b, (i, v)| if v > b.1 { (i, v) } else { b },
    )
}

#[allow(clippy::too_many_arguments)]
fn finish(
    grid: &[f32],
    lags: usize,
    rows: usize,
    floors: &[f64],
    row: usize,
    lag: usize,
    peak: f64,
    second: f64,
) -> Peak {
    // Signal amplitude above each row's floor, for interpolation.
    let amp = |r: usize, l: usize| (f64::from(grid[r * lags + l]) - floors[r]).max(0.0).sqrt();
    let a0 = amp(row, lag);
    let am = amp(row, (lag + lags - 1) % lags);
    let ap = amp(row, (lag + 1) % lags);
    let lag_frac = lag as f64 + triangle_offset(am, a0, ap);
    let row_frac = if row > 0 && row + 1 < rows {
        parabola_offset(amp(row - 1, lag), a0, amp(row + 1, lag))
    } else {
        0.0
    };
    Peak {
        row,
        lag,
        metric: peak,
        peak_ratio: if second > 0.0 {
            peak / second
        } else {
            f64::INFINITY
        },
        noise_mean: floors[row],
        lag_frac,
        row_frac,
    }
}

/// Offset in [-0.5, 0.5] of the apex of a symmetric triangle sampled at -1, 0, +1 with values
/// `m`, `c`, `p` (`c` the largest): the C/A autocorrelation is a triangle two chips wide, and
/// with more than two samples per chip all three samples lie on it. With `p >= m` the apex is
/// at `d = (p - m) / (2 (c - m))` (slopes equal: `c - m = s`, `p - m = 2 s d`).
pub(crate) fn triangle_offset(m: f64, c: f64, p: f64) -> f64 {
    let d = if p >= m {
        let den = 2.0 * (c - m);
        if den > 0.0 {
            (p - m) / den
        } else {
            0.0
        }
    } else {
        let den = 2.0 * (c - p);
        if den > 0.0 {
            (p - m) / den
        } else {
            0.0
        }
    };
    d.clamp(-0.5, 0.5)
}

/// Offset in [-0.5, 0.5] of the vertex of the parabola through (-1, m), (0, c), (1, p): the
/// Doppler response |sinc(f T)| near its peak.
pub(crate) fn parabola_offset(m: f64, c: f64, p: f64) -> f64 {
    let den = 2.0 * (2.0 * c - m - p);
    if den > 0.0 {
        ((p - m) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Marks detections that are likely cross-correlations with a stronger detection of the same
/// search, and clears their `detected` flag.
///
/// C/A codes of different PRNs cross-correlate at up to -23.9 dB (values -65/1023 and 63/1023)
/// at equal Doppler and about -21 dB at Doppler differences of whole kHz (Kaplan & Hegarty 2nd
/// ed. section 4.3.2), so a 48 dB-Hz satellite looks like a 24 to 27 dB-Hz one on other PRNs:
/// within reach of a long weak-signal search, and of any search next to an unrealistically strong
/// (60+ dB-Hz) simulated signal. Detection `j` is taken for a cross-correlation of `i` when its
/// C/N0 is at least `margin_db` below that of `i` and, when both have a refined Doppler (10 or
/// more prompts), their Dopplers differ by a whole number of kHz to within 30 Hz (the codes'
/// spectral lines are 1 kHz apart); with fewer prompts the C/N0 test alone decides.
pub(crate) fn mark_cross_correlations(results: &mut [AcqResult], margin_db: f64) {
    let strong: Vec<(Prn, f64, f64, bool)> = results
        .iter()
        .filter(|r| r.detected)
        .filter_map(|r| {
            r.cn0_dbhz
                .map(|c| (r.prn, c, r.doppler_hz, r.refine_ms >= 10))
        })
        .collect();
    for r in results.iter_mut().filter(|r| r.detected) {
        let Some(cn0) = r.cn0_dbhz else { continue };
        let refined = r.refine_ms >= 10;
        let culprit = strong
            .iter()
            .filter(|s| s.0 != r.prn && s.1 - cn0 >= margin_db)
            .find(|s| {
                let d = (r.doppler_hz - s.2 + 500.0).rem_euclid(1000.0) - 500.0;
                !(refined && s.3) || d.abs() <= 30.0
            });
        if let Some(s) = culprit {
            r.detected = false;
            r.cross_correlation_of = Some(s.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_apex_is_exact_on_a_triangle() {
        for &d in &[-0.45, -0.2, 0.0, 0.13, 0.5] {
            let tri = |x: f64| 4.0 - (x - d).abs();
            let got = triangle_offset(tri(-1.0), tri(0.0), tri(1.0));
            assert!((got - d).abs() < 1e-12, "{d} -> {got}");
        }
    }

    #[test]
    fn parabola_vertex_is_exact_on_a_parabola() {
        let d = 0.3;
        let par = |x: f64| 5.0 - (x - d) * (x - d);
        assert!((parabola_offset(par(-1.0), par(0.0), par(1.0)) - d).abs() < 1e-12);
    }

    #[test]
    fn floor_excludes_the_peak_window() {
        let (rows, lags) = (3, 100);
        let mut grid = vec![1.0f32; rows * lags];
        grid[lags + 40] = 100.0;
        grid[lags + 41] = 50.0;
        grid[2 * lags + 80] = 4.0;
        let p = analyse(&grid, rows, lags, 2, &mut Vec::new());
        assert_eq!((p.row, p.lag), (1, 40));
        assert!((p.noise_mean - 1.0).abs() < 1e-9);
        assert!((p.peak_ratio - 100.0 / (4.0 / (1.0 + 3.0 / 95.0))).abs() < 1e-9);
        assert!(p.lag_frac > 40.0 && p.lag_frac < 40.5);
    }
}
