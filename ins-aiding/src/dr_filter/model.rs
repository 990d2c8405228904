//! The transition of one DR row: the exact Jacobian of the mechanization (module `dr_filter`).

use crate::dr_mechanization::{sinc, DrParams};
use nalgebra::{SMatrix, SVector};

/// Full 8-state transition and noise-input matrices of one row.
#[derive(Debug, Clone)]
pub struct RowModel {
    /// `F` (8x8, full state order).
    pub f: SMatrix<f64, 8, 8>,
    /// Noise input of a heading increment error (rad): column of `G`.
    pub g_heading: SVector<f64, 8>,
    /// Noise input of an odometer pulse count error (pulses) on the velocity only.
    pub g_pulse_vel: SVector<f64, 8>,
}

/// The exact Jacobian of [`crate::dr_step`] with respect to the 8 error states (module equations), for
/// the row (`gyro_v`, `pulses`, `dt`) processed from heading `heading_rad` with `params`.
pub fn row_model(
    params: &DrParams,
    heading_rad: f64,
    gyro_v: f64,
    pulses: f64,
    dt: f64,
) -> RowModel {
    let k = std::f64::consts::PI / 180.0;
    let dpsi = k * params.sf_g_dps_per_v * (gyro_v - params.v_nom_v) * dt;
    let g_s = k * (gyro_v - params.v_nom_v) * dt;
    let g_v = -k * params.sf_g_dps_per_v * dt;
    let s = params.sf_n_m_per_pulse * pulses / dt;
    let h = 0.5 * dpsi;
    let c = sinc(h);
    // dc/d(dpsi) = (1/2) d sinc(h)/dh.
    let dsinc = if h.abs() < 1e-4 {
        -h / 3.0
    } else {
        (h * h.cos() - h.sin()) / (h * h)
    };
    let c1 = 0.5 * dsinc;
    let psi_m = heading_rad + h;
    let psi1 = heading_rad + dpsi;
    let (u_m, up_m) = ([psi_m.sin(), psi_m.cos()], [psi_m.cos(), -psi_m.sin()]);
    let (u_1, up_1) = ([psi1.sin(), psi1.cos()], [psi1.cos(), -psi1.sin()]);
    let mut f = SMatrix::<f64, 8, 8>::zeros();
    for i in 0..2 {
        let d = s * dt * (c1 * u_m[i] + 0.5 * c * up_m[i]);
        f[(i, i)] = 1.0;
        f[(i, 4)] = s * dt * c * up_m[i];
        f[(i, 5)] = d * g_s;
        f[(i, 6)] = d * g_v;
        f[(i, 7)] = pulses * c * u_m[i];
        f[(2 + i, 4)] = s * up_1[i];
        f[(2 + i, 5)] = s * up_1[i] * g_s;
        f[(2 + i, 6)] = s * up_1[i] * g_v;
        f[(2 + i, 7)] = pulses / dt * u_1[i];
    }
    f[(4, 4)] = 1.0;
    f[(4, 5)] = g_s;
    f[(4, 6)] = g_v;
    for i in 5..8 {
        f[(i, i)] = 1.0;
    }
    let mut g_heading = SVector::<f64, 8>::zeros();
    let mut g_pulse_vel = SVector::<f64, 8>::zeros();
    for i in 0..2 {
        g_heading[i] = s * dt * (c1 * u_m[i] + 0.5 * c * up_m[i]);
        g_heading[2 + i] = s * up_1[i];
        g_pulse_vel[2 + i] = params.sf_n_m_per_pulse / dt * u_1[i];
    }
    g_heading[4] = 1.0;
    RowModel {
        f,
        g_heading,
        g_pulse_vel,
    }
}
