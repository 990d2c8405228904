//! The receiver's configuration: one plain struct, the defaults defined once.
//!
//! [`ReceiverConfig`] is what a `gpsrx.toml` file holds (`[tracking]`, `[run]` and `[dr]`
//! tables; unknown keys are errors), what the command line produces (file, then options) and
//! what library users build directly (`ReceiverConfig::default()` and change a field).

use gpsrx_tracking::ChannelConfig;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Ionosphere correction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum IonoModel {
    /// Broadcast Klobuchar (IS-GPS-200 20.3.3.5.2.5), decoded from subframe 4 page 18 or from
    /// a navigation file; a typical set until then.
    #[default]
    Klobuchar,
    /// No correction.
    None,
}

/// Troposphere correction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TropoModel {
    /// Saastamoinen with a standard atmosphere.
    #[default]
    Saastamoinen,
    /// No correction (simulated recordings without troposphere).
    None,
}

/// The `[run]` table: acquisition and navigation settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RunSettings {
    /// Observable and fix rate, Hz (1 to 50).
    pub rate_hz: f64,
    /// Elevation mask, degrees.
    pub elevation_mask_deg: f64,
    /// Ionosphere correction.
    pub iono: IonoModel,
    /// Troposphere correction.
    pub tropo: TropoModel,
    /// RAIM false-alarm probability.
    pub raim_pfa: f64,
    /// Acquisition Doppler half-width, Hz.
    pub doppler_max_hz: f64,
    /// Acquisition Doppler search centre (a front-end frequency offset), Hz.
    pub doppler_center_hz: f64,
    /// Acquisition coherent integration, ms (1 to 10).
    pub acq_coherent_ms: u32,
    /// Acquisition non-coherent blocks (1 to 1000).
    pub acq_noncoherent: u32,
    /// Use satellites whose ephemeris says they are unhealthy.
    pub allow_unhealthy: bool,
    /// Full GPS week near the recording, to resolve the broadcast 10-bit week (default: the
    /// navigation file's, else the current week).
    pub week: Option<u32>,
    /// PRNs to search for (empty: all 32).
    pub prns: Vec<u8>,
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            rate_hz: 10.0,
            elevation_mask_deg: 5.0,
            iono: IonoModel::Klobuchar,
            tropo: TropoModel::Saastamoinen,
            raim_pfa: 1e-3,
            doppler_max_hz: 5000.0,
            doppler_center_hz: 0.0,
            acq_coherent_ms: 1,
            acq_noncoherent: 10,
            allow_unhealthy: false,
            week: None,
            prns: Vec::new(),
        }
    }
}

/// The `[dr]` table: the nominal DR sensor parameters (seed 000) and the fusion settings of
/// `gpsrx run --dr`. Unset values take [`gpsrx_ins_aiding::DrParams::default`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrRunConfig {
    /// Gyro scale factor Sf_G, deg/s/V.
    pub sf_g_dps_per_v: Option<f64>,
    /// Gyro zero-rate voltage V_nom, V.
    pub v_nom_v: Option<f64>,
    /// Odometer scale factor Sf_N, m/pulse.
    pub sf_n_m_per_pulse: Option<f64>,
    /// `proposed` or `conventional`.
    pub filter: Option<String>,
    /// Least interval between GNSS updates of the filters, s.
    pub update_interval_s: Option<f64>,
}

/// Everything the receiver is configured with.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReceiverConfig {
    /// Tracking channels: loops, lock and C/N0 thresholds.
    pub tracking: ChannelConfig,
    /// Acquisition and navigation.
    pub run: RunSettings,
    /// Dead-reckoning fusion.
    pub dr: DrRunConfig,
}

/// A configuration that cannot be used; the message names the setting and its valid range.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file cannot be read.
    #[error("cannot read config {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file is not valid TOML for this struct (unknown key, wrong type).
    #[error("config {path}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// What the parser said.
        message: String,
    },
    /// A value out of its range.
    #[error("{0}")]
    Invalid(String),
}

impl ReceiverConfig {
    /// Parses a `gpsrx.toml` text (`path` names it in errors); missing keys take the defaults.
    pub fn from_toml(text: &str, path: &str) -> Result<Self, ConfigError> {
        toml::from_str(text).map_err(|e| ConfigError::Parse {
            path: path.to_string(),
            message: e.to_string(),
        })
    }

    /// Reads a `gpsrx.toml` file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// Checks every value against its valid range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.tracking
            .validate()
            .map_err(|e| ConfigError::Invalid(format!("tracking configuration: {e}")))?;
        self.run.validate()
    }
}

impl RunSettings {
    /// Checks every value against its valid range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |m: String| Err(ConfigError::Invalid(m));
        if !(1.0..=50.0).contains(&self.rate_hz) {
            return bad(format!("rate {} Hz: use 1 to 50 Hz", self.rate_hz));
        }
        if !(-10.0..=90.0).contains(&self.elevation_mask_deg) {
            return bad(format!(
                "elevation mask {} deg: use -10 to 90",
                self.elevation_mask_deg
            ));
        }
        if !(self.raim_pfa > 0.0 && self.raim_pfa < 1.0) {
            return bad(format!(
                "RAIM false-alarm probability {}: use a value in (0, 1)",
                self.raim_pfa
            ));
        }
        if !(self.doppler_max_hz > 0.0 && self.doppler_max_hz <= 100e3) {
            return bad(format!(
                "Doppler search half-width {} Hz: use (0, 100000]",
                self.doppler_max_hz
            ));
        }
        if !(self.doppler_center_hz.is_finite() && self.doppler_center_hz.abs() <= 100e3) {
            return bad(format!(
                "Doppler search centre {} Hz: use a value within +-100000",
                self.doppler_center_hz
            ));
        }
        if !(1..=10).contains(&self.acq_coherent_ms) {
            return bad(format!(
                "acquisition coherent integration {} ms: use 1 to 10 ms",
                self.acq_coherent_ms
            ));
        }
        if !(1..=1000).contains(&self.acq_noncoherent) {
            return bad(format!(
                "acquisition non-coherent blocks {}: use 1 to 1000",
                self.acq_noncoherent
            ));
        }
        if let Some(p) = self.prns.iter().find(|p| !(1..=32).contains(*p)) {
            return bad(format!("PRN {p}: GPS PRNs are 1 to 32"));
        }
        Ok(())
    }
}
