//! Receiver trajectories: where the antenna is, how fast it moves and how it accelerates, at any
//! instant. Every kind is continuous in position, velocity and acceleration (C2), so the signal's
//! phases are smooth at the sample level.
//!
//! - static: a fixed ECEF point;
//! - CSV: natural cubic splines through the given positions (C2 by construction);
//! - built-in motions (`motion`): vehicle manoeuvres (cruise, accelerate, jerk, turn, stop) on
//!   roads of given grade in the local level (ENU) frame of the start point, integrated with RK4
//!   at 1 ms and evaluated between steps by quintic Hermite interpolation of position, velocity
//!   and acceleration (C2). The local frame is a plane tangent at the start, so the height above
//!   the ellipsoid grows as `d^2 / (2 R)` over a distance `d` (0.8 m at 3 km) on top of the
//!   climb the grade gives.

mod motion;
mod segment_plan;

pub use motion::{MotionTable, VehicleState};

use crate::sim::scenario::ReceiverConfig;
use crate::sim::SimError;
use gpsrx_nav::frames::{Llh, Vector3};
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
            ReceiverConfig::Motion { .. } => Ok(Self::Motion(MotionTable::from_config(
                cfg,
                duration_s + 2.0,
                MotionTable::DT_S,
            )?)),
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
