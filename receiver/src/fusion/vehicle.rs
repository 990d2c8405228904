//! A trajectory in ECEF (the simulator's truth) seen as a land vehicle: local east/north/up
//! position, speed along the path, heading, yaw rate, longitudinal acceleration and road pitch —
//! the [`VehicleTruth`] the DR and accelerometer sensor models of `gpsrx_ins_aiding` take.
//!
//! With `R` the ECEF -> ENU rotation at the origin, `v = R v_ecef`, `a = R a_ecef`:
//! - speed `s = |v|` (the odometer measures distance along the road, slopes included);
//! - heading `psi = atan2(v_E, v_N)` (clockwise from north);
//! - yaw rate `dpsi/dt = (v_N a_E - v_E a_N) / (v_E^2 + v_N^2)`;
//! - longitudinal acceleration `a_long = (v . a) / s`;
//! - pitch `theta = atan2(v_U, sqrt(v_E^2 + v_N^2))`.
//!
//! Below `STILL_MPS` the vehicle stands still: heading and pitch are held from the last moving
//! instant, yaw rate is 0 and `a_long` is the acceleration along the held heading.

use gpsrx_ins_aiding::VehicleTruth;
use gpsrx_nav::frames::{enu_rotation, Llh};
use nalgebra::Vector3;

/// Speed below which the vehicle counts as standing still, m/s.
const STILL_MPS: f64 = 0.05;

/// One instant of an ECEF trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EcefState {
    /// Time, s.
    pub t_s: f64,
    /// Position, m.
    pub pos_m: Vector3<f64>,
    /// Velocity, m/s.
    pub vel_mps: Vector3<f64>,
    /// Acceleration, m/s^2.
    pub acc_mps2: Vector3<f64>,
}

/// The vehicle view of `states` (in time order) in the local level frame of `origin`.
pub fn vehicle_truth(origin: &Llh, states: &[EcefState]) -> Vec<VehicleTruth> {
    let r = enu_rotation(origin);
    let o = origin.to_ecef();
    let mut heading = 0.0;
    let mut pitch = 0.0;
    let mut first_heading = None;
    let out: Vec<VehicleTruth> = states
        .iter()
        .map(|s| {
            let p = r * (s.pos_m - o);
            let v = r * s.vel_mps;
            let a = r * s.acc_mps2;
            let horiz2 = v.x * v.x + v.y * v.y;
            let speed = v.norm();
            let moving = speed > STILL_MPS;
            let yaw_rate = if moving && horiz2 > 0.0 {
                heading = v.x.atan2(v.y);
                pitch = v.z.atan2(horiz2.sqrt());
                first_heading.get_or_insert(heading);
                (v.y * a.x - v.x * a.y) / horiz2
            } else {
                0.0
            };
            let a_long = if moving {
                v.dot(&a) / speed
            } else {
                // Along the held heading and pitch.
                let dir = Vector3::new(
                    heading.sin() * pitch.cos(),
                    heading.cos() * pitch.cos(),
                    pitch.sin(),
                );
                dir.dot(&a)
            };
            VehicleTruth {
                t_s: s.t_s,
                east_m: p.x,
                north_m: p.y,
                up_m: p.z,
                speed_mps: speed,
                heading_rad: heading,
                yaw_rate_rad_s: yaw_rate,
                a_long_mps2: a_long,
                pitch_rad: pitch,
            }
        })
        .collect();
    // A vehicle that starts at rest faces where it first moves.
    match first_heading {
        Some(h0) => out
            .into_iter()
            .scan(false, |moved, mut v| {
                *moved |= v.speed_mps > STILL_MPS;
                if !*moved {
                    v.heading_rad = h0;
                }
                Some(v)
            })
            .collect(),
        None => out,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle of radius `r` at speed `s` in the local frame of `origin`, counter-clockwise
    /// seen from above (heading decreasing): analytic position, velocity, acceleration.
    fn circle(origin: &Llh, r_m: f64, s_mps: f64, t: f64) -> EcefState {
        let w = s_mps / r_m;
        let rot = enu_rotation(origin).transpose();
        let ang = w * t;
        // Start at the origin heading north, turning left (towards west).
        let p = Vector3::new(r_m * (ang.cos() - 1.0), r_m * ang.sin(), 0.0);
        let v = Vector3::new(-s_mps * ang.sin(), s_mps * ang.cos(), 0.0);
        let a = Vector3::new(-s_mps * w * ang.cos(), -s_mps * w * ang.sin(), 0.0);
        EcefState {
            t_s: t,
            pos_m: origin.to_ecef() + rot * p,
            vel_mps: rot * v,
            acc_mps2: rot * a,
        }
    }

    #[test]
    fn a_left_circle_has_the_analytic_heading_and_yaw_rate() {
        let origin = Llh::from_degrees(37.5, 127.0, 50.0);
        let states: Vec<EcefState> = (0..100)
            .map(|k| circle(&origin, 50.0, 10.0, k as f64 * 0.1))
            .collect();
        let v = vehicle_truth(&origin, &states);
        for (s, t) in v.iter().zip(&states) {
            let ang = 0.2 * t.t_s;
            let heading = gpsrx_ins_aiding::wrap_pi(-ang);
            assert!((s.speed_mps - 10.0).abs() < 1e-9);
            assert!((gpsrx_ins_aiding::wrap_pi(s.heading_rad - heading)).abs() < 1e-9);
            assert!(
                (s.yaw_rate_rad_s + 0.2).abs() < 1e-9,
                "{}",
                s.yaw_rate_rad_s
            );
            assert!(s.a_long_mps2.abs() < 1e-9);
            assert!(s.pitch_rad.abs() < 1e-6);
            assert!((s.east_m - 50.0 * (ang.cos() - 1.0)).abs() < 1e-6);
            assert!((s.north_m - 50.0 * ang.sin()).abs() < 1e-6);
        }
    }

    #[test]
    fn a_climb_has_its_pitch_and_a_stop_keeps_the_heading() {
        let origin = Llh::from_degrees(10.0, 20.0, 0.0);
        let rot = enu_rotation(&origin).transpose();
        // Climbing east at 5 % grade, braking at 1 m/s^2 to a stop at t = 10 s.
        let grade = 0.05f64;
        let dir = Vector3::new(1.0, 0.0, grade) / (1.0 + grade * grade).sqrt();
        let states: Vec<EcefState> = (0..150)
            .map(|k| {
                let t = k as f64 * 0.1;
                let (d, s, a) = if t < 10.0 {
                    (10.0 * t - 0.5 * t * t, 10.0 - t, -1.0)
                } else {
                    (50.0, 0.0, 0.0)
                };
                EcefState {
                    t_s: t,
                    pos_m: origin.to_ecef() + rot * (dir * d),
                    vel_mps: rot * (dir * s),
                    acc_mps2: rot * (dir * a),
                }
            })
            .collect();
        let v = vehicle_truth(&origin, &states);
        for s in &v {
            assert!((s.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
            assert!((s.pitch_rad - grade.atan()).abs() < 1e-9, "{}", s.pitch_rad);
            if s.t_s < 9.9 {
                assert!((s.a_long_mps2 + 1.0).abs() < 1e-9);
            }
        }
        assert_eq!(v.last().map(|s| s.speed_mps), Some(0.0));
    }
}
