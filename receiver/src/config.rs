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
    /// Largest PDOP of a valid fix: a solution with a worse geometry is written flagged
    /// (quality `none`): 4 satellites nearly in a plane gave PDOP 217 and 90 m errors that no
    /// integrity test can see (RAIM needs 5).
    pub max_pdop: f64,
    /// Acquisition Doppler half-width, Hz.
    pub doppler_max_hz: f64,
    /// Acquisition Doppler search centre (a front-end frequency offset), Hz.
    pub doppler_center_hz: f64,
    /// Acquisition coherent integration, ms (1 to 10).
    pub acq_coherent_ms: u32,
    /// Acquisition non-coherent blocks (1 to 1000).
    pub acq_noncoherent: u32,
    /// Probability that a PRN absent from the signal is reported as a satellite, over the
    /// whole run (the background search spends it over its searches of that PRN).
    pub acq_pfa: f64,
    /// CPU time the background search may spend per second of signal, s (modelled:
    /// `crate::pipeline::channels::search_schedule`); a first round of searches may spend
    /// [`crate::pipeline::channels::BURST_S`] at once. 0: no background search, only
    /// the re-acquisition of lost satellites.
    pub search_budget_s: f64,
    /// Satellites tracked from which the first most sensitive background search (10 ms x 50)
    /// of a PRN nothing is predicted of waits 5 minutes instead of following its 10 ms x 13
    /// one at once ([`crate::pipeline::channels::DEFER_DEEP_FROM_TRACKED`], 8); 33: never
    /// (a weak satellite beside strong ones found in the first second, at the CPU cost of a
    /// deep round over every absent PRN).
    pub defer_deep_search_from: usize,
    /// Use satellites whose ephemeris says they are unhealthy.
    pub allow_unhealthy: bool,
    /// Without an INS: when every signal is gone at once under dynamics, feed the motion of
    /// the last fixes forward into the channels until a fix after the return
    /// ([`crate::pipeline::aiding::OutageBridge`]). Off: the loops coast alone.
    pub outage_bridge: bool,
    /// Full GPS week of the recording: labels times until subframe 1 gives the week, and
    /// resolves the broadcast 10-bit week (default: the recording's date, else the navigation
    /// file's week; else unknown, see [`crate::pipeline::WeekReference`]).
    pub week: Option<u32>,
    /// PRNs to search for (empty: all 32).
    pub prns: Vec<u8>,
    /// Approximate GPS time of the recording's first sample (`--time WEEK:TOW`; default: the
    /// SigMF `core:datetime`), within a minute: with [`RunSettings::approx_llh`] and `--nav`,
    /// the first fix comes from the code phases alone (`crate::pipeline::timing::coarse_fix`).
    pub approx_time: Option<gpsrx_nav::time::GpsTime>,
    /// Approximate position, `[latitude deg, longitude deg, height m]` (WGS-84), within
    /// 100 km (`--approx-llh LAT,LON,H`).
    pub approx_llh: Option<[f64; 3]>,
    /// Draw the PNG plots of the run (`track.png`, `skyplot.png`, `cn0.png`, `dop.png`,
    /// `dr.png` with `--dr`) into the output directory (`gpsrx run --no-plots`: false).
    pub plots: bool,
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            rate_hz: 10.0,
            elevation_mask_deg: 5.0,
            iono: IonoModel::Klobuchar,
            tropo: TropoModel::Saastamoinen,
            raim_pfa: 1e-3,
            max_pdop: default_max_pdop(),
            doppler_max_hz: 5000.0,
            doppler_center_hz: 0.0,
            acq_coherent_ms: 1,
            acq_noncoherent: 10,
            acq_pfa: 1e-5,
            search_budget_s: crate::pipeline::channels::DEFAULT_PER_SIGNAL_S,
            defer_deep_search_from: crate::pipeline::channels::DEFER_DEEP_FROM_TRACKED,
            allow_unhealthy: false,
            outage_bridge: true,
            week: None,
            prns: Vec::new(),
            approx_time: None,
            approx_llh: None,
            plots: true,
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
    /// The navigation filter of vector tracking (`[tracking] mode = "vector"`).
    pub vector: VectorSettings,
}

