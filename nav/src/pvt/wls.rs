//! Iterative weighted least squares for position and receiver clock, seed 001 eqs. 3.3-3.7,
//! with landmark ranges as stochastic constraints (eqs. 3.9-3.12).
//!
//! Gauss-Markov model y = A xi + e, e ~ (0, sigma0^2 P^-1) (eq. 3.3): y holds the
//! observed-minus-computed pseudoranges, each row of A is [-l^T, 1] with l the unit vector from
//! the receiver to the satellite, P = diag(1/sigma_i^2) from [`super::Weighting`]. Landmark
//! rows z0 = K xi + e0 are [u^T, 0] (u from the landmark to the receiver, no clock term) with
//! weight 1/sigma_m^2. The update is xi = (N + K^T P0 K)^-1 (c + K^T P0 z0) (eq. 3.4 / 3.10),
//! added to the estimate (eq. 3.5) until the position update is below 0.1 mm.
//! Afterwards sigma0^2 = (e^T P e + e0^T P0 e0) / (n + l - 4) (eq. 3.6 / 3.11) and
//! D{xi} = sigma0^2 (N + K^T P0 K)^-1 (eq. 3.7 / 3.12). With no redundancy sigma0 is set to 1
//! (the a-priori covariance is reported).

use super::landmark::Landmark;
use super::model::{predict, Predicted, PreparedSat, PvtOptions};
use super::PvtError;
use crate::frames::Vector3;
use crate::time::GpsTime;
use nalgebra::{Matrix4, Vector4};

/// Unknowns: x, y, z, clock bias.
pub const N_UNKNOWNS: usize = 4;
/// Position update below which the iteration has converged, m.
pub const CONVERGED_STEP_M: f64 = 1e-4;
/// Position update below which the position counts as known (elevation mask and atmosphere
/// switched on), m.
pub const POSITION_KNOWN_STEP_M: f64 = 1000.0;
/// Geometry whose (unweighted) GDOP exceeds this is reported as singular.
pub const MAX_GDOP: f64 = 1.0e4;
/// A position estimate further than this from the Earth's centre has diverged, m.
const MAX_RADIUS_M: f64 = 1.0e8;

/// Everything one epoch's least-squares runs share.
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    /// Receive time by the receiver clock.
    pub epoch_rx_time: GpsTime,
    /// Validated satellites.
    pub sats: &'a [PreparedSat],
    /// Landmark ranges.
    pub landmarks: &'a [Landmark],
    /// Options.
    pub opts: &'a PvtOptions,
    /// Starting position and clock bias (None: Earth's centre, 0).
    pub start: Option<(Vector3<f64>, f64)>,
}

/// A converged least-squares fix.
#[derive(Debug, Clone, PartialEq)]
pub struct Fix {
    /// Position, ECEF, m.
    pub pos_m: Vector3<f64>,
    /// Receiver clock bias, m.
    pub clock_bias_m: f64,
    /// Indices (into the prepared satellites) of the satellites used.
    pub used: Vec<usize>,
    /// Indices of satellites dropped by the elevation mask.
    pub masked: Vec<usize>,
    /// Model of each used satellite at the solution.
    pub predictions: Vec<Predicted>,
    /// Post-fit residuals of the used satellites, m.
    pub sat_residuals_m: Vec<f64>,
    /// Post-fit landmark residuals, m.
    pub landmark_residuals_m: Vec<f64>,
    /// Design rows of all observations (satellites first, then landmarks), unweighted.
    pub geometry_rows: Vec<[f64; 4]>,
    /// A-priori sigma of each observation, same order, m.
    pub sigmas_m: Vec<f64>,
    /// (A^T P A)^-1 with the a-priori weights.
    pub n_inv: Matrix4<f64>,
    /// Weighted sum of squared residuals e^T P e (+ e0^T P0 e0).
    pub wsse: f64,
    /// Degrees of freedom n + l - 4.
    pub dof: usize,
    /// sigma0 (1 when dof = 0).
    pub sigma0: f64,
    /// sigma0^2 N^-1, m^2.
    pub covariance: Matrix4<f64>,
    /// Iterations used.
    pub iterations: usize,
}

/// Unweighted GDOP of a set of design rows, or infinity if singular.
pub fn gdop_of(rows: &[[f64; 4]]) -> f64 {
    let mut g = Matrix4::zeros();
    for r in rows {
        let a = Vector4::from(*r);
        g += a * a.transpose();
    }
    match g.try_inverse() {
        Some(inv) if inv.trace() >= 0.0 && inv.trace().is_finite() => inv.trace().sqrt(),
        _ => f64::INFINITY,
    }
}

