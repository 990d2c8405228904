//! The theoretical tracking threshold of a cell: the rule of thumb `3 sigma + theta_e <= 45` deg
//! for a Costas PLL (Kaplan & Hegarty, *Understanding GPS*, 2nd ed., sec. 5.6; oracles.md
//! "Noise"), solved for C/N0 by bisection, and the floor the receiver's own lock detector sets.
//!
//! # The rule of thumb
//!
//! `sigma_PLL = sqrt(sigma_t^2 + sigma_v^2 + sigma_A^2)`, and lock holds while
//! `3 sigma_PLL + theta_e <= 45` deg, with
//!
//! - thermal jitter `sigma_t = (360/2 pi) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))` deg
//!   ([`pll_jitter_deg`], Kaplan eq. 5.6);
//! - oscillator (Allan) jitter `sigma_A = 144 sigma_y(tau) f_L / Bn` deg (2nd order) or
//!   `160 sigma_y(tau) f_L / Bn` (3rd order), `tau` the loop's time constant (Kaplan
//!   eqs. 5.10-5.11); Kaplan gives no 1st-order value ([`allan_jitter_deg`]);
//! - vibration jitter `sigma_v`: 0 (the study's receiver does not vibrate);
//! - dynamic stress `theta_e = 360 (d^n theta/dt^n) / omega0^n` deg for a loop of order `n`
//!   under a residual whose `n`-th phase derivative (cycles/s^n) is constant, `omega0` =
//!   Bn/0.25, Bn/0.53, Bn/0.7845 (Kaplan Table 5.6; [`dynamic_stress_deg`]); unbounded when a
//!   higher derivative is non-zero.
//!
//! `sigma_t` falls with C/N0, so the threshold is the one root of
//! `sigma_PLL(CN0) + theta_e/3 = 15` deg ([`rule_threshold_dbhz`]).
//!
//! # The lock detector's floor
//!
//! "Lock held" is what the receiver's carrier lock detector reports
//! ([`gpsrx_tracking::PllLockDetector`]): the steadiness `|LPF(S^2)| / s` of bit-aligned
//! 20-prompt coherent sums `S` (`s` their signal power, estimated without the noise bias) at or
//! above 0.7. In lock its expected value is `exp(-2 sigma^2)` (`sigma` the phase jitter, rad);
//! its estimate has the relative error `eps = sqrt(a/(2 - a) (4 rho + 2)/rho^2)`, `rho = M CN0 T1`
//! (`M` = 20 prompts of `T1` = 1 ms) and `a` the detector's low-pass coefficient (adapted to
//! `rho`, at least `min_alpha`), of which `eps/sqrt(2)` lies along the signal. Below the C/N0
//! where `exp(-2 sigma^2) - 1.645 eps/sqrt(2)` reaches the threshold ([`detector_floor_dbhz`])
//! the detector reports lock less than 95 % of the time even for a loop that holds the phase:
//! a threshold of the receiver, not of the loop.
//!
//! # The discriminator's own noise
//!
//! Kaplan's thermal term carries the squaring loss `1 + 1/(2 T CN0)` of the product (`I Q`)
//! Costas discriminator, derived for a linearised loop at moderate SNR. The receiver's
//! discriminator is `atan(Q/I)`, whose output folds into `(-pi/2, pi/2]`: below about 0 dB of
//! prompt SNR its variance per unit of slope grows faster than that (at `rho = CN0 T` = 0.5,
//! 2.0x the formula's; at 0.06, 3.0x), so the rule with the discriminator's exact statistics
//! through the linearised digital loop ([`rule_atan_dbhz`]) lies above Kaplan's, the more so
//! the lower the prompt SNR at the threshold (and, through the digital loop's phase noise gain,
//! the larger `Bn T`).
//! Curran, Lachapelle and Murphy (IEEE TAES 48(2), 2012) make the same point for
//! discriminator-specific PLL thresholds. The study reports both.
//!
//! # The stability floor
//!
//! The Costas `atan(Q/I)` discriminator's slope falls with the prompt SNR `rho = CN0 T` as
//! `1 - exp(-rho)` (`crate::bandwidth::costas_atan_stats`). The receiver divides the
//! discriminator by that slope, down to [`MIN_COSTAS_SLOPE`]
//! ([`gpsrx_tracking::CarrierLoop::costas_gain`]), so the loop keeps its design gain while the
//! slope is above it and runs at `k = slope / MIN_COSTAS_SLOPE` below ([`loop_gain`]). Orders
//! 1 and 2 stay stable at any gain; a 3rd-order loop is only conditionally stable (the analog
//! loop `s^3 + k b3 w s^2 + k a3 w^2 s + k w^3` needs `k > 1/(a3 b3) = 0.38` by Routh), so below
//! the C/N0 where `k` falls under the digital loop's critical gain ([`stability_floor_dbhz`])
//! the linearised loop is unstable and its phase error grows until it slips, whatever the
//! jitter.

