//! Receiver trajectories: where the antenna is, how fast it moves and how it accelerates, at any
//! instant. Every kind is continuous in position, velocity and acceleration (C2), so the signal's
//! phases are smooth at the sample level.
//!
//! - static: a fixed ECEF point;
//! - CSV: natural cubic splines through the given positions (C2 by construction);
//! - built-in motions: horizontal manoeuvres in the local level (ENU) frame of the start point,
//!   integrated with RK4 at 1 ms and evaluated between steps by quintic Hermite interpolation of
//!   position, velocity and acceleration (C2). The local frame is a plane tangent at the start,
//!   so the height above the ellipsoid grows as `d^2 / (2 R)` over a distance `d` (0.8 m at 3 km).

use crate::sim::scenario::{ReceiverConfig, Segment, TurnDirection};
use crate::sim::SimError;
use gpsrx_nav::frames::{enu_rotation, Llh, Vector3};
use nalgebra::Matrix3;
use std::path::Path;

/// Standard gravity, m/s^2.
pub const G0_MPS2: f64 = 9.80665;

/// Receiver kinematic state in ECEF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RxState {
    /// Position, m.
    pub pos_m: Vector3<f64>,
    /// Velocity, m/s.
    pub vel_mps: Vector3<f64>,
    /// Acceleration, m/s^2.
    pub acc_mps2: Vector3<f64>,
}

/// A receiver trajectory, evaluated at seconds since the start of the recording (true time).
#[derive(Debug, Clone)]
pub enum Trajectory {
    /// A fixed antenna.
    Static(Vector3<f64>),
    /// Natural cubic splines through CSV positions.
    Spline(SplineTrajectory),
    /// Built-in motion, tabulated.
    Motion(MotionTable),
}

impl Trajectory {
    /// Builds the trajectory a scenario describes; `duration_s` is checked against CSV spans.
    pub fn from_config(
        cfg: &ReceiverConfig,
        base_dir: &Path,
        duration_s: f64,
    ) -> Result<Self, SimError> {
        match cfg {
            ReceiverConfig::Static {
                llh_deg: Some(l), ..
            } => Ok(Self::Static(Llh::from_degrees(l[0], l[1], l[2]).to_ecef())),
            ReceiverConfig::Static {
                ecef_m: Some(e), ..
            } => Ok(Self::Static(Vector3::new(e[0], e[1], e[2]))),
            ReceiverConfig::Static { .. } => Err(SimError::Scenario(
                "static receiver needs llh_deg or ecef_m".into(),
            )),
            ReceiverConfig::Csv { path } => {
                let p = base_dir.join(path);
                let sp = SplineTrajectory::from_csv(&p)?;
                if sp.t_end() < duration_s + 1.0 || sp.t_start() > -0.5 {
                    return Err(SimError::Scenario(format!(
                        "{}: the trajectory covers {:.3}..{:.3} s but the scenario needs -0.5..{:.1} s \
                         (light time and the last samples need a margin)",
                        p.display(),
                        sp.t_start(),
                        sp.t_end(),
                        duration_s + 1.0
                    )));
                }
                Ok(Self::Spline(sp))
            }
            ReceiverConfig::Motion {
                start_llh_deg,
                heading_deg,
                speed_mps,
                transition_s,
                segments,
            } => {
                let origin =
                    Llh::from_degrees(start_llh_deg[0], start_llh_deg[1], start_llh_deg[2]);
                Ok(Self::Motion(MotionTable::integrate(
                    &origin,
                    heading_deg.to_radians(),
                    *speed_mps,
                    *transition_s,
                    segments,
                    duration_s + 2.0,
                )?))
            }
        }
    }

    /// The state at `t_s` seconds from the start.
    pub fn state(&self, t_s: f64) -> RxState {
        match self {
            Self::Static(p) => RxState {
                pos_m: *p,
                vel_mps: Vector3::zeros(),
                acc_mps2: Vector3::zeros(),
            },
            Self::Spline(s) => s.state(t_s),
            Self::Motion(m) => m.state(t_s),
        }
    }
}

/// One natural cubic spline `y(t)` through knots `(t_i, y_i)` (second derivative 0 at both ends).
#[derive(Debug, Clone)]
struct CubicSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives at the knots.
    m: Vec<f64>,
}

