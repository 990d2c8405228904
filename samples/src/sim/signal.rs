//! The sample kernel: one satellite's spread, data-modulated carrier added to a block of samples.
//!
//! Between two nodes (one code period apart) the code phase and carrier phase advance linearly,
//! starting exactly at the values the propagation model gives at the first node and ending within
//! rounding of those at the next. The residual is the curvature of the phase over one interval:
//! `|a| T^2 / (8 lambda)` cycles for a line-of-sight acceleration `a` and node spacing `T`, i.e.
//! 6.5e-5 cycle (0.02 deg) at 10 g and 1 ms: far below thermal noise.
//!
//! Phases are fixed point: code phase in 2^-32 chip, carrier phase in 2^-32 cycle, so the
//! per-sample work is two integer additions, two table look-ups and a complex multiply-add.

use gpsrx_dsp::nco::{cycles_to_fixed, SinCosTable};
use num_complex::Complex32;

/// Chips per navigation data bit (20 code periods of 1023 chips).
pub const CHIPS_PER_BIT: f64 = 20.0 * 1023.0;

const FIX: f64 = 4_294_967_296.0;

/// Linear code and carrier phase over a block of samples.
#[derive(Debug, Clone, Copy)]
pub struct PhaseRamp {
    /// Code phase at the first sample, chips from the reference bit boundary (>= 0).
    pub chips0: f64,
    /// Code phase advance per sample, chips.
    pub chips_per_sample: f64,
    /// Carrier phase at the first sample, cycles.
    pub cycles0: f64,
    /// Carrier phase advance per sample, cycles.
    pub cycles_per_sample: f64,
}

/// Adds `amplitude * d(t) * c(t) * exp(j 2 pi phi(t))` to `out`, where `c` is the code (given
/// three times over in `code3`, +1/-1) and `d` the data bits (`bits[i]` for chips
/// `i*20460 .. (i+1)*20460`; bits past the end count as +1).
pub fn add_signal(
    out: &mut [Complex32],
    ramp: &PhaseRamp,
    code3: &[i8],
    bits: &[i8],
    amplitude: f32,
    table: &SinCosTable,
) {
    let n = out.len();
    let mut k = 0usize;
    let code_step = (ramp.chips_per_sample * FIX).round() as u64;
    let carrier_step = cycles_to_fixed(ramp.cycles_per_sample);
    while k < n {
        let c = ramp.chips0 + k as f64 * ramp.chips_per_sample;
        let bit_index = (c / CHIPS_PER_BIT).floor().max(0.0) as usize;
        let next_edge = (bit_index as f64 + 1.0) * CHIPS_PER_BIT;
        let run = (((next_edge - c) / ramp.chips_per_sample).ceil() as usize).clamp(1, n - k);
        let sign = f32::from(bits.get(bit_index).copied().unwrap_or(1));
        let a = amplitude * sign;
        let period_start = (c / 1023.0).floor() * 1023.0;
        let mut code_phase = ((c - period_start) * FIX) as u64;
        let mut carrier = cycles_to_fixed(ramp.cycles0 + k as f64 * ramp.cycles_per_sample);
        for s in &mut out[k..k + run] {
            let chip = f32::from(code3[(code_phase >> 32) as usize]);
            let rot = table.lookup(carrier);
            let v = a * chip;
            s.re += v * rot.re;
            s.im += v * rot.im;
            code_phase += code_step;
            carrier = carrier.wrapping_add(carrier_step);
        }
        k += run;
    }
}

/// The code of one satellite three times over, so a block of up to two code periods can be read
/// without wrapping.
pub fn triple_code(chips: &[i8; 1023]) -> Vec<i8> {
    let mut v = Vec::with_capacity(3 * 1023);
    for _ in 0..3 {
        v.extend_from_slice(chips);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_dsp::{CaCode, Prn};

    #[test]
    fn kernel_matches_a_direct_evaluation() {
        let code = CaCode::new(Prn::new(5).unwrap_or_else(|e| panic!("{e}")));
        let code3 = triple_code(code.chips());
        let bits = vec![1i8, -1, 1];
        let fs = 4.0e6;
        let ramp = PhaseRamp {
            chips0: 20460.0 - 300.3,
            chips_per_sample: 1.023e6 * (1.0 + 2e-6) / fs,
            cycles0: 0.123,
            cycles_per_sample: 1234.5 / fs,
        };
        let mut out = vec![Complex32::new(0.0, 0.0); 4000];
        let table = SinCosTable::new(12);
        add_signal(&mut out, &ramp, &code3, &bits, 2.0, &table);
        let mut max_err = 0.0f64;
        let mut mismatched_chips = 0;
        for (k, s) in out.iter().enumerate() {
            let c = ramp.chips0 + k as f64 * ramp.chips_per_sample;
            let bit = bits[(c / CHIPS_PER_BIT) as usize];
            let chip = code.chip(c as usize % 1023);
            let ph =
                2.0 * std::f64::consts::PI * (ramp.cycles0 + k as f64 * ramp.cycles_per_sample);
            let v = 2.0 * f64::from(bit) * f64::from(chip);
            let e = ((f64::from(s.re) - v * ph.cos()).powi(2)
                + (f64::from(s.im) - v * ph.sin()).powi(2))
            .sqrt();
            if e > 0.1 {
                mismatched_chips += 1; // a sample on a chip edge may round to the neighbour
            } else {
                max_err = max_err.max(e);
            }
        }
        assert!(
            mismatched_chips <= 2,
            "{mismatched_chips} samples with the wrong chip or bit"
        );
        // Table of 4096: half a bin is pi/4096 rad, times the amplitude 2.
        assert!(
            max_err < 2.0 * std::f64::consts::PI / 4096.0 + 1e-5,
            "{max_err}"
        );
    }
}
