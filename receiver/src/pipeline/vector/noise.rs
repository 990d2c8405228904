//! Measurement noise of one channel from its C/N0: the thermal-noise formulas of the tracking
//! loops (`oracles.md`, Kaplan ch. 5), turned into the variances the navigation filter weights
//! the channel's pseudorange and Doppler with.
//!
//! - Code: a non-coherent early-minus-late power DLL of noise bandwidth `Bn`, spacing `d`
//!   chips, integration `T`: `sigma_tau = sqrt((Bn d / (2 CN0)) (1 + 2 / (T CN0 (2 - d))))`
//!   chips (Kaplan eq. 5.41), times 293.05 m per chip; plus a floor for what the formula
//!   leaves out (multipath, the model's residual atmosphere).
//! - Doppler: the observables' Doppler is the carrier phase differenced across the epoch,
//!   `(phi(t + dt) - phi(t - dt)) / (2 dt)` (`navigation::observables`), so its noise is the
//!   PLL's phase jitter `sigma_phi = sqrt((Bn / CN0) (1 + 1 / (2 T CN0))) / (2 pi)` cycles
//!   (Kaplan eq. 5.6) times `sqrt(2) / (2 dt)`; plus a floor. (A channel whose PLL is not
//!   locked gives no observables.) [`fll_jitter_hz`], the frequency jitter of a frequency
//!   discriminator (Kaplan eq. 5.21), is the bound for a channel tracked by its FLL alone.
//!
//! `CN0` is linear (Hz): `10^(C/N0 / 10)`.
//!
//! A measurement taken every `dt` from a loop whose errors are correlated over `1 / (4 Bn)`
//! (a 1st-order loop's time constant) is not white at the filter's rate: its variance is
//! scaled by `max(1, 1 / (4 Bn dt))` ([`correlation_scale`]), the number of filter updates per
//! independent loop output, so that a 1 Hz DLL read at 10 Hz counts for what it is worth.

use gpsrx_core::constants::{CA_CHIP_RATE_HZ, SPEED_OF_LIGHT_MPS};
use std::f64::consts::PI;

/// Length of a C/A chip, m (`c / 1.023 MHz`, 293.05 m).
pub const CHIP_M: f64 = SPEED_OF_LIGHT_MPS / CA_CHIP_RATE_HZ;
/// Floor of the pseudorange sigma, m: multipath and the residual of the atmosphere models.
pub const CODE_FLOOR_M: f64 = 1.0;
/// Floor of the Doppler sigma, Hz (0.01 m/s): oscillator and model residuals.
pub const DOPPLER_FLOOR_HZ: f64 = 0.05;
/// Lowest C/N0 the formulas are evaluated at, dB-Hz (below, the loops are not tracking).
pub const CN0_FLOOR_DBHZ: f64 = 15.0;

/// The loop settings that set a channel's measurement noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopNoise {
    /// DLL noise bandwidth, Hz.
    pub dll_bn_hz: f64,
    /// Early-late spacing, chips.
    pub el_spacing_chips: f64,
    /// Carrier loop (PLL) noise bandwidth, Hz.
    pub carrier_bn_hz: f64,
    /// Coherent integration, s.
    pub t_coh_s: f64,
}

impl LoopNoise {
    /// The noise settings of a tracking loop configuration.
    pub fn of(loops: &gpsrx_tracking::LoopConfig) -> Self {
        Self {
            dll_bn_hz: loops.dll_bw_hz,
            el_spacing_chips: loops.el_spacing_chips,
            carrier_bn_hz: loops.pll_bw_hz.max(loops.fll_bw_hz),
            t_coh_s: loops.t_coh_s,
        }
    }
}

fn linear_cn0(cn0_dbhz: f64) -> f64 {
    let c = if cn0_dbhz.is_finite() {
        cn0_dbhz
    } else {
        CN0_FLOOR_DBHZ
    };
    10f64.powf(c.max(CN0_FLOOR_DBHZ) / 10.0)
}

/// DLL thermal jitter, chips (Kaplan eq. 5.41; module docs).
pub fn dll_jitter_chips(bn_hz: f64, d_chips: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let cn0 = linear_cn0(cn0_dbhz);
    let d = d_chips.clamp(0.05, 1.0);
    (bn_hz * d / (2.0 * cn0) * (1.0 + 2.0 / (t_s * cn0 * (2.0 - d)))).sqrt()
}

/// PLL thermal phase jitter of a Costas loop, cycles (Kaplan eq. 5.6; module docs).
pub fn pll_jitter_cycles(bn_hz: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let cn0 = linear_cn0(cn0_dbhz);
    (bn_hz / cn0 * (1.0 + 1.0 / (2.0 * t_s * cn0))).sqrt() / (2.0 * PI)
}

/// Frequency-discriminator jitter, Hz (Kaplan eq. 5.21; module docs).
pub fn fll_jitter_hz(bn_hz: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let cn0 = linear_cn0(cn0_dbhz);
    let f = if cn0_dbhz >= 35.0 { 1.0 } else { 2.0 };
    (4.0 * f * bn_hz / cn0 * (1.0 + 1.0 / (t_s * cn0))).sqrt() / (2.0 * PI * t_s)
}

