//! After a detection: 1-ms prompt correlations aligned to the code periods, the fine Doppler from
//! their squares, and the C/N0 from their power.
//!
//! The prompts start where a C/A period starts, so every data-bit edge (IS-GPS-200: bits are 20
//! whole code periods) falls between two prompts, never inside one. Squaring a prompt removes the
//! BPSK data (`d^2 = 1`), leaving a tone at twice the residual Doppler that can be integrated
//! coherently over the whole record whatever the bit pattern.
//!
//! The code phase is then refined by early, prompt and late correlators half a chip apart
//! (a triangle fit to their amplitudes), and the C/N0 is taken at the apex of that triangle.

use crate::constants::{CA_CHIP_RATE_HZ, CA_CODE_LENGTH, F_L1_HZ};
use crate::correlator::{Correlator, PackedCode, ReplicaState, SampleSlice, MAX_TAPS};
use num_complex::{Complex32, Complex64};
use rustfft::Fft;
use std::sync::Arc;

/// Correlations over whole code periods `k = 0..k_max` starting at `code_phase_samples`:
/// `p_k = sum_n x[n] c(n - offset) exp(-j 2 pi f n / fs)`, one output per `offsets_samples`
/// entry (0 = prompt; +-d = late/early replicas), the carrier wiped off at `dopplers_hz.0` and
/// the code run at the rate of the carrier Doppler `dopplers_hz.1` (code Doppler = carrier
/// Doppler / 1540; the two differ for real samples whose spectrum is folded around 0 Hz,
/// IF = k fs, where a satellite at Doppler D may be seen at -D while its code still runs at
/// 1.023 MHz (1 + D / f_L1)). Stops where the samples end.
///
/// Each period is one call of the tracking loops' block correlator (`correlator`: SIMD where the
/// CPU has it, f32 arithmetic, the carrier seeded exactly in f64 at the first sample of every
/// period and the code from a 2^-32-chip NCO), so the cost per sample is the same at any rate.
///
/// `samples` are read as held: in place when complex f32, else converted one period at a time
/// into `buf` (the same f32 values, so the same correlations).
#[allow(clippy::too_many_arguments)]
pub(crate) fn correlate_periods(
    samples: SampleSlice<'_>,
    buf: &mut Vec<Complex32>,
    correlator: &Correlator,
    code: &PackedCode,
    fs_hz: f64,
    code_phase_samples: f64,
    dopplers_hz: (f64, f64),
    k_max: usize,
    offsets_samples: &[f64],
    out: &mut [Vec<Complex64>],
) {
    out.iter_mut().for_each(Vec::clear);
    let (doppler_hz, code_doppler_hz) = dopplers_hz;
    let chip_rate = CA_CHIP_RATE_HZ * (1.0 + code_doppler_hz / F_L1_HZ);
    let chips_per_sample = chip_rate / fs_hz;
    let period = CA_CODE_LENGTH as f64 / chips_per_sample;
    let tau = code_phase_samples.rem_euclid(period);
    let cycles_per_sample = doppler_hz / fs_hz;
    // A replica delayed by `o` samples reads the chip `o * chips_per_sample` earlier.
    let mut taps = [0.0f64; MAX_TAPS];
    let n_taps = offsets_samples.len().min(MAX_TAPS).min(out.len());
    for (t, o) in taps.iter_mut().zip(offsets_samples) {
        *t = -o * chips_per_sample;
    }
    let mut acc = [Complex32::new(0.0, 0.0); MAX_TAPS];
    for k in 0..k_max {
        let start = tau + k as f64 * period;
        let n0 = start.ceil() as usize;
        let n1 = (start + period).ceil() as usize;
        if n1 > samples.len() {
            break;
        }
        let state = ReplicaState {
            code_phase_chips: (n0 as f64 - start) * chips_per_sample,
            code_rate_chips_s: chip_rate,
            carrier_phase_cycles: (cycles_per_sample * n0 as f64).rem_euclid(1.0),
            carrier_freq_hz: doppler_hz,
            carrier_rate_hz_s: 0.0,
        };
        let held = super::input::span_cf32(samples, n0, n1, buf);
        correlator.correlate_packed(
            SampleSlice::Cf32(held),
            fs_hz,
            code,
            &state,
            &taps[..n_taps],
            &mut acc[..n_taps],
        );
        for (o, a) in out.iter_mut().zip(&acc[..n_taps]) {
            o.push(Complex64::new(f64::from(a.re), f64::from(a.im)));
        }
    }
}

