//! Numerically controlled oscillators.
//!
//! A [`PhaseAccumulator`] holds a phase in units of 2^-32 cycle and advances it by a fixed step
//! every sample: `phase[k+1] = phase[k] + step (mod 2^32)`, so its frequency resolution is
//! `fs / 2^32` and it never drifts: the phase after `n` samples is exactly `phase0 + n * step`.
//! A [`SinCosTable`] turns the top bits of that phase into `exp(j 2 pi phase)`.

use num_complex::Complex32;

/// One cycle in phase-accumulator units.
const CYCLE: f64 = 4_294_967_296.0; // 2^32

/// A fixed-point phase accumulator: 32 fractional bits of a cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PhaseAccumulator {
    /// Current phase, units of 2^-32 cycle.
    pub phase: u32,
    /// Phase step per sample, units of 2^-32 cycle (two's complement for negative frequencies).
    pub step: u32,
}

impl PhaseAccumulator {
    /// An oscillator at `phase_cycles` (any real, reduced modulo 1) running at `freq_hz` when
    /// sampled at `fs_hz`.
    pub fn new(phase_cycles: f64, freq_hz: f64, fs_hz: f64) -> Self {
        Self {
            phase: cycles_to_fixed(phase_cycles),
            step: cycles_to_fixed(freq_hz / fs_hz),
        }
    }

    /// The current phase in cycles, in [0, 1).
    pub fn phase_cycles(&self) -> f64 {
        f64::from(self.phase) / CYCLE
    }

    /// Advances by one sample and returns the phase before the step.
    #[inline(always)]
    pub fn next_phase(&mut self) -> u32 {
        let p = self.phase;
        self.phase = self.phase.wrapping_add(self.step);
        p
    }
}

/// Converts a phase in cycles to 2^-32-cycle units, modulo one cycle.
pub fn cycles_to_fixed(cycles: f64) -> u32 {
    let frac = cycles - cycles.floor();
    // frac is in [0, 1]; the product can round up to exactly 2^32, which wraps to 0 as it should.
    ((frac * CYCLE) as u64 & 0xFFFF_FFFF) as u32
}

/// A table of `exp(j 2 pi i / N)` for `N = 2^bits`, indexed by the top `bits` of a
/// [`PhaseAccumulator`] phase. The worst-case phase error is `1/(2N)` cycle (from truncation of the
/// index: the table samples the centre of each bin, so the error is at most half a bin).
#[derive(Debug, Clone)]
pub struct SinCosTable {
    shift: u32,
    table: Vec<Complex32>,
}

impl SinCosTable {
    /// A table with `2^bits` entries (`bits` in 4..=16).
    pub fn new(bits: u32) -> Self {
        let bits = bits.clamp(4, 16);
        let n = 1usize << bits;
        let table = (0..n)
            .map(|i| {
                let ph = 2.0 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
                Complex32::new(ph.cos() as f32, ph.sin() as f32)
            })
            .collect();
        Self {
            shift: 32 - bits,
            table,
        }
    }

    /// `exp(j 2 pi phase / 2^32)`, to within half a table bin.
    #[inline(always)]
    pub fn lookup(&self, phase: u32) -> Complex32 {
        self.table[(phase >> self.shift) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accumulator_is_exact_over_long_runs() {
        // After n samples the phase is exactly phase0 + n*step mod 2^32: no drift, ever.
        let mut nco = PhaseAccumulator::new(0.25, 1234.5678, 4.0e6);
        let n: u64 = 10_000_000;
        for _ in 0..n {
            nco.next_phase();
        }
        let expected = (u64::from(cycles_to_fixed(0.25)) + n * u64::from(nco.step)) & 0xFFFF_FFFF;
        assert_eq!(u64::from(nco.phase), expected);
        // And the frequency error is at most half an LSB: fs / 2^33.
        let f = f64::from(nco.step) / CYCLE * 4.0e6;
        assert!((f - 1234.5678).abs() <= 4.0e6 / CYCLE);
    }

    #[test]
    fn table_matches_exp_within_half_a_bin() {
        let t = SinCosTable::new(10);
        let max_err = std::f64::consts::PI / 1024.0 + 1e-6; // half a bin in radians (chord < arc)
        for k in 0..5000u32 {
            let phase = k.wrapping_mul(858_993_459);
            let exact = 2.0 * std::f64::consts::PI * f64::from(phase) / CYCLE;
            let v = t.lookup(phase);
            let err = ((f64::from(v.re) - exact.cos()).powi(2)
                + (f64::from(v.im) - exact.sin()).powi(2))
            .sqrt();
            assert!(err <= max_err, "phase {phase}: {err}");
        }
    }

    #[test]
    fn negative_frequencies_wrap() {
        let mut nco = PhaseAccumulator::new(0.0, -1.0e6, 4.0e6);
        nco.next_phase();
        assert!((nco.phase_cycles() - 0.75).abs() < 1e-9);
    }
}
