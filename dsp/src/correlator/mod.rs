//! Block correlators: carrier wipe-off and accumulation against N code replicas in one pass.
//!
//! For a block of complex baseband samples `x[k]`, `k = 0..n`, sampled at `fs`, and a replica
//! with code phase `c(k) = c0 + k * rc / fs` (chips) and carrier phase
//! `phi(k) = phi0 + k f / fs + k^2 fdot / (2 fs^2)` (cycles), tap `i` at code offset `delta_i`
//! chips accumulates
//!
//! `C_i = sum_k x[k] * exp(-j 2 pi phi(k)) * code(c(k) + delta_i)`.
//!
//! This is the scalar reference kernel (fixed-point NCOs: carrier phase in 2^-32 cycle with a
//! 4096-entry table, code phase in 2^-32 chip); the SIMD kernels of the performance work must
//! agree with it.

use crate::constants::CA_CODE_LENGTH;
use crate::nco::{cycles_to_fixed, SinCosTable};
use num_complex::Complex32;
use std::sync::OnceLock;

const FIX: f64 = 4_294_967_296.0;

/// The replica's code and carrier state at the first sample of a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplicaState {
    /// Code phase at the first sample, chips (any real; reduced modulo 1023).
    pub code_phase_chips: f64,
    /// Code rate, chips per second (1.023e6 plus code Doppler).
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

fn table() -> &'static SinCosTable {
    static TABLE: OnceLock<SinCosTable> = OnceLock::new();
    TABLE.get_or_init(|| SinCosTable::new(12))
}

