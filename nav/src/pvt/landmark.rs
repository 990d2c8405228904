//! Ranges to surveyed landmarks as extra observations (seed 001 eqs. 3.8-3.12).
//!
//! A landmark range PV = |r_L - r_rx| + e (eq. 3.8) has no receiver clock term. Linearised at
//! the current estimate it adds the row K = [u^T, 0] (u = (r_rx - r_L)/|r_rx - r_L|, eq. 3.9)
//! with weight 1/sigma_m^2, and the least squares becomes eq. 3.10. So 3 satellites and 1
//! landmark (4 observations, rank 4) already fix position and clock.
//!
//! With exactly 4 observations the non-linear problem can have two solutions (the
//! pseudorange locus of 3 satellites, a curve, crosses the sphere of radius PV around the
//! landmark twice); the solver returns the one the iteration reaches from its start, so give
//! a `prior` (e.g. the last fix) when satellites are this scarce. Without one the iteration
//! starts at the Earth's centre; if it fails, [`solve_from_landmarks`] starts from 8 points around the landmarks and, between two
//! solutions that fit equally well, keeps the one nearer the landmarks' height: the landmarks
//! of seed 001 are at street level, like the antenna, and the second solution lies along the
//! satellite curve, which points up towards the satellites (100 |u.n| m away for a 50 m range,
//! u the landmark direction, n the curve's).

use super::model::predict;
use super::wls::{iterate, Context, Fix};
use super::PvtError;
use crate::frames::{enu_rotation, Llh, Vector3};

/// Starting points (evenly spaced bearings) around the landmarks without a prior.
const START_BEARINGS: usize = 8;
/// Weighted cost difference (chi-square, 1 degree of freedom) below which two solutions fit
/// equally well.
const SAME_FIT_CHI2: f64 = 1.0;

/// A range measured to a surveyed 3D point (e.g. a building recognised by a camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landmark {
    /// Surveyed position, WGS-84 ECEF, m.
    pub ecef_m: Vector3<f64>,
    /// Measured range from the receiver antenna to the point, m.
    pub range_m: f64,
    /// Standard deviation of the range, m (seed 001: about 2 % of the range).
    pub sigma_m: f64,
}

/// Rejects landmarks with non-finite values, negative ranges or non-positive sigmas.
pub fn validate(landmarks: &[Landmark]) -> Result<(), PvtError> {
    for (index, lm) in landmarks.iter().enumerate() {
        let bad = |field, value| {
            Err(PvtError::InvalidLandmark {
                index,
                field,
                value,
            })
        };
        if let Some(v) = lm.ecef_m.iter().find(|v| !v.is_finite()) {
            return bad("ecef_m", *v);
        }
        if !(lm.range_m.is_finite() && lm.range_m >= 0.0) {
            return bad("range_m", lm.range_m);
        }
        if !(lm.sigma_m.is_finite() && lm.sigma_m > 0.0) {
            return bad("sigma_m", lm.sigma_m);
        }
    }
    Ok(())
}

/// Solves without a prior when landmarks are given: from points at the mean landmark range
/// horizontally around the landmarks' centroid (every 45 deg; one start when the active
/// satellites fix the position alone), clock bias from the mean pseudorange residual there.
/// Keeps the best-fitting solution; between equal fits (the two solutions of an exactly
/// determined epoch), the one closest to the landmarks' mean height.
pub fn solve_from_landmarks(ctx: &Context<'_>, active: &[bool]) -> Result<Fix, PvtError> {
    let n_lm = ctx.landmarks.len().max(1) as f64;
    let centre = ctx
        .landmarks
        .iter()
        .fold(Vector3::zeros(), |acc, l| acc + l.ecef_m)
        / n_lm;
    let radius = (ctx.landmarks.iter().map(|l| l.range_m).sum::<f64>() / n_lm).max(1.0);
    let origin = Llh::from_ecef(&centre);
    let to_ecef = enu_rotation(&origin).transpose();
    let n_active = active.iter().filter(|a| **a).count();
    let starts = if n_active >= super::wls::N_UNKNOWNS {
        1
    } else {
        START_BEARINGS
    };
    let mut best: Option<Fix> = None;
    let mut last_err = None;
    for k in 0..starts {
        let bearing = std::f64::consts::TAU * k as f64 / START_BEARINGS as f64;
        let (sb, cb) = bearing.sin_cos();
        let pos = centre + to_ecef * Vector3::new(radius * sb, radius * cb, 0.0);
        let clock = start_clock(ctx, active, &pos);
        match iterate(ctx, active, (pos, clock), true) {
            Ok(fix) => best = Some(better(best, fix, origin.h_m)),
            Err(e) => last_err = Some(e),
        }
    }
    best.ok_or(last_err.unwrap_or(PvtError::Diverged {
        iterations: 0,
        last_step_m: f64::INFINITY,
    }))
}

/// Mean of pseudorange minus modelled range of the active satellites at `pos`, m.
fn start_clock(ctx: &Context<'_>, active: &[bool], pos: &Vector3<f64>) -> f64 {
    let tow = ctx.epoch_rx_time.tow_s;
    let (sum, n) = ctx
        .sats
        .iter()
        .zip(active)
        .filter(|(_, a)| **a)
        .map(|(s, _)| s.pseudorange_m - predict(s, pos, true, ctx.opts, tow).range_model_m)
        .fold((0.0, 0usize), |(s, n), r| (s + r, n + 1));
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// The better of two fixes: the lower weighted cost, or, within [`SAME_FIT_CHI2`], the one
/// whose height is closer to `h_landmarks_m`.
fn better(best: Option<Fix>, fix: Fix, h_landmarks_m: f64) -> Fix {
    let Some(b) = best else { return fix };
    if (b.wsse - fix.wsse).abs() > SAME_FIT_CHI2 {
        return if fix.wsse < b.wsse { fix } else { b };
    }
    let dh = |f: &Fix| (Llh::from_ecef(&f.pos_m).h_m - h_landmarks_m).abs();
    if dh(&fix) < dh(&b) {
        fix
    } else {
        b
    }
}