/// The `[vector]` table: the navigation filter of vector tracking
/// (`crate::pipeline::vector`), used when `[tracking] mode = "vector"`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VectorSettings {
    /// Acceleration power spectral density of the white-noise-acceleration model, per ECEF
    /// axis, m^2/s^3 (default 10: a car or a gently manoeuvring aircraft; a 10 g turn wants
    /// 1000 or more).
    pub accel_psd_m2_s3: f64,
    /// Receiver oscillator white frequency noise `h0`, s (default 2e-19, a TCXO).
    pub clock_h0: f64,
    /// Receiver oscillator random-walk frequency noise `h-2`, 1/s (default 2e-20, a TCXO).
    pub clock_h_2: f64,
    /// False-alarm probability of the innovation test that excludes a channel's measurement
    /// (chi-square, 1 degree of freedom), in (0, 0.5) (default 1e-3).
    pub gate_pfa: f64,
    /// Longest time the filter predicts a satellite (and, with none, all of them) without an
    /// admitted measurement and holds its channel through the outage on that prediction, s,
    /// in (0, 30] (default 5; its position-sigma test may end it sooner).
    pub max_coast_s: f64,
    /// With an INS (`--ins`): power spectral density of the INS velocity error's random walk,
    /// per ECEF axis, m^2/s^3, in (0, 1e6] (default 0.1: 0.1 m/s per 0.1 s epoch). An
    /// accelerometer bias of 1 mg grows the error by only 0.01 m/s per second, but an INS
    /// whose output is 50 ms late is 0.2 m/s off the Dopplers per epoch in a 10 g turn: at
    /// 0.01 the filter excluded its Dopplers and stayed 4 m/s off after the turn.
    pub ins_accel_psd_m2_s3: f64,
}

impl Default for VectorSettings {
    fn default() -> Self {
        Self {
            accel_psd_m2_s3: 10.0,
            clock_h0: 2e-19,
            clock_h_2: 2e-20,
            gate_pfa: 1e-3,
            max_coast_s: 5.0,
            ins_accel_psd_m2_s3: 0.1,
        }
    }
}

