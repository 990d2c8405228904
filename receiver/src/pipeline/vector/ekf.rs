//! The navigation filter of vector tracking: an extended Kalman filter of 8 states, ECEF
//! position and velocity and the receiver clock bias and drift,
//! `x = [r (m), v (m/s), b = c dt_rx (m), d = c dt_rx' (m/s)]`.
//!
//! # Process model
//!
//! White-noise acceleration (a constant-velocity model, Brown & Hwang 9.3), per ECEF axis
//! with acceleration power spectral density `q` (m^2/s^3), and the two-state clock of a
//! crystal oscillator described by its Allan-variance coefficients `h0` (white frequency) and
//! `h-2` (random-walk frequency) (Brown & Hwang 9.3, eqs. 9.3.10-9.3.12):
//!
//! ```text
//! F = [I  dt I  0  0 ]      Q_axis  = q [dt^3/3  dt^2/2; dt^2/2  dt]
//!     [0   I    0  0 ]      Q_clock = c^2 [Sf dt + Sg dt^3/3   Sg dt^2/2; Sg dt^2/2   Sg dt]
//!     [0   0    1  dt]      Sf = h0 / 2,  Sg = 2 pi^2 h-2
//!     [0   0    0  1 ]
//! ```
//!
//! # With an INS
//!
//! The INS measures the motion: over an interval its velocity change `dv` (from the INS
//! file's velocities) drives the prediction, `r += v dt + dv dt / 2`, `v += dv`, and the
//! process noise is that of the INS's velocity error (`[vector] ins_accel_psd_m2_s3`: an
//! accelerometer bias of 1 mg grows 0.01 m/s per second, a late INS output errs by its latency times the change of acceleration), not of the vehicle's acceleration.
//! The velocity state is then the INS velocity corrected by the measurements: its error is
//! a random walk the Dopplers follow (no accelerometer-bias states: the INS log gives no
//! attitude, and a body-frame bias turns with the vehicle).
//!
//! # Measurement update
//!
//! Linearised rows `z - h(x_prior) = H dx + e`, `e ~ N(0, R)` (built in `measure`). Every row's
//! normalised innovation squared against the prior, `NIS_i = nu_i^2 / (H_i P H_i^T + R_i)`,
//! is tested against the chi-square quantile of 1 degree of freedom at the gate's false-alarm
//! probability; a row above it is excluded (a channel whose measurement disagrees with the
//! filter and the other channels: one bad channel cannot drag the rest). The admitted rows
//! update the state together: `S = H P H^T + R`, `K = P H^T S^-1`, `x += K nu`, and the
//! covariance in Joseph form `P = (I - K H) P (I - K H)^T + K R K^T`.
//!
//! A whole-millisecond step of the receiver clock (the navigation processor keeps it within
//! 0.5 ms of GPS time) moves every pseudorange by the same 299.8 km: when the median code
//! innovation is beyond [`CLOCK_STEP_M`] the clock bias takes it before the test.

use gpsrx_core::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::pvt::PvtSolution;
use nalgebra::{DMatrix, DVector, SMatrix, SVector, Vector3};

/// Number of states.
pub const N_STATES: usize = 8;
/// State vector.
pub type State = SVector<f64, N_STATES>;
/// State covariance.
pub type Covariance = SMatrix<f64, N_STATES, N_STATES>;
/// Index of the clock bias (m).
pub const BIAS: usize = 6;
/// Index of the clock drift (m/s).
pub const DRIFT: usize = 7;
/// A median code innovation beyond this is a receiver clock step, m (module docs).
pub const CLOCK_STEP_M: f64 = 3000.0;

/// The oscillator of the receiver clock by its Allan-variance coefficients.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClockModel {
    /// White frequency noise `h0`, s.
    pub h0: f64,
    /// Random-walk frequency noise `h-2`, 1/s.
    pub h_2: f64,
}

impl ClockModel {
    /// A temperature-compensated crystal oscillator (TCXO): `h0` = 2e-19 s, `h-2` = 2e-20 /s
    /// (Brown & Hwang, Table 9.2).
    pub const TCXO: ClockModel = ClockModel {
        h0: 2e-19,
        h_2: 2e-20,
    };
}

/// The filter's tuning.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterParams {
    /// Acceleration power spectral density per ECEF axis, m^2/s^3.
    pub accel_psd_m2_s3: f64,
    /// Receiver clock.
    pub clock: ClockModel,
    /// Chi-square gate of one row (1 degree of freedom).
    pub gate: f64,
}

/// What kind of measurement a row is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowKind {
    /// Pseudorange, m.
    Code,
    /// Pseudorange rate from the Doppler, m/s.
    Doppler,
}

/// One linearised measurement: `innovation = z - h(x_prior) = h . dx + e`, `var(e) = var`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Satellite.
    pub prn: u8,
    /// Pseudorange or Doppler.
    pub kind: RowKind,
    /// `z - h(x_prior)`, m or m/s.
    pub innovation: f64,
    /// The row of the measurement matrix.
    pub h: SVector<f64, N_STATES>,
    /// Measurement variance, m^2 or (m/s)^2.
    pub var: f64,
}

