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
/// Otherwise the replica covers the whole block (N = M P samples, P = fs x 1 ms not whole): the
/// samples of the 1 ms-periodic code are a sum of tones at whole kHz, which fall on the signed
/// bins `M j` of the N-point spectrum (exactly when M P is a whole number, to within
/// `M |N - M P| j / N` bins otherwise: 0.06 bin at 2 MHz with 10 ms at 16.3676 MHz), so
/// `corr(tau) = (1/N) sum_j X_N[M j] conj(C_N[M j]) exp(j 2 pi j tau M / N)` is again a one-period
/// inverse FFT (j signed, the same decimated bins as the blocks', see
/// [`Layout::decimated_bin`]). (Before: the correlation of the whole N-point spectrum, an
/// inverse FFT M times longer for the same lags.)
///
/// The search layout has `inv_len` bins: the `keep_pos` lowest non-negative frequencies at the
/// start, the `keep_neg` lowest negative ones at the end, zeros between (when `inv_len` exceeds
/// the spectrum). The scale stays `1/spec_len`, so an `inv_len`-point inverse FFT gives the
/// band-limited correlation at lags `m * spec_len / inv_len` input samples.
pub(crate) fn replica_spectra(layout: &Layout, fs_hz: f64, fft: &Arc<dyn Fft<f32>>) -> ReplicaSet {
    let n = layout.spec_len;
    let len = layout.replica_len;
    let d = if len == n { 1 } else { layout.decimation };
    let m = layout.inv_len;
    let (kp, kn) = (layout.keep_pos, layout.keep_neg);
    let mut chips = vec![0i8; len];
    let mut spec = vec![Complex32::new(0.0, 0.0); len];
    let mut scratch = vec![Complex32::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    let mut mean_power = vec![0.0f32; n];
    let scale = 1.0 / len as f32;
    let spectra = Prn::all()
        .map(|prn| {
            CaCode::new(prn).sample(fs_hz, CA_CHIP_RATE_HZ, 0.0, &mut chips);
            for (s, &c) in spec.iter_mut().zip(&chips) {
                *s = Complex32::new(f32::from(c), 0.0);
            }
            fft.process_with_scratch(&mut spec, &mut scratch);
            let mut out = vec![Complex32::new(0.0, 0.0); m];
            for k in 0..n {
                let v = spec[layout.decimated_bin(k, 0, d, len)];
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
    ReplicaSet {
        spectra,
        power: mean_power,
        key: ReplicaKey::of(layout, fs_hz),
    }
}

/// The replica spectra of the 32 PRNs in one search layout ([`replica_spectra`]), shared by
/// the engines whose layouts give the same ones ([`ReplicaKey`]).
#[derive(Debug)]
pub(crate) struct ReplicaSet {
    /// Per PRN (index 0 = PRN 1), `inv_len` bins.
    pub(crate) spectra: Vec<Vec<Complex32>>,
    /// Mean `|C[k]|^2` of the 32 replicas over the whole block spectrum (`spec_len` bins).
    pub(crate) power: Vec<f32>,
    key: ReplicaKey,
}

impl ReplicaSet {
    /// Whether `layout` at `fs_hz` has these replica spectra.
    pub(crate) fn fits(&self, layout: &Layout, fs_hz: f64) -> bool {
        self.key == ReplicaKey::of(layout, fs_hz)
    }
}

/// What the replica spectra of a layout depend on: the rate, the decimated spectrum and
/// replica lengths (with the decimation when the replica spans the whole block), and the
/// search length with its kept bins. The coherent integration, the blocks and the Doppler
/// range do not enter when a code period is a whole number of samples, so every level of a
/// background search at such a rate has the same replicas.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ReplicaKey {
    fs_hz: f64,
    spec_len: usize,
    replica_len: usize,
    decimation: usize,
    inv_len: usize,
    keep_pos: usize,
    keep_neg: usize,
}

impl ReplicaKey {
    fn of(layout: &Layout, fs_hz: f64) -> Self {
        Self {
            fs_hz,
            spec_len: layout.spec_len,
            replica_len: layout.replica_len,
            decimation: if layout.replica_len == layout.spec_len {
                1
            } else {
                layout.decimation
            },
            inv_len: layout.inv_len,
            keep_pos: layout.keep_pos,
            keep_neg: layout.keep_neg,
        }
    }
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