use super::params::RULE_LIMIT_DEG;
use super::Dynamics;
use crate::bandwidth::{costas_atan_stats, stable_with_slope};
use gpsrx_tracking::carrier_loop::MIN_COSTAS_SLOPE;
use gpsrx_tracking::loop_filter::omega0;
use gpsrx_tracking::phase_sim::pll_jitter_deg;
use gpsrx_tracking::LoopFilter;
use gpsrx_tracking::PllLockConfig;

/// Oscillator (Allan) phase jitter of a PLL, degrees: `144 sigma_y f_L / Bn` (order 2) or
/// `160 sigma_y f_L / Bn` (order 3), Kaplan & Hegarty eqs. 5.10-5.11; `sigma_y` the Allan
/// deviation at the loop's time constant. `None` for order 1 with a noisy clock (Kaplan gives
/// no 1st-order value); 0 for a perfect clock.
pub fn allan_jitter_deg(
    order: u8,
    bn_hz: f64,
    allan_deviation: f64,
    f_carrier_hz: f64,
) -> Option<f64> {
    if allan_deviation == 0.0 {
        return Some(0.0);
    }
    let k = match order {
        2 => 144.0,
        3 => 160.0,
        _ => return None,
    };
    Some(k * allan_deviation * f_carrier_hz / bn_hz)
}

/// Dynamic stress error of a loop of `order` with noise bandwidth `bn_hz` under the residual
/// `dynamics`, degrees: `360 (d^n theta/dt^n)/omega0^n` (Kaplan sec. 5.6, oracles.md "Loop
/// filters"); infinite when the residual has a non-zero derivative above the loop's order.
pub fn dynamic_stress_deg(order: u8, bn_hz: f64, dynamics: &Dynamics) -> f64 {
    if dynamics.degree() > order {
        return f64::INFINITY;
    }
    let n = usize::from(order.clamp(1, 3));
    let d = dynamics.phase_derivatives()[n - 1];
    360.0 * d.abs() / omega0(order, bn_hz).powi(n as i32)
}

/// The inputs of a theoretical threshold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RuleInputs {
    /// Noise bandwidth Bn, Hz.
    pub bn_hz: f64,
    /// Predetection integration time T, s.
    pub t_coh_s: f64,
    /// Oscillator jitter, deg.
    pub allan_deg: f64,
    /// Vibration jitter, deg.
    pub vibration_deg: f64,
    /// Dynamic stress error, deg.
    pub stress_deg: f64,
}

impl RuleInputs {
    /// `sigma_PLL` at `cn0_dbhz`, deg.
    pub fn sigma_deg(&self, cn0_dbhz: f64) -> f64 {
        let t = pll_jitter_deg(self.bn_hz, cn0_dbhz, self.t_coh_s);
        (t * t + self.allan_deg.powi(2) + self.vibration_deg.powi(2)).sqrt()
    }
}

