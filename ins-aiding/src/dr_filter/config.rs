//! Filter kinds, fix sources, heading initialisation and the filter settings.

use crate::dr_error::DrError;

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
    /// Full-state indices (see [`crate::DrFusion::STATE_NAMES`]) of this kind's states, in order.
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