/// Runs the iteration with the satellites flagged in `active` (same length as `ctx.sats`).
pub fn solve_position(ctx: &Context<'_>, active: &[bool]) -> Result<Fix, PvtError> {
    let opts = ctx.opts;
    let (mut pos, mut clock) = ctx.start.unwrap_or((Vector3::zeros(), 0.0));
    let mut known = ctx.start.is_some();
    let mask_rad = opts.elevation_mask_deg.to_radians();
    let tow = ctx.epoch_rx_time.tow_s;
    let mut last_step = f64::INFINITY;
    for iteration in 1..=opts.max_iterations {
        let mut rows: Vec<[f64; 4]> = Vec::new();
        let mut sigmas = Vec::new();
        let mut y = Vec::new();
        let mut used = Vec::new();
        let mut masked = Vec::new();
        let mut predictions = Vec::new();
        for (i, sat) in ctx.sats.iter().enumerate() {
            if !active.get(i).copied().unwrap_or(false) {
                continue;
            }
            let p = predict(sat, &pos, known, opts, tow);
            if known && p.el_rad < mask_rad {
                masked.push(i);
                continue;
            }
            rows.push([-p.los.x, -p.los.y, -p.los.z, 1.0]);
            sigmas.push(opts.weighting.sigma_m(p.el_rad, sat.cn0_dbhz));
            y.push(sat.pseudorange_m - p.range_model_m - clock);
            used.push(i);
            predictions.push(p);
        }
        let n_sat = used.len();
        for lm in ctx.landmarks {
            let d = pos - lm.ecef_m;
            let rho = d.norm();
            let u = if rho > 0.0 { d / rho } else { Vector3::zeros() };
            rows.push([u.x, u.y, u.z, 0.0]);
            sigmas.push(lm.sigma_m);
            y.push(lm.range_m - rho);
        }
        if rows.len() < N_UNKNOWNS || n_sat == 0 {
            return Err(PvtError::TooFewObservations {
                available: rows.len(),
                satellites: n_sat,
                landmarks: ctx.landmarks.len(),
                required: N_UNKNOWNS,
                stage: "elevation mask",
            });
        }
        let gdop = gdop_of(&rows);
        if gdop > MAX_GDOP {
            return Err(PvtError::SingularGeometry { gdop });
        }
        let mut n = Matrix4::zeros();
        let mut c = Vector4::zeros();
        for ((r, s), yi) in rows.iter().zip(&sigmas).zip(&y) {
            let a = Vector4::from(*r);
            let w = 1.0 / (s * s);
            n += a * a.transpose() * w;
            c += a * (w * yi);
        }
        let n_inv = n.try_inverse().ok_or(PvtError::SingularGeometry { gdop })?;
        let dx = n_inv * c;
        pos += Vector3::new(dx[0], dx[1], dx[2]);
        clock += dx[3];
        last_step = Vector3::new(dx[0], dx[1], dx[2]).norm();
        if !(pos.iter().all(|v| v.is_finite()) && clock.is_finite()) || pos.norm() > MAX_RADIUS_M {
            return Err(PvtError::Diverged {
                iterations: iteration,
                last_step_m: last_step,
            });
        }
        if known && last_step < CONVERGED_STEP_M {
            // Post-fit residuals e = y - A xi (the model at the final point differs from this
            // by the update squared over the range, < 1e-15 m).
            let resid: Vec<f64> = rows
                .iter()
                .zip(&y)
                .map(|(r, yi)| yi - Vector4::from(*r).dot(&dx))
                .collect();
            let wsse: f64 = resid
                .iter()
                .zip(&sigmas)
                .map(|(e, s)| (e / s) * (e / s))
                .sum();
            let dof = rows.len() - N_UNKNOWNS;
            let sigma0 = if dof > 0 {
                (wsse / dof as f64).sqrt()
            } else {
                1.0
            };
            return Ok(Fix {
                pos_m: pos,
                clock_bias_m: clock,
                used,
                masked,
                predictions,
                sat_residuals_m: resid[..n_sat].to_vec(),
                landmark_residuals_m: resid[n_sat..].to_vec(),
                geometry_rows: rows,
                sigmas_m: sigmas,
                n_inv,
                wsse,
                dof,
                sigma0,
                covariance: n_inv * (sigma0 * sigma0),
                iterations: iteration,
            });
        }
        if !known && last_step < POSITION_KNOWN_STEP_M {
            known = true;
        }
    }
    Err(PvtError::Diverged {
        iterations: opts.max_iterations,
        last_step_m: last_step,
    })
}