impl VectorSettings {
    /// Checks every value against its valid range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |key: &str, v: f64, range: &str| {
            Err(ConfigError::Invalid(format!(
                "[vector] {key} = {v}: use {range}"
            )))
        };
        if !(self.accel_psd_m2_s3.is_finite()
            && self.accel_psd_m2_s3 > 0.0
            && self.accel_psd_m2_s3 <= 1e6)
        {
            return bad(
                "accel_psd_m2_s3",
                self.accel_psd_m2_s3,
                "a value in (0, 1e6] m^2/s^3",
            );
        }
        if !(self.clock_h0.is_finite() && self.clock_h0 > 0.0 && self.clock_h0 < 1e-15) {
            return bad(
                "clock_h0",
                self.clock_h0,
                "a value in (0, 1e-15) s (a TCXO: 2e-19)",
            );
        }
        if !(self.clock_h_2.is_finite() && self.clock_h_2 > 0.0 && self.clock_h_2 < 1e-15) {
            return bad(
                "clock_h_2",
                self.clock_h_2,
                "a value in (0, 1e-15) /s (a TCXO: 2e-20)",
            );
        }
        if !(self.gate_pfa > 0.0 && self.gate_pfa < 0.5) {
            return bad("gate_pfa", self.gate_pfa, "a probability in (0, 0.5)");
        }
        if !(self.ins_accel_psd_m2_s3.is_finite()
            && self.ins_accel_psd_m2_s3 > 0.0
            && self.ins_accel_psd_m2_s3 <= 1e6)
        {
            return bad(
                "ins_accel_psd_m2_s3",
                self.ins_accel_psd_m2_s3,
                "a value in (0, 1e6] m^2/s^3",
            );
        }
        if !(self.max_coast_s > 0.0 && self.max_coast_s <= 30.0) {
            return bad("max_coast_s", self.max_coast_s, "a time in (0, 30] s");
        }
        Ok(())
    }
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
    /// A setting a front end may also take from its own input (a command-line option, a
    /// keyword) out of its range: `key` names it in the configuration file.
    #[error("{key}: {message}")]
    Setting {
        /// The setting in the configuration file, e.g. `[run] week`.
        key: &'static str,
        /// The value and its valid range.
        message: String,
    },
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

    /// Checks every value against its valid range: the tracking loops (and
    /// `[tracking] cn0_lost_dbhz` and `vector_cn0_lost_dbhz` within [`CN0_LOST_RANGE_DBHZ`]),
    /// `[run]`, `[vector]` and `[dr]`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.tracking
            .validate()
            .map_err(|e| ConfigError::Invalid(format!("tracking configuration: {e}")))?;
        let (lo, hi) = CN0_LOST_RANGE_DBHZ;
        let cn0_lost = self.tracking.cn0_lost_dbhz;
        if !(lo..=hi).contains(&cn0_lost) {
            return Err(ConfigError::Invalid(format!(
                "[tracking] cn0_lost_dbhz = {cn0_lost}: use {lo} to {hi} dB-Hz (the C/N0 below which a channel counts as lost; default 25)"
            )));
        }
        let vector_lost = self.tracking.vector_cn0_lost_dbhz;
        if !(lo..=hi).contains(&vector_lost) {
            return Err(ConfigError::Invalid(format!(
                "[tracking] vector_cn0_lost_dbhz = {vector_lost}: use {lo} to {hi} dB-Hz (the C/N0 below which a channel the vector filter checks counts as lost; default 19)"
            )));
        }
        self.run.validate()?;
        self.vector.validate()?;
        self.dr.validate()
    }
}

/// The valid range of `[tracking] cn0_lost_dbhz`, dB-Hz: below 10 dB-Hz no channel is ever
/// released (it tracks noise), above 45 dB-Hz nearly every real signal is.
pub const CN0_LOST_RANGE_DBHZ: (f64, f64) = (10.0, 45.0);

/// The valid range of a full GPS week (`[run] week`, `--week`): week 1024 began in August
/// 1999, week 4096 comes in 2058.
pub const WEEK_RANGE: (u32, u32) = (1024, 4096);

