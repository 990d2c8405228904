//! Line-of-sight carrier Doppler (seed 004 eq. 6; IS-GPS-200 3.3.1.1 for the L1 frequency).
//!
//! With `u` the unit vector from the receiver to the satellite, the range rate is
//! `rho_dot = (v_sv - v_rx) . u` and the L1 Doppler, positive when the range shrinks, is
//!
//! ```text
//! f_D = -rho_dot / lambda_L1 + f_L1 (d_sv - d_rx)
//! ```
//!
//! with `d_sv`, `d_rx` the satellite and receiver clock drifts (s/s): a satellite clock running
//! fast transmits above 1575.42 MHz, a receiver clock running fast sees every signal lower
//! (pseudorange rate `rho_dot + c d_rx - c d_sv`, `f_D = -pseudorange rate / lambda_L1`).
//! Seed 004 writes eq. 6 as `((v_sv - v_rx) . l) / lambda` with `l = -u` pointing from the
//! satellite to the receiver.

use crate::constants::{F_L1_HZ, LAMBDA_L1_M};
use nalgebra::Vector3;

/// A position and velocity in one ECEF frame (m, m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PosVel {
    /// Position, m.
    pub pos_m: Vector3<f64>,
    /// Velocity, m/s.
    pub vel_mps: Vector3<f64>,
}

/// Range rate `rho_dot = (v_sv - v_rx) . u` (m/s) of the satellite `sv` seen from the receiver
/// `rx` (same ECEF frame), or None when the range is zero or not finite.
pub fn range_rate_mps(sv: &PosVel, rx: &PosVel) -> Option<f64> {
    let d = sv.pos_m - rx.pos_m;
    let range = d.norm();
    if !(range.is_finite() && range > 0.0) {
        return None;
    }
    Some((sv.vel_mps - rx.vel_mps).dot(&(d / range)))
}

/// Line-of-sight L1 carrier Doppler, Hz: `-rho_dot / lambda_L1 + f_L1 (d_sv - d_rx)` (module
/// documentation), with `sv_clock_drift_s_s` = `d_sv` and `rx_clock_drift_s_s` = `d_rx`. None
/// when the range is zero or not finite.
pub fn los_doppler_hz(
    sv: &PosVel,
    rx: &PosVel,
    sv_clock_drift_s_s: f64,
    rx_clock_drift_s_s: f64,
) -> Option<f64> {
    let range_rate = range_rate_mps(sv, rx)?;
    Some(-range_rate / LAMBDA_L1_M + F_L1_HZ * (sv_clock_drift_s_s - rx_clock_drift_s_s))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pv(pos: [f64; 3], vel: [f64; 3]) -> PosVel {
        PosVel {
            pos_m: Vector3::from(pos),
            vel_mps: Vector3::from(vel),
        }
    }

    #[test]
    fn approaching_is_positive_and_magnitude_is_range_rate_over_lambda() {
        let sv = [20_000e3, 0.0, 0.0];
        let rx = [6_371e3, 0.0, 0.0];
        // Receiver moving towards the satellite at 10 m/s: range shrinks at 10 m/s.
        let f = los_doppler_hz(&pv(sv, [0.0; 3]), &pv(rx, [10.0, 0.0, 0.0]), 0.0, 0.0);
        assert!(f.is_some_and(|f| (f - 10.0 / LAMBDA_L1_M).abs() < 1e-9 && f > 52.0));
        // Motion across the line of sight gives nothing.
        let f = los_doppler_hz(
            &pv(sv, [0.0, 3000.0, 0.0]),
            &pv(rx, [0.0, 0.0, 50.0]),
            0.0,
            0.0,
        );
        assert!(f.is_some_and(|f| f.abs() < 1e-9));
        // A receiver clock running fast (positive drift) lowers every Doppler by f_L1 * drift,
        // a satellite clock running fast raises it.
        let f = los_doppler_hz(&pv(sv, [0.0; 3]), &pv(rx, [0.0; 3]), 0.0, 1e-8);
        assert!(f.is_some_and(|f| (f + 15.7542).abs() < 1e-9));
        let f = los_doppler_hz(&pv(sv, [0.0; 3]), &pv(rx, [0.0; 3]), 1e-8, 0.0);
        assert!(f.is_some_and(|f| (f - 15.7542).abs() < 1e-9));
        // No direction, no Doppler.
        assert!(los_doppler_hz(&pv(rx, [1.0; 3]), &pv(rx, [0.0; 3]), 0.0, 0.0).is_none());
        assert!(range_rate_mps(&pv([f64::NAN; 3], [0.0; 3]), &pv(rx, [0.0; 3])).is_none());
    }
}
