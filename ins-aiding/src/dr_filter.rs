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
//! `sf_n_psd` times `dt`.
//!
//! **Measurements** (eq. 14): `z_p = p_DR - p_GNSS = [I 0] x + u_p` and (8-state only)
//! `z_v = v_DR - v_GNSS = [0 I 0] x + u_v`, with `R` the 2x2 (east, north) covariance of the PVT
//! solution. Updates use the Joseph form; the estimate is then fed back (closed loop): position,
//! velocity and heading corrected, and `Sf_G`, `V_nom`, `Sf_N` of the mechanization replaced by
//! their calibrated values, after which the error estimate is zero again. Measurements apply at
//! the time of the last propagated row: propagate up to the measurement time first.

use crate::dr_error::DrError;
use crate::dr_log::DrSample;
use crate::dr_mechanization::{sinc, DrMechanization, DrParams, DrState};
use crate::vehicle::wrap_pi;
use nalgebra::{DMatrix, DVector, Matrix2, SMatrix, SVector};

/// Speed above which the course over ground fixes the heading, m/s.
pub const MIN_COURSE_SPEED_MPS: f64 = 3.0;

/// Which error model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum DrFilterKind {
    /// Seed 000's proposed filter: 8 states, GNSS position and velocity updates.
    Proposed8,
    /// The conventional filter of seed 000 eq. 7: 4 states, GNSS position updates only.
    Conventional4,
}

impl DrFilterKind {
    /// Full-state indices (see [`DrFusion::STATE_NAMES`]) of this kind's states, in order.
    pub fn state_indices(&self) -> &'static [usize] {
        match self {
            DrFilterKind::Proposed8 => &[0, 1, 2, 3, 4, 5, 6, 7],
            DrFilterKind::Conventional4 => &[0, 1, 4, 7],
        }
    }
}

/// Where a position fix came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FixSource {
    /// GNSS alone (no DR).
    Gnss,
    /// DR corrected by a recent GNSS update.
    Fused,
    /// DR alone (GNSS outage).
    DrOnly,
}

impl FixSource {
    /// `"gnss"`, `"fused"` or `"dr"` (for CSV outputs).
    pub fn as_str(&self) -> &'static str {
        match self {
            FixSource::Gnss => "gnss",
            FixSource::Fused => "fused",
            FixSource::DrOnly => "dr",
        }
    }
}

/// The course over ground (heading clockwise from north, rad) of a GNSS velocity, if the speed is
/// at least `min_speed_mps` (below it the course is noise; [`MIN_COURSE_SPEED_MPS`] suits cars).
pub fn heading_from_velocity(ve_mps: f64, vn_mps: f64, min_speed_mps: f64) -> Option<f64> {
    let speed = ve_mps.hypot(vn_mps);
    (speed.is_finite() && speed >= min_speed_mps).then(|| ve_mps.atan2(vn_mps))
}

fn d_pos_sigma() -> f64 {
    10.0
}
fn d_vel_sigma() -> f64 {
    1.0
}
fn d_heading_sigma() -> f64 {
    5.0
}
fn d_sf_g_sigma() -> f64 {
    3.0
}
fn d_v_nom_sigma() -> f64 {
    0.02
}
fn d_sf_n_sigma() -> f64 {
    0.05
}
fn d_pos_psd() -> f64 {
    0.01
}
fn d_vel_noise() -> f64 {
    0.05
}
fn d_heading_psd() -> f64 {
    1e-6
}
fn d_conv_heading_psd() -> f64 {
    1e-4
}
fn d_sf_g_psd() -> f64 {
    1e-6
}
fn d_v_nom_psd() -> f64 {
    1e-10
}
fn d_sf_n_psd() -> f64 {
    1e-9
}