impl DrRunConfig {
    /// Checks every value that is set against its valid range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let check = |key: &str, value: Option<f64>, lo: f64, lo_open: bool, hi: f64, unit: &str| {
            let Some(v) = value else {
                return Ok(());
            };
            let above_lo = if lo_open { v > lo } else { v >= lo };
            if v.is_finite() && above_lo && v <= hi {
                return Ok(());
            }
            let open = if lo_open { "(" } else { "[" };
            Err(ConfigError::Invalid(format!(
                "[dr] {key} = {v}: use a value in {open}{lo}, {hi}] {unit}"
            )))
        };
        check(
            "sf_g_dps_per_v",
            self.sf_g_dps_per_v,
            0.0,
            true,
            1000.0,
            "deg/s/V (seed 000: 45.045)",
        )?;
        check(
            "v_nom_v",
            self.v_nom_v,
            -10.0,
            false,
            10.0,
            "V (seed 000: 2.5)",
        )?;
        check(
            "sf_n_m_per_pulse",
            self.sf_n_m_per_pulse,
            0.0,
            true,
            10.0,
            "m/pulse (seed 000: 0.1)",
        )?;
        check(
            "update_interval_s",
            self.update_interval_s,
            0.0,
            true,
            60.0,
            "s",
        )?;
        match self.filter.as_deref() {
            None | Some("proposed" | "conventional") => Ok(()),
            Some(other) => Err(ConfigError::Invalid(format!(
                "[dr] filter = \"{other}\": use \"proposed\" or \"conventional\""
            ))),
        }
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
        if !(self.max_pdop.is_finite() && self.max_pdop >= 1.0) {
            return bad(format!(
                "largest PDOP {}: use a number of at least 1 (e.g. 20)",
                self.max_pdop
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
        if !(self.acq_pfa > 0.0 && self.acq_pfa <= 0.1) {
            return bad(format!(
                "acquisition false-alarm probability {}: use a value in (0, 0.1]",
                self.acq_pfa
            ));
        }
        if !(self.search_budget_s.is_finite() && (0.0..=2.0).contains(&self.search_budget_s)) {
            return bad(format!(
                "search budget {} CPU s per second of signal: use 0 to 2",
                self.search_budget_s
            ));
        }
        if self.defer_deep_search_from > 33 {
            return bad(format!(
                "deep search deferred from {} satellites tracked: use 0 to 33 (33: never)",
                self.defer_deep_search_from
            ));
        }
        if let Some(p) = self.prns.iter().find(|p| !(1..=32).contains(*p)) {
            return bad(format!("PRN {p}: GPS PRNs are 1 to 32"));
        }
        if let Some(t) = self.approx_time {
            check_approx_time(&t).map_err(|message| ConfigError::Setting {
                key: "[run] approx_time",
                message,
            })?;
        }
        if let Some(llh) = self.approx_llh {
            check_approx_llh(&llh).map_err(|message| ConfigError::Setting {
                key: "[run] approx_llh",
                message,
            })?;
        }
        if let Some(w) = self.week {
            let (lo, hi) = WEEK_RANGE;
            if !(lo..=hi).contains(&w) {
                return Err(ConfigError::Setting {
                    key: "[run] week",
                    message: format!(
                        "GPS week {w}: give the full week number, {lo} to {hi} (e.g. 2190 for 1 January 2022)"
                    ),
                });
            }
        }
        Ok(())
    }
}

/// Valid heights of an approximate position, m (the coarse-time solution wants a position near
/// the Earth's surface).
pub const APPROX_HEIGHT_RANGE_M: (f64, f64) = (-1000.0, 100_000.0);

/// Checks an approximate time (`[run] approx_time`): a full week in [`WEEK_RANGE`]
/// and a time of week in [0, 604800) s.
pub fn check_approx_time(t: &gpsrx_nav::time::GpsTime) -> Result<(), String> {
    let (lo, hi) = WEEK_RANGE;
    if !(lo..=hi).contains(&t.week) {
        return Err(format!(
            "approximate time week {}: give the full GPS week, {lo} to {hi} (e.g. 2190:538200)",
            t.week
        ));
    }
    if !(t.tow_s.is_finite() && (0.0..604_800.0).contains(&t.tow_s)) {
        return Err(format!(
            "approximate time of week {} s: use 0 to 604800 s",
            t.tow_s
        ));
    }
    Ok(())
}

/// Checks an approximate position (`[run] approx_llh`): latitude within
/// +-90 deg, longitude within +-180 deg, height in [`APPROX_HEIGHT_RANGE_M`].
pub fn check_approx_llh(llh: &[f64; 3]) -> Result<(), String> {
    let [lat, lon, h] = *llh;
    let (hlo, hhi) = APPROX_HEIGHT_RANGE_M;
    if !(lat.is_finite() && lat.abs() <= 90.0) {
        return Err(format!("approximate latitude {lat} deg: use -90 to 90 deg"));
    }
    if !(lon.is_finite() && lon.abs() <= 180.0) {
        return Err(format!(
            "approximate longitude {lon} deg: use -180 to 180 deg"
        ));
    }
    if !(h.is_finite() && (hlo..=hhi).contains(&h)) {
        return Err(format!(
            "approximate height {h} m: use {hlo} to {hhi} m above the ellipsoid"
        ));
    }
    Ok(())
}

/// The default [`RunSettings::max_pdop`]: 20 (u-blox receivers mask at 25, RTKLIB's GDOP mask is
/// 30; at 20 a metre of code noise is at most 20 m of position).
fn default_max_pdop() -> f64 {
    20.0
}