/// Correlates `samples` with the replica of `code` (+1/-1 chips) described by `state`, one
/// accumulation per entry of `tap_offsets_chips`, written to `out` (same length).
///
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
    let table = table();
    let n_code = CA_CODE_LENGTH as f64;
    let code_step = (state.code_rate_chips_s / fs_hz * FIX).round() as u64;
    let code_len_fix = (CA_CODE_LENGTH as u64) << 32;
    // Carrier: second-order fixed-point accumulator. The phase step is kept in 2^-32 cycle per
    // sample as i64 so that it can ramp.
    let step0 = state.carrier_freq_hz / fs_hz;
    let dstep = state.carrier_rate_hz_s / (fs_hz * fs_hz);
    let mut carrier = cycles_to_fixed(-state.carrier_phase_cycles);
    // Wipe-off multiplies by exp(-j 2 pi phi): run the accumulator at the negated frequency.
    // The phase increment between samples k and k+1 is step0 + dstep (k + 1/2).
    let mut step = (-(step0 + 0.5 * dstep) * FIX).round() as i64;
    let dstep_fix = (-dstep * FIX).round() as i64;
    let mut phases: Vec<u64> = tap_offsets_chips
        .iter()
        .map(|d| ((state.code_phase_chips + d).rem_euclid(n_code) * FIX) as u64)
        .collect();
    let mut acc = vec![Complex32::new(0.0, 0.0); out.len()];
    for &x in samples {
        let rot = table.lookup(carrier);
        let w = x * rot;
        for (p, a) in phases.iter_mut().zip(acc.iter_mut()) {
            let chip = f32::from(code[(*p >> 32) as usize]);
            *a += w * chip;
            *p += code_step;
            if *p >= code_len_fix {
                *p -= code_len_fix;
            }
        }
        carrier = carrier.wrapping_add(step as u32);
        step += dstep_fix;
    }
    out.copy_from_slice(&acc);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ca_code::{CaCode, Prn};
    use rand::{Rng, SeedableRng};

    /// f64 reference: the definition in the module doc, evaluated directly.
    fn reference(
        samples: &[Complex32],
        fs: f64,
        code: &CaCode,
        s: &ReplicaState,
        taps: &[f64],
    ) -> Vec<(f64, f64)> {
        taps.iter()
            .map(|d| {
                let (mut re, mut im) = (0.0, 0.0);
                for (k, x) in samples.iter().enumerate() {
                    let k = k as f64;
                    let t = k / fs;
                    let ph = s.carrier_phase_cycles
                        + s.carrier_freq_hz * t
                        + 0.5 * s.carrier_rate_hz_s * t * t;
                    let ang = -2.0 * std::f64::consts::PI * ph;
                    let c = f64::from(code.chip(
                        ((s.code_phase_chips + d + s.code_rate_chips_s * t).rem_euclid(1023.0))
                            as usize,
                    ));
                    let (xr, xi) = (f64::from(x.re), f64::from(x.im));
                    re += c * (xr * ang.cos() - xi * ang.sin());
                    im += c * (xr * ang.sin() + xi * ang.cos());
                }
                (re, im)
            })
            .collect()
    }

    #[test]
    fn matches_the_f64_reference_on_random_input() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let code = CaCode::new(Prn::new(12).unwrap_or_else(|e| panic!("{e}")));
        for &n in &[1usize, 7, 1000, 4093] {
            let x: Vec<Complex32> = (0..n)
                .map(|_| Complex32::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)))
                .collect();
            let s = ReplicaState {
                code_phase_chips: rng.random_range(0.0..1023.0),
                code_rate_chips_s: 1.023e6 + rng.random_range(-5.0..5.0),
                carrier_phase_cycles: rng.random_range(0.0..1.0),
                carrier_freq_hz: rng.random_range(-5000.0..5000.0),
                carrier_rate_hz_s: rng.random_range(-2000.0..2000.0),
            };
            let taps = [-0.5, 0.0, 0.5];
            let mut out = [Complex32::new(0.0, 0.0); 3];
            correlate(&x, 4.0e6, code.chips(), &s, &taps, &mut out);
            let r = reference(&x, 4.0e6, &code, &s, &taps);
            for (o, (re, im)) in out.iter().zip(r) {
                // Error budget: table phase error <= pi/4096 rad per sample (random sign) plus
                // f32 accumulation; bound |err| <= 2e-3 * sqrt(n) * rms|x| + rare chip-edge
                // disagreements (fixed vs f64 code phase), each worth at most 2|x| <= 2.9.
                let err = ((f64::from(o.re) - re).powi(2) + (f64::from(o.im) - im).powi(2)).sqrt();
                assert!(err < 2e-3 * (n as f64).sqrt() + 6.0, "n {n}: err {err}");
            }
        }
    }

    #[test]
    fn aligned_replica_collects_all_the_signal() {
        // A noise-free signal equal to the replica gives |P| = n; early/late at +-0.5 chip give
        // about n/2 (triangle correlation at 4 samples per chip).
        let code = CaCode::new(Prn::new(1).unwrap_or_else(|e| panic!("{e}")));
        let fs = 4.092e6;
        let s = ReplicaState {
            code_phase_chips: 100.25,
            code_rate_chips_s: 1.023e6,
            carrier_phase_cycles: 0.3,
            carrier_freq_hz: 1234.0,
            carrier_rate_hz_s: 0.0,
        };
        let n = 4092;
        let x: Vec<Complex32> = (0..n)
            .map(|k| {
                let t = k as f64 / fs;
                let ph = 2.0 * std::f64::consts::PI * (0.3 + 1234.0 * t);
                let c = f64::from(code.chip(((100.25 + 1.023e6 * t) % 1023.0) as usize));
                Complex32::new((c * ph.cos()) as f32, (c * ph.sin()) as f32)
            })
            .collect();
        let mut out = [Complex32::new(0.0, 0.0); 3];
        correlate(&x, fs, code.chips(), &s, &[-0.5, 0.0, 0.5], &mut out);
        assert!(
            (out[1].norm() / n as f32 - 1.0).abs() < 2e-3,
            "{}",
            out[1].norm()
        );
        assert!(out[1].arg().abs() < 2e-3);
        for e in [out[0], out[2]] {
            assert!(
                (e.norm() / n as f32 - 0.5).abs() < 0.01,
                "{}",
                e.norm() / n as f32
            );
        }
    }

    #[test]
    fn advancing_the_state_is_consistent_with_correlating_in_two_halves() {
        let code = CaCode::new(Prn::new(7).unwrap_or_else(|e| panic!("{e}")));
        let mut rng = rand::rngs::StdRng::seed_from_u64(9);
        let x: Vec<Complex32> = (0..2000)
            .map(|_| Complex32::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)))
            .collect();
        let s = ReplicaState {
            code_phase_chips: 5.0,
            code_rate_chips_s: 1.023e6,
            carrier_phase_cycles: 0.1,
            carrier_freq_hz: 700.0,
            carrier_rate_hz_s: 300.0,
        };
        let mut whole = [Complex32::new(0.0, 0.0)];
        correlate(&x, 2.0e6, code.chips(), &s, &[0.0], &mut whole);
        let (mut a, mut b) = ([Complex32::new(0.0, 0.0)], [Complex32::new(0.0, 0.0)]);
        correlate(&x[..1000], 2.0e6, code.chips(), &s, &[0.0], &mut a);
        correlate(
            &x[1000..],
            2.0e6,
            code.chips(),
            &s.advanced(1000, 2.0e6),
            &[0.0],
            &mut b,
        );
        assert!(
            (whole[0] - (a[0] + b[0])).norm() < 0.5,
            "{} vs {}",
            whole[0],
            a[0] + b[0]
        );
    }
}
