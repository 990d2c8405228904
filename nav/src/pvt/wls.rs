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
//!
//! Once the position is known to 1 km the iteration is Newton's with Levenberg-Marquardt
//! damping (Nocedal & Wright 10.3): xi = (H + lambda tr(H)/4 I)^-1 c with
//! H = N + K^T P0 K - sum_j (e0_j / sigma_j^2) (I - u_j u_j^T) / rho_j the Hessian of
//! e^T P e / 2 (the landmark ranges' curvature; the satellites' is 1e-6 of it and left out).
//! lambda = 0 as long as every step lowers the weighted cost, raised tenfold from 1e-3 after a
//! step that does not and lowered tenfold after one that does. With 3 satellites and a landmark
//! the noisy satellite solution curve can miss the landmark's range sphere: there is no exact
//! solution, the Gauss-Newton step oscillates, and the least-squares point is where the curve
//! grazes the sphere (u perpendicular to the curve, A^T P A singular). There the curvature
//! term keeps H positive definite and D{xi} = sigma0^2 H^-1 (the observed information) is the
//! covariance; where the observations are consistent (e0 = 0) H = N and this is eq. 3.12.
//! DOP is geometric (A^T A)^-1 unless its PDOP exceeds [`PvtOptions::max_pdop`]; then it is
//! taken from the cofactor w H^-1 (w the mean weight) and the fix is refused as
//! [`PvtError::WeakGeometry`] only when that PDOP exceeds the limit too. GDOP of A^T A above
//! [`MAX_GDOP`] during the cold start is [`PvtError::SingularGeometry`].

use super::dop::dop_enu;
use super::landmark::Landmark;
use super::model::{predict, Predicted, PreparedSat, PvtOptions};
use super::PvtError;
use crate::frames::{Llh, Vector3};
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
/// First Levenberg-Marquardt damping (relative to tr(N)/4) after a step that raised the cost.
const LAMBDA_FIRST: f64 = 1e-3;
/// Damping above which no step lowers the cost any more: the estimate is a minimum to
/// machine precision.
const LAMBDA_MAX: f64 = 1e12;
/// Longest step from a saddle point along the direction of negative curvature, m.
const MAX_SADDLE_STEP_M: f64 = 100.0;
/// Saddle escapes per iteration.
const MAX_SADDLE_ESCAPES: usize = 3;
/// Relative cost decrease below which an accepted step ends the iteration.
const COST_RTOL: f64 = 1e-12;

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
    /// Starting position and clock bias (None: Earth's centre, 0, then, with landmarks,
    /// around them: [`super::landmark::solve_from_landmarks`]).
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
    /// (A^T P A)^-1 with the a-priori weights (H^-1, module docs, where the landmark ranges
    /// are not met exactly).
    pub n_inv: Matrix4<f64>,
    /// DOP at the solution (geometric, or from the observed information, module docs).
    pub dop: super::dop::Dop,
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

/// The observation equations linearised at one position and clock bias.
#[derive(Debug, Clone)]
struct Linearized {
    rows: Vec<[f64; 4]>,
    sigmas: Vec<f64>,
    /// Observed minus computed, m.
    y: Vec<f64>,
    used: Vec<usize>,
    masked: Vec<usize>,
    predictions: Vec<Predicted>,
    /// Per landmark: (I - u u^T) e0 / (sigma^2 rho), the range's curvature term of the Hessian.
    curvature: Vec<nalgebra::Matrix3<f64>>,
}

impl Linearized {
    /// Weighted cost e^T P e at the linearisation point.
    fn cost(&self) -> f64 {
        self.y
            .iter()
            .zip(&self.sigmas)
            .map(|(e, s)| (e / s) * (e / s))
            .sum()
    }