impl CubicSpline {
    /// Solves the tridiagonal system for the knot second derivatives (Thomas algorithm).
    fn new(t: Vec<f64>, y: Vec<f64>) -> Self {
        let n = t.len();
        let mut m = vec![0.0; n];
        if n > 2 {
            let mut c = vec![0.0; n];
            let mut d = vec![0.0; n];
            for i in 1..n - 1 {
                let h0 = t[i] - t[i - 1];
                let h1 = t[i + 1] - t[i];
                let a = h0 / 6.0;
                let b = (h0 + h1) / 3.0;
                let cc = h1 / 6.0;
                let rhs = (y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0;
                let denom = b - a * c[i - 1];
                c[i] = cc / denom;
                d[i] = (rhs - a * d[i - 1]) / denom;
            }
            for i in (1..n - 1).rev() {
                m[i] = d[i] - c[i] * m[i + 1];
            }
        }
        Self { t, y, m }
    }

    /// Value, first and second derivative at `x` (clamped to the knot range).
    fn eval(&self, x: f64) -> (f64, f64, f64) {
        let n = self.t.len();
        let x = x.clamp(self.t[0], self.t[n - 1]);
        let i = match self.t.binary_search_by(|v| v.total_cmp(&x)) {
            Ok(i) => i.min(n - 2),
            Err(i) => i.saturating_sub(1).min(n - 2),
        };
        let h = self.t[i + 1] - self.t[i];
        let a = (self.t[i + 1] - x) / h;
        let b = (x - self.t[i]) / h;
        let (m0, m1, y0, y1) = (self.m[i], self.m[i + 1], self.y[i], self.y[i + 1]);
        let v = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let d =
            (y1 - y0) / h - (3.0 * a * a - 1.0) / 6.0 * h * m0 + (3.0 * b * b - 1.0) / 6.0 * h * m1;
        let dd = a * m0 + b * m1;
        (v, d, dd)
    }
}

/// A trajectory from CSV positions.
#[derive(Debug, Clone)]
pub struct SplineTrajectory {
    axes: [CubicSpline; 3],
}

impl SplineTrajectory {
    /// Reads `t_s,x_m,y_m,z_m` (ECEF) or `t_s,lat_deg,lon_deg,h_m` rows.
    pub fn from_csv(path: &Path) -> Result<Self, SimError> {
        let io = |m: String| SimError::Io {
            path: path.to_path_buf(),
            message: m,
        };
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_path(path)
            .map_err(|e| io(e.to_string()))?;
        let headers = rdr.headers().map_err(|e| io(e.to_string()))?.clone();
        let col = |name: &str| headers.iter().position(|h| h == name);
        let (ecef, idx) = match (col("t_s"), col("x_m"), col("y_m"), col("z_m"), col("lat_deg"), col("lon_deg"), col("h_m")) {
            (Some(t), Some(x), Some(y), Some(z), _, _, _) => (true, [t, x, y, z]),
            (Some(t), _, _, _, Some(la), Some(lo), Some(h)) => (false, [t, la, lo, h]),
            _ => {
                return Err(io(format!(
                    "trajectory CSV needs a header `t_s,x_m,y_m,z_m` (ECEF) or `t_s,lat_deg,lon_deg,h_m`; found `{}`",
                    headers.iter().collect::<Vec<_>>().join(",")
                )))
            }
        };
        let mut t = Vec::new();
        let mut xyz: [Vec<f64>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        for (row, rec) in rdr.records().enumerate() {
            let line = row + 2;
            let rec = rec.map_err(|e| io(format!("line {line}: {e}")))?;
            let mut v = [0.0; 4];
            for (k, &i) in idx.iter().enumerate() {
                let field = rec.get(i).unwrap_or("");
                v[k] = field
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| io(format!("line {line}: `{field}` is not a finite number")))?;
            }
            if let Some(&last) = t.last() {
                if v[0] <= last {
                    return Err(io(format!(
                        "line {line}: t_s = {} does not increase (previous {last})",
                        v[0]
                    )));
                }
            }
            let p = if ecef {
                Vector3::new(v[1], v[2], v[3])
            } else {
                Llh::from_degrees(v[1], v[2], v[3]).to_ecef()
            };
            t.push(v[0]);
            for a in 0..3 {
                xyz[a].push(p[a]);
            }
        }
        if t.len() < 4 {
            return Err(io(format!(
                "a trajectory needs at least 4 rows, found {}",
                t.len()
            )));
        }
        let [x, y, z] = xyz;
        Ok(Self {
            axes: [
                CubicSpline::new(t.clone(), x),
                CubicSpline::new(t.clone(), y),
                CubicSpline::new(t, z),
            ],
        })
    }

    fn t_start(&self) -> f64 {
        self.axes[0].t[0]
    }

    fn t_end(&self) -> f64 {
        *self.axes[0].t.last().unwrap_or(&0.0)
    }

