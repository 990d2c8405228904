//! Sub-sample code phase by a band-limited matched replica: the maximum over the delay of the
//! non-coherent power of the correlation with the C/A code as a continuous waveform, limited to
//! the front end's band.
//!
//! # Why
//!
//! A replica made of the code's chips point-sampled at `t_n - tau` changes only when a chip
//! edge crosses a sample instant. At a rate that is a whole multiple of the chip rate (SnapperGPS:
//! 4.092 MHz, 4 samples a chip) every edge crosses at once, so the correlation is a staircase in
//! `tau` with steps of one sample (73 m): any fit to it sees the delay only to within a sample,
//! and how it interpolates depends on where the peak falls. The signal itself, filtered by the
//! front end before its quantiser (the noise dithers the 1-bit samples), carries the delay
//! continuously; a replica limited to the same band correlates with it smoothly.
//!
//! # Equations
//!
//! With `N = fs T` samples per code period (`T` = 1 ms, `N` whole), the code as a periodic
//! waveform starting at `t = 0` is `c(t) = sum_k C_k exp(j 2 pi k t / T)` with the Fourier
//! coefficients of 1023 rectangular chips `c_i`:
//!
//! ```text
//! C_k = (1/1023) sinc(k/1023) exp(-j pi k/1023) sum_i c_i exp(-j 2 pi k i / 1023)
//! ```
//!
//! Period `m` of the samples, carrier wiped off at the Doppler seen (`w_n`, `n = 0..N`), with
//! the DFT `D_q = sum_n w_n exp(-j 2 pi q n / N)`, correlates with the replica delayed to start
//! at sample `tau_m` as
//!
//! ```text
//! y_m(tau) = sum_n w_n c((n - tau_m) / fs) = sum_{|k| <= K} C_k D_{-k mod N} exp(-j 2 pi k tau_m / N)
//! ```
//!
//! where `K = floor(B T)` keeps the harmonics within the band `|f| <= B` (the noise outside it
//! is left out; with `B` the front end's band this is the matched filter). `tau_m = tau - m N
//! D / f_L1` follows the code Doppler `D`. The estimate maximises `P(tau) = sum_m |y_m(tau)|^2`
//! (carrier phase and data bits drop out): a grid of [`GRID_STEP_SAMPLES`] over
//! +-[`SPAN_SAMPLES`] around the start, then a golden-section search to [`TOLERANCE_SAMPLES`].

use gpsrx_dsp::constants::{CA_CODE_LENGTH, F_L1_HZ};
use gpsrx_dsp::{CaCode, Prn};
use num_complex::{Complex, Complex32, Complex64};
use rustfft::{Fft, FftPlanner};
use std::cell::RefCell;
use std::f64::consts::PI;
use std::sync::Arc;

thread_local! {
    /// One planner per thread: it keeps the plans of the lengths it made (1023 and N), which
    /// cost more to make than to run once.
    static PLANNER: RefCell<FftPlanner<f64>> = RefCell::new(FftPlanner::new());
}

/// The forward FFT of `len` points, from this thread's planner.
fn forward_fft(len: usize) -> Arc<dyn Fft<f64>> {
    PLANNER.with(|p| p.borrow_mut().plan_fft_forward(len))
}

/// Half-width of the delay searched around the start, samples.
pub const SPAN_SAMPLES: f64 = 1.0;
/// Grid step of the first pass, samples.
pub const GRID_STEP_SAMPLES: f64 = 0.25;
/// Width of the final golden-section bracket, samples.
pub const TOLERANCE_SAMPLES: f64 = 1e-3;