    /// Normal matrix N = A^T P A and right-hand side A^T P y.
    fn normal(&self) -> (Matrix4<f64>, Vector4<f64>) {
        let mut n = Matrix4::zeros();
        let mut c = Vector4::zeros();
        for ((r, s), yi) in self.rows.iter().zip(&self.sigmas).zip(&self.y) {
            let a = Vector4::from(*r);
            let w = 1.0 / (s * s);
            n += a * a.transpose() * w;
            c += a * (w * yi);
        }
        (n, c)
    }

    /// Hessian of e^T P e / 2 (module docs) and the right-hand side A^T P y.
    fn hessian(&self) -> (Matrix4<f64>, Vector4<f64>) {
        let (mut h, c) = self.normal();
        for k in &self.curvature {
            let mut block = h.fixed_view_mut::<3, 3>(0, 0);
            block -= k;
        }
        (h, c)
    }
}

/// Linearises the active satellites and all landmarks at (`pos`, `clock`).
fn linearize(
    ctx: &Context<'_>,
    active: &[bool],
    pos: &Vector3<f64>,
    clock: f64,
    known: bool,
) -> Result<Linearized, PvtError> {
    let opts = ctx.opts;
    let mask_rad = opts.elevation_mask_deg.to_radians();
    let mut lin = Linearized {
        rows: Vec::new(),
        sigmas: Vec::new(),
        y: Vec::new(),
        used: Vec::new(),
        masked: Vec::new(),
        predictions: Vec::new(),
        curvature: Vec::new(),
    };
    for (i, sat) in ctx.sats.iter().enumerate() {
        if !active.get(i).copied().unwrap_or(false) {
            continue;
        }
        let p = predict(sat, pos, known, opts, ctx.epoch_rx_time.tow_s);
        if known && p.el_rad < mask_rad {
            lin.masked.push(i);
            continue;
        }
        lin.rows.push([-p.los.x, -p.los.y, -p.los.z, 1.0]);
        lin.sigmas
            .push(opts.weighting.sigma_m(p.el_rad, sat.cn0_dbhz));
        lin.y.push(sat.pseudorange_m - p.range_model_m - clock);
        lin.used.push(i);
        lin.predictions.push(p);
    }
    for lm in ctx.landmarks {
        let d = pos - lm.ecef_m;
        let rho = d.norm();
        let u = if rho > 0.0 { d / rho } else { Vector3::zeros() };
        lin.rows.push([u.x, u.y, u.z, 0.0]);
        lin.sigmas.push(lm.sigma_m);
        lin.y.push(lm.range_m - rho);
        if rho > 0.0 {
            let e0 = lm.range_m - rho;
            let k = (nalgebra::Matrix3::identity() - u * u.transpose())
                * (e0 / (lm.sigma_m * lm.sigma_m * rho));
            lin.curvature.push(k);
        }
    }
    if lin.rows.len() < N_UNKNOWNS || lin.used.is_empty() {
        return Err(PvtError::TooFewObservations {
            available: lin.rows.len(),
            satellites: lin.used.len(),
            landmarks: ctx.landmarks.len(),
            required: N_UNKNOWNS,
            stage: "elevation mask",
        });
    }
    Ok(lin)
}

/// Runs the iteration with the satellites flagged in `active` (same length as `ctx.sats`),
/// from `ctx.start`, or without one from the Earth's centre, and with landmarks, when that
/// fails, from around the landmarks ([`super::landmark::solve_from_landmarks`]).
pub fn solve_position(ctx: &Context<'_>, active: &[bool]) -> Result<Fix, PvtError> {
    match ctx.start {
        Some(start) => iterate(ctx, active, start, true),
        None if ctx.landmarks.is_empty() => iterate(ctx, active, (Vector3::zeros(), 0.0), false),
        None => iterate(ctx, active, (Vector3::zeros(), 0.0), false)
            .or_else(|_| super::landmark::solve_from_landmarks(ctx, active)),
    }
}