/// What one update did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UpdateOutcome {
    /// Rows that updated the state.
    pub admitted: usize,
    /// Pseudorange rows among them.
    pub admitted_code: usize,
    /// Rows excluded by the innovation test: satellite, kind, NIS.
    pub rejected: Vec<(u8, RowKind, f64)>,
    /// The clock bias took a receiver clock step of this many metres.
    pub clock_step_m: Option<f64>,
}

/// The 8-state navigation filter (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct NavFilter {
    x: State,
    p: Covariance,
    params: FilterParams,
}

impl NavFilter {
    /// A filter at state `x` with covariance `p`.
    pub fn new(x: State, p: Covariance, params: FilterParams) -> Self {
        Self { x, p, params }
    }

    /// A filter started from a least-squares fix: its position, clock bias and their
    /// covariance, its velocity and clock drift and theirs (a velocity of 10 m/s sigma and a
    /// drift of 100 m/s sigma when the fix has none).
    pub fn from_solution(sol: &PvtSolution, params: FilterParams) -> Self {
        let mut x = State::zeros();
        let mut p = Covariance::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&sol.pos_ecef_m);
        x[BIAS] = sol.clock_bias_m;
        for i in 0..3 {
            for j in 0..3 {
                p[(i, j)] = sol.covariance[(i, j)];
            }
            p[(i, BIAS)] = sol.covariance[(i, 3)];
            p[(BIAS, i)] = sol.covariance[(3, i)];
        }
        p[(BIAS, BIAS)] = sol.covariance[(3, 3)];
        match (sol.vel_ecef_mps, sol.clock_drift_mps, sol.vel_covariance) {
            (Some(v), Some(d), Some(c)) => {
                x.fixed_rows_mut::<3>(3).copy_from(&v);
                x[DRIFT] = d;
                for i in 0..3 {
                    for j in 0..3 {
                        p[(3 + i, 3 + j)] = c[(i, j)];
                    }
                    p[(3 + i, DRIFT)] = c[(i, 3)];
                    p[(DRIFT, 3 + i)] = c[(3, i)];
                }
                p[(DRIFT, DRIFT)] = c[(3, 3)];
            }
            _ => {
                for i in 3..6 {
                    p[(i, i)] = 100.0;
                }
                p[(DRIFT, DRIFT)] = 1e4;
            }
        }
        // A covariance that is not finite (a degenerate fix) starts wide instead.
        if p.iter().any(|v| !v.is_finite()) {
            p = Covariance::from_diagonal(&SVector::from([
                100.0, 100.0, 100.0, 100.0, 100.0, 100.0, 1e4, 1e4,
            ]));
        }
        Self { x, p, params }
    }

    /// The state.
    pub fn state(&self) -> &State {
        &self.x
    }

    /// The covariance.
    pub fn covariance(&self) -> &Covariance {
        &self.p
    }

    /// Position, ECEF m.
    pub fn position_m(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(0).into()
    }

    /// Velocity, ECEF m/s.
    pub fn velocity_mps(&self) -> Vector3<f64> {
        self.x.fixed_rows::<3>(3).into()
    }

    /// 3-D position sigma, m: `sqrt(trace(P_rr))`.
    pub fn position_sigma_m(&self) -> f64 {
        (self.p[(0, 0)] + self.p[(1, 1)] + self.p[(2, 2)])
            .max(0.0)
            .sqrt()
    }

    /// The state transition `F` over `dt_s` (module docs).
    pub fn transition(dt_s: f64) -> Covariance {
        let mut f = Covariance::identity();
        for i in 0..3 {
            f[(i, 3 + i)] = dt_s;
        }
        f[(BIAS, DRIFT)] = dt_s;
        f
    }

    /// The process noise `Q` over `dt_s` (module docs).
    pub fn process_noise(params: &FilterParams, dt_s: f64) -> Covariance {
        let dt = dt_s.abs();
        let q = params.accel_psd_m2_s3;
        let mut m = Covariance::zeros();
        for i in 0..3 {
            m[(i, i)] = q * dt.powi(3) / 3.0;
            m[(i, 3 + i)] = q * dt * dt / 2.0;
            m[(3 + i, i)] = q * dt * dt / 2.0;
            m[(3 + i, 3 + i)] = q * dt;
        }
        let c2 = SPEED_OF_LIGHT_MPS * SPEED_OF_LIGHT_MPS;
        let sf = params.clock.h0 / 2.0;
        let sg = 2.0 * std::f64::consts::PI.powi(2) * params.clock.h_2;
        m[(BIAS, BIAS)] = c2 * (sf * dt + sg * dt.powi(3) / 3.0);
        m[(BIAS, DRIFT)] = c2 * sg * dt * dt / 2.0;
        m[(DRIFT, BIAS)] = m[(BIAS, DRIFT)];
        m[(DRIFT, DRIFT)] = c2 * sg * dt;
        m
    }

    /// The state `dt_s` ahead, without changing the filter.
    pub fn predicted_state(&self, dt_s: f64) -> State {
        Self::transition(dt_s) * self.x
    }

    /// Propagates state and covariance by `dt_s`.
    pub fn predict(&mut self, dt_s: f64) {
        self.predict_driven(dt_s, &Vector3::zeros(), self.params.accel_psd_m2_s3);
    }

    /// Propagates state and covariance by `dt_s` with the velocity change `dv_mps` an INS
    /// measured over it (module docs, "With an INS"): `r += v dt + dv dt / 2`, `v += dv`, and
    /// the process noise of `accel_psd_m2_s3` (the INS's velocity error, not the vehicle's
    /// motion). A non-finite `dv_mps` counts as none.
    pub fn predict_driven(&mut self, dt_s: f64, dv_mps: &Vector3<f64>, accel_psd_m2_s3: f64) {
        if !(dt_s.is_finite() && dt_s != 0.0) {
            return;
        }
        let f = Self::transition(dt_s);
        self.x = f * self.x;
        if dv_mps.iter().all(|v| v.is_finite()) {
            for i in 0..3 {
                self.x[i] += 0.5 * dv_mps[i] * dt_s;
                self.x[3 + i] += dv_mps[i];
            }
        }
        let params = FilterParams {
            accel_psd_m2_s3,
            ..self.params
        };
        self.p = f * self.p * f.transpose() + Self::process_noise(&params, dt_s);
        self.p = 0.5 * (self.p + self.p.transpose());
    }

    /// The innovation variance `H P H^T + R` of a row.
    pub fn innovation_var(&self, row: &Row) -> f64 {
        (row.h.transpose() * self.p * row.h)[(0, 0)] + row.var
    }

    /// Updates with `rows` (module docs: clock step, innovation test, joint update). Rows
    /// with a non-finite value are dropped.
    pub fn update(&mut self, rows: &[Row]) -> UpdateOutcome {
        let mut rows: Vec<Row> = rows
            .iter()
            .filter(|r| {
                r.innovation.is_finite() && r.var > 0.0 && r.h.iter().all(|v| v.is_finite())
            })
            .copied()
            .collect();
        let mut out = UpdateOutcome::default();
        if let Some(step) = self.clock_step(&rows) {
            self.x[BIAS] += step;
            for r in rows.iter_mut().filter(|r| r.kind == RowKind::Code) {
                r.innovation -= step;
            }
            out.clock_step_m = Some(step);
        }
        let mut admitted: Vec<Row> = Vec::with_capacity(rows.len());
        for r in rows {
            let nis = r.innovation * r.innovation / self.innovation_var(&r);
            if nis <= self.params.gate {
                admitted.push(r);
            } else {
                out.rejected.push((r.prn, r.kind, nis));
            }
        }
        out.admitted = admitted.len();
        out.admitted_code = admitted.iter().filter(|r| r.kind == RowKind::Code).count();
        if !admitted.is_empty() {
            self.apply(&admitted);
        }
        out
    }

    /// The median code innovation when it is a clock step (module docs).
    fn clock_step(&self, rows: &[Row]) -> Option<f64> {
        let mut code: Vec<f64> = rows
            .iter()
            .filter(|r| r.kind == RowKind::Code)
            .map(|r| r.innovation)
            .collect();
        if code.is_empty() {
            return None;
        }
        code.sort_by(f64::total_cmp);
        let median = code[code.len() / 2];
        (median.abs() > CLOCK_STEP_M).then_some(median)
    }

    /// The joint update with the admitted rows (Joseph form).
    fn apply(&mut self, rows: &[Row]) {
        let m = rows.len();
        let mut h = DMatrix::<f64>::zeros(m, N_STATES);
        let mut r = DMatrix::<f64>::zeros(m, m);
        let mut nu = DVector::<f64>::zeros(m);
        for (i, row) in rows.iter().enumerate() {
            h.row_mut(i).copy_from(&row.h.transpose());
            r[(i, i)] = row.var;
            nu[i] = row.innovation;
        }
        let p = DMatrix::from_column_slice(N_STATES, N_STATES, self.p.as_slice());
        let s = &h * &p * h.transpose() + &r;
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let k = &p * h.transpose() * s_inv;
        let dx = &k * nu;
        let i_kh = DMatrix::<f64>::identity(N_STATES, N_STATES) - &k * &h;
        let p_new = &i_kh * &p * i_kh.transpose() + &k * &r * k.transpose();
        if dx.iter().chain(p_new.iter()).any(|v| !v.is_finite()) {
            return;
        }
        for i in 0..N_STATES {
            self.x[i] += dx[i];
            for j in 0..N_STATES {
                self.p[(i, j)] = 0.5 * (p_new[(i, j)] + p_new[(j, i)]);
            }
        }
    }
}
