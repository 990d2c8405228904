//! Code replicas resampled to the sampling rate, and their spectra for FFT correlation.

use super::config::Layout;
use crate::constants::CA_CHIP_RATE_HZ;
use crate::{CaCode, Prn};
use num_complex::Complex32;
use rustfft::Fft;
use std::sync::Arc;

/// The conjugate spectra of the 32 replicas in the search layout, scaled so that the inverse FFT
/// of `X * R` is the plain correlation sum `corr[tau] = sum_n x[n] c[n - tau]`; and the mean
/// `|C[k]|^2` over the 32 PRNs at every bin of the full spectrum (for the noise of a full-band
/// correlation, see [`Layout`]).
///
/// With a whole number L of samples per code period the replica is one period (L samples): a block
/// of M periods correlated with an L-periodic replica has a spectrum that is non-zero only on
/// every M-th bin, `C_N[M j] = M C_L[j]`, so `corr[tau] = (1/L) IDFT_L(X_N[M j] conj(C_L[j]))`.
/// Otherwise the replica covers the whole block (N samples, the last chip cut where the block
/// ends) and `corr = (1/N) IDFT_N(X_N conj(C_N))`.
///
/// The search layout has `inv_len` bins: the `keep_pos` lowest non-negative frequencies at the
/// start, the `keep_neg` lowest negative ones at the end, zeros between (when `inv_len` exceeds
/// the spectrum). The scale stays `1/spec_len`, so an `inv_len`-point inverse FFT gives the
/// band-limited correlation at lags `m * spec_len / inv_len` input samples.
pub(crate) fn replica_spectra(
    layout: &Layout,
    fs_hz: f64,
    fft: &Arc<dyn Fft<f32>>,
) -> (Vec<Vec<Complex32>>, Vec<f32>) {
    let n = layout.spec_len;
    let m = layout.inv_len;
    let (kp, kn) = (layout.keep_pos, layout.keep_neg);
    let mut chips = vec![0i8; n];
    let mut spec = vec![Complex32::new(0.0, 0.0); n];
    let mut scratch = vec![Complex32::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    let mut mean_power = vec![0.0f32; n];
    let scale = 1.0 / n as f32;
    let replicas = Prn::all()
        .map(|prn| {
            CaCode::new(prn).sample(fs_hz, CA_CHIP_RATE_HZ, 0.0, &mut chips);
            for (s, &c) in spec.iter_mut().zip(&chips) {
                *s = Complex32::new(f32::from(c), 0.0);
            }
            fft.process_with_scratch(&mut spec, &mut scratch);
            let mut out = vec![Complex32::new(0.0, 0.0); m];
            for (k, v) in spec.iter().enumerate() {
                let c = v.conj() * scale;
                mean_power[k] += c.norm_sqr() / 32.0;
                if k < kp {
                    out[k] = c;
                } else if k >= n - kn {
                    out[m - (n - k)] = c;
                }
            }
            out
        })
        .collect();
    (replicas, mean_power)
}

/// `exp(-j 2 pi q n / (Q N))` for `n` in the block, one vector per fractional Doppler offset
/// `q = 1..Q` (offset 0 needs no wipe-off).
pub(crate) fn fractional_wipeoffs(layout: &Layout) -> Vec<Vec<Complex32>> {
    let q_total = layout.subdivision;
    let n = layout.block_len;
    (1..q_total)
        .map(|q| {
            let cycles_per_sample = q as f64 / (q_total * n) as f64;
            (0..n)
                .map(|k| {
                    let ph = -2.0 * std::f64::consts::PI * cycles_per_sample * k as f64;
                    Complex32::new(ph.cos() as f32, ph.sin() as f32)
                })
                .collect()
        })
        .collect()
}
