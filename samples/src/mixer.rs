//! Mixing IF samples down to baseband: `x[n] · exp(-j 2π f_IF n / fs)`, with `n` counted from
//! the first sample of the file.
//!
//! The phase of each block is computed afresh from the absolute sample index (in `f64`), and a
//! unit phasor is stepped at most [`RESEED_EVERY`] samples before it is recomputed, so the
//! oscillator neither drifts in magnitude nor accumulates phase error over hours of samples.

use num_complex::{Complex32, Complex64};

/// Samples between exact recomputations of the oscillator phase.
pub const RESEED_EVERY: usize = 4096;

/// A numerically controlled oscillator at `-if_hz` that multiplies sample blocks in place.
#[derive(Debug, Clone, Copy)]
pub struct Mixer {
    /// IF in cycles per sample.
    cycles_per_sample: f64,
}

impl Mixer {
    /// A mixer removing `if_hz` from samples taken at `fs_hz`.
    pub fn new(if_hz: f64, fs_hz: f64) -> Self {
        // Only the fractional cycles per sample matter at integer sample indices; keeping just
        // them makes an IF of a whole multiple of fs exactly the identity.
        Mixer {
            cycles_per_sample: (if_hz / fs_hz).rem_euclid(1.0),
        }
    }

    /// `exp(-j 2π f n / fs)` for absolute sample index `n`.
    fn phasor_at(&self, n: u64) -> Complex64 {
        let cycles = (self.cycles_per_sample * n as f64).rem_euclid(1.0);
        Complex64::from_polar(1.0, -std::f64::consts::TAU * cycles)
    }

    /// Multiplies `block` (whose first sample has absolute index `first`) by the oscillator.
    pub fn mix(&self, first: u64, block: &mut [Complex32]) {
        let step = Complex64::from_polar(1.0, -std::f64::consts::TAU * self.cycles_per_sample);
        for (k, chunk) in block.chunks_mut(RESEED_EVERY).enumerate() {
            let mut p = self.phasor_at(first + (k * RESEED_EVERY) as u64);
            for s in chunk {
                *s *= Complex32::new(p.re as f32, p.im as f32);
                p *= step;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_splitting_does_not_change_the_result() {
        let m = Mixer::new(1.25e6, 4.0e6);
        let mut whole = vec![Complex32::new(1.0, 0.0); 10_000];
        m.mix(7, &mut whole);
        let mut parts = vec![Complex32::new(1.0, 0.0); 10_000];
        let (a, b) = parts.split_at_mut(1234);
        m.mix(7, a);
        m.mix(7 + 1234, b);
        for (x, y) in whole.iter().zip(&parts) {
            assert!((x - y).norm() < 1e-5);
        }
    }

    #[test]
    fn far_indices_stay_on_the_unit_circle() {
        let m = Mixer::new(4.092e6, 16.368e6);
        let mut block = vec![Complex32::new(1.0, 0.0); 3];
        // 3 hours at 16.368 MHz
        m.mix(176_774_400_000, &mut block);
        for s in &block {
            assert!((s.norm() - 1.0).abs() < 1e-6);
        }
        // IF = fs/4: the phasor is -j^n; n divisible by 4 gives +1
        assert!((block[0] - Complex32::new(1.0, 0.0)).norm() < 1e-4);
    }

    #[test]
    fn an_if_of_fs_is_the_identity() {
        let m = Mixer::new(4.092e6, 4.092e6);
        let mut block: Vec<Complex32> = (0..5000).map(|k| Complex32::new(k as f32, 1.0)).collect();
        let orig = block.clone();
        m.mix(123_456_789, &mut block);
        for (a, b) in block.iter().zip(&orig) {
            assert!((a - b).norm() < 1e-3 * b.norm().max(1.0));
        }
    }
}
