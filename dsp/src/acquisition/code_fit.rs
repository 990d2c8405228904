//! Sub-sample code phase from the shape of the correlation peak: a least-squares parabola
//! through the non-coherent power at several lags around the peak, re-centred until it stays.
//!
//! The acquisition's own refinement ([`super::AcquisitionEngine`]) fits a triangle to early,
//! prompt and late correlators half a chip apart. A front end whose bandwidth is a few MHz
//! rounds the top of the triangle, so that fit is biased by up to a few hundredths of a chip
//! depending on where the peak falls between samples; when every metre counts (snapshot
//! positioning from a few milliseconds) this fit is used instead. With K one-millisecond
//! prompts `p_k(tau)` at lags `tau_j = tau_0 + j d` (j = -J..J, d = `spacing_chips`), the
//! power `P(tau_j) = (1/K) sum_k |p_k(tau_j)|^2` (data bits and carrier phase drop out) is
//! fitted by `a + b x + c x^2`, x = j d; the vertex `-b / (2c)` moves `tau_0`, and the fit is
//! repeated around the new centre ([`MAX_ITERATIONS`] at most). The noise adds the same
//! constant to every `P` and does not move the vertex; any symmetric peak (ideal triangle or
//! band-limited) has its vertex at the true delay once centred, so the estimate is unbiased to
//! first order whatever the front-end filter, and its noise is that of an early-minus-late
//! discriminator about `2 J d` wide.

use super::refine::correlate_periods;
use crate::constants::CA_CHIP_RATE_HZ;
use crate::correlator::{Correlator, PackedCode, SampleSlice, MAX_TAPS};
use crate::{CaCode, Prn};
use num_complex::{Complex32, Complex64};

/// Re-centrings of the fit at most.
pub const MAX_ITERATIONS: usize = 8;

/// Settings of [`fit_code_phase`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CodeFitOptions {
    /// Lag spacing d, chips.
    pub spacing_chips: f64,
    /// Lags either side of the centre, J (1 <= J, 2 J + 1 <= 8).
    pub half_lags: usize,
    /// Whole code periods of prompts used at most.
    pub max_periods: usize,
}

impl Default for CodeFitOptions {
    /// d = 0.15 chip, J = 2 (+-0.3 chip), up to 1000 periods (on the 60 SnapperGPS snapshots
    /// d = 0.05 to 0.3 chip with J = 2 or 3 gave median errors of 19 to 45 m, this one the
    /// least).
    fn default() -> Self {
        Self {
            spacing_chips: 0.15,
            half_lags: 2,
            max_periods: 1000,
        }
    }
}

/// The code phase (sample index where a C/A period starts, in `[0, fs 1 ms)`) refined from
/// `code_phase_samples` for `prn`, the carrier wiped off at `dopplers_hz.0` (as seen) and the
/// code run at the rate of the satellite's Doppler `dopplers_hz.1` (they differ in sign for a
/// folded real spectrum; module docs of [`super`]). `None` when
/// the samples hold no whole code period after the start, when the power is not peaked
/// (c >= 0), or when the settings are out of range.
pub fn fit_code_phase(
    samples: &[Complex32],
    fs_hz: f64,
    prn: Prn,
    code_phase_samples: f64,
    dopplers_hz: (f64, f64),
    opts: &CodeFitOptions,
) -> Option<f64> {
    let n_lags = 2 * opts.half_lags + 1;
    if opts.half_lags == 0
        || n_lags > MAX_TAPS
        || !(opts.spacing_chips > 0.0 && opts.spacing_chips < 1.0)
    {
        return None;
    }
    if !(fs_hz.is_finite() && fs_hz > 0.0 && code_phase_samples.is_finite()) {
        return None;
    }
    let correlator = Correlator::best();
    let code = PackedCode::new(CaCode::new(prn).chips());
    let period = fs_hz * 1e-3;
    let d_samples = opts.spacing_chips * fs_hz / CA_CHIP_RATE_HZ;
    let offsets: Vec<f64> = (0..n_lags)
        .map(|j| (j as f64 - opts.half_lags as f64) * d_samples)
        .collect();
    let mut out: Vec<Vec<Complex64>> = vec![Vec::new(); n_lags];
    let mut tau = code_phase_samples;
    let max_step = opts.half_lags as f64 * d_samples;
    for _ in 0..MAX_ITERATIONS {
        correlate_periods(
            SampleSlice::Cf32(samples),
            &mut Vec::new(),
            &correlator,
            &code,
            fs_hz,
            tau,
            dopplers_hz,
            opts.max_periods,
            &offsets,
            &mut out,
        );
        let k = out[0].len();
        if k == 0 {
            return None;
        }
        let power: Vec<f64> = out
            .iter()
            .map(|o| o.iter().map(|p| p.norm_sqr()).sum::<f64>() / k as f64)
            .collect();
        let step = parabola_vertex(&offsets, &power)?.clamp(-max_step, max_step);
        tau += step;
        if step.abs() < 1e-3 {
            break;
        }
    }
    Some(tau.rem_euclid(period))
}

