//! Built-in vehicle motions (`[receiver] kind = "motion"`): segments of cruise, acceleration
//! (for a time or to a target speed), jerk, turns and stops on a road of given grade, integrated
//! in the local level (ENU) frame of the start point.
//!
//! The state is `[east, north, up, speed, heading]`, `speed` along the road, `heading` clockwise
//! from north; the controls are the longitudinal acceleration `a` and the yaw rate `psi_dot`
//! (linear ramps over `transition_s` between segments, so the jerk is bounded), and the road
//! angle `gamma = atan(grade)` (a smoothstep `3w^2 - 2w^3` over `grade_transition_s`, so its rate
//! is continuous). With the road direction `d = (cos gamma sin psi, cos gamma cos psi, sin gamma)`:
//!
//! ```text
//! velocity     v_enu = speed d                     (up = speed sin gamma, horizontal speed cos gamma)
//! acceleration a_enu = a d + speed (psi_dot dd/dpsi + gamma_dot dd/dgamma)
//! ```
//!
//! RK4 integrates the state every `step_s` (1 ms for the signal simulator); between steps
//! position, velocity and acceleration are interpolated by quintic Hermite polynomials (C2).
//!
//! Reaching a target speed exactly: an acceleration `a` ramped in from `a0` over `r` and held for
//! `h`, then ramped out over `r` at the start of the next segment, changes the speed by
//! `a0 r/2 + a (h + r)`; the planner solves it for `h`, rounds `h` up to the table step and
//! lowers `a` to match, so the speed lands on the target (0 for a stop) without overshooting.
//! RK4 integrates the piecewise-linear acceleration exactly, and the speed is clamped at 0 while
//! standing, so it is never negative.

use super::segment_plan::{plan, Controls, GradeRamp, Phase, PhaseSpec, IDLE};
use super::RxState;
#[cfg(test)]
use super::G0_MPS2;
#[cfg(test)]
use crate::sim::scenario::TurnDirection;
use crate::sim::scenario::{ReceiverConfig, Segment};
use crate::sim::SimError;
use gpsrx_nav::frames::{enu_rotation, Llh, Vector3};
use nalgebra::Matrix3;
use std::collections::VecDeque;

/// A built-in motion tabulated every `step_s` in the local ENU frame.
#[derive(Debug, Clone)]
pub struct MotionTable {
    origin_ecef: Vector3<f64>,
    /// ENU -> ECEF rotation (transpose of the ECEF -> ENU one).
    enu_to_ecef: Matrix3<f64>,
    /// Table step, s.
    step_s: f64,
    /// Per step: position, velocity, acceleration (ENU).
    rows: Vec<[Vector3<f64>; 3]>,
    /// Per step: heading, rad clockwise from north (not wrapped).
    heading_rad: Vec<f64>,
    /// The control phases, in time order.
    phases: Vec<Phase>,
    /// The road-grade ramps, in time order.
    grades: Vec<GradeRamp>,
}

/// What a vehicle's own sensors would see at one instant: the inputs of dead-reckoning and
/// accelerometer models (seed 000 eqs. 1-3, seed 002); the shared [`gpsrx_core::VehicleState`].
pub use gpsrx_core::vehicle::VehicleState;

/// Motion state integrated in the level frame: east, north, up, speed, heading.
type State = [f64; 5];

fn derivative(s: &State, c: Controls, gamma: f64) -> State {
    let (sin, cos) = s[4].sin_cos();
    let (sg, cg) = gamma.sin_cos();
    [
        s[3] * cg * sin,
        s[3] * cg * cos,
        s[3] * sg,
        c.accel_mps2,
        c.yaw_rate_rad_s,
    ]
}

fn add(s: &State, k: &State, h: f64) -> State {
    std::array::from_fn(|j| s[j] + h * k[j])
}