    fn state(&self, t_s: f64) -> RxState {
        let mut s = RxState {
            pos_m: Vector3::zeros(),
            vel_mps: Vector3::zeros(),
            acc_mps2: Vector3::zeros(),
        };
        for a in 0..3 {
            let (p, v, acc) = self.axes[a].eval(t_s);
            s.pos_m[a] = p;
            s.vel_mps[a] = v;
            s.acc_mps2[a] = acc;
        }
        s
    }
}

/// A built-in motion tabulated every [`MotionTable::DT_S`] in the local ENU frame.
#[derive(Debug, Clone)]
pub struct MotionTable {
    origin_ecef: Vector3<f64>,
    /// ENU -> ECEF rotation (transpose of the ECEF -> ENU one).
    enu_to_ecef: Matrix3<f64>,
    /// Per step: position, velocity, acceleration (ENU).
    rows: Vec<[Vector3<f64>; 3]>,
}

/// Longitudinal acceleration and turn rate commanded at one instant.
#[derive(Debug, Clone, Copy)]
struct Controls {
    accel_mps2: f64,
    yaw_rate_rad_s: f64,
}

/// A segment resolved to absolute times and control laws.
#[derive(Debug, Clone, Copy)]
struct Phase {
    t0: f64,
    t1: f64,
    from: Controls,
    to: Controls,
    jerk_mps3: f64,
    ramp_s: f64,
}

impl Phase {
    fn controls(&self, t: f64) -> Controls {
        let tau = (t - self.t0).max(0.0);
        let w = if self.ramp_s > 0.0 {
            (tau / self.ramp_s).min(1.0)
        } else {
            1.0
        };
        Controls {
            accel_mps2: self.from.accel_mps2
                + w * (self.to.accel_mps2 - self.from.accel_mps2)
                + self.jerk_mps3 * tau,
            yaw_rate_rad_s: self.from.yaw_rate_rad_s
                + w * (self.to.yaw_rate_rad_s - self.from.yaw_rate_rad_s),
        }
    }
}

/// Motion state integrated in the plane: east, north, speed, heading (clockwise from north).
type PlaneState = [f64; 4];

fn derivative(s: &PlaneState, c: Controls) -> PlaneState {
    let (sin, cos) = s[3].sin_cos();
    [s[2] * sin, s[2] * cos, c.accel_mps2, c.yaw_rate_rad_s]
}

impl MotionTable {
    /// Table step, seconds.
    pub const DT_S: f64 = 1.0e-3;

