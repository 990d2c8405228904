//! GPS/DR fusion (seed 000): the proposed 8-state error filter using GNSS position and
//! carrier-based velocity (eqs. 5-14), and the conventional 4-state position-only filter (eq. 7),
//! both closed-loop around a [`DrMechanization`].
//!
//! **Error states** (DR minus truth): [`DrFilterKind::Proposed8`] has
//! `x = [dp_E, dp_N, dv_E, dv_N, dpsi, dSf_G, dV_nom, dSf_N]` (m, m, m/s, m/s, rad, deg/s/V, V,
//! m/pulse); [`DrFilterKind::Conventional4`] has `x = [dp_E, dp_N, dpsi, dSf_N]` (eq. 7): it does
//! not model the gyro's errors, so its heading drifts with them during outages.
//!
//! **Transition.** `F` is the exact Jacobian of one mechanization row ([`crate::dr_step`]) with respect
//! to the error state, so it agrees with finite differences of the mechanization (tested). With
//! `u(x) = (sin x, cos x)`, `u'(x) = (cos x, -sin x)`, `dpsi = Sf_G (V_g - V_nom) dt` (rad),
//! `c = sinc(dpsi/2)`, `psi_m = psi + dpsi/2`, `s = Sf_N N / dt`:
//! - heading (eqs. 5-6): `dpsi' = dpsi + g_S dSf_G + g_V dV_nom`, `g_S = (V_g - V_nom) dt`,
//!   `g_V = -Sf_G dt` (both times pi/180);
//! - velocity (eqs. 10-11): `dv' = s u'(psi') (dpsi + g_S dSf_G + g_V dV_nom) + (N/dt) u(psi') dSf_N`;
//! - position (eqs. 7 and 12): `dp' = dp + s dt c u'(psi_m) dpsi + D (g_S dSf_G + g_V dV_nom)
//!   + N c u(psi_m) dSf_N`, with `D = d(dp)/d(dpsi) = s dt (c_1 u(psi_m) + c u'(psi_m) / 2)`,
//!   `c_1 = dc/d(dpsi)`;
//! - sensor parameters: random walks (eq. 6).
//!
//! This differs from eq. 13 as printed in one respect: eq. 11 carries `dv(k+1) = dv(k) + ...`
//! (its eq. 10 drops `dv(k-1)` assuming the previous velocity was compensated), which has no
//! counterpart in the mechanization, whose velocity is recomputed each row from heading and
//! odometer (eq. 1); here `dv'` is that row's velocity error, and position couples to the same
//! heading and scale errors directly (to first order `dp' = dp + dv' dt`, eq. 12).
//!
//! **Process noise** `Q = G diag(q) G^T` per row of `dt` seconds ([`DrFilterConfig`]): heading
//! noise `q_psi = heading_psd_rad2_per_s dt` enters `dpsi` (so also `dv'` and `dp'` through the
//! row's turn); odometer quantisation `1/6` pulse^2 (the difference of two carried
//! fractions, each uniform in [0, 1)) and `vel_noise_mps^2` enter `dv'` only (the
//! pulse remainder is carried, so quantisation does not accumulate in position);
//! `pos_psd_m2_per_s dt` enters `dp`; the parameters walk with `sf_g_psd`, `v_nom_psd`,
//! `sf_n_psd` times `dt`. The defaults suit a 10 Hz automotive gyro and odometer: heading
//! 1e-6 rad^2/s (0.06 deg/sqrt(s)), `Sf_G` 1e-6 (deg/s/V)^2/s, `V_nom` 1e-10 V^2/s, `Sf_N`
//! 1e-9 (m/pulse)^2/s, position 0.01 m^2/s, velocity 0.05 m/s; the 4-state filter's heading
//! PSD (1e-4 rad^2/s) is larger because it must absorb the gyro errors it does not model.
//! On data consistent with the model the 8-state filter's NEES is within its chi-square bounds
//! (tests/dr_fusion.rs).
//!
//! The velocity compared with GNSS is the mechanization's `s (sin psi_k, cos psi_k)`: the mean
//! speed of the last row (it lags the instantaneous speed by `a dt / 2`, 0.05 m/s at 1 m/s^2 and
//! 10 Hz) along the heading at its end.
//!
//! **Measurements** (eq. 14): `z_p = p_DR - p_GNSS = [I 0] x + u_p` and (8-state only)
//! `z_v = v_DR - v_GNSS = [0 I 0] x + u_v`, with `R` the 2x2 (east, north) covariance of the PVT
//! solution. Updates use the Joseph form; the estimate is then fed back (closed loop): position,
//! velocity and heading corrected, and `Sf_G`, `V_nom`, `Sf_N` of the mechanization replaced by
//! their calibrated values, after which the error estimate is zero again. Measurements apply at
//! the time of the last propagated row: propagate up to the measurement time first.

