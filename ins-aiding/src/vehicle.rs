//! The vehicle truth the DR and accelerometer sensor models sample: a land vehicle in a local
//! east-north-up frame (the receiver converts its ENU truth into these).

use crate::dr_error::DrError;
use std::f64::consts::PI;

/// Truth of a land vehicle at one instant: the shared [`gpsrx_core::VehicleState`] (also what
/// the simulator's motion tables give), under the name the sensor models use.
pub use gpsrx_core::vehicle::VehicleState as VehicleTruth;

/// Checks a truth trajectory: at least 2 states, finite values, speeds `>= 0` (to 1e-6 m/s), strictly
/// increasing time.
pub fn validate_truth(truth: &[VehicleTruth]) -> Result<(), DrError> {
    if truth.len() < 2 {
        return Err(DrError::Config(format!(
            "a vehicle truth trajectory needs at least 2 states (found {})",
            truth.len()
        )));
    }
    for (i, s) in truth.iter().enumerate() {
        let v = [
            s.t_s,
            s.east_m,
            s.north_m,
            s.up_m,
            s.speed_mps,
            s.heading_rad,
            s.yaw_rate_rad_s,
            s.a_long_mps2,
            s.pitch_rad,
        ];
        if v.iter().any(|x| !x.is_finite()) {
            return Err(DrError::Config(format!(
                "vehicle truth state {i} has a non-finite value"
            )));
        }
        if s.speed_mps < -1e-6 {
            return Err(DrError::Config(format!(
                "vehicle truth state {i}: speed_mps = {} is negative (the path speed is a magnitude)",
                s.speed_mps
            )));
        }
        if i > 0 && s.t_s <= truth[i - 1].t_s {
            return Err(DrError::Config(format!(
                "vehicle truth state {i}: t_s = {} does not increase",
                s.t_s
            )));
        }
    }
    Ok(())
}

/// `a` wrapped to `(-pi, pi]`.
pub fn wrap_pi(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

/// The truth integrated for the odometer and gyro: cumulative path length (trapezoid of
/// `speed_mps`) and unwrapped heading at each truth state, interpolated linearly in time.
#[derive(Debug, Clone)]
pub(crate) struct TruthIntegrals {
    t_s: Vec<f64>,
    distance_m: Vec<f64>,
    heading_rad: Vec<f64>,
}

impl TruthIntegrals {
    pub fn new(truth: &[VehicleTruth]) -> TruthIntegrals {
        let mut t_s = Vec::with_capacity(truth.len());
        let mut distance_m = Vec::with_capacity(truth.len());
        let mut heading_rad = Vec::with_capacity(truth.len());
        for (i, s) in truth.iter().enumerate() {
            t_s.push(s.t_s);
            if i == 0 {
                distance_m.push(0.0);
                heading_rad.push(s.heading_rad);
            } else {
                let p = &truth[i - 1];
                let d = distance_m[i - 1] + 0.5 * (p.speed_mps + s.speed_mps) * (s.t_s - p.t_s);
                distance_m.push(d);
                let h = heading_rad[i - 1] + wrap_pi(s.heading_rad - p.heading_rad);
                heading_rad.push(h);
            }
        }
        TruthIntegrals {
            t_s,
            distance_m,
            heading_rad,
        }
    }

    /// (distance, unwrapped heading) at `t` (clamped to the trajectory's span).
    pub fn at(&self, t: f64) -> (f64, f64) {
        let n = self.t_s.len();
        let k = self.t_s.partition_point(|&x| x <= t).clamp(1, n - 1);
        let (t0, t1) = (self.t_s[k - 1], self.t_s[k]);
        let f = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let lerp = |v: &[f64]| v[k - 1] + f * (v[k] - v[k - 1]);
        (lerp(&self.distance_m), lerp(&self.heading_rad))
    }
}

/// The truth state at `t` (linear interpolation between the two neighbouring states, heading
/// through the shorter arc; clamped to the trajectory's span). `truth` must be validated.
pub fn interpolate_truth(truth: &[VehicleTruth], t: f64) -> VehicleTruth {
    let n = truth.len();
    let k = truth.partition_point(|s| s.t_s <= t).clamp(1, n - 1);
    let (a, b) = (&truth[k - 1], &truth[k]);
    let f = ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0);
    let l = |x: f64, y: f64| x + f * (y - x);
    VehicleTruth {
        t_s: t,
        east_m: l(a.east_m, b.east_m),
        north_m: l(a.north_m, b.north_m),
        up_m: l(a.up_m, b.up_m),
        speed_mps: l(a.speed_mps, b.speed_mps),
        heading_rad: a.heading_rad + f * wrap_pi(b.heading_rad - a.heading_rad),
        yaw_rate_rad_s: l(a.yaw_rate_rad_s, b.yaw_rate_rad_s),
        a_long_mps2: l(a.a_long_mps2, b.a_long_mps2),
        pitch_rad: l(a.pitch_rad, b.pitch_rad),
    }
}
