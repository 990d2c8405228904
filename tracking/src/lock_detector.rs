//! Phase-lock and code-lock detectors with hysteresis.
//!
//! PLL lock (Van Dierendonck, Kaplan Sec. 5.11.2): sum `M` prompts coherently, form the
//! narrow-band difference and power `NBD = I^2 - Q^2`, `NBP = I^2 + Q^2` of the sum, low-pass both
//! and take `C2phi = LPF(NBD)/LPF(NBP)`, an estimate of `cos(2 phi)`: 1 in phase lock, about 0 out
//! of lock, and insensitive to data bits (a flip changes the sign of I and Q together).
//! With noise of variance 1 per component on each prompt and amplitude A, `E[NBD] = M^2 A^2 cos 2phi`
//! and `E[NBP] = M^2 A^2 + 2M`, so the indicator reads `cos(2 phi) * rho/(rho + 1)` with
//! `rho = M C/N0 T`: the coherent sum keeps that factor near 1 (0.95 at 30 dB-Hz, M T = 20 ms).
//!
//! A loop that tracks with a steady phase offset (a 2nd-order loop under a constant Doppler
//! rate, e.g. the ramp an INS accelerometer bias leaves in the feed-forward: `B / (lambda w0^2)`
//! cycles, 0.1-0.16 cycle at 0.4 Hz for 1 mg) reads a low `cos 2phi` although it holds the
//! signal. The lock test therefore asks whether the phase is *steady*: with also
//! `NBS = 2 I Q` low-passed, `|(NBD, NBS)| / NBP` estimates `|E[exp(2 j phi)]|` (1 for any steady
//! phase, 0 for a wandering one) and `atan2(NBS, NBD) / 2` the steady offset, which must stay
//! within [`PllLockConfig::max_offset_cycles`] of zero (a Costas discriminator slips at 1/4
//! cycle). Without an offset the test is the classic `cos 2phi >= threshold`.
//!
//! Code lock: the C/N0 estimate (see [`crate::cn0`]) against a threshold.
//!
//! Both decisions go through a [`Hysteresis`] up/down counter: lock is declared when the counter
//! reaches its maximum, lost when it falls back to zero.

use num_complex::Complex64;

/// An up/down counter: +1 on a good test, -1 on a bad one, clamped to `0..=max`. Locked once it
/// reaches `max`, unlocked once it reaches 0: a single bad test does not break lock and a single
/// good one does not make it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hysteresis {
    count: u32,
    max: u32,
    locked: bool,
}

impl Hysteresis {
    /// A counter that needs `max` (at least 1) net good tests to declare lock.
    pub fn new(max: u32) -> Self {
        Self {
            count: 0,
            max: max.max(1),
            locked: false,
        }
    }

    /// Feeds one test result; returns the lock state.
    pub fn update(&mut self, good: bool) -> bool {
        if good {
            self.count = (self.count + 1).min(self.max);
        } else {
            self.count = self.count.saturating_sub(1);
        }
        if self.count == self.max {
            self.locked = true;
        } else if self.count == 0 {
            self.locked = false;
        }
        self.locked
    }

    /// The lock state.
    pub fn locked(&self) -> bool {
        self.locked
    }

    /// Back to unlocked with an empty counter.
    pub fn reset(&mut self) {
        self.count = 0;
        self.locked = false;
    }
}

/// PLL lock detector settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PllLockConfig {
    /// Prompts summed coherently before each test (`M`; 20 for 1 ms prompts, 1 for 20 ms).
    pub coherent_sum: u32,
    /// Low-pass coefficient per test, `y += alpha (x - y)` (0 < alpha <= 1).
    pub alpha: f64,
    /// `cos(2 phi)` threshold: 0.7 is |phi| < 22.8 deg.
    pub threshold: f64,
    /// Hysteresis counter length, tests.
    pub count: u32,
    /// Largest steady phase offset still counted as lock, cycles.
    pub max_offset_cycles: f64,
}

impl Default for PllLockConfig {
    fn default() -> Self {
        Self {
            coherent_sum: 20,
            alpha: 0.1,
            threshold: 0.7,
            count: 10,
            max_offset_cycles: 0.2,
        }
    }
}

/// Narrow-band phase-lock indicator `cos(2 phi)` with hysteresis.
#[derive(Debug, Clone)]
pub struct PllLockDetector {
    cfg: PllLockConfig,
    sum: Complex64,
    n: u32,
    nbd: f64,
    nbs: f64,
    nbp: f64,
    primed: bool,
    hyst: Hysteresis,
}

impl PllLockDetector {
    /// A detector; out-of-range settings are clamped (`coherent_sum >= 1`, `alpha` into (0, 1]).
    pub fn new(cfg: PllLockConfig) -> Self {
        let alpha = if cfg.alpha.is_finite() {
            cfg.alpha.clamp(1e-6, 1.0)
        } else {
            0.1
        };
        let cfg = PllLockConfig {
            coherent_sum: cfg.coherent_sum.max(1),
            alpha,
            ..cfg
        };
        Self {
            cfg,
            sum: Complex64::new(0.0, 0.0),
            n: 0,
            nbd: 0.0,
            nbs: 0.0,
            nbp: 0.0,
            primed: false,
            hyst: Hysteresis::new(cfg.count),
        }
    }