/// `max(1, 1 / (4 Bn dt))`: how many filter updates of interval `dt_s` one independent output
/// of a loop of noise bandwidth `bn_hz` spans (module docs).
pub fn correlation_scale(bn_hz: f64, dt_s: f64) -> f64 {
    if bn_hz > 0.0 && dt_s > 0.0 {
        (1.0 / (4.0 * bn_hz * dt_s)).max(1.0)
    } else {
        1.0
    }
}

/// Pseudorange variance, m^2, of a channel at `cn0_dbhz` read every `dt_s`.
pub fn code_variance_m2(loops: &LoopNoise, cn0_dbhz: f64, dt_s: f64) -> f64 {
    let s = dll_jitter_chips(
        loops.dll_bn_hz,
        loops.el_spacing_chips,
        cn0_dbhz,
        loops.t_coh_s,
    ) * CHIP_M;
    (s * s + CODE_FLOOR_M * CODE_FLOOR_M) * correlation_scale(loops.dll_bn_hz, dt_s)
}

/// Doppler variance, Hz^2, of a channel at `cn0_dbhz` whose Doppler is its carrier phase
/// differenced over `2 dt_s` (module docs).
pub fn doppler_variance_hz2(loops: &LoopNoise, cn0_dbhz: f64, dt_s: f64) -> f64 {
    let phi = pll_jitter_cycles(loops.carrier_bn_hz, cn0_dbhz, loops.t_coh_s);
    let s = phi * std::f64::consts::SQRT_2 / (2.0 * dt_s.max(1e-3));
    (s * s + DOPPLER_FLOOR_HZ * DOPPLER_FLOOR_HZ) * correlation_scale(loops.carrier_bn_hz, dt_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dll_jitter_matches_a_hand_computation() {
        // 1 Hz, 1 chip, 45 dB-Hz (31,623 Hz), 1 ms: sqrt(1/63,246 (1 + 2/31.62)) = 0.0041002 chip.
        let s = dll_jitter_chips(1.0, 1.0, 45.0, 1e-3);
        assert!((s - 0.004_100_2).abs() < 1e-7, "{s}");
        // 6 dB less C/N0: about twice the jitter (and a little more from the squaring loss).
        let weak = dll_jitter_chips(1.0, 1.0, 39.0, 1e-3);
        assert!(weak / s > 2.0 && weak / s < 2.2, "{}", weak / s);
    }

    #[test]
    fn fll_jitter_matches_a_hand_computation() {
        // 18 Hz, 45 dB-Hz, 1 ms, F = 1: sqrt(72/31,623 (1 + 1/31.62)) / (2 pi 1e-3) = 7.713 Hz.
        let s = fll_jitter_hz(18.0, 45.0, 1e-3);
        assert!((s - 7.713).abs() < 1e-3, "{s}");
    }

    #[test]
    fn pll_jitter_matches_a_hand_computation() {
        // 18 Hz, 45 dB-Hz, 1 ms: sqrt(18/31,623 (1 + 1/63.25)) / 2 pi = 0.003827 cycle
        // (1.38 deg, as Kaplan's Fig. 5.11 reads).
        let s = pll_jitter_cycles(18.0, 45.0, 1e-3);
        assert!((s - 0.003_827).abs() < 1e-6, "{s}");
        // The Doppler of phases 0.2 s apart: sqrt(2) x 0.003827 / 0.2 = 0.02706 Hz, under the
        // 0.05 Hz floor.
        let loops = LoopNoise {
            dll_bn_hz: 1.0,
            el_spacing_chips: 1.0,
            carrier_bn_hz: 18.0,
            t_coh_s: 1e-3,
        };
        let v = doppler_variance_hz2(&loops, 45.0, 0.1);
        assert!(
            (v.sqrt() - (0.027_06f64.powi(2) + 0.0025).sqrt()).abs() < 1e-4,
            "{}",
            v.sqrt()
        );
    }

    #[test]
    fn weaker_channels_weigh_less_and_slow_loops_count_once_per_time_constant() {
        let loops = LoopNoise {
            dll_bn_hz: 1.0,
            el_spacing_chips: 1.0,
            carrier_bn_hz: 18.0,
            t_coh_s: 1e-3,
        };
        assert!(code_variance_m2(&loops, 30.0, 0.1) > code_variance_m2(&loops, 45.0, 0.1));
        assert!(doppler_variance_hz2(&loops, 30.0, 0.1) > doppler_variance_hz2(&loops, 45.0, 0.1));
        // 1 Hz DLL read at 10 Hz: 1/(4 x 1 x 0.1) = 2.5 updates per independent output.
        assert!((correlation_scale(1.0, 0.1) - 2.5).abs() < 1e-12);
        assert_eq!(correlation_scale(18.0, 0.1), 1.0);
        // Nonsense C/N0 gives the floor's variance, not NaN.
        assert!(code_variance_m2(&loops, f64::NAN, 0.1).is_finite());
    }
}