/// Initial uncertainty and process noise of the fusion filters (units in the names; `psd` values
/// are per second: the per-row variance is `psd * dt`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrFilterConfig {
    /// Initial position sigma, m (default 10).
    #[serde(default = "d_pos_sigma")]
    pub init_pos_sigma_m: f64,
    /// Initial velocity sigma, m/s (default 1).
    #[serde(default = "d_vel_sigma")]
    pub init_vel_sigma_mps: f64,
    /// Initial heading sigma, deg (default 5).
    #[serde(default = "d_heading_sigma")]
    pub init_heading_sigma_deg: f64,
    /// Initial `Sf_G` sigma, deg/s/V (default 3: covers a 20 deg tilt, +2.9).
    #[serde(default = "d_sf_g_sigma")]
    pub init_sf_g_sigma_dps_per_v: f64,
    /// Initial `V_nom` sigma, V (default 0.02).
    #[serde(default = "d_v_nom_sigma")]
    pub init_v_nom_sigma_v: f64,
    /// Initial `Sf_N` sigma relative to the nominal value (default 0.05).
    #[serde(default = "d_sf_n_sigma")]
    pub init_sf_n_sigma_rel: f64,
    /// Position process noise PSD, m^2/s (default 0.01).
    #[serde(default = "d_pos_psd")]
    pub pos_psd_m2_per_s: f64,
    /// Velocity noise per row besides odometer quantisation, m/s (default 0.05).
    #[serde(default = "d_vel_noise")]
    pub vel_noise_mps: f64,
    /// Heading process noise PSD of the 8-state filter (gyro noise), rad^2/s (default 1e-6).
    #[serde(default = "d_heading_psd")]
    pub heading_psd_rad2_per_s: f64,
    /// Heading process noise PSD of the 4-state filter, which must also cover the unmodelled gyro
    /// bias and scale errors, rad^2/s (default 1e-4).
    #[serde(default = "d_conv_heading_psd")]
    pub conventional_heading_psd_rad2_per_s: f64,
    /// `Sf_G` random-walk PSD, (deg/s/V)^2/s (default 1e-6).
    #[serde(default = "d_sf_g_psd")]
    pub sf_g_psd: f64,
    /// `V_nom` random-walk PSD, V^2/s (default 1e-10).
    #[serde(default = "d_v_nom_psd")]
    pub v_nom_psd: f64,
    /// `Sf_N` random-walk PSD, (m/pulse)^2/s (default 1e-9).
    #[serde(default = "d_sf_n_psd")]
    pub sf_n_psd: f64,
}

impl Default for DrFilterConfig {
    fn default() -> Self {
        Self {
            init_pos_sigma_m: d_pos_sigma(),
            init_vel_sigma_mps: d_vel_sigma(),
            init_heading_sigma_deg: d_heading_sigma(),
            init_sf_g_sigma_dps_per_v: d_sf_g_sigma(),
            init_v_nom_sigma_v: d_v_nom_sigma(),
            init_sf_n_sigma_rel: d_sf_n_sigma(),
            pos_psd_m2_per_s: d_pos_psd(),
            vel_noise_mps: d_vel_noise(),
            heading_psd_rad2_per_s: d_heading_psd(),
            conventional_heading_psd_rad2_per_s: d_conv_heading_psd(),
            sf_g_psd: d_sf_g_psd(),
            v_nom_psd: d_v_nom_psd(),
            sf_n_psd: d_sf_n_psd(),
        }
    }
}

impl DrFilterConfig {
    /// Checks: initial sigmas positive, noise values `>= 0`, all finite.
    pub fn validate(&self) -> Result<(), DrError> {
        let pos = [
            ("init_pos_sigma_m", self.init_pos_sigma_m),
            ("init_vel_sigma_mps", self.init_vel_sigma_mps),
            ("init_heading_sigma_deg", self.init_heading_sigma_deg),
            ("init_sf_g_sigma_dps_per_v", self.init_sf_g_sigma_dps_per_v),
            ("init_v_nom_sigma_v", self.init_v_nom_sigma_v),
            ("init_sf_n_sigma_rel", self.init_sf_n_sigma_rel),
        ];
        for (n, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(DrError::Config(format!(
                    "DR filter: {n} = {v} must be positive"
                )));
            }
        }
        let nonneg = [
            ("pos_psd_m2_per_s", self.pos_psd_m2_per_s),
            ("vel_noise_mps", self.vel_noise_mps),
            ("heading_psd_rad2_per_s", self.heading_psd_rad2_per_s),
            (
                "conventional_heading_psd_rad2_per_s",
                self.conventional_heading_psd_rad2_per_s,
            ),
            ("sf_g_psd", self.sf_g_psd),
            ("v_nom_psd", self.v_nom_psd),
            ("sf_n_psd", self.sf_n_psd),
        ];
        for (n, v) in nonneg {
            if !(v.is_finite() && v >= 0.0) {
                return Err(DrError::Config(format!(
                    "DR filter: {n} = {v} must be >= 0"
                )));
            }
        }
        Ok(())
    }
}

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

