//! The INS-velocity Doppler feed-forward (seed 004 eq. 6).
//!
//! `f = ((v_sv - v_rx) . l) / lambda` with `l` the unit vector from the satellite to the
//! receiver; written here with `u = -l` (receiver to satellite) as `f = -((v_sv - v_rx) . u) /
//! lambda`, positive when the range shrinks. A receiver clock drift `d` (s/s) adds `-f_L1 d`.

use nalgebra::Vector3;

/// L1 wavelength, m (c / 1575.42 MHz).
pub const LAMBDA_L1_M: f64 = 299_792_458.0 / 1_575.42e6;

/// Line-of-sight carrier Doppler (Hz) of a satellite at `sv_pos_m` moving at `sv_vel_mps` seen
/// by a receiver at `rx_pos_m` moving at `rx_vel_mps` (same ECEF frame), with receiver clock
/// drift `rx_clock_drift_s_s`.
pub fn los_doppler_hz(
    sv_pos_m: &Vector3<f64>,
    sv_vel_mps: &Vector3<f64>,
    rx_pos_m: &Vector3<f64>,
    rx_vel_mps: &Vector3<f64>,
    rx_clock_drift_s_s: f64,
) -> f64 {
    let d = sv_pos_m - rx_pos_m;
    let range = d.norm();
    if range.is_nan() || range <= 0.0 {
        return 0.0;
    }
    let u = d / range;
    let range_rate = (sv_vel_mps - rx_vel_mps).dot(&u);
    -range_rate / LAMBDA_L1_M - rx_clock_drift_s_s * 1_575.42e6
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn approaching_is_positive_and_magnitude_is_range_rate_over_lambda() {
        let sv = Vector3::new(20_000e3, 0.0, 0.0);
        let rx = Vector3::new(6_371e3, 0.0, 0.0);
        // Receiver moving towards the satellite at 10 m/s: range shrinks at 10 m/s.
        let f = los_doppler_hz(
            &sv,
            &Vector3::zeros(),
            &rx,
            &Vector3::new(10.0, 0.0, 0.0),
            0.0,
        );
        assert!((f - 10.0 / LAMBDA_L1_M).abs() < 1e-9, "{f}");
        // Motion across the line of sight gives nothing.
        let f = los_doppler_hz(
            &sv,
            &Vector3::new(0.0, 3000.0, 0.0),
            &rx,
            &Vector3::new(0.0, 0.0, 50.0),
            0.0,
        );
        assert!(f.abs() < 1e-9, "{f}");
        // A clock running fast (positive drift) lowers every Doppler by f_L1 * drift.
        let f = los_doppler_hz(&sv, &Vector3::zeros(), &rx, &Vector3::zeros(), 1e-8);
        assert!((f + 15.7542).abs() < 1e-9, "{f}");
    }
}
