//! Block correlators: carrier wipe-off and accumulation against N code replicas in one pass.
//!
//! For a block of complex baseband samples `x[k]`, `k = 0..n`, sampled at `fs`, and a replica
//! with code phase `c(k) = c0 + k * rc / fs` (chips) and carrier phase
//! `phi(k) = phi0 + k f / fs + k^2 fdot / (2 fs^2)` (cycles), tap `i` at code offset `delta_i`
//! chips accumulates
//!
//! `C_i = sum_k x[k] * exp(-j 2 pi phi(k)) * code(c(k) + delta_i)`.
//!
//! Two ways in:
//! - [`correlate`], the scalar reference kernel on `Complex32` samples (fixed-point NCOs: carrier
//!   phase in 2^-48 cycle with a 4096-entry table, code phase in 2^-32 chip).
//! - [`Correlator`], a kernel chosen at run time ([`Isa`] x [`Arithmetic`]) that reads ci8, ci16
//!   or cf32 samples directly ([`SampleSlice`]). The SIMD kernels (AVX2+FMA, AVX-512) generate
//!   the carrier with a vectorised rotator seeded exactly (f64) at the start of every call and
//!   every 256 vector steps, and the code replicas from a bit-packed code ([`PackedCode`]) with
//!   the same 2^-32-chip code NCO as the reference, so their chips agree with it exactly. The
//!   int16 kernels on ci8 and ci16 work in 16-bit lanes (`vpmulhrsw` wipe-off, ci16 scaled by
//!   the block's headroom; the code looked up with `vpshufb` from a byte per chip): 16 samples
//!   per step with AVX2, 32 with AVX-512 VNNI (`vpdpwssd`), about twice the speed of the f32
//!   kernels ([`Arithmetic::Auto`] takes them on ci8 and ci16).
//!
//! Build a [`Correlator`] once (e.g. [`Correlator::best`]) and a [`PackedCode`] once per PRN,
//! then call [`Correlator::correlate_packed`] per block: it allocates nothing.

mod kernel;
mod packed;
mod plan;
mod scalar;
#[cfg(target_arch = "x86_64")]
mod simd;

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
mod avx2_i16;
#[cfg(target_arch = "x86_64")]
mod avx512;
#[cfg(target_arch = "x86_64")]
mod avx512_i16;
#[cfg(target_arch = "x86_64")]
mod int16_lanes;

#[cfg(test)]
mod kernel_tests;
#[cfg(test)]
mod tests;

pub use kernel::{Arithmetic, Correlator, Isa, SampleSlice};
pub use packed::PackedCode;

use crate::constants::CA_CODE_LENGTH;
use num_complex::Complex32;

/// The most taps one kernel pass accumulates; [`Correlator::correlate`] and [`correlate`]
/// process more taps in chunks of this many (one more pass over the samples per chunk).
pub const MAX_TAPS: usize = 8;

/// The replica's code and carrier state at the first sample of a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplicaState {
    /// Code phase at the first sample, chips (any real; reduced modulo 1023).
    pub code_phase_chips: f64,
    /// Code rate, chips per second (1.023e6 plus code Doppler; must be >= 0).
    pub code_rate_chips_s: f64,
    /// Carrier phase at the first sample, cycles.
    pub carrier_phase_cycles: f64,
    /// Carrier frequency at the first sample, Hz (IF + Doppler).
    pub carrier_freq_hz: f64,
    /// Carrier frequency rate over the block, Hz/s (0 for a constant frequency).
    pub carrier_rate_hz_s: f64,
}

impl ReplicaState {
    /// The state `n` samples later (phases advanced, frequency ramped).
    pub fn advanced(&self, n: usize, fs_hz: f64) -> ReplicaState {
        let t = n as f64 / fs_hz;
        ReplicaState {
            code_phase_chips: (self.code_phase_chips + self.code_rate_chips_s * t)
                .rem_euclid(CA_CODE_LENGTH as f64),
            carrier_phase_cycles: (self.carrier_phase_cycles
                + self.carrier_freq_hz * t
                + 0.5 * self.carrier_rate_hz_s * t * t)
                .rem_euclid(1.0),
            carrier_freq_hz: self.carrier_freq_hz + self.carrier_rate_hz_s * t,
            ..*self
        }
    }
}

/// Correlates `samples` with the replica of `code` (+1/-1 chips) described by `state`, one
/// accumulation per entry of `tap_offsets_chips`, written to `out` (same length).
///
/// The scalar reference kernel: a table carrier (phase error <= 1/8192 cycle) and the 2^-32-chip
/// code NCO. Allocates nothing; more than [`MAX_TAPS`] taps are processed in chunks.
/// A meaningless block description (`fs_hz` not finite and positive, a non-finite state or tap
/// offset) writes NaN to every output.
/// Panics only if `out.len() != tap_offsets_chips.len()` (a programming error, not user input).
pub fn correlate(
    samples: &[Complex32],
    fs_hz: f64,
    code: &[i8; CA_CODE_LENGTH],
    state: &ReplicaState,
    tap_offsets_chips: &[f64],
    out: &mut [Complex32],
) {
    assert_eq!(out.len(), tap_offsets_chips.len(), "one output per tap");
    if !is_meaningful(fs_hz, state, tap_offsets_chips) {
        out.fill(Complex32::new(f32::NAN, f32::NAN));
        return;
    }
    for (taps, out) in tap_offsets_chips
        .chunks(MAX_TAPS)
        .zip(out.chunks_mut(MAX_TAPS))
    {
        scalar::correlate_f32(samples, fs_hz, code, state, taps, out);
    }
}

/// Whether `fs_hz` is finite and positive and the state and tap offsets are finite.
fn is_meaningful(fs_hz: f64, state: &ReplicaState, taps: &[f64]) -> bool {
    fs_hz.is_finite()
        && fs_hz > 0.0
        && [
            state.code_phase_chips,
            state.code_rate_chips_s,
            state.carrier_phase_cycles,
            state.carrier_freq_hz,
            state.carrier_rate_hz_s,
        ]
        .iter()
        .chain(taps)
        .all(|v| v.is_finite())
}