/// Far lags (chips) at which [`peak_to_noise`] measures the noise: more than a chip from the
/// peak and from each other.
const NOISE_LAGS_CHIPS: [f64; 7] = [97.0, 211.0, 333.0, 457.0, 599.0, 733.0, 877.0];

/// Non-coherent power at `code_phase_samples` over the mean power at seven far lags (noise),
/// both from the same whole code periods (at most `max_periods`), Dopplers as in
/// [`fit_code_phase`]: about 1 on noise alone (the
/// power is a mean of K exponential terms, K periods) and `1 + T C/N0` on a signal (T = 1 ms).
/// `None` without a whole period or with zero noise.
pub fn peak_to_noise(
    samples: &[Complex32],
    fs_hz: f64,
    prn: Prn,
    code_phase_samples: f64,
    dopplers_hz: (f64, f64),
    max_periods: usize,
) -> Option<(f64, usize)> {
    let per_chip = fs_hz / CA_CHIP_RATE_HZ;
    let mut offsets = vec![0.0];
    offsets.extend(NOISE_LAGS_CHIPS.iter().map(|c| c * per_chip));
    let out = period_correlations(
        samples,
        fs_hz,
        prn,
        code_phase_samples,
        dopplers_hz,
        max_periods,
        &offsets,
    );
    let k = out[0].len();
    if k == 0 {
        return None;
    }
    let power = |o: &Vec<Complex64>| o.iter().map(|p| p.norm_sqr()).sum::<f64>() / k as f64;
    let noise = out[1..].iter().map(power).sum::<f64>() / (out.len() - 1) as f64;
    (noise > 0.0 && noise.is_finite()).then(|| (power(&out[0]) / noise, k))
}

/// The complex correlation of each whole code period (at most `max_periods`) with the code
/// starting at `code_phase_samples` plus each of `offsets_samples`, Dopplers as in
/// [`fit_code_phase`]: `out[i][m]` for offset `i` and period `m` (the same correlator as
/// [`peak_to_noise`]). At most [`MAX_TAPS`] offsets: the vectors of any further ones stay
/// empty.
pub fn period_correlations(
    samples: &[Complex32],
    fs_hz: f64,
    prn: Prn,
    code_phase_samples: f64,
    dopplers_hz: (f64, f64),
    max_periods: usize,
    offsets_samples: &[f64],
) -> Vec<Vec<Complex64>> {
    let correlator = Correlator::best();
    let code = PackedCode::new(CaCode::new(prn).chips());
    let mut out: Vec<Vec<Complex64>> = vec![Vec::new(); offsets_samples.len()];
    correlate_periods(
        SampleSlice::Cf32(samples),
        &mut Vec::new(),
        &correlator,
        &code,
        fs_hz,
        code_phase_samples,
        dopplers_hz,
        max_periods,
        offsets_samples,
        &mut out,
    );
    out
}

/// Vertex of the least-squares parabola through `(x, y)`, if it is a maximum.
fn parabola_vertex(x: &[f64], y: &[f64]) -> Option<f64> {
    // Normal equations of y = a + b x + c x^2.
    let mut s = [0.0f64; 5];
    let mut t = [0.0f64; 3];
    for (&xi, &yi) in x.iter().zip(y) {
        let mut p = 1.0;
        for (k, sk) in s.iter_mut().enumerate() {
            *sk += p;
            if k < 3 {
                t[k] += p * yi;
            }
            p *= xi;
        }
    }
    // Cramer's rule on [[s0 s1 s2] [s1 s2 s3] [s2 s3 s4]] [a b c]^T = t.
    let det3 = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let m = [[s[0], s[1], s[2]], [s[1], s[2], s[3]], [s[2], s[3], s[4]]];
    let det = det3(m);
    if det.abs() < 1e-300 || !det.is_finite() {
        return None;
    }
    let with = |col: usize| {
        let mut a = m;
        for (row, tv) in a.iter_mut().zip(t) {
            row[col] = tv;
        }
        det3(a) / det
    };
    let (b, c) = (with(1), with(2));
    (c < 0.0 && b.is_finite()).then(|| -b / (2.0 * c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_of_a_sampled_parabola() {
        let x: Vec<f64> = (-3..=3).map(|j| f64::from(j) * 0.1).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|v| 5.0 - 2.0 * (v - 0.037) * (v - 0.037))
            .collect();
        let v = parabola_vertex(&x, &y).expect("maximum");
        assert!((v - 0.037).abs() < 1e-12, "{v}");
        let up: Vec<f64> = y.iter().map(|v| -v).collect();
        assert_eq!(parabola_vertex(&x, &up), None);
    }
}