mod config;
mod model;
#[cfg(test)]
mod tests;

pub use config::{
    heading_from_velocity, DrFilterConfig, DrFilterKind, FixSource, MIN_COURSE_SPEED_MPS,
};
pub use model::{row_model, RowModel};

use crate::dr_error::DrError;
use crate::dr_log::DrSample;
use crate::dr_mechanization::{DrMechanization, DrParams, DrState};
use crate::vehicle::wrap_pi;
use nalgebra::{DMatrix, Matrix2, SMatrix, SVector};

type Matrix8 = SMatrix<f64, 8, 8>;

/// A GPS/DR fusion filter ([`DrFilterKind`]) around a DR mechanization (module documentation).
#[derive(Debug, Clone)]
pub struct DrFusion {
    kind: DrFilterKind,
    config: DrFilterConfig,
    mech: DrMechanization,
    /// Error covariance over the full 8 states; the rows and columns of states this kind does not
    /// carry are zero (so they never act), which equals the kind's own filter.
    p: Matrix8,
    last_update_t_s: Option<f64>,
}

impl DrFusion {
    /// Names and units of the 8 full error states (the 4-state filter uses 0, 1, 4, 7).
    pub const STATE_NAMES: [&'static str; 8] = [
        "dp_east_m",
        "dp_north_m",
        "dv_east_mps",
        "dv_north_mps",
        "dheading_rad",
        "dsf_g_dps_per_v",
        "dv_nom_v",
        "dsf_n_m_per_pulse",
    ];

    /// A filter starting at (`east_m`, `north_m`) with `heading_rad` (clockwise from north; see
    /// [`heading_from_velocity`]) and the nominal sensor parameters `params` (the configuration's
    /// `Sf_G`, `V_nom`, `Sf_N`; they also convert engineering-unit rows). To start from a saved
    /// calibration, add [`DrFusion::with_calibration`].
    pub fn new(
        kind: DrFilterKind,
        params: DrParams,
        east_m: f64,
        north_m: f64,
        heading_rad: f64,
        config: DrFilterConfig,
    ) -> Result<DrFusion, DrError> {
        config.validate()?;
        let mech = DrMechanization::new(params, east_m, north_m, heading_rad)?;
        let full = [
            config.init_pos_sigma_m,
            config.init_pos_sigma_m,
            config.init_vel_sigma_mps,
            config.init_vel_sigma_mps,
            config.init_heading_sigma_deg.to_radians(),
            config.init_sf_g_sigma_dps_per_v,
            config.init_v_nom_sigma_v,
            config.init_sf_n_sigma_rel * params.sf_n_m_per_pulse,
        ];
        let mut p = Matrix8::zeros();
        for &i in kind.state_indices() {
            p[(i, i)] = full[i] * full[i];
        }
        Ok(DrFusion {
            kind,
            config,
            mech,
            p,
            last_update_t_s: None,
        })
    }

    /// Starts from a previous run's calibration (e.g. [`DrParams::load`]) instead of the nominal
    /// parameters given to [`DrFusion::new`], which remain the reference that converts
    /// engineering-unit rows (the units the log was made with). Seed 000: this avoids the long
    /// convergence of the gyro scale factor. The initial parameter sigmas are unchanged (shrink
    /// them in [`DrFilterConfig`] for a trusted calibration).
    pub fn with_calibration(mut self, calibrated: DrParams) -> Result<DrFusion, DrError> {
        self.mech.set_params(calibrated)?;
        Ok(self)
    }