    fn integrate(
        origin: &Llh,
        heading_rad: f64,
        speed_mps: f64,
        transition_s: f64,
        segments: &[Segment],
        span_s: f64,
    ) -> Result<Self, SimError> {
        let n = (span_s / Self::DT_S).ceil() as usize + 2;
        let mut rows = Vec::with_capacity(n);
        let mut s: PlaneState = [0.0, 0.0, speed_mps, heading_rad];
        let idle = Controls {
            accel_mps2: 0.0,
            yaw_rate_rad_s: 0.0,
        };
        let mut phase = Phase {
            t0: 0.0,
            t1: f64::INFINITY,
            from: idle,
            to: idle,
            jerk_mps3: 0.0,
            ramp_s: 0.0,
        };
        let mut seg_iter = segments.iter();
        let mut next_switch = 0.0;
        let mut started = false;
        for i in 0..n {
            let t = i as f64 * Self::DT_S;
            if t >= next_switch - 1e-9 {
                // Enter the next segment (or cruise forever after the last).
                let current = if started { phase.controls(t) } else { idle };
                started = true;
                let seg = seg_iter.next();
                let (dur, to, jerk) = match seg {
                    None => (f64::INFINITY, idle, 0.0),
                    Some(Segment::Cruise { duration_s }) => (*duration_s, idle, 0.0),
                    Some(Segment::Accelerate {
                        duration_s,
                        accel_mps2,
                    }) => (
                        *duration_s,
                        Controls {
                            accel_mps2: *accel_mps2,
                            yaw_rate_rad_s: 0.0,
                        },
                        0.0,
                    ),
                    Some(Segment::Jerk {
                        duration_s,
                        jerk_mps3,
                    }) => (
                        *duration_s,
                        Controls {
                            accel_mps2: current.accel_mps2,
                            yaw_rate_rad_s: 0.0,
                        },
                        *jerk_mps3,
                    ),
                    Some(Segment::Turn {
                        duration_s,
                        radius_m,
                        accel_g,
                        direction,
                    }) => {
                        let v = s[2];
                        if v <= 0.1 {
                            return Err(SimError::Scenario(format!(
                                "a turn segment starting at t = {t:.1} s needs the vehicle moving (speed {v:.2} m/s)"
                            )));
                        }
                        let rate = match (radius_m, accel_g) {
                            (Some(r), _) if *r > 0.0 => v / r,
                            (None, Some(g)) if *g > 0.0 => g * G0_MPS2 / v,
                            _ => {
                                return Err(SimError::Scenario(
                                    "turn radius_m / accel_g must be positive".into(),
                                ))
                            }
                        };
                        let sign = if *direction == TurnDirection::Right {
                            1.0
                        } else {
                            -1.0
                        };
                        (
                            *duration_s,
                            Controls {
                                accel_mps2: 0.0,
                                yaw_rate_rad_s: sign * rate,
                            },
                            0.0,
                        )
                    }
                };
                if dur.is_nan() || dur <= 0.0 {
                    return Err(SimError::Scenario(format!(
                        "a motion segment has duration {dur} s; it must be positive"
                    )));
                }
                phase = Phase {
                    t0: t,
                    t1: t + dur,
                    from: current,
                    to,
                    jerk_mps3: jerk,
                    ramp_s: transition_s.min(dur),
                };
                next_switch = phase.t1;
            }
            let c = phase.controls(t);
            let (sin, cos) = s[3].sin_cos();
            let pos = Vector3::new(s[0], s[1], 0.0);
            let vel = Vector3::new(s[2] * sin, s[2] * cos, 0.0);
            let acc = Vector3::new(
                c.accel_mps2 * sin + s[2] * c.yaw_rate_rad_s * cos,
                c.accel_mps2 * cos - s[2] * c.yaw_rate_rad_s * sin,
                0.0,
            );
            rows.push([pos, vel, acc]);
            // RK4 step with the time-varying controls.
            let h = Self::DT_S;
            let k1 = derivative(&s, phase.controls(t));
            let k2 = derivative(&add(&s, &k1, h / 2.0), phase.controls(t + h / 2.0));
            let k3 = derivative(&add(&s, &k2, h / 2.0), phase.controls(t + h / 2.0));
            let k4 = derivative(&add(&s, &k3, h), phase.controls(t + h));
            for j in 0..4 {
                s[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
            if s[2] < 0.0 {
                return Err(SimError::Scenario(format!(
                    "the motion reverses at t = {t:.2} s (speed below zero): shorten the braking segment"
                )));
            }
        }
        Ok(Self {
            origin_ecef: origin.to_ecef(),
            enu_to_ecef: enu_rotation(origin).transpose(),
            rows,
        })
    }

    fn state(&self, t_s: f64) -> RxState {
        let last = self.rows.len() - 2;
        let x = (t_s / Self::DT_S).max(0.0);
        let i = (x.floor() as usize).min(last);
        let u = (x - i as f64).clamp(0.0, 1.0);
        let [p0, v0, a0] = self.rows[i];
        let [p1, v1, a1] = self.rows[i + 1];
        let (p, v, a) = quintic_hermite(&p0, &v0, &a0, &p1, &v1, &a1, Self::DT_S, u);
        RxState {
            pos_m: self.origin_ecef + self.enu_to_ecef * p,
            vel_mps: self.enu_to_ecef * v,
            acc_mps2: self.enu_to_ecef * a,
        }
    }
}

fn add(s: &PlaneState, k: &PlaneState, h: f64) -> PlaneState {
    [
        s[0] + h * k[0],
        s[1] + h * k[1],
        s[2] + h * k[2],
        s[3] + h * k[3],
    ]
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
    fn spline_is_exact_for_a_straight_line_and_interpolates_knots() {
        let t: Vec<f64> = (0..10).map(|i| f64::from(i) * 0.5).collect();
        let y: Vec<f64> = t.iter().map(|&t| 3.0 + 2.0 * t).collect();
        let s = CubicSpline::new(t, y);
        for &x in &[0.1, 1.3, 4.4] {
            let (v, d, dd) = s.eval(x);
            assert!((v - (3.0 + 2.0 * x)).abs() < 1e-12);
            assert!((d - 2.0).abs() < 1e-12);
            assert!(dd.abs() < 1e-12);
        }
    }

    #[test]
    fn circle_has_the_commanded_centripetal_acceleration() {
        let origin = Llh::from_degrees(37.0, 127.0, 50.0);
        let segs = vec![Segment::Turn {
            duration_s: 10.0,
            radius_m: None,
            accel_g: Some(5.0),
            direction: TurnDirection::Left,
        }];
        let m = MotionTable::integrate(&origin, 0.0, 60.0, 0.5, &segs, 12.0)
            .unwrap_or_else(|e| panic!("{e}"));
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
    }

    #[test]
    fn acceleration_is_continuous_through_a_transition() {
        let origin = Llh::from_degrees(10.0, 20.0, 0.0);
        let segs = vec![
            Segment::Cruise { duration_s: 1.0 },
            Segment::Accelerate {
                duration_s: 5.0,
                accel_mps2: 10.0,
            },
        ];
        let m = MotionTable::integrate(&origin, 0.0, 5.0, 0.5, &segs, 8.0)
            .unwrap_or_else(|e| panic!("{e}"));
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
