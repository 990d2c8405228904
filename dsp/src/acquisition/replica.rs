//! Code replicas resampled to the sampling rate, and their spectra for FFT correlation.

use super::config::Layout;
use crate::constants::CA_CHIP_RATE_HZ;
use crate::{CaCode, Prn};
use num_complex::Complex32;
use rustfft::Fft;
use std::sync::Arc;

/// The conjugate spectrum of one PRN's replica, scaled so that the inverse FFT of
/// `X * R` is the plain correlation sum `corr[tau] = sum_n x[n] c[n - tau]`.
///
/// With a whole number L of samples per code period the replica is one period (L samples): a block
/// of M periods correlated with an L-periodic replica has a spectrum that is non-zero only on
/// every M-th bin, `C_N[M j] = M C_L[j]`, so `corr[tau] = (1/L) IDFT_L(X_N[M j] conj(C_L[j]))`.
/// Otherwise the replica covers the whole block (N samples, the last chip cut where the block
/// ends) and `corr = (1/N) IDFT_N(X_N conj(C_N))`.
pub(crate) fn replica_spectra(
    layout: &Layout,
    fs_hz: f64,
    fft: &Arc<dyn Fft<f32>>,
) -> Vec<Vec<Complex32>> {
    let n = layout.inv_len;
    let mut chips = vec![0i8; n];
    let mut scratch = vec![Complex32::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    let scale = 1.0 / n as f32;
    Prn::all()
        .map(|prn| {
            CaCode::new(prn).sample(fs_hz, CA_CHIP_RATE_HZ, 0.0, &mut chips);
            let mut spec: Vec<Complex32> = chips
                .iter()
                .map(|&c| Complex32::new(f32::from(c), 0.0))
                .collect();
            fft.process_with_scratch(&mut spec, &mut scratch);
            for v in spec.iter_mut() {
                *v = v.conj() * scale;
            }
            spec
        })
        .collect()
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