    /// Processes one DR row: mechanization and covariance prediction `P = F P F^T + Q`.
    pub fn propagate(&mut self, sample: &DrSample) -> Result<(), DrError> {
        let before = *self.mech.state();
        let params = *self.mech.params();
        let Some(t_prev) = before.t_s else {
            self.mech.propagate(sample)?;
            return Ok(());
        };
        let dt = sample.t_s - t_prev;
        let (gyro_v, pulses) = self.mech.raw_equivalent(&sample.reading, dt);
        if self.mech.propagate(sample)?.is_none() {
            return Ok(());
        }
        let m = row_model(&params, before.heading_rad, gyro_v, pulses, dt);
        let c = &self.config;
        let q_heading = match self.kind {
            DrFilterKind::Proposed8 => c.heading_psd_rad2_per_s,
            DrFilterKind::Conventional4 => c.conventional_heading_psd_rad2_per_s,
        } * dt;
        // The row's count error is the difference of two carried fractions (each uniform in
        // [0, 1), variance 1/12): variance 1/6 pulse^2.
        let q_pulse = if sample.reading.is_raw() {
            1.0 / 6.0
        } else {
            0.0
        };
        let mut q = m.g_heading * m.g_heading.transpose() * q_heading
            + m.g_pulse_vel * m.g_pulse_vel.transpose() * q_pulse;
        for (i, v) in [
            (0, c.pos_psd_m2_per_s * dt),
            (1, c.pos_psd_m2_per_s * dt),
            (2, c.vel_noise_mps * c.vel_noise_mps),
            (3, c.vel_noise_mps * c.vel_noise_mps),
            (5, c.sf_g_psd * dt),
            (6, c.v_nom_psd * dt),
            (7, c.sf_n_psd * dt),
        ] {
            q[(i, i)] += v;
        }
        self.p = m.f * self.p * m.f.transpose() + q;
        self.p = (self.p + self.p.transpose()) * 0.5;
        self.zero_unused_states();
        Ok(())
    }

    /// Zeroes the rows and columns of the states this kind does not carry.
    fn zero_unused_states(&mut self) {
        let idx = self.kind.state_indices();
        for i in (0..8).filter(|i| !idx.contains(i)) {
            self.p.row_mut(i).fill(0.0);
            self.p.column_mut(i).fill(0.0);
        }
    }

    /// GNSS position update (`z = p_DR - p_GNSS`, eq. 14); `cov` is the PVT's 2x2 (east, north)
    /// covariance, m^2. Returns the normalised innovation squared (chi-square, 2 degrees of
    /// freedom when the filter is consistent).
    pub fn update_position(
        &mut self,
        east_m: f64,
        north_m: f64,
        cov: Matrix2<f64>,
    ) -> Result<f64, DrError> {
        let s = self.mech.state();
        let z = [s.east_m - east_m, s.north_m - north_m];
        self.update(z, cov, 0, "position")
    }

    /// GNSS (carrier/Doppler) velocity update (`z = v_DR - v_GNSS`, eq. 14); `cov` in
    /// (m/s)^2. Returns the normalised innovation squared, or None for the 4-state filter, which
    /// ignores velocity.
    pub fn update_velocity(
        &mut self,
        ve_mps: f64,
        vn_mps: f64,
        cov: Matrix2<f64>,
    ) -> Result<Option<f64>, DrError> {
        if self.kind == DrFilterKind::Conventional4 {
            return Ok(None);
        }
        let s = self.mech.state();
        let z = [s.vel_east_mps - ve_mps, s.vel_north_mps - vn_mps];
        self.update(z, cov, 2, "velocity").map(Some)
    }

    fn update(
        &mut self,
        z: [f64; 2],
        r: Matrix2<f64>,
        first_full_state: usize,
        what: &str,
    ) -> Result<f64, DrError> {
        if !(z.iter().all(|v| v.is_finite()) && r.iter().all(|v| v.is_finite())) {
            return Err(DrError::Input(format!(
                "GNSS {what} update with a non-finite value"
            )));
        }
        if (r[(0, 1)] - r[(1, 0)]).abs() > 1e-9 * (r[(0, 0)] + r[(1, 1)]).abs()
            || r.cholesky().is_none()
        {
            return Err(DrError::Input(format!(
                "GNSS {what} covariance {r:?} is not symmetric positive definite"
            )));
        }
        let idx = self.kind.state_indices();
        if !(idx.contains(&first_full_state) && idx.contains(&(first_full_state + 1))) {
            return Err(DrError::Input(format!(
                "the {:?} filter has no {what} states",
                self.kind
            )));
        }
        let mut h = SMatrix::<f64, 2, 8>::zeros();
        h[(0, first_full_state)] = 1.0;
        h[(1, first_full_state + 1)] = 1.0;
        let s = h * self.p * h.transpose() + r;
        let s_inv = s.try_inverse().ok_or_else(|| {
            DrError::Input(format!("GNSS {what} innovation covariance is singular"))
        })?;
        let y = SVector::<f64, 2>::from(z);
        let nis = (y.transpose() * s_inv * y)[(0, 0)];
        let k = self.p * h.transpose() * s_inv;
        let dx = k * y;
        let ikh = Matrix8::identity() - k * h;
        self.p = ikh * self.p * ikh.transpose() + k * r * k.transpose();
        self.p = (self.p + self.p.transpose()) * 0.5;
        self.zero_unused_states();
        let mut full = [0.0; 8];
        for &i in idx {
            full[i] = dx[i];
        }
        self.feed_back(&full);
        self.last_update_t_s = self.mech.state().t_s;
        Ok(nis)
    }