/// The code phase (sample index where a C/A period starts, in `[0, N)`) of `prn` near
/// `code_phase_samples` (module docs), the carrier wiped off at `dopplers_hz.0` (as seen) and
/// the code run at the rate of the satellite's Doppler `dopplers_hz.1`, with the replica
/// limited to `|f| <= band_hz`. `None` when `fs_hz` holds no whole number of samples per
/// millisecond, the band holds no harmonic or exceeds the sampling rate, or the samples hold
/// no whole period.
pub fn band_limited_code_phase(
    samples: &[Complex32],
    fs_hz: f64,
    prn: Prn,
    code_phase_samples: f64,
    dopplers_hz: (f64, f64),
    band_hz: f64,
) -> Option<f64> {
    let n_f = fs_hz * 1e-3;
    let n = n_f.round() as usize;
    if !(n_f.is_finite() && (n_f - n as f64).abs() < 1e-6 && n > 0) {
        return None;
    }
    let k_max = (band_hz * 1e-3).floor() as usize;
    if !(band_hz.is_finite() && k_max >= 1 && 2 * k_max < n && code_phase_samples.is_finite()) {
        return None;
    }
    let periods = samples.len() / n;
    if periods == 0 {
        return None;
    }
    let harmonics = code_harmonics(prn, k_max);
    let spectra = period_spectra(samples, n, periods, fs_hz, dopplers_hz.0);
    // G_{m,k} = C_k D_m[-k mod N], k = -K..=K.
    let g: Vec<Vec<Complex64>> = spectra
        .iter()
        .map(|d| {
            harmonics
                .iter()
                .enumerate()
                .map(|(i, c)| {
                    let k = i as i64 - k_max as i64;
                    c * d[(-k).rem_euclid(n as i64) as usize]
                })
                .collect()
        })
        .collect();
    let drift = -(n as f64) * dopplers_hz.1 / F_L1_HZ;
    let power = |tau: f64| -> f64 {
        g.iter()
            .enumerate()
            .map(|(m, gm)| correlation(gm, k_max, tau + m as f64 * drift, n).norm_sqr())
            .sum()
    };
    let steps = (SPAN_SAMPLES / GRID_STEP_SAMPLES).round() as i64;
    let (best, _) = (-steps..=steps)
        .map(|s| {
            let tau = code_phase_samples + s as f64 * GRID_STEP_SAMPLES;
            (tau, power(tau))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let tau = golden_max(
        &power,
        best - GRID_STEP_SAMPLES,
        best + GRID_STEP_SAMPLES,
        TOLERANCE_SAMPLES,
    );
    Some(tau.rem_euclid(n as f64))
}

/// `y(tau) = sum_k G_k exp(-j 2 pi k tau / N)`, k = -K..=K (module docs).
fn correlation(g: &[Complex64], k_max: usize, tau: f64, n: usize) -> Complex64 {
    let step = Complex64::from_polar(1.0, -2.0 * PI * tau / n as f64);
    let mut z = Complex64::from_polar(1.0, 2.0 * PI * tau * k_max as f64 / n as f64);
    let mut sum = Complex64::new(0.0, 0.0);
    for gk in g {
        sum += gk * z;
        z *= step;
    }
    sum
}

/// `C_k` for k = -K..=K (module docs).
fn code_harmonics(prn: Prn, k_max: usize) -> Vec<Complex64> {
    let len = CA_CODE_LENGTH;
    let mut a: Vec<Complex64> = CaCode::new(prn)
        .chips()
        .iter()
        .map(|&c| Complex64::new(f64::from(c), 0.0))
        .collect();
    forward_fft(len).process(&mut a);
    (0..=2 * k_max)
        .map(|i| {
            let k = i as i64 - k_max as i64;
            let x = k as f64 / len as f64;
            let sinc = if k == 0 {
                1.0
            } else {
                (PI * x).sin() / (PI * x)
            };
            let j = k.rem_euclid(len as i64) as usize;
            a[j] * Complex64::from_polar(sinc / len as f64, -PI * x)
        })
        .collect()
}

/// The DFT of each whole period of `samples` with the carrier at `doppler_hz` wiped off.
fn period_spectra(
    samples: &[Complex32],
    n: usize,
    periods: usize,
    fs_hz: f64,
    doppler_hz: f64,
) -> Vec<Vec<Complex64>> {
    let fft = forward_fft(n);
    let w = -2.0 * PI * doppler_hz / fs_hz;
    (0..periods)
        .map(|m| {
            let mut d: Vec<Complex64> = samples[m * n..(m + 1) * n]
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    let phase = w * (m * n + i) as f64;
                    Complex::new(f64::from(s.re), f64::from(s.im))
                        * Complex64::from_polar(1.0, phase)
                })
                .collect();
            fft.process(&mut d);
            d
        })
        .collect()
}

/// The maximum of a unimodal `f` on `[a, b]` by golden-section search to width `tol`.
fn golden_max(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, tol: f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > tol {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - r * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A noiseless band-limited code delayed by a fraction of a sample at 4 samples a chip
    /// (the staircase case): the estimate is the delay, whatever the fraction.
    #[test]
    fn finds_a_fractional_delay_on_a_commensurate_grid() {
        let prn = Prn::new(7).expect("prn");
        let fs = 4.092e6;
        let n = 4092;
        let band = 1.5e6;
        let k_max = 1500;
        let c = code_harmonics(prn, k_max);
        for &tau in &[100.0, 100.25, 100.5, 1234.73, 4091.9] {
            // The band-limited code starting at sample tau, 12 periods, Doppler 0.
            let one: Vec<Complex32> = (0..n)
                .map(|i| {
                    let y = correlation(&c, k_max, tau - i as f64, n);
                    Complex32::new(y.re as f32, 0.0)
                })
                .collect();
            let x: Vec<Complex32> = one.iter().cycle().take(12 * n).copied().collect();
            let est = band_limited_code_phase(&x, fs, prn, tau.round() + 0.4, (0.0, 0.0), band)
                .expect("estimate");
            let d = (est - tau + 0.5 * n as f64).rem_euclid(n as f64) - 0.5 * n as f64;
            assert!(d.abs() < 2e-3, "tau {tau}: {est} ({d})");
        }
    }
}