/// The damped Gauss-Newton iteration from (`start`), `known` when the start is within 1 km
/// (otherwise undamped steps until the update falls below [`POSITION_KNOWN_STEP_M`]).
pub fn iterate(
    ctx: &Context<'_>,
    active: &[bool],
    start: (Vector3<f64>, f64),
    known: bool,
) -> Result<Fix, PvtError> {
    let (mut pos, mut clock) = start;
    let mut known = known;
    let mut lin = linearize(ctx, active, &pos, clock, known)?;
    let mut lambda = 0.0;
    let mut escapes = 0;
    let mut last_step = f64::INFINITY;
    for iteration in 1..=ctx.opts.max_iterations {
        if !known && gdop_of(&lin.rows) > MAX_GDOP {
            return Err(PvtError::SingularGeometry {
                gdop: gdop_of(&lin.rows),
            });
        }
        let (n, c) = if known { lin.hessian() } else { lin.normal() };
        let damped = n + Matrix4::identity() * (lambda * n.trace() / 4.0);
        let dx = damped.try_inverse().ok_or(PvtError::SingularGeometry {
            gdop: gdop_of(&lin.rows),
        })? * c;
        let step = Vector3::new(dx[0], dx[1], dx[2]);
        let (trial_pos, trial_clock) = (pos + step, clock + dx[3]);
        if !(trial_pos.iter().all(|v| v.is_finite()) && trial_clock.is_finite())
            || trial_pos.norm() > MAX_RADIUS_M
        {
            return Err(PvtError::Diverged {
                iterations: iteration,
                last_step_m: step.norm(),
            });
        }
        if !known {
            (pos, clock, last_step) = (trial_pos, trial_clock, step.norm());
            known = last_step < POSITION_KNOWN_STEP_M;
            lin = linearize(ctx, active, &pos, clock, known)?;
            continue;
        }
        let trial = linearize(ctx, active, &trial_pos, trial_clock, true)?;
        let comparable = trial.used == lin.used;
        let (before, after) = (lin.cost(), trial.cost());
        if !comparable || after <= before {
            (pos, clock, last_step, lin) = (trial_pos, trial_clock, step.norm(), trial);
            lambda = if lambda > 1e-9 { lambda / 10.0 } else { 0.0 };
            let stalled = comparable && before - after <= COST_RTOL * (1.0 + before);
            if last_step < CONVERGED_STEP_M || stalled {
                match escape_saddle(ctx, active, &lin, &pos, clock, &mut escapes)? {
                    Some((p, c, l)) => (pos, clock, lin, lambda) = (p, c, l, 0.0),
                    None => return finish(ctx, lin, pos, clock, iteration),
                }
            }
        } else {
            lambda = if lambda == 0.0 {
                LAMBDA_FIRST
            } else {
                lambda * 10.0
            };
            if lambda > LAMBDA_MAX {
                match escape_saddle(ctx, active, &lin, &pos, clock, &mut escapes)? {
                    Some((p, c, l)) => (pos, clock, lin, lambda) = (p, c, l, 0.0),
                    None => return finish(ctx, lin, pos, clock, iteration),
                }
            }
        }
    }
    Err(PvtError::Diverged {
        iterations: ctx.opts.max_iterations,
        last_step_m: last_step,
    })
}

