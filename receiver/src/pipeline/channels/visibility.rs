//! Which satellites a receiver sees, and at what Doppler: from an ephemeris, a position and
//! velocity, the time and the receiver clock drift (assisted acquisition).
//!
//! The satellite state is taken at transmit time `t - tau` (light time iterated three times
//! from 75 ms) and rotated by the Earth's rotation during the flight (IS-GPS-200
//! 20.3.3.4.3.3.2; [`gpsrx_nav::ephemeris::Ephemeris::at_reception`]). With `u` the unit
//! vector from the receiver to the satellite, the range rate is `rho_dot = (v_sv - v_rx) . u`
//! and the Doppler, positive when the range shrinks, is
//! `f_D = -rho_dot / lambda_L1 + f_L1 (d_sv - d_rx)` ([`gpsrx_core::los_doppler_hz`]).

use gpsrx_core::{los_doppler_hz, PosVel};
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::frames::SvAtReception;
use gpsrx_nav::{azimuth_elevation, GpsTime};

/// What an ephemeris predicts for one satellite at the receiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatPrediction {
    /// Carrier Doppler, Hz (with the receiver clock drift given).
    pub doppler_hz: f64,
    /// Elevation, degrees.
    pub elevation_deg: f64,
    /// Azimuth, degrees clockwise from north.
    pub azimuth_deg: f64,
}

/// The prediction for the satellite of `eph` seen at GPS time `t` by a receiver at `rx`
/// (ECEF position and velocity) whose clock drifts by `rx_clock_drift_s_s`; `None` when the
/// geometry is degenerate (a receiver at the satellite).
pub fn predict(
    eph: &Ephemeris,
    rx: &PosVel,
    t: GpsTime,
    rx_clock_drift_s_s: f64,
) -> Option<SatPrediction> {
    predict_seen(
        &eph.at_reception(t, &rx.pos_m, 0.075, 3),
        rx,
        rx_clock_drift_s_s,
    )
}

/// The prediction from the satellite's state at reception `seen` (from an ephemeris, or an
/// almanac: [`gpsrx_nav::almanac::Almanac::at_reception`]), as [`predict`].
pub fn predict_seen(
    seen: &SvAtReception,
    rx: &PosVel,
    rx_clock_drift_s_s: f64,
) -> Option<SatPrediction> {
    let sv = PosVel {
        pos_m: seen.sv.pos_m,
        vel_mps: seen.sv.vel_mps,
    };
    let doppler_hz = los_doppler_hz(&sv, rx, seen.sv.clock_drift_s_s, rx_clock_drift_s_s)?;
    let (az, el) = azimuth_elevation(&rx.pos_m, &seen.sv.pos_m);
    doppler_hz.is_finite().then_some(SatPrediction {
        doppler_hz,
        elevation_deg: el.to_degrees(),
        azimuth_deg: az.to_degrees(),
    })
}