/// ENU velocity and acceleration of the state under controls `c` on a road at angle `gamma`
/// changing at `gamma_dot` (module doc).
fn kinematics(s: &State, c: Controls, gamma: f64, gamma_dot: f64) -> (Vector3<f64>, Vector3<f64>) {
    let (sin, cos) = s[4].sin_cos();
    let (sg, cg) = gamma.sin_cos();
    let d = Vector3::new(cg * sin, cg * cos, sg);
    let d_psi = Vector3::new(cg * cos, -cg * sin, 0.0);
    let d_gamma = Vector3::new(-sg * sin, -sg * cos, cg);
    let v = s[3];
    (
        d * v,
        d * c.accel_mps2 + (d_psi * c.yaw_rate_rad_s + d_gamma * gamma_dot) * v,
    )
}

impl MotionTable {
    /// Table step the signal simulator uses, seconds.
    pub const DT_S: f64 = 1.0e-3;

    /// Integrates a `kind = "motion"` receiver over `[0, span_s]` every `step_s` seconds
    /// (1 ms, [`Self::DT_S`], for IF samples; 10 ms is ample for vehicle truth).
    pub fn from_config(cfg: &ReceiverConfig, span_s: f64, step_s: f64) -> Result<Self, SimError> {
        let ReceiverConfig::Motion {
            start_llh_deg,
            heading_deg,
            speed_mps,
            transition_s,
            grade_percent,
            grade_transition_s,
            segments,
        } = cfg
        else {
            return Err(SimError::Scenario(
                "a motion table needs [receiver] kind = \"motion\"".into(),
            ));
        };
        if !(step_s.is_finite() && step_s > 0.0 && span_s.is_finite() && span_s > 0.0) {
            return Err(SimError::Scenario(format!(
                "motion table: step {step_s} s and span {span_s} s must be positive"
            )));
        }
        let origin = Llh::from_degrees(start_llh_deg[0], start_llh_deg[1], start_llh_deg[2]);
        let start = Start {
            heading_rad: heading_deg.to_radians(),
            speed_mps: *speed_mps,
            grade_rad: (grade_percent / 100.0).atan(),
        };
        let ramps = Ramps {
            transition_s: *transition_s,
            grade_transition_s: *grade_transition_s,
        };
        Self::integrate(&origin, start, ramps, segments, span_s, step_s)
    }