/// Leaves a saddle point of the cost: where the iteration stops with an indefinite Hessian
/// (3 satellites and a landmark: the point of the satellite curve nearest the landmark, inside
/// its range sphere, between the two solutions), steps both ways along the eigenvector of the
/// most negative eigenvalue (2^-6 to 2 times the distance where the quadratic model of the
/// cost reaches zero) and returns the lowest-cost point if it lowers the cost (at most [`MAX_SADDLE_ESCAPES`] times). None at a minimum.
fn escape_saddle(
    ctx: &Context<'_>,
    active: &[bool],
    lin: &Linearized,
    pos: &Vector3<f64>,
    clock: f64,
    escapes: &mut usize,
) -> Result<Option<(Vector3<f64>, f64, Linearized)>, PvtError> {
    let (h, _) = lin.hessian();
    let eig = h.symmetric_eigen();
    let (k, min_eig) = eig.eigenvalues.argmin();
    if min_eig >= 0.0 || *escapes >= MAX_SADDLE_ESCAPES {
        return Ok(None);
    }
    *escapes += 1;
    let v = eig.eigenvectors.column(k).into_owned();
    // Along v the cost is e^T P e + 2 min_eig t^2 to second order: zero at t0.
    let t0 = (lin.cost() / -min_eig)
        .sqrt()
        .clamp(1e-3, MAX_SADDLE_STEP_M);
    let mut best: Option<(Vector3<f64>, f64, Linearized)> = None;
    for k in -6..=1 {
        for sign in [1.0, -1.0] {
            let t = sign * t0 * 2f64.powi(k);
            let d = v * t;
            let (p, c) = (pos + Vector3::new(d[0], d[1], d[2]), clock + d[3]);
            let trial = linearize(ctx, active, &p, c, true)?;
            let lower = best.as_ref().map_or(lin.cost(), |b| b.2.cost());
            if trial.used == lin.used && trial.cost() < lower {
                best = Some((p, c, trial));
            }
        }
    }
    Ok(best)
}

/// The fix at the converged point: geometry checks, residuals, sigma0 and covariance.
fn finish(
    ctx: &Context<'_>,
    lin: Linearized,
    pos: Vector3<f64>,
    clock: f64,
    iterations: usize,
) -> Result<Fix, PvtError> {
    let (h, _) = lin.hessian();
    let h_inv = h
        .try_inverse()
        .filter(|q| (0..4).all(|i| q[(i, i)] > 0.0 && q[(i, i)].is_finite()))
        .ok_or(PvtError::SingularGeometry {
            gdop: gdop_of(&lin.rows),
        })?;
    let llh = Llh::from_ecef(&pos);
    let geometric = dop_enu(&lin.rows, &llh).filter(|d| d.pdop <= ctx.opts.max_pdop);
    let dop = match geometric {
        Some(d) => d,
        None => effective_dop(&lin, &h_inv, &llh)?,
    };
    if dop.pdop > ctx.opts.max_pdop {
        return Err(PvtError::WeakGeometry {
            pdop: dop.pdop,
            max_pdop: ctx.opts.max_pdop,
            satellites: lin.used.len(),
            landmarks: ctx.landmarks.len(),
        });
    }
    let n_inv = h_inv;
    let wsse = lin.cost();
    let dof = lin.rows.len() - N_UNKNOWNS;
    let sigma0 = if dof > 0 {
        (wsse / dof as f64).sqrt()
    } else {
        1.0
    };
    let n_sat = lin.used.len();
    Ok(Fix {
        pos_m: pos,
        clock_bias_m: clock,
        sat_residuals_m: lin.y[..n_sat].to_vec(),
        landmark_residuals_m: lin.y[n_sat..].to_vec(),
        used: lin.used,
        masked: lin.masked,
        predictions: lin.predictions,
        geometry_rows: lin.rows,
        sigmas_m: lin.sigmas,
        n_inv,
        dop,
        wsse,
        dof,
        sigma0,
        covariance: n_inv * (sigma0 * sigma0),
        iterations,
    })
}

/// DOP from the observed-information cofactor w H^-1 (w the mean weight of the observations):
/// the geometric DOP's counterpart at a point where A^T A is (nearly) singular.
fn effective_dop(
    lin: &Linearized,
    h_inv: &Matrix4<f64>,
    llh: &Llh,
) -> Result<super::dop::Dop, PvtError> {
    let w = lin.sigmas.iter().map(|s| 1.0 / (s * s)).sum::<f64>() / lin.sigmas.len() as f64;
    let q = h_inv * w;
    let qp: nalgebra::Matrix3<f64> = q.fixed_view::<3, 3>(0, 0).into_owned();
    super::dop::dop_from_cofactor(&qp, q[(3, 3)], llh).ok_or(PvtError::SingularGeometry {
        gdop: gdop_of(&lin.rows),
    })
}