    /// Feeds one prompt; returns the lock state (updated every `coherent_sum` prompts).
    pub fn update(&mut self, prompt: Complex64) -> bool {
        if prompt.re.is_finite() && prompt.im.is_finite() {
            self.sum += prompt;
        }
        self.n += 1;
        if self.n < self.cfg.coherent_sum {
            return self.hyst.locked();
        }
        let (i, q) = (self.sum.re, self.sum.im);
        self.sum = Complex64::new(0.0, 0.0);
        self.n = 0;
        let (nbd, nbs, nbp) = (i * i - q * q, 2.0 * i * q, i * i + q * q);
        if self.primed {
            self.nbd += self.cfg.alpha * (nbd - self.nbd);
            self.nbs += self.cfg.alpha * (nbs - self.nbs);
            self.nbp += self.cfg.alpha * (nbp - self.nbp);
        } else {
            (self.nbd, self.nbs, self.nbp, self.primed) = (nbd, nbs, nbp, true);
        }
        let steady = self.phase_steadiness() >= self.cfg.threshold
            && self.phase_offset_cycles().abs() <= self.cfg.max_offset_cycles;
        self.hyst.update(steady)
    }

    /// `|E[exp(2 j phi)]|` estimated as `|(NBD, NBS)| / NBP`: 1 for a steady phase (whatever
    /// its offset), 0 for a wandering one (0 before the first test).
    pub fn phase_steadiness(&self) -> f64 {
        if self.nbp > 0.0 {
            self.nbd.hypot(self.nbs) / self.nbp
        } else {
            0.0
        }
    }

    /// The steady phase offset, `atan2(NBS, NBD) / 2`, cycles in `(-1/4, 1/4]` (a data bit
    /// flips the sign of the prompt: the offset is known modulo a half cycle).
    pub fn phase_offset_cycles(&self) -> f64 {
        0.5 * self.nbs.atan2(self.nbd) / std::f64::consts::TAU
    }

    /// The filtered `cos(2 phi)` indicator (0 before the first test).
    pub fn cos_2phi(&self) -> f64 {
        if self.nbp > 0.0 {
            self.nbd / self.nbp
        } else {
            0.0
        }
    }

    /// The lock state.
    pub fn locked(&self) -> bool {
        self.hyst.locked()
    }
}

/// Code lock: C/N0 estimate above a threshold, with hysteresis.
#[derive(Debug, Clone)]
pub struct CodeLockDetector {
    threshold_dbhz: f64,
    hyst: Hysteresis,
}

impl CodeLockDetector {
    /// Lock when the C/N0 estimates stay above `threshold_dbhz` for `count` net estimates.
    pub fn new(threshold_dbhz: f64, count: u32) -> Self {
        Self {
            threshold_dbhz,
            hyst: Hysteresis::new(count),
        }
    }

    /// Feeds one C/N0 estimate (dB-Hz); returns the lock state. NaN counts as a failed test.
    pub fn update(&mut self, cn0_dbhz: f64) -> bool {
        self.hyst.update(cn0_dbhz >= self.threshold_dbhz)
    }

    /// The lock state.
    pub fn locked(&self) -> bool {
        self.hyst.locked()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hysteresis_needs_net_good_tests() {
        let mut h = Hysteresis::new(3);
        assert!(!h.update(true));
        assert!(!h.update(false));
        assert!(!h.update(true));
        assert!(!h.update(true));
        assert!(h.update(true));
        assert!(h.update(false));
        assert!(h.update(false));
        assert!(!h.update(false));
    }

    #[test]
    fn cos2phi_reads_the_phase_and_ignores_bits() {
        for deg in [0.0_f64, 20.0, 45.0, 70.0, 90.0] {
            let mut d = PllLockDetector::new(PllLockConfig {
                coherent_sum: 4,
                ..PllLockConfig::default()
            });
            for k in 0..400 {
                let bit = if (k / 20) % 3 == 0 { -1.0 } else { 1.0 };
                d.update(Complex64::from_polar(bit * 5.0, deg.to_radians()));
            }
            assert!((d.cos_2phi() - (2.0 * deg.to_radians()).cos()).abs() < 1e-9);
            // A steady phase up to max_offset_cycles (72 deg) is lock.
            assert_eq!(d.locked(), deg < 72.0);
        }
    }

    #[test]
    fn a_steady_offset_within_the_limit_is_lock_and_a_wandering_phase_is_not() {
        // A 2nd-order loop's static offset of 0.12 cycle (43 deg): cos 2phi = 0.13, yet the
        // phase is steady; 0.23 cycle is too near the Costas slip at 1/4.
        for (offset, want) in [(0.12_f64, true), (-0.15, true), (0.23, false)] {
            let mut d = PllLockDetector::new(PllLockConfig::default());
            for k in 0..2000 {
                let bit = if (k / 20) % 3 == 0 { -1.0 } else { 1.0 };
                d.update(Complex64::from_polar(
                    bit * 5.0,
                    offset * std::f64::consts::TAU,
                ));
            }
            assert!((d.phase_offset_cycles() - offset).abs() < 1e-9, "{offset}");
            assert!((d.phase_steadiness() - 1.0).abs() < 1e-9);
            assert_eq!(d.locked(), want, "offset {offset} cycle");
        }
        // A phase turning at 2 Hz (a frequency error): never steady.
        let mut d = PllLockDetector::new(PllLockConfig::default());
        for k in 0..2000 {
            let phi = std::f64::consts::TAU * 2.0 * f64::from(k) * 1e-3;
            d.update(Complex64::from_polar(5.0, phi));
        }
        assert!(d.phase_steadiness() < 0.3, "{}", d.phase_steadiness());
        assert!(!d.locked());
    }

    #[test]
    fn code_lock_follows_cn0() {
        let mut c = CodeLockDetector::new(30.0, 2);
        assert!(!c.update(35.0));
        assert!(c.update(35.0));
        assert!(c.update(f64::NAN));
        assert!(!c.update(20.0));
    }
}
