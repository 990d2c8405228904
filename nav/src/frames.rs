//! WGS-84 geodetic coordinates, ECEF and local East-North-Up frames and the Earth-rotation
//! correction, defined in [`gpsrx_core::frames`] and re-exported here, plus the light-time
//! solution that finds where a satellite was when it sent the signal received now.

use crate::constants::SPEED_OF_LIGHT_MPS;
use crate::ephemeris::SvState;
pub use gpsrx_core::frames::{
    azimuth_elevation, enu_rotation, rotate_for_earth_rotation, rotation_rate_times, Llh,
};
pub use nalgebra::Vector3;

/// A satellite as seen at reception (the result of [`light_time`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SvAtReception {
    /// The satellite state at transmit time `t_rx - tau_k` (`tau_k` the last flight time the
    /// iteration evaluated the satellite at), with `pos_m` and `vel_mps` rotated by
    /// `R3(OmegaE tau_k)` into the ECEF frame of reception; the clock terms are unchanged.
    pub sv: SvState,
    /// Geometric range `|R3(OmegaE tau_k) r_sv(t_rx - tau_k) - r_rx|`, m.
    pub range_m: f64,
    /// The next flight-time estimate `range_m / c`, s.
    pub flight_time_s: f64,
}

/// Light-time solution with the Earth's rotation during the flight (IS-GPS-200 20.3.3.4.3.3.2):
/// the flight time `tau` solves
///
/// ```text
/// c tau = |R3(OmegaE tau) r_sv(t_rx - tau) - r_rx(t_rx)|
/// ```
///
/// by fixed-point iteration from `tau_guess_s`, `iterations` passes (at least one) of
/// `tau_{k+1} = |R3(OmegaE tau_k) r_sv(t_rx - tau_k) - r_rx| / c`. `state_at(tau)` is the
/// satellite state at transmit time `t_rx - tau` in the ECEF frame of that instant (normally
/// `eph.sv_state(t_rx.add_seconds(-tau))`, see [`crate::Ephemeris::at_reception`]; a constant
/// state when the transmit time is already known from the pseudorange and only the rotation
/// is wanted).
///
/// Each pass shrinks the error by about `|range rate| / c` (< 3e-6), so from a guess within
/// 10 ms two passes leave < 1e-12 s; one pass from 75 ms is good to ~0.1 us.
pub fn light_time(
    mut state_at: impl FnMut(f64) -> SvState,
    rx_pos_m: &Vector3<f64>,
    tau_guess_s: f64,
    iterations: usize,
) -> SvAtReception {
    let mut tau = tau_guess_s;
    let mut tau_k = tau;
    let mut sv = state_at(tau);
    let mut range_m = 0.0;
    for k in 0..iterations.max(1) {
        if k > 0 {
            sv = state_at(tau);
        }
        tau_k = tau;
        let pos = rotate_for_earth_rotation(&sv.pos_m, tau_k);
        range_m = (pos - rx_pos_m).norm();
        sv.pos_m = pos;
        tau = range_m / SPEED_OF_LIGHT_MPS;
    }
    sv.vel_mps = rotate_for_earth_rotation(&sv.vel_mps, tau_k);
    SvAtReception {
        sv,
        range_m,
        flight_time_s: tau,
    }
}