    fn integrate(
        origin: &Llh,
        start: Start,
        ramps: Ramps,
        segments: &[Segment],
        span_s: f64,
        step_s: f64,
    ) -> Result<Self, SimError> {
        let n = (span_s / step_s).ceil() as usize + 2;
        let mut rows = Vec::with_capacity(n);
        let mut heading_rad = Vec::with_capacity(n);
        let mut s: State = [0.0, 0.0, 0.0, start.speed_mps, start.heading_rad];
        let mut phases: Vec<Phase> = Vec::new();
        let mut grades = vec![GradeRamp {
            t0: 0.0,
            dur_s: 0.0,
            from_rad: start.grade_rad,
            to_rad: start.grade_rad,
        }];
        let mut phase = Phase {
            t0: 0.0,
            t1: 0.0,
            from: IDLE,
            to: IDLE,
            jerk_mps3: 0.0,
            ramp_s: 0.0,
            standstill: false,
        };
        let mut queue: VecDeque<PhaseSpec> = VecDeque::new();
        let mut segs = segments.iter().enumerate();
        let grade_at = |grades: &[GradeRamp], t: f64| grade_lookup(grades, t);
        for i in 0..n {
            let t = i as f64 * step_s;
            while t >= phase.t1 - 1e-9 {
                let current = phase.controls(t);
                let spec = match queue.pop_front() {
                    Some(p) => p,
                    None => match segs.next() {
                        None => PhaseSpec::new(f64::INFINITY, IDLE),
                        Some((k, seg)) => {
                            if let Some(g) = seg.grade_percent() {
                                let (now, _) = grade_at(&grades, t);
                                grades.push(GradeRamp {
                                    t0: t,
                                    dur_s: ramps.grade_transition_s,
                                    from_rad: now,
                                    to_rad: (g / 100.0).atan(),
                                });
                            }
                            let k = k + 1;
                            queue.extend(plan(
                                k,
                                seg,
                                t,
                                s[3],
                                current,
                                ramps.transition_s,
                                step_s,
                            )?);
                            continue;
                        }
                    },
                };
                if spec.dur_s.is_nan() || spec.dur_s < 0.0 {
                    return Err(SimError::Scenario(format!(
                        "a motion segment has duration {} s; it must be positive",
                        spec.dur_s
                    )));
                }
                phases.push(phase);
                phase = Phase {
                    t0: t,
                    t1: t + spec.dur_s,
                    from: current,
                    to: spec.to,
                    jerk_mps3: spec.jerk_mps3,
                    ramp_s: ramps.transition_s.min(spec.dur_s),
                    standstill: spec.standstill,
                };
            }
            let c = phase.controls(t);
            let (gamma, gamma_dot) = grade_at(&grades, t);
            let (vel, acc) = kinematics(&s, c, gamma, gamma_dot);
            rows.push([Vector3::new(s[0], s[1], s[2]), vel, acc]);
            heading_rad.push(s[4]);
            // RK4 step with the time-varying controls and road angle.
            let h = step_s;
            let mid = grade_at(&grades, t + h / 2.0).0;
            let k1 = derivative(&s, c, gamma);
            let k2 = derivative(&add(&s, &k1, h / 2.0), phase.controls(t + h / 2.0), mid);
            let k3 = derivative(&add(&s, &k2, h / 2.0), phase.controls(t + h / 2.0), mid);
            let k4 = derivative(
                &add(&s, &k3, h),
                phase.controls(t + h),
                grade_at(&grades, t + h).0,
            );
            for j in 0..5 {
                s[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
            if s[3] < 0.0 {
                if phase.standstill || s[3] > -1e-6 {
                    s[3] = 0.0;
                } else {
                    return Err(SimError::Scenario(format!(
                        "the motion reverses at t = {t:.2} s (speed below zero): shorten the \
                         braking segment, or brake with `to_speed_mps = 0` or a `stop` segment"
                    )));
                }
            }
        }
        phases.push(phase);
        Ok(Self {
            origin_ecef: origin.to_ecef(),
            enu_to_ecef: enu_rotation(origin).transpose(),
            step_s,
            rows,
            heading_rad,
            phases,
            grades,
        })
    }

    /// Table step, s.
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// Seconds covered by the table.
    pub fn span_s(&self) -> f64 {
        (self.rows.len() - 2) as f64 * self.step_s
    }

    /// Row index and fraction of `t_s`.
    fn locate(&self, t_s: f64) -> (usize, f64) {
        let last = self.rows.len() - 2;
        let x = (t_s / self.step_s).max(0.0);
        let i = (x.floor() as usize).min(last);
        (i, (x - i as f64).clamp(0.0, 1.0))
    }

    /// Position, velocity and acceleration in the local ENU frame of the start at `t_s`.
    pub fn enu_state(&self, t_s: f64) -> [Vector3<f64>; 3] {
        let (i, u) = self.locate(t_s);
        let [p0, v0, a0] = self.rows[i];
        let [p1, v1, a1] = self.rows[i + 1];
        let (p, v, a) = quintic_hermite(&p0, &v0, &a0, &p1, &v1, &a1, self.step_s, u);
        [p, v, a]
    }

    /// The state at `t_s` seconds from the start, in ECEF.
    pub fn state(&self, t_s: f64) -> RxState {
        let [p, v, a] = self.enu_state(t_s);
        RxState {
            pos_m: self.origin_ecef + self.enu_to_ecef * p,
            vel_mps: self.enu_to_ecef * v,
            acc_mps2: self.enu_to_ecef * a,
        }
    }

    /// The vehicle's own view at `t_s` (speed, heading, yaw rate, longitudinal acceleration,
    /// road slope), for dead-reckoning and accelerometer models.
    pub fn vehicle_state(&self, t_s: f64) -> VehicleState {
        let [p, v, _] = self.enu_state(t_s);
        let (i, u) = self.locate(t_s);
        let psi = self.heading_rad[i] + u * (self.heading_rad[i + 1] - self.heading_rad[i]);
        let k = self.phases.partition_point(|ph| ph.t0 <= t_s).max(1) - 1;
        let c = self.phases[k].controls(t_s);
        let (gamma, _) = grade_lookup(&self.grades, t_s);
        let speed = v.norm();
        VehicleState {
            t_s,
            east_m: p[0],
            north_m: p[1],
            up_m: p[2],
            speed_mps: speed,
            heading_rad: wrap_pi(psi),
            yaw_rate_rad_s: c.yaw_rate_rad_s,
            a_long_mps2: if speed < 1e-9 && self.phases[k].standstill {
                0.0
            } else {
                c.accel_mps2
            },
            pitch_rad: gamma,
        }
    }
}

/// Where a motion starts.
#[derive(Debug, Clone, Copy)]
struct Start {
    heading_rad: f64,
    speed_mps: f64,
    grade_rad: f64,
}

/// Transition times of the controls and of the road grade.
#[derive(Debug, Clone, Copy)]
struct Ramps {
    transition_s: f64,
    grade_transition_s: f64,
}

/// Road angle and rate at `t` from the last ramp started at or before `t`.
fn grade_lookup(grades: &[GradeRamp], t: f64) -> (f64, f64) {
    let k = grades.partition_point(|g| g.t0 <= t).max(1) - 1;
    grades[k].at(t)
}

/// Wraps an angle to (-pi, pi].
fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(std::f64::consts::TAU);
    if w > std::f64::consts::PI {
        w - std::f64::consts::TAU
    } else {
        w
    }
}

/// Quintic Hermite interpolation on one step of length `h` at fraction `u`: matches position,
/// velocity and acceleration at both ends, so the result is C2 across steps.
#[allow(clippy::too_many_arguments)]
fn quintic_hermite(
    p0: &Vector3<f64>,
    v0: &Vector3<f64>,
    a0: &Vector3<f64>,
    p1: &Vector3<f64>,
    v1: &Vector3<f64>,
    a1: &Vector3<f64>,
    h: f64,
    u: f64,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let (u2, u3, u4, u5) = (u * u, u * u * u, u * u * u * u, u * u * u * u * u);
    // Basis functions and their first and second derivatives with respect to u.
    let h0 = [
        1.0 - 10.0 * u3 + 15.0 * u4 - 6.0 * u5,
        -30.0 * u2 + 60.0 * u3 - 30.0 * u4,
        -60.0 * u + 180.0 * u2 - 120.0 * u3,
    ];
    let h1 = [
        u - 6.0 * u3 + 8.0 * u4 - 3.0 * u5,
        1.0 - 18.0 * u2 + 32.0 * u3 - 15.0 * u4,
        -36.0 * u + 96.0 * u2 - 60.0 * u3,
    ];
    let h2 = [
        0.5 * (u2 - 3.0 * u3 + 3.0 * u4 - u5),
        0.5 * (2.0 * u - 9.0 * u2 + 12.0 * u3 - 5.0 * u4),
        0.5 * (2.0 - 18.0 * u + 36.0 * u2 - 20.0 * u3),
    ];
    let h3 = [
        0.5 * (u3 - 2.0 * u4 + u5),
        0.5 * (3.0 * u2 - 8.0 * u3 + 5.0 * u4),
        0.5 * (6.0 * u - 24.0 * u2 + 20.0 * u3),
    ];
    let h4 = [
        -4.0 * u3 + 7.0 * u4 - 3.0 * u5,
        -12.0 * u2 + 28.0 * u3 - 15.0 * u4,
        -24.0 * u + 84.0 * u2 - 60.0 * u3,
    ];
    let h5 = [
        10.0 * u3 - 15.0 * u4 + 6.0 * u5,
        30.0 * u2 - 60.0 * u3 + 30.0 * u4,
        60.0 * u - 180.0 * u2 + 120.0 * u3,
    ];
    let combine = |k: usize| {
        p0 * h0[k]
            + v0 * (h * h1[k])
            + a0 * (h * h * h2[k])
            + a1 * (h * h * h3[k])
            + v1 * (h * h4[k])
            + p1 * h5[k]
    };
    (combine(0), combine(1) / h, combine(2) / (h * h))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(speed_mps: f64, segments: Vec<Segment>, span_s: f64) -> MotionTable {
        let origin = Llh::from_degrees(37.0, 127.0, 50.0);
        let start = Start {
            heading_rad: 0.0,
            speed_mps,
            grade_rad: 0.0,
        };
        let ramps = Ramps {
            transition_s: 0.5,
            grade_transition_s: 3.0,
        };
        MotionTable::integrate(&origin, start, ramps, &segments, span_s, MotionTable::DT_S)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn quintic_hermite_reproduces_a_quintic_polynomial() {
        // p(t) = t^5 is reproduced exactly by quintic Hermite from its end values.
        let h = 0.3;
        let f = |t: f64| Vector3::new(t.powi(5), 2.0 * t.powi(3), -t);
        let fd = |t: f64| Vector3::new(5.0 * t.powi(4), 6.0 * t * t, -1.0);
        let fdd = |t: f64| Vector3::new(20.0 * t.powi(3), 12.0 * t, 0.0);
        let t0 = 0.7;
        for &u in &[0.0, 0.25, 0.5, 0.9, 1.0] {
            let (p, v, a) = quintic_hermite(
                &f(t0),
                &fd(t0),
                &fdd(t0),
                &f(t0 + h),
                &fd(t0 + h),
                &fdd(t0 + h),
                h,
                u,
            );
            let t = t0 + u * h;
            assert!((p - f(t)).norm() < 1e-12);
            assert!((v - fd(t)).norm() < 1e-10);
            assert!((a - fdd(t)).norm() < 1e-8);
        }
    }

    #[test]
    fn circle_has_the_commanded_centripetal_acceleration() {
        let m = table(
            60.0,
            vec![Segment::Turn {
                duration_s: Some(10.0),
                angle_deg: None,
                radius_m: None,
                accel_g: Some(5.0),
                direction: TurnDirection::Left,
                grade_percent: None,
            }],
            12.0,
        );
        let s = m.state(5.0);
        assert!((s.vel_mps.norm() - 60.0).abs() < 1e-6);
        assert!(
            (s.acc_mps2.norm() / G0_MPS2 - 5.0).abs() < 1e-6,
            "{}",
            s.acc_mps2.norm() / G0_MPS2
        );
        // Velocity is the derivative of position and acceleration that of velocity.
        let dt = 1e-3;
        let (a, b) = (m.state(5.0 - dt), m.state(5.0 + dt));
        assert!(((b.pos_m - a.pos_m) / (2.0 * dt) - s.vel_mps).norm() < 1e-4);
        assert!(((b.vel_mps - a.vel_mps) / (2.0 * dt) - s.acc_mps2).norm() < 1e-3);
        // The vehicle view: a left turn is a negative yaw rate of a / v.
        let vs = m.vehicle_state(5.0);
        assert!((vs.yaw_rate_rad_s + 5.0 * G0_MPS2 / 60.0).abs() < 1e-9);
    }

    #[test]
    fn acceleration_is_continuous_through_a_transition() {
        let m = table(
            5.0,
            vec![
                Segment::Cruise {
                    duration_s: 1.0,
                    grade_percent: None,
                },
                Segment::Accelerate {
                    duration_s: Some(5.0),
                    accel_mps2: 10.0,
                    to_speed_mps: None,
                    grade_percent: None,
                },
            ],
            8.0,
        );
        let mut prev = m.state(0.9).acc_mps2;
        let mut t = 0.9;
        while t < 2.0 {
            t += 1e-4;
            let a = m.state(t).acc_mps2;
            // Jerk bound: 10 m/s^2 over 0.5 s = 20 m/s^3 -> at most 2e-3 m/s^2 per 0.1 ms step.
            assert!((a - prev).norm() < 2.5e-3, "t {t}");
            prev = a;
        }
        assert!((m.state(3.0).acc_mps2.norm() - 10.0).abs() < 1e-9);
    }
}
