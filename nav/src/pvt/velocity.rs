//! Receiver velocity and clock drift from Dopplers by least squares.
//!
//! The measured pseudorange rate is rr = -doppler * lambda_L1 (Doppler positive when the
//! satellite approaches). Its model, the derivative of the light-time range
//! c tau = |R3(w tau) r_sv(t - tau) - r_rx(t)| with respect to the receive time, is
//!
//! ```text
//! rr = k l.(R3 v_sv - v_rx) + d_rx - c dt_sv_dot,   k = 1 / (1 - q/c),
//! q  = l.(w R3' r_sv - R3 v_sv)
//! ```
//!
//! with l the unit line of sight, R3' = dR3/dtheta, d_rx the receiver clock drift (m/s). The
//! factor k (about 1 +- 3e-6) and the rotation terms are mm/s effects, kept so that a
//! noise-free epoch gives the velocity to well below 1 mm/s. Ionospheric and tropospheric
//! rates are not modelled (below 1 cm/s). The model is linear in (v_rx, d_rx), so one
//! weighted least-squares step solves it, with weights 1/sigma^2,
//! sigma = `doppler_sigma_mps` * sqrt([`super::Weighting::cn0_scale`]); covariance
//! sigma0^2 N^-1 as for the position.

use super::model::{Predicted, PreparedSat, PvtOptions};
use super::wls::{Fix, N_UNKNOWNS};
use crate::constants::{LAMBDA_L1_M, SPEED_OF_LIGHT_MPS};
use crate::frames::{rotate_for_earth_rotation, rotation_rate_times, Vector3};
use nalgebra::{Matrix4, Vector4};

/// Velocity and clock-drift estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocitySolution {
    /// Receiver velocity, ECEF, m/s.
    pub vel_ecef_mps: Vector3<f64>,
    /// Receiver clock drift times c, m/s.
    pub clock_drift_mps: f64,
    /// Covariance of (vx, vy, vz, drift), (m/s)^2.
    pub covariance: Matrix4<f64>,
    /// A-posteriori sigma0 (1 without redundancy).
    pub sigma0: f64,
    /// Dopplers used.
    pub n_used: usize,
}

/// The satellite's part of the pseudorange-rate model above, at one prediction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatRangeRate {
    /// Light-time factor k = 1 / (1 - q/c).
    pub k: f64,
    /// Satellite velocity rotated into the frame of reception, R3 v_sv, m/s.
    pub v_sv_mps: Vector3<f64>,
    /// Rate of the modelled pseudorange for a receiver fixed in ECEF with no clock drift,
    /// k l.(R3 v_sv) - c dt_sv_dot, m/s (the d/dt of [`Predicted::range_model_m`] with respect
    /// to the receive time, atmosphere rates neglected).
    pub rate_mps: f64,
}

/// Evaluates k, R3 v_sv and the static-receiver range rate of `sat` at the prediction `pred`.
pub fn sat_range_rate(sat: &PreparedSat, pred: &Predicted) -> SatRangeRate {
    let tau = pred.flight_time_s;
    let v_sv = rotate_for_earth_rotation(&sat.sv.vel_mps, tau);
    let l = pred.los;
    let q = l.dot(&(rotation_rate_times(&sat.sv.pos_m, tau) - v_sv));
    let k = 1.0 / (1.0 - q / SPEED_OF_LIGHT_MPS);
    SatRangeRate {
        k,
        v_sv_mps: v_sv,
        rate_mps: k * l.dot(&v_sv) - SPEED_OF_LIGHT_MPS * sat.sv.clock_drift_s_s,
    }
}

/// Solves velocity and drift from the Dopplers of the satellites in `fix`; None with fewer
/// than 4 Dopplers or a singular geometry.
pub fn solve_velocity(
    sats: &[PreparedSat],
    fix: &Fix,
    opts: &PvtOptions,
) -> Option<VelocitySolution> {
    let lambda_m = LAMBDA_L1_M;
    let mut rows = Vec::new();
    let mut y = Vec::new();
    let mut sigmas = Vec::new();
    for (&i, pred) in fix.used.iter().zip(&fix.predictions) {
        let sat = sats.get(i)?;
        let Some(doppler_hz) = sat.doppler_hz else {
            continue;
        };
        let rr_meas = -doppler_hz * lambda_m;
        let sr = sat_range_rate(sat, pred);
        let (k, l) = (sr.k, pred.los);
        rows.push(Vector4::new(-k * l.x, -k * l.y, -k * l.z, 1.0));
        y.push(rr_meas - sr.rate_mps);
        sigmas.push(opts.doppler_sigma_mps * opts.weighting.cn0_scale(sat.cn0_dbhz).sqrt());
    }
    if rows.len() < N_UNKNOWNS {
        return None;
    }
    let mut n = Matrix4::zeros();
    let mut c = Vector4::zeros();
    for ((a, yi), s) in rows.iter().zip(&y).zip(&sigmas) {
        let w = 1.0 / (s * s);
        n += a * a.transpose() * w;
        c += a * (w * yi);
    }
    let n_inv = n.try_inverse()?;
    let x = n_inv * c;
    let wsse: f64 = rows
        .iter()
        .zip(&y)
        .zip(&sigmas)
        .map(|((a, yi), s)| ((yi - a.dot(&x)) / s).powi(2))
        .sum();
    let dof = rows.len() - N_UNKNOWNS;
    let sigma0 = if dof > 0 {
        (wsse / dof as f64).sqrt()
    } else {
        1.0
    };
    let sol = VelocitySolution {
        vel_ecef_mps: Vector3::new(x[0], x[1], x[2]),
        clock_drift_mps: x[3],
        covariance: n_inv * (sigma0 * sigma0),
        sigma0,
        n_used: rows.len(),
    };
    let finite = x.iter().all(|v| v.is_finite()) && sol.covariance.iter().all(|v| v.is_finite());
    finite.then_some(sol)
}