    /// Closed-loop feedback of an error estimate (full state order): subtracts it from the
    /// mechanization's solution and parameters. Parameters are kept within 0.2-5 times their
    /// nominal values (a guard against a diverged filter).
    fn feed_back(&mut self, dx: &[f64; 8]) {
        let nominal = *self.mech.nominal_params();
        let old = *self.mech.params();
        let clamp = |v: f64, nom: f64| v.clamp(0.2 * nom, 5.0 * nom);
        let new = DrParams {
            sf_g_dps_per_v: clamp(old.sf_g_dps_per_v - dx[5], nominal.sf_g_dps_per_v),
            v_nom_v: old.v_nom_v - dx[6],
            sf_n_m_per_pulse: clamp(old.sf_n_m_per_pulse - dx[7], nominal.sf_n_m_per_pulse),
        };
        // Validated by construction (positive, finite), so this cannot fail.
        let _ = self.mech.set_params(new);
        let kind = self.kind;
        let s = self.mech.state_mut();
        s.east_m -= dx[0];
        s.north_m -= dx[1];
        s.heading_rad = wrap_pi(s.heading_rad - dx[4]);
        match kind {
            DrFilterKind::Proposed8 => {
                s.vel_east_mps -= dx[2];
                s.vel_north_mps -= dx[3];
            }
            DrFilterKind::Conventional4 => {
                s.speed_mps *= new.sf_n_m_per_pulse / old.sf_n_m_per_pulse;
                s.vel_east_mps = s.speed_mps * s.heading_rad.sin();
                s.vel_north_mps = s.speed_mps * s.heading_rad.cos();
            }
        }
    }

    /// The fused solution (after the last row and update).
    pub fn state(&self) -> &DrState {
        self.mech.state()
    }

    /// The current calibrated sensor parameters (save them with [`DrParams::save`]).
    pub fn params(&self) -> &DrParams {
        self.mech.params()
    }

    /// The error covariance in this kind's state order ([`DrFilterKind::state_indices`]).
    pub fn covariance(&self) -> DMatrix<f64> {
        let idx = self.kind.state_indices();
        DMatrix::from_fn(idx.len(), idx.len(), |i, j| self.p[(idx[i], idx[j])])
    }

    /// The error covariance over the full 8 states ([`DrFusion::STATE_NAMES`]), with zero rows
    /// and columns for the states this kind does not carry.
    pub fn full_covariance(&self) -> &SMatrix<f64, 8, 8> {
        &self.p
    }

    /// The 2x2 (east, north) position covariance, m^2.
    pub fn position_covariance(&self) -> Matrix2<f64> {
        Matrix2::new(
            self.p[(0, 0)],
            self.p[(0, 1)],
            self.p[(1, 0)],
            self.p[(1, 1)],
        )
    }

    /// The variance of full state `i` (0-7, [`DrFusion::STATE_NAMES`]), None if this kind does
    /// not carry it.
    pub fn state_variance(&self, full_index: usize) -> Option<f64> {
        self.kind
            .state_indices()
            .contains(&full_index)
            .then(|| self.p[(full_index, full_index)])
    }

    /// The filter kind.
    pub fn kind(&self) -> DrFilterKind {
        self.kind
    }

    /// The mechanization inside.
    pub fn mechanization(&self) -> &DrMechanization {
        &self.mech
    }

    /// The DR time of the last GNSS update.
    pub fn last_update_t_s(&self) -> Option<f64> {
        self.last_update_t_s
    }

    /// [`FixSource::Fused`] if a GNSS update came within `max_age_s` of the current DR time,
    /// else [`FixSource::DrOnly`].
    pub fn fix_source(&self, max_age_s: f64) -> FixSource {
        match (self.mech.state().t_s, self.last_update_t_s) {
            (Some(t), Some(u)) if t - u <= max_age_s => FixSource::Fused,
            _ => FixSource::DrOnly,
        }
    }
}