/// Lowest C/N0 (dB-Hz) at which `f` (decreasing in C/N0) is `<= 0`, by bisection on
/// [-20, 100] dB-Hz to 1e-6 dB; `None` when `f` is positive even at 100 dB-Hz.
fn lowest_root(f: impl Fn(f64) -> f64) -> Option<f64> {
    let (mut lo, mut hi) = (-20.0_f64, 100.0_f64);
    if f(hi) > 0.0 {
        return None;
    }
    if f(lo) <= 0.0 {
        return Some(lo);
    }
    while hi - lo > 1e-6 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

/// The rule-of-thumb threshold, dB-Hz: the C/N0 at which `3 sigma_PLL + theta_e = 45` deg;
/// `None` when the jitter that does not fall with C/N0 and the stress already break the rule.
pub fn rule_threshold_dbhz(r: &RuleInputs) -> Option<f64> {
    if !r.stress_deg.is_finite() {
        return None;
    }
    lowest_root(|c| 3.0 * r.sigma_deg(c) + r.stress_deg - RULE_LIMIT_DEG)
}

/// The loop gain the receiver's carrier loop runs at, relative to its design, at `cn0_dbhz`
/// and integration time `t_coh_s`: the Costas slope `1 - exp(-CN0 T)` over the slope it is
/// normalised by, `max(slope, MIN_COSTAS_SLOPE)` (module docs "The stability floor"; with the
/// detector's C/N0 taken as exact).
pub fn loop_gain(cn0_dbhz: f64, t_coh_s: f64) -> f64 {
    let slope = 1.0 - (-(10f64.powf(cn0_dbhz / 10.0)) * t_coh_s).exp();
    slope / slope.max(MIN_COSTAS_SLOPE)
}

/// The rule with the stress error a loop of reduced gain leaves: the gain `k` ([`loop_gain`])
/// scales the loop, and a steady-state error is inversely proportional to it, so
/// `3 sigma_PLL + theta_e / k <= 45` deg. The same as [`rule_threshold_dbhz`] without stress.
pub fn rule_with_slope_dbhz(r: &RuleInputs) -> Option<f64> {
    if !r.stress_deg.is_finite() {
        return None;
    }
    lowest_root(|c| 3.0 * r.sigma_deg(c) + r.stress_deg / loop_gain(c, r.t_coh_s) - RULE_LIMIT_DEG)
}

/// Thermal phase jitter of the receiver's own carrier loop, deg, at `cn0_dbhz`: the Costas
/// `atan(Q/I)` discriminator's output variance `v(rho)` (cycles^2, exact for Gaussian noise and
/// random data bits: `crate::bandwidth::costas_atan_stats`) divided by its squared slope
/// `(1 - exp(-rho))^2` (the receiver's normalisation, taken as ideal), through the linearised
/// digital loop: `sigma = 360 sqrt(v / slope^2 * sum h^2)`, `sum h^2` its phase noise gain
/// (`phase_gain`, [`crate::bandwidth::LoopNoiseGains::phase_gain_of`] at slope 1; `~ 2 Bn T`). At high prompt
/// SNR `v -> 1/(2 rho)/(2 pi)^2` and this is Kaplan's coherent term `Bn/CN0`; at low SNR the
/// atan's output folds into `(-pi/2, pi/2]` and its variance exceeds the formula's squaring
/// loss `1 + 1/(2 rho)`, which is that of the product (`I Q`) discriminator (module docs "The
/// discriminator's own noise").
pub fn atan_thermal_jitter_deg(cn0_dbhz: f64, t_coh_s: f64, phase_gain: f64) -> f64 {
    let stats = costas_atan_stats(cn0_dbhz, t_coh_s);
    if stats.slope <= 0.0 {
        return f64::INFINITY;
    }
    360.0 * (stats.noise_var / (stats.slope * stats.slope) * phase_gain).sqrt()
}

/// The rule of thumb with the receiver's own thermal jitter ([`atan_thermal_jitter_deg`] with
/// the loop's `phase_gain`) in place of Kaplan's formula, and the stress over the normalised
/// loop gain as in [`rule_with_slope_dbhz`]: `3 sigma + theta_e / k <= 45` deg, dB-Hz.
pub fn rule_atan_dbhz(r: &RuleInputs, phase_gain: f64) -> Option<f64> {
    if !r.stress_deg.is_finite() || !phase_gain.is_finite() {
        return None;
    }
    lowest_root(|c| {
        let t = atan_thermal_jitter_deg(c, r.t_coh_s, phase_gain);
        let sigma = (t * t + r.allan_deg.powi(2) + r.vibration_deg.powi(2)).sqrt();
        3.0 * sigma + r.stress_deg / loop_gain(c, r.t_coh_s) - RULE_LIMIT_DEG
    })
}

/// The relative error of the lock detector's steadiness estimate at the block SNR `rho`
/// (`M CN0 T1`): `sqrt(a/(2 - a) (4 rho + 2)/rho^2)` with the detector's adapted low-pass
/// coefficient `a = 2x/(1 + x)`, `x = eps^2 rho^2/(4 rho + 2)`, clamped to
/// `[min_alpha, alpha]` (module docs).
pub fn detector_relative_error(rho: f64, cfg: &PllLockConfig) -> f64 {
    let var = (4.0 * rho + 2.0) / (rho * rho);
    let x = cfg.relative_error * cfg.relative_error / var;
    let a = (2.0 * x / (1.0 + x)).clamp(cfg.min_alpha, cfg.alpha);
    (a / (2.0 - a) * var).sqrt()
}

/// The C/N0 (dB-Hz) below which the receiver's lock detector (default settings) reports lock
/// less than 95 % of the time: `exp(-2 sigma^2) - 1.645 eps/sqrt(2) = threshold` (module
/// docs), `sigma` the rule's `sigma_PLL` in radians; `None` when a steady stress error beyond
/// the detector's offset limit already fails it.
pub fn detector_floor_dbhz(r: &RuleInputs) -> Option<f64> {
    let cfg = PllLockConfig::default();
    if r.stress_deg / 360.0 > cfg.max_offset_cycles {
        return None;
    }
    let m_t1 = f64::from(cfg.coherent_sum) * 1e-3;
    lowest_root(|c| {
        let sigma_rad = r.sigma_deg(c).to_radians();
        let rho = m_t1 * 10f64.powf(c / 10.0);
        let eps = detector_relative_error(rho, &cfg);
        cfg.threshold - ((-2.0 * sigma_rad * sigma_rad).exp() - 1.645 * eps / 2f64.sqrt())
    })
}

/// The lowest C/N0 (dB-Hz) at which the linearised digital loop (`order`, `bn_hz`, `t_coh_s`)
/// at the gain [`loop_gain`] is stable (module docs); `None` when it is
/// stable down to -20 dB-Hz (orders 1 and 2) or not even at 100 dB-Hz.
pub fn stability_floor_dbhz(order: u8, bn_hz: f64, t_coh_s: f64) -> Option<f64> {
    if order < 3 {
        // Unconditionally stable at every gain below 1 (module docs); the numerical test is
        // marginal at vanishing gains, where the poles sit on z = 1.
        return None;
    }
    let filter = LoopFilter::pll(order, bn_hz).ok()?;
    let stable = |c: f64| stable_with_slope(&filter, t_coh_s, loop_gain(c, t_coh_s));
    let floor = lowest_root(|c| if stable(c) { -1.0 } else { 1.0 })?;
    (floor > -20.0).then_some(floor)
}

#[cfg(test)]
mod tests {
    use super::super::params::F_L1_HZ;
    use super::*;
    use std::f64::consts::PI;

    fn static_inputs(bn_hz: f64, t_coh_s: f64) -> RuleInputs {
        RuleInputs {
            bn_hz,
            t_coh_s,
            allan_deg: 0.0,
            vibration_deg: 0.0,
            stress_deg: 0.0,
        }
    }

    /// Static, thermal only: `sigma^2 = Bn/c + Bn/(2 T c^2)` (rad^2) at the limit `s = 15` deg
    /// is a quadratic in `1/c`, so `c = (Bn + sqrt(Bn^2 + 2 s^2 Bn/T)) / (2 s^2)`. By hand for
    /// Bn = 18 Hz, T = 1 ms: s^2 = 0.068539, c = (18 + sqrt(324 + 2467.4))/0.137078 = 516.8,
    /// 27.13 dB-Hz; Bn = 10 Hz, T = 20 ms: c = (10 + sqrt(100 + 68.54))/0.137078 = 167.7,
    /// 22.25 dB-Hz.
    #[test]
    fn static_threshold_matches_the_hand_computed_quadratic() {
        for (bn, t, want) in [(18.0, 1e-3, 27.13), (10.0, 20e-3, 22.25)] {
            let got = rule_threshold_dbhz(&static_inputs(bn, t)).unwrap_or(f64::NAN);
            assert!((got - want).abs() < 0.01, "Bn {bn} T {t}: {got}");
            let s2 = 15f64.to_radians().powi(2);
            let c = (bn + (bn * bn + 2.0 * s2 * bn / t).sqrt()) / (2.0 * s2);
            assert!((got - 10.0 * c.log10()).abs() < 1e-4);
        }
    }

    /// oracles.md: thermal jitter 9.41 deg at Bn 18 Hz, 30 dB-Hz, T = 1 ms; oscillator jitter
    /// 7.6 deg at 3 Hz for sigma_A = 1e-10 (2nd order, 144 sigma_A f_L / Bn); the 3rd-order
    /// stress `0.4828 (d3R/dt3)/Bn^3` (the equivalent form of `1/omega0^3`): 10 g/s of jerk
    /// (185,520 deg/s^3) at 18 Hz is 15.36 deg; 2nd order `0.2809 (d2R/dt2)/Bn^2`: 1 g at 18 Hz
    /// is 16.08 deg.
    #[test]
    fn jitter_and_stress_match_kaplans_numbers() {
        assert!((pll_jitter_deg(18.0, 30.0, 1e-3) - 9.41).abs() < 0.01);
        let a = allan_jitter_deg(2, 3.0, 1e-10, F_L1_HZ).unwrap_or(f64::NAN);
        assert!((a - 7.56).abs() < 0.01, "{a}");
        assert!(allan_jitter_deg(1, 3.0, 1e-10, F_L1_HZ).is_none());
        assert_eq!(allan_jitter_deg(1, 3.0, 0.0, F_L1_HZ), Some(0.0));
        let jerk = dynamic_stress_deg(3, 18.0, &Dynamics::JerkUnaided { g_per_s: 10.0 });
        assert!(
            (jerk - 0.4828 * 185_520.0 / 18f64.powi(3)).abs() < 0.02,
            "{jerk}"
        );
        let acc = dynamic_stress_deg(2, 18.0, &Dynamics::AccelUnaided { g: 1.0 });
        assert!((acc - 0.2809 * 18_552.0 / 324.0).abs() < 0.01, "{acc}");
        assert_eq!(
            dynamic_stress_deg(2, 18.0, &Dynamics::JerkUnaided { g_per_s: 1.0 }),
            f64::INFINITY
        );
    }

    /// The atan jitter against a Monte Carlo run of the receiver's own discriminator
    /// (`gpsrx_tracking::discriminator::costas_atan` on `A d e^{j phi} + n`, `A = sqrt(2 rho)`,
    /// random bits, unit noise per component, 400,000 draws, fixed seed): its variance at
    /// `phi = 0` and its slope from `phi = +-0.05` rad agree with `costas_atan_stats`, so the
    /// per-update noise `var/slope^2` exceeds the formula's `(1 + 1/(2 rho))/(2 rho)` by 2.0x at
    /// `rho` = 0.5 and 3x at 0.06 (module docs); at high SNR the two agree (`rho` = 100, 1 %).
    #[test]
    fn atan_noise_matches_a_monte_carlo_run_of_the_receivers_discriminator() {
        use gpsrx_tracking::discriminator::costas_atan;
        use num_complex::Complex64;
        use rand::{Rng, SeedableRng};
        use rand_distr::StandardNormal;
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let n = 400_000;
        for (rho, want_ratio) in [(0.5, 1.98), (0.06, 3.0), (100.0, 1.0)] {
            let a = (2.0_f64 * rho).sqrt();
            let mut draw = |phi: f64| -> (f64, f64) {
                let (mut m, mut m2) = (0.0, 0.0);
                for _ in 0..n {
                    let d = if rng.random::<bool>() { 1.0 } else { -1.0 };
                    let p = Complex64::from_polar(a * d, phi)
                        + Complex64::new(rng.sample(StandardNormal), rng.sample(StandardNormal));
                    let x = costas_atan(p);
                    m += x;
                    m2 += x * x;
                }
                (m / n as f64, m2 / n as f64)
            };
            let (_, var) = draw(0.0);
            // The slope from the mean at +-0.1 rad; at rho = 0.06 (slope 0.058) 400,000 draws
            // leave it 30 % uncertain, so only the variance is checked there.
            let slope = (draw(0.1).0 - draw(-0.1).0) / (0.2 / (2.0 * PI));
            // rho = CN0 T with T = 1 ms.
            let cn0_dbhz = 10.0 * (rho / 1e-3).log10();
            let stats = costas_atan_stats(cn0_dbhz, 1e-3);
            assert!(
                (var / stats.noise_var - 1.0).abs() < 0.02,
                "rho {rho}: {var} {stats:?}"
            );
            assert!(
                rho < 0.1 || (slope / stats.slope - 1.0).abs() < 0.08,
                "rho {rho}: {slope} {stats:?}"
            );
            let formula = (1.0 + 1.0 / (2.0 * rho)) / (2.0 * rho) / (4.0 * PI * PI);
            let ratio = stats.noise_var / stats.slope.powi(2) / formula;
            assert!(
                (ratio - want_ratio).abs() < 0.05 * want_ratio,
                "rho {rho}: {ratio}"
            );
            // Through a loop of phase gain g the jitter is 360 sqrt(var/slope^2 g).
            let g = 0.0008;
            let got = atan_thermal_jitter_deg(cn0_dbhz, 1e-3, g);
            let want = 360.0 * (stats.noise_var / stats.slope.powi(2) * g).sqrt();
            assert!((got - want).abs() < 1e-9 * want);
        }
    }

    /// A stress of 45 deg leaves nothing for the jitter: no threshold; 30 deg leaves
    /// `sigma <= 5` deg, which at 18 Hz, T = 1 ms needs c with `Bn/c (1 + 1/(2Tc)) = (5 deg)^2`.
    #[test]
    fn stress_raises_the_threshold_until_there_is_none() {
        let mut r = static_inputs(18.0, 1e-3);
        r.stress_deg = 45.0;
        assert_eq!(rule_threshold_dbhz(&r), None);
        r.stress_deg = 30.0;
        let got = rule_threshold_dbhz(&r).unwrap_or(f64::NAN);
        let s2 = 5f64.to_radians().powi(2);
        let c = (18.0 + (324.0 + 2.0 * s2 * 18.0 / 1e-3).sqrt()) / (2.0 * s2);
        assert!((got - 10.0 * c.log10()).abs() < 1e-4, "{got}");
    }

    /// The loop gain is 1 while the Costas slope is above [`MIN_COSTAS_SLOPE`] (0.05: 17.1
    /// dB-Hz at T = 1 ms, 4.1 dB-Hz at 20 ms) and `slope / 0.05` below; a loop whose stressed
    /// threshold lies above that (1 g into a 2nd-order 18 Hz loop, 16 deg: the plain rule's
    /// 29.8 dB-Hz) keeps its design gain, so the rule with the gain is the plain rule.
    #[test]
    fn the_loop_keeps_its_design_gain_above_the_normalisation_limit() {
        let c0 = 10.0 * (-(1.0 - MIN_COSTAS_SLOPE).ln() / 1e-3).log10();
        assert!((c0 - 17.10).abs() < 0.01, "{c0}");
        assert_eq!(loop_gain(c0 + 0.1, 1e-3), 1.0);
        let below = c0 - 3.0;
        let slope = 1.0 - (-(10f64.powf(below / 10.0)) * 1e-3).exp();
        assert!((loop_gain(below, 1e-3) - slope / MIN_COSTAS_SLOPE).abs() < 1e-12);
        let mut r = static_inputs(18.0, 1e-3);
        assert_eq!(rule_with_slope_dbhz(&r), rule_threshold_dbhz(&r));
        r.stress_deg = 16.08;
        let plain = rule_threshold_dbhz(&r).unwrap_or(f64::NAN);
        assert!((plain - 29.8).abs() < 0.1, "{plain}");
        assert_eq!(rule_with_slope_dbhz(&r), rule_threshold_dbhz(&r));
    }

    /// A 3rd-order loop at Bn T = 0.003 is nearly analog: unstable below the Routh gain
    /// `1/(a3 b3) = 0.379`; the receiver normalises the slope down to 0.05, so the gain is
    /// `(1 - exp(-c T))/0.05 = 0.379`, `c = -ln(1 - 0.019)/T` = 19.1 Hz at T = 1 ms, 12.8 dB-Hz
    /// (26.8 dB-Hz without the normalisation); a 2nd-order loop has no floor.
    #[test]
    fn third_order_loops_have_a_stability_floor() {
        let want = 10.0 * (-(1.0 - MIN_COSTAS_SLOPE / (1.1 * 2.4f64)).ln() / 1e-3).log10();
        let got = stability_floor_dbhz(3, 3.0, 1e-3).unwrap_or(f64::NAN);
        assert!((got - want).abs() < 0.3, "{got} vs {want}");
        assert_eq!(stability_floor_dbhz(2, 3.0, 1e-3), None);
        assert_eq!(stability_floor_dbhz(1, 18.0, 1e-3), None);
    }

    /// The detector floor: with no jitter it is where `1 - 1.645 eps/sqrt(2) = 0.7`, i.e.
    /// `eps = 0.258`. At `rho` = 0.3: `x = 0.0144 * 0.09 / 3.2 = 4.05e-4`, `a` clamps to
    /// `min_alpha` = 0.002, `eps = sqrt(0.002/1.998 * 35.56) = 0.1887`; `eps` = 0.258 with `a`
    /// clamped needs `(4 rho + 2)/rho^2 = 66.5`, `rho` = 0.206, 10.1 dB-Hz. Jitter raises it.
    #[test]
    fn detector_floor_is_where_the_estimate_fails_the_threshold() {
        let cfg = PllLockConfig::default();
        let eps = detector_relative_error(0.3, &cfg);
        assert!((eps - 0.1887).abs() < 0.001, "{eps}");
        let floor = detector_floor_dbhz(&static_inputs(1e-6, 20e-3)).unwrap_or(f64::NAN);
        let rho = 0.02 * 10f64.powf(floor / 10.0);
        let at_floor = detector_relative_error(rho, &cfg);
        assert!(
            (1.0 - 1.645 * at_floor / 2f64.sqrt() - 0.7).abs() < 1e-6,
            "{floor}"
        );
        assert!((floor - 10.1).abs() < 0.1, "{floor}");
        let wide = detector_floor_dbhz(&static_inputs(18.0, 1e-3)).unwrap_or(f64::NAN);
        assert!(wide > floor + 1.0, "{wide}");
    }
}