/// A GPS/DR fusion filter ([`DrFilterKind`]) around a DR mechanization (module documentation).
#[derive(Debug, Clone)]
pub struct DrFusion {
    kind: DrFilterKind,
    config: DrFilterConfig,
    mech: DrMechanization,
    /// Error covariance in this kind's state order.
    p: DMatrix<f64>,
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
        let idx = kind.state_indices();
        let p = DMatrix::from_diagonal(&DVector::from_iterator(
            idx.len(),
            idx.iter().map(|&i| full[i] * full[i]),
        ));
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
        let idx = self.kind.state_indices();
        let n = idx.len();
        let f = DMatrix::from_fn(n, n, |r, col| m.f[(idx[r], idx[col])]);
        let q = DMatrix::from_fn(n, n, |r, col| q[(idx[r], idx[col])]);
        self.p = &f * &self.p * f.transpose() + q;
        self.p = (&self.p + self.p.transpose()) * 0.5;
        Ok(())
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
        let n = idx.len();
        let col = |full: usize| idx.iter().position(|&i| i == full);
        let (Some(c0), Some(c1)) = (col(first_full_state), col(first_full_state + 1)) else {
            return Err(DrError::Input(format!(
                "the {:?} filter has no {what} states",
                self.kind
            )));
        };
        let mut h = DMatrix::<f64>::zeros(2, n);
        h[(0, c0)] = 1.0;
        h[(1, c1)] = 1.0;
        let r = DMatrix::from_fn(2, 2, |i, j| r[(i, j)]);
        let s = &h * &self.p * h.transpose() + &r;
        let s_inv = s.clone().try_inverse().ok_or_else(|| {
            DrError::Input(format!("GNSS {what} innovation covariance is singular"))
        })?;
        let y = DVector::from_row_slice(&z);
        let nis = (y.transpose() * &s_inv * &y)[(0, 0)];
        let k = &self.p * h.transpose() * &s_inv;
        let dx = &k * &y;
        let ikh = DMatrix::<f64>::identity(n, n) - &k * &h;
        self.p = &ikh * &self.p * ikh.transpose() + &k * &r * k.transpose();
        self.p = (&self.p + self.p.transpose()) * 0.5;
        let mut full = [0.0; 8];
        for (j, &i) in idx.iter().enumerate() {
            full[i] = dx[j];
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
    pub fn covariance(&self) -> &DMatrix<f64> {
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
        let j = self
            .kind
            .state_indices()
            .iter()
            .position(|&i| i == full_index)?;
        Some(self.p[(j, j)])
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dr_mechanization::dr_step;

    /// The mechanization row as a function of the full state (position, heading, parameters):
    /// returns (position, velocity, heading) after the row.
    fn row(x: &[f64; 8], gyro_v: f64, pulses: f64, dt: f64) -> [f64; 5] {
        let p = DrParams {
            sf_g_dps_per_v: x[5],
            v_nom_v: x[6],
            sf_n_m_per_pulse: x[7],
        };
        let s = dr_step(&p, x[4], gyro_v, pulses, dt);
        [
            x[0] + s.dpos_m[0],
            x[1] + s.dpos_m[1],
            s.vel_mps[0],
            s.vel_mps[1],
            s.heading_rad,
        ]
    }

    /// F against central differences of the mechanization: each error state perturbed by
    /// +-h, the row re-run, the outputs differenced. Agreement to 1e-6 relative (h^2 truncation
    /// and rounding are far below), for a straight row, a gentle turn and a sharp turn.
    #[test]
    fn transition_matches_finite_differences_of_the_mechanization() {
        let base = [120.0, -40.0, 0.0, 0.0, 0.7, 47.9, 2.48, 0.098];
        let h = [1e-3, 1e-3, 1e-3, 1e-3, 1e-6, 1e-5, 1e-7, 1e-7];
        for (gyro_v, pulses, dt) in [
            (2.48, 150.0, 0.1),
            (2.48 + 1e-7, 150.0, 0.1),
            (2.53, 120.0, 0.1),
            (2.9, 80.0, 0.5),
        ] {
            let m = row_model(
                &DrParams {
                    sf_g_dps_per_v: base[5],
                    v_nom_v: base[6],
                    sf_n_m_per_pulse: base[7],
                },
                base[4],
                gyro_v,
                pulses,
                dt,
            );
            for j in 0..8 {
                let mut xp = base;
                let mut xm = base;
                xp[j] += h[j];
                xm[j] -= h[j];
                let (fp, fm) = (row(&xp, gyro_v, pulses, dt), row(&xm, gyro_v, pulses, dt));
                for i in 0..5 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h[j]);
                    let an = m.f[(i, j)];
                    let tol = 1e-6 * (1.0 + an.abs());
                    assert!(
                        (fd - an).abs() < tol,
                        "F[{i},{j}] = {an}, finite difference {fd} (gyro {gyro_v} V, {pulses} pulses, dt {dt})"
                    );
                }
                // Parameters are random walks: identity rows.
                for i in 5..8 {
                    assert_eq!(m.f[(i, j)], if i == j { 1.0 } else { 0.0 });
                }
            }
            // Noise inputs: a heading-increment error (through V_g) and a pulse error (velocity).
            let k = std::f64::consts::PI / 180.0 * base[5] * dt;
            let dv = 1e-7;
            let (fp, fm) = (
                row(&base, gyro_v + dv, pulses, dt),
                row(&base, gyro_v - dv, pulses, dt),
            );
            for i in 0..5 {
                let fd = (fp[i] - fm[i]) / (2.0 * dv * k);
                assert!(
                    (fd - m.g_heading[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "G_psi[{i}]"
                );
            }
            let (fp, fm) = (
                row(&base, gyro_v, pulses + 1e-3, dt),
                row(&base, gyro_v, pulses - 1e-3, dt),
            );
            for i in 2..4 {
                let fd = (fp[i] - fm[i]) / 2e-3;
                assert!(
                    (fd - m.g_pulse_vel[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "G_N[{i}]"
                );
            }
        }
    }

    #[test]
    fn course_over_ground_needs_speed() {
        let h = heading_from_velocity(10.0, -10.0, MIN_COURSE_SPEED_MPS);
        assert!(h.is_some_and(|h| (h - 135f64.to_radians()).abs() < 1e-12));
        assert!(heading_from_velocity(1.0, 1.0, MIN_COURSE_SPEED_MPS).is_none());
        assert!(heading_from_velocity(f64::NAN, 1.0, MIN_COURSE_SPEED_MPS).is_none());
    }

    #[test]
    fn updates_check_their_input_and_the_4_state_filter_ignores_velocity() {
        let mut f = DrFusion::new(
            DrFilterKind::Conventional4,
            DrParams::default(),
            0.0,
            0.0,
            0.0,
            DrFilterConfig::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(f.covariance().nrows(), 4);
        let r = Matrix2::new(4.0, 0.0, 0.0, 4.0);
        assert!(f.update_velocity(1.0, 2.0, r).is_ok_and(|n| n.is_none()));
        assert!(f.update_position(f64::NAN, 0.0, r).is_err());
        assert!(f
            .update_position(0.0, 0.0, Matrix2::new(1.0, 2.0, 2.0, 1.0))
            .is_err());
        assert!(f
            .update_position(0.0, 0.0, Matrix2::new(1.0, 0.5, 0.0, 1.0))
            .is_err());
        assert_eq!(f.fix_source(1.5), FixSource::DrOnly);
        // A 3 m east offset with 10 m prior sigma and 2 m measurement sigma: gain 100/104.
        let nis = f
            .update_position(-3.0, 0.0, r)
            .unwrap_or_else(|e| panic!("{e}"));
        assert!((nis - 9.0 / 104.0).abs() < 1e-12);
        assert!((f.state().east_m + 3.0 * 100.0 / 104.0).abs() < 1e-12);
        assert!((f.position_covariance()[(0, 0)] - 400.0 / 104.0).abs() < 1e-9);
        assert_eq!(f.state_variance(2), None);
        let bad = DrFilterConfig {
            init_pos_sigma_m: 0.0,
            ..DrFilterConfig::default()
        };
        assert!(DrFusion::new(
            DrFilterKind::Proposed8,
            DrParams::default(),
            0.0,
            0.0,
            0.0,
            bad
        )
        .is_err());
    }
}