/// Signal amplitude of correlations whose noise variance is `noise_var`, by power minus noise:
/// `sqrt(max(mean |p|^2 - sigma^2, 0))`.
pub(crate) fn amplitude(corr: &[Complex64], noise_var: f64) -> f64 {
    if corr.is_empty() {
        return 0.0;
    }
    let p = corr.iter().map(|p| p.norm_sqr()).sum::<f64>() / corr.len() as f64;
    (p - noise_var).max(0.0).sqrt()
}

/// Residual Doppler (Hz) of `prompts` spaced `t_p` seconds apart, from the zero-padded FFT of
/// their squares (a tone at twice the residual, data bits removed) with a parabola through the
/// magnitudes at the peak. Only offsets up to `max_dev_hz` (< 1/(4 t_p)) are considered.
/// `None` when fewer than two prompts or when the peak does not stand out of the squared
/// spectrum (peak/mean power below `min(10, K/3)`, K prompts: a pure tone gives K).
pub(crate) fn fine_doppler(
    prompts: &[Complex64],
    t_p: f64,
    max_dev_hz: f64,
    fft: &Arc<dyn Fft<f32>>,
    buf: &mut [Complex32],
    scratch: &mut [Complex32],
) -> Option<f64> {
    let k = prompts.len();
    let f = buf.len();
    if k < 2 || k > f {
        return None;
    }
    // Normalise so that f32 keeps the dynamic range whatever the input units.
    let scale = prompts.iter().map(|p| p.norm_sqr()).sum::<f64>() / k as f64;
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    buf.fill(Complex32::new(0.0, 0.0));
    for (b, p) in buf.iter_mut().zip(prompts) {
        let z = p * p / scale;
        *b = Complex32::new(z.re as f32, z.im as f32);
    }
    fft.process_with_scratch(buf, scratch);
    let bin_hz = 1.0 / (f as f64 * t_p); // of the doubled frequency
    let max_bins = ((2.0 * max_dev_hz / bin_hz).floor() as usize).min(f / 2 - 1);
    let idx = |m: i64| m.rem_euclid(f as i64) as usize;
    let (mut best, mut best_m) = (f32::NEG_INFINITY, 0i64);
    for m in -(max_bins as i64)..=(max_bins as i64) {
        let v = buf[idx(m)].norm_sqr();
        if v > best {
            best = v;
            best_m = m;
        }
    }
    let mean = buf.iter().map(|v| f64::from(v.norm_sqr())).sum::<f64>() / f as f64;
    if f64::from(best) < mean * (k as f64 / 3.0).min(10.0) {
        return None;
    }
    let mag = |m: i64| f64::from(buf[idx(m)].norm());
    let d = super::detect::parabola_offset(mag(best_m - 1), mag(best_m), mag(best_m + 1));
    Some((best_m as f64 + d) * bin_hz / 2.0)
}

/// C/N0 (dB-Hz) from the signal amplitude `amp` of correlations over `t_p` seconds whose noise
/// variance is `noise_var` (known from the search grid's floor):
/// `C/N0 = amp^2 / (sigma^2 t_p)` (a correlation with amplitude A per sample over L samples has
/// |p|^2 = L^2 A^2 against noise L sigma_x^2, and C/N0 = A^2 fs / sigma_x^2). With `amp` from
/// [`amplitude`] this is the "power minus noise" estimator, insensitive to data bits and to the
/// carrier phase. `None` when the amplitude is not positive.
pub(crate) fn cn0_dbhz(amp: f64, noise_var: f64, t_p: f64) -> Option<f64> {
    (amp > 0.0 && noise_var > 0.0 && t_p > 0.0)
        .then(|| 10.0 * (amp * amp / (noise_var * t_p)).log10())
        .filter(|c| c.is_finite())
}
