//! Simulator scenarios: the TOML file that says what to simulate.
//!
//! Every key is documented in `samples/scenarios/README.md`; unknown keys are rejected with the
//! list of valid ones (a misspelt option must never be silently ignored).

use crate::format::SampleFormat;
use crate::sim::SimError;
use gpsrx_nav::time::GpsTime;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The file name a scenario uses to ask for the broadcast ephemerides shipped inside the binary
/// (`samples/data/brdc0010.22n`, 2022-01-01).
pub const BUILTIN_NAV: &str = "builtin:brdc0010.22n";

/// The shipped RINEX navigation file, embedded so that `gpsrx demo` needs no other file.
pub const BUILTIN_NAV_TEXT: &str = include_str!("../../data/brdc0010.22n");

/// The default scenario (static receiver in Seoul, 2022-01-01, 40 s, 4 MHz ci8).
pub const DEFAULT_SCENARIO_TOML: &str = include_str!("../../scenarios/default.toml");

/// A 25-minute urban drive with intersections, stops and hills (`samples/scenarios/urban-drive.toml`),
/// the vehicle trajectory of `gpsrx study dr`.
pub const URBAN_DRIVE_TOML: &str = include_str!("../../scenarios/urban-drive.toml");

/// The highest sampling rate the simulator writes, Hz: 100 MHz. A GPS L1 C/A receiver needs
/// 2-5 MHz, a few tens of MHz at most; the simulator generates 0.1 s of samples per work unit in
/// memory, so a rate far above this would exhaust it.
pub const MAX_FS_HZ: f64 = 100e6;

/// The most samples one simulation writes (`duration_s * fs_hz`): 1e11, e.g. 1000 s at 100 MHz
/// or 13.5 h at 2.048 MHz (200 GB as ci8).
pub const MAX_SAMPLES: f64 = 1e11;

/// A complete simulation scenario.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Free text describing the scenario.
    #[serde(default)]
    pub description: String,
    /// GPS time of the first sample (receiver clock).
    pub start: StartTime,
    /// Length of the recording, seconds.
    pub duration_s: f64,
    /// Seed of the noise generator: the same seed gives the same bytes.
    #[serde(default)]
    pub seed: u64,
    /// RINEX 2/3 navigation file (relative to the scenario file), or `builtin:brdc0010.22n`.
    pub nav: String,
    /// Output file format, sampling rate and quantisation.
    pub output: OutputConfig,
    /// Receiver trajectory.
    pub receiver: ReceiverConfig,
    /// Receiver clock.
    #[serde(default)]
    pub clock: ClockConfig,
    /// Which satellites, how strong.
    #[serde(default)]
    pub satellites: SatelliteConfig,
    /// Ionosphere and troposphere switches.
    #[serde(default)]
    pub atmosphere: AtmosphereConfig,
    /// Signal blockages.
    #[serde(default)]
    pub outages: Vec<Outage>,
    /// C/N0 ramps (a tracking-threshold scan: satellites fading slowly to nothing).
    #[serde(default)]
    pub fades: Vec<Fade>,
    /// Truth output options.
    #[serde(default)]
    pub truth: TruthConfig,
    /// The `[ins]` table: INS error models, parsed by `gpsrx_ins_aiding::InsErrorConfig` (the
    /// simulator itself ignores it; `gpsrx simulate` writes ins.csv from it).
    #[serde(default)]
    pub ins: Option<toml::Table>,
    /// The `[dr]` table: gyro and odometer error models of a vehicle, parsed by
    /// `gpsrx_ins_aiding::DrSensorConfig` (`gpsrx simulate` writes dr.csv from it).
    #[serde(default)]
    pub dr: Option<toml::Table>,
    /// The `[accel]` table: longitudinal accelerometer error model, parsed by
    /// `gpsrx_ins_aiding::AccelSensorConfig` (`gpsrx simulate` writes accel.csv from it).
    #[serde(default)]
    pub accel: Option<toml::Table>,
}

/// Start time: either `week` + `tow_s`, or a GPS-time calendar string `"2022-01-01 05:30:00"`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartTime {
    /// Full GPS week number (not modulo 1024).
    pub week: Option<u32>,
    /// GPS time of week, seconds.
    pub tow_s: Option<f64>,
    /// Calendar date and time in the GPS time scale, `YYYY-MM-DD HH:MM:SS`.
    pub gps_calendar: Option<String>,
}

/// Output sample format and rate.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    /// Sample format name (`ci8`, `ci16_le`, `cf32_le`, `ri8`, `ci2`, `ci1`, ...).
    pub format: String,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Intermediate frequency, Hz (0 for complex baseband).
    #[serde(default)]
    pub if_hz: f64,
    /// Noise standard deviation per component in output units (LSBs for integer formats).
    /// Default: 20 for 8-bit, 1000 for 16-bit, 1.0 for float, 2.0 for 2-bit (threshold at 1 sigma),
    /// 1.0 for 1-bit.
    pub noise_sigma: Option<f64>,
    /// File name stem of the recording inside the output directory.
    #[serde(default = "default_name")]
    pub name: String,
}

fn default_name() -> String {
    "signal".to_string()
}

/// The receiver's motion.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ReceiverConfig {
    /// A fixed antenna, given as `llh_deg = [lat, lon, h]` or `ecef_m = [x, y, z]`.
    Static {
        /// Latitude (deg), longitude (deg), height over the WGS-84 ellipsoid (m).
        llh_deg: Option<[f64; 3]>,
        /// ECEF position, m.
        ecef_m: Option<[f64; 3]>,
    },
    /// Positions from a CSV file (`t_s,x_m,y_m,z_m` ECEF or `t_s,lat_deg,lon_deg,h_m`) at any
    /// rate, interpolated by a natural cubic spline (position, velocity and acceleration
    /// continuous).
    Csv {
        /// Path of the CSV file, relative to the scenario file.
        path: String,
    },
    /// Built-in horizontal motions in the local level frame at the start point.
    Motion {
        /// Start position: latitude (deg), longitude (deg), height (m).
        start_llh_deg: [f64; 3],
        /// Initial heading, degrees clockwise from north.
        #[serde(default)]
        heading_deg: f64,
        /// Initial speed, m/s.
        #[serde(default)]
        speed_mps: f64,
        /// Time over which longitudinal acceleration and turn rate change between segments
        /// (linear ramps, so the jerk is bounded), seconds. 0 gives acceleration steps.
        #[serde(default = "default_transition")]
        transition_s: f64,
        /// Road grade at the start, percent (rise over horizontal run x 100; positive uphill).
        #[serde(default)]
        grade_percent: f64,
        /// Time over which the road grade changes between segments that set a new
        /// `grade_percent` (a smoothstep `3w^2 - 2w^3`, so the vertical acceleration stays
        /// continuous), seconds.
        #[serde(default = "default_grade_transition")]
        grade_transition_s: f64,
        /// Motion segments, one after the other; after the last, the motion continues at
        /// constant velocity.
        segments: Vec<Segment>,
    },
}

fn default_transition() -> f64 {
    0.5
}

fn default_grade_transition() -> f64 {
    3.0
}

/// Default braking deceleration of a `stop` segment, m/s^2.
pub const DEFAULT_STOP_DECEL_MPS2: f64 = 2.0;

/// Steepest road grade a segment may set, percent (Baldwin Street, the steepest street in the
/// world, is 35 %).
pub const MAX_GRADE_PERCENT: f64 = 40.0;

/// One segment of a built-in motion.
///
/// Every segment takes an optional `grade_percent`: the road grade it drives on (reached over
/// `grade_transition_s` from the segment start); without it the grade of the previous segment
/// continues.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Segment {
    /// Constant speed.
    Cruise {
        /// Length, s.
        duration_s: f64,
        /// Road grade, percent (default: unchanged).
        grade_percent: Option<f64>,
    },
    /// Constant longitudinal acceleration (negative to brake), either for `duration_s` or until
    /// the speed reaches `to_speed_mps`.
    Accelerate {
        /// Length, s (give this or `to_speed_mps`).
        duration_s: Option<f64>,
        /// Longitudinal acceleration, m/s^2. With `to_speed_mps` this is the largest magnitude:
        /// the plateau is rounded to the table step, which lowers it slightly.
        accel_mps2: f64,
        /// Target speed, m/s: the segment lasts until the acceleration, ramped back to zero over
        /// `transition_s` at the start of the next segment, leaves exactly this speed (the next
        /// segment must start with zero acceleration, as cruise, turn and stop do, and last at
        /// least `transition_s`). `0` brings the vehicle to rest without reversing.
        to_speed_mps: Option<f64>,
        /// Road grade, percent (default: unchanged).
        grade_percent: Option<f64>,
    },
    /// A turn at the current speed with a given radius or centripetal acceleration, for a time
    /// or through an angle.
    Turn {
        /// Length, s (give this or `angle_deg`).
        duration_s: Option<f64>,
        /// Heading change, degrees (e.g. 90 at an intersection): the segment lasts
        /// `angle / turn rate`, the turn rate ramping in over `transition_s` at its start and out
        /// at the start of the next segment.
        angle_deg: Option<f64>,
        /// Turn radius, m (give this or `accel_g`).
        radius_m: Option<f64>,
        /// Centripetal acceleration in g (9.80665 m/s^2), instead of a radius.
        accel_g: Option<f64>,
        /// `"left"` or `"right"` (default right).
        #[serde(default)]
        direction: TurnDirection,
        /// Road grade, percent (default: unchanged).
        grade_percent: Option<f64>,
    },
    /// Longitudinal acceleration ramping at a constant jerk from its current value.
    Jerk {
        /// Length, s.
        duration_s: f64,
        /// Jerk, m/s^3.
        jerk_mps3: f64,
        /// Road grade, percent (default: unchanged).
        grade_percent: Option<f64>,
    },
    /// Brake to rest at `decel_mps2` (jerk-limited over `transition_s`, never reversing), then
    /// stand still for `duration_s` (the braking time comes on top).
    Stop {
        /// Time at rest, s (0: drive off at once).
        duration_s: f64,
        /// Braking deceleration, m/s^2, positive (default 2).
        decel_mps2: Option<f64>,
        /// Road grade, percent (default: unchanged).
        grade_percent: Option<f64>,
    },
}

impl Segment {
    /// The road grade this segment sets, percent (None: unchanged).
    pub fn grade_percent(&self) -> Option<f64> {
        match self {
            Self::Cruise { grade_percent, .. }
            | Self::Accelerate { grade_percent, .. }
            | Self::Turn { grade_percent, .. }
            | Self::Jerk { grade_percent, .. }
            | Self::Stop { grade_percent, .. } => *grade_percent,
        }
    }

    /// Checks the values TOML types cannot (positive durations, one of two alternatives, grades
    /// within [`MAX_GRADE_PERCENT`]); `k` numbers the segment from 1 in the messages.
    pub fn validate(&self, k: usize) -> Result<(), String> {
        let bad = |m: String| Err(format!("segment {k}: {m}"));
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("segment {k}: {name} = {v} must be positive"))
            }
        };
        if let Some(g) = self.grade_percent() {
            if !(g.is_finite() && g.abs() <= MAX_GRADE_PERCENT) {
                return bad(format!(
                    "grade_percent = {g} must be within +-{MAX_GRADE_PERCENT}"
                ));
            }
        }
        match self {
            Self::Cruise { duration_s, .. } | Self::Jerk { duration_s, .. } => {
                positive("duration_s", *duration_s)
            }
            Self::Turn {
                duration_s,
                angle_deg,
                radius_m,
                accel_g,
                ..
            } => {
                match (duration_s, angle_deg) {
                    (Some(d), None) => positive("duration_s", *d)?,
                    (None, Some(a)) => positive("angle_deg", *a)?,
                    _ => return bad("a turn needs exactly one of duration_s or angle_deg".into()),
                }
                if radius_m.is_some() == accel_g.is_some() {
                    return bad("a turn segment needs exactly one of radius_m or accel_g".into());
                }
                Ok(())
            }
            Self::Accelerate {
                duration_s,
                accel_mps2,
                to_speed_mps,
                ..
            } => {
                if !accel_mps2.is_finite() {
                    return bad(format!("accel_mps2 = {accel_mps2} must be a number"));
                }
                match (duration_s, to_speed_mps) {
                    (Some(d), None) => positive("duration_s", *d),
                    (None, Some(v)) if v.is_finite() && *v >= 0.0 => {
                        if *accel_mps2 == 0.0 {
                            return bad(
                                "accelerate to_speed_mps needs a non-zero accel_mps2".into()
                            );
                        }
                        Ok(())
                    }
                    (None, Some(v)) => bad(format!("to_speed_mps = {v} must be >= 0")),
                    _ => bad(
                        "an accelerate segment needs exactly one of duration_s or to_speed_mps"
                            .into(),
                    ),
                }
            }
            Self::Stop {
                duration_s,
                decel_mps2,
                ..
            } => {
                if !(duration_s.is_finite() && *duration_s >= 0.0) {
                    return bad(format!("stop duration_s = {duration_s} must be >= 0"));
                }
                positive("decel_mps2", decel_mps2.unwrap_or(DEFAULT_STOP_DECEL_MPS2))
            }
        }
    }
}

/// Turn direction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TurnDirection {
    /// Counter-clockwise seen from above.
    Left,
    /// Clockwise seen from above.
    #[default]
    Right,
}

/// Receiver clock model: `b(t) = bias_s + drift_s_s * t + w(t)`, `w` a white-frequency-noise
/// random walk whose Allan deviation at 1 s is `allan_deviation_1s`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClockConfig {
    /// Clock bias at the first sample, seconds.
    #[serde(default)]
    pub bias_s: f64,
    /// Clock drift, s/s (1e-6 = 1 ppm, about -1575 Hz of Doppler offset).
    #[serde(default)]
    pub drift_s_s: f64,
    /// Allan deviation at tau = 1 s of the white frequency noise (0 = none).
    #[serde(default)]
    pub allan_deviation_1s: f64,
    /// Random-walk frequency noise, power-law coefficient h_-2 of S_y(f) = h_-2 / f^2 (1/s;
    /// 0 = none): adds (2 pi^2 / 3) h_-2 tau to the Allan variance (see `sim::clock`).
    #[serde(default)]
    pub random_walk_fm_h_m2: f64,
}

/// Satellite selection and signal strength.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SatelliteConfig {
    /// Elevation mask, degrees: satellites below it at the start are not simulated.
    #[serde(default = "default_mask")]
    pub elevation_mask_deg: f64,
    /// Simulate only these PRNs (those above the horizon); default all above the mask.
    pub prns: Option<Vec<u8>>,
    /// C/N0 at zenith, dB-Hz (elevation model: `zenith - horizon_loss * (1 - sin el)`).
    #[serde(default = "default_cn0_zenith")]
    pub cn0_zenith_dbhz: f64,
    /// C/N0 loss from zenith to the horizon, dB.
    #[serde(default = "default_cn0_loss")]
    pub cn0_horizon_loss_db: f64,
    /// One C/N0 for every satellite, dB-Hz, instead of the elevation model.
    pub cn0_all_dbhz: Option<f64>,
    /// Per-satellite C/N0 overrides.
    #[serde(default)]
    pub cn0: Vec<Cn0Override>,
    /// Modulate the navigation data bits (false: a dataless signal, for loop studies).
    #[serde(default = "default_true")]
    pub nav_data: bool,
    /// Send a real almanac in subframes 4 and 5 (IS-GPS-200 20.3.3.5, 25-page cycle), derived
    /// from the ephemerides of all 32 PRNs at the start. Off by default: subframe 4 then
    /// carries the ionosphere/UTC page 18 in every frame, whereas with the almanac page 18
    /// comes once per 12.5 min and short recordings may hold none.
    #[serde(default)]
    pub almanac: bool,
}

impl Default for SatelliteConfig {
    fn default() -> Self {
        Self {
            elevation_mask_deg: default_mask(),
            prns: None,
            cn0_zenith_dbhz: default_cn0_zenith(),
            cn0_horizon_loss_db: default_cn0_loss(),
            cn0_all_dbhz: None,
            cn0: Vec::new(),
            nav_data: true,
            almanac: false,
        }
    }
}

fn default_mask() -> f64 {
    5.0
}
fn default_cn0_zenith() -> f64 {
    47.0
}
fn default_cn0_loss() -> f64 {
    9.0
}
fn default_true() -> bool {
    true
}

/// A fixed C/N0 for one satellite.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cn0Override {
    /// PRN.
    pub prn: u8,
    /// C/N0, dB-Hz.
    pub dbhz: f64,
}

/// Atmosphere switches.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtmosphereConfig {
    /// Klobuchar ionosphere from the nav file's alpha/beta (code delayed, carrier advanced).
    #[serde(default = "default_true")]
    pub ionosphere: bool,
    /// Saastamoinen troposphere (standard atmosphere).
    #[serde(default = "default_true")]
    pub troposphere: bool,
}

impl Default for AtmosphereConfig {
    fn default() -> Self {
        Self {
            ionosphere: true,
            troposphere: true,
        }
    }
}

/// A C/N0 ramp: from `start_s` to `end_s` the listed satellites' C/N0 changes by `db_per_s`
/// (negative: a fade), and stays at the level reached after it.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fade {
    /// Start, seconds from the first sample.
    pub start_s: f64,
    /// End, seconds from the first sample.
    pub end_s: f64,
    /// Rate of the C/N0 change, dB/s.
    pub db_per_s: f64,
    /// Faded PRNs (empty: all).
    #[serde(default)]
    pub prns: Vec<u8>,
}

impl Fade {
    /// The C/N0 change it has made at `t_s`, dB.
    pub fn db_at(&self, t_s: f64) -> f64 {
        self.db_per_s * (t_s.min(self.end_s) - self.start_s).max(0.0)
    }
}

/// A window in which signals are blocked.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outage {
    /// Start, seconds from the first sample.
    pub start_s: f64,
    /// End, seconds from the first sample.
    pub end_s: f64,
    /// Blocked PRNs (empty: all).
    #[serde(default)]
    pub prns: Vec<u8>,
}

/// Truth output options.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthConfig {
    /// Rate of `truth.csv` and `truth_sv.csv` rows, Hz.
    #[serde(default = "default_truth_rate")]
    pub rate_hz: f64,
}

impl Default for TruthConfig {
    fn default() -> Self {
        Self {
            rate_hz: default_truth_rate(),
        }
    }
}

fn default_truth_rate() -> f64 {
    100.0
}

impl Scenario {
    /// Parses a scenario from TOML text. `base_dir` resolves relative paths in it.
    pub fn from_toml(text: &str) -> Result<Self, SimError> {
        let sc: Scenario = toml::from_str(text).map_err(|e| SimError::Scenario(e.to_string()))?;
        sc.validate()?;
        Ok(sc)
    }

    /// Reads and validates a scenario file.
    pub fn load(path: &Path) -> Result<(Self, PathBuf), SimError> {
        let text = std::fs::read_to_string(path).map_err(|e| SimError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let sc = Self::from_toml(&text).map_err(|e| match e {
            SimError::Scenario(m) => SimError::Scenario(format!("{}: {m}", path.display())),
            other => other,
        })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Ok((sc, base))
    }

    /// The built-in default scenario.
    pub fn default_scenario() -> Result<Self, SimError> {
        Self::from_toml(DEFAULT_SCENARIO_TOML)
    }

    /// GPS time of the first sample.
    pub fn start_time(&self) -> Result<GpsTime, SimError> {
        let s = &self.start;
        match (s.week, s.tow_s, &s.gps_calendar) {
            (Some(w), Some(t), None) => Ok(GpsTime::new(w, t)),
            (None, None, Some(c)) => parse_calendar(c),
            _ => Err(SimError::Scenario(
                "[start] needs either `week` and `tow_s`, or `gps_calendar = \"YYYY-MM-DD HH:MM:SS\"`"
                    .into(),
            )),
        }
    }

    /// The output sample format.
    pub fn format(&self) -> Result<SampleFormat, SimError> {
        self.output
            .format
            .parse::<SampleFormat>()
            .map_err(|e| SimError::Scenario(format!("[output] format: {e}")))
    }

    /// Noise standard deviation per component in output units.
    pub fn noise_sigma(&self) -> Result<f64, SimError> {
        if let Some(s) = self.output.noise_sigma {
            return Ok(s);
        }
        let fmt = self.format()?;
        Ok(match fmt {
            SampleFormat::Ci8 | SampleFormat::Ri8 | SampleFormat::Cu8 { .. } => 20.0,
            SampleFormat::Ci16Le | SampleFormat::Ri16Le => 1000.0,
            SampleFormat::Cf32Le | SampleFormat::Cf64Le | SampleFormat::Rf32Le => 1.0,
            SampleFormat::Packed2 { map, .. } => {
                // Threshold halfway between the inner and outer levels at 1 sigma.
                let inner = map.iter().map(|v| v.abs()).fold(f32::INFINITY, f32::min);
                let outer = map.iter().map(|v| v.abs()).fold(0.0f32, f32::max);
                f64::from(inner + outer) / 2.0
            }
            SampleFormat::Packed1Complex | SampleFormat::Packed1Real { .. } => 1.0,
        })
    }

    /// Checks values that TOML types cannot, and the size of the recording: `fs_hz` at most
    /// [`MAX_FS_HZ`], `duration_s * fs_hz` at most [`MAX_SAMPLES`].
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |m: String| Err(SimError::Scenario(m));
        self.start_time()?;
        let fmt = self.format()?;
        if !(self.duration_s.is_finite() && self.duration_s > 0.0) {
            return bad(format!("duration_s = {} must be positive", self.duration_s));
        }
        let fs = self.output.fs_hz;
        let min_fs = if fmt.is_complex() { 1.023e6 } else { 2.046e6 };
        if !(fs.is_finite() && fs >= min_fs) {
            return bad(format!(
                "[output] fs_hz = {fs} is too low for GPS L1 C/A: at least {min_fs} Hz for {} samples",
                if fmt.is_complex() { "complex" } else { "real" }
            ));
        }
        if fs > MAX_FS_HZ {
            return bad(format!(
                "[output] fs_hz = {fs} Hz is above the simulator's limit of {} MHz (a GPS L1 C/A receiver needs a few MHz, at most a few tens): use a lower rate",
                MAX_FS_HZ / 1e6
            ));
        }
        let samples = self.duration_s * fs;
        if samples > MAX_SAMPLES {
            return bad(format!(
                "duration_s x fs_hz = {} s x {fs} Hz = {samples:.3e} samples is above the simulator's limit of {MAX_SAMPLES:.0e} samples (e.g. 1000 s at 100 MHz, 13.5 h at 2.048 MHz): shorten duration_s or lower fs_hz",
                self.duration_s
            ));
        }
        let f_if = self.output.if_hz;
        if !f_if.is_finite() || (fmt.is_complex() && f_if.abs() >= fs / 2.0) {
            return bad(format!(
                "[output] if_hz = {f_if} is outside the band (|IF| < fs/2)"
            ));
        }
        let real_if_ok = f_if > 0.0 && f_if < fs / 2.0;
        if !fmt.is_complex() && !real_if_ok {
            return bad(format!(
                "[output] if_hz = {f_if}: a real output needs 0 < IF < fs/2 \
                 (ideally 1.023 MHz < IF < fs/2 - 1.023 MHz so the main lobe does not fold)"
            ));
        }
        if let Some(s) = self.output.noise_sigma {
            if !(s.is_finite() && s > 0.0) {
                return bad(format!("[output] noise_sigma = {s} must be positive"));
            }
        }
        if !(self.truth.rate_hz > 0.0 && self.truth.rate_hz <= 1000.0) {
            return bad(format!(
                "[truth] rate_hz = {} must be in (0, 1000]",
                self.truth.rate_hz
            ));
        }
        if let Some(prns) = &self.satellites.prns {
            for &p in prns {
                if !(1..=32).contains(&p) {
                    return bad(format!("[satellites] prns: {p} is not a GPS PRN (1-32)"));
                }
            }
        }
        for c in &self.satellites.cn0 {
            if !(1..=32).contains(&c.prn) || !c.dbhz.is_finite() {
                return bad(format!(
                    "[[satellites.cn0]] prn {} dbhz {} is invalid",
                    c.prn, c.dbhz
                ));
            }
        }
        for o in &self.outages {
            if !(o.start_s.is_finite() && o.end_s.is_finite() && o.end_s > o.start_s) {
                return bad(format!(
                    "[[outages]] {}..{} s: end must follow start",
                    o.start_s, o.end_s
                ));
            }
        }
        for f in &self.fades {
            if !(f.start_s.is_finite() && f.end_s.is_finite() && f.end_s > f.start_s) {
                return bad(format!(
                    "[[fades]] {}..{} s: end must follow start",
                    f.start_s, f.end_s
                ));
            }
            if !(f.db_per_s.is_finite() && f.db_per_s.abs() <= 100.0) {
                return bad(format!(
                    "[[fades]] db_per_s = {}: use a rate within +-100 dB/s",
                    f.db_per_s
                ));
            }
        }
        if self.clock.random_walk_fm_h_m2 < 0.0 || !self.clock.random_walk_fm_h_m2.is_finite() {
            return bad("[clock] random_walk_fm_h_m2 must be >= 0".into());
        }
        if self.clock.allan_deviation_1s < 0.0 || !self.clock.allan_deviation_1s.is_finite() {
            return bad("[clock] allan_deviation_1s must be >= 0".into());
        }
        match &self.receiver {
            ReceiverConfig::Static { llh_deg, ecef_m } => {
                if llh_deg.is_some() == ecef_m.is_some() {
                    return bad(
                        "[receiver] kind = \"static\" needs exactly one of llh_deg or ecef_m"
                            .into(),
                    );
                }
            }
            ReceiverConfig::Csv { .. } => {}
            ReceiverConfig::Motion {
                segments,
                transition_s,
                grade_percent,
                grade_transition_s,
                speed_mps,
                ..
            } => {
                if !(transition_s.is_finite() && *transition_s >= 0.0) {
                    return bad("[receiver] transition_s must be >= 0".into());
                }
                if !(grade_transition_s.is_finite() && *grade_transition_s >= 0.0) {
                    return bad("[receiver] grade_transition_s must be >= 0".into());
                }
                if !(speed_mps.is_finite() && *speed_mps >= 0.0) {
                    return bad(format!("[receiver] speed_mps = {speed_mps} must be >= 0"));
                }
                if !(grade_percent.is_finite() && grade_percent.abs() <= MAX_GRADE_PERCENT) {
                    return bad(format!(
                        "[receiver] grade_percent = {grade_percent} must be within +-{MAX_GRADE_PERCENT}"
                    ));
                }
                for (k, s) in segments.iter().enumerate() {
                    s.validate(k + 1)
                        .map_err(|m| SimError::Scenario(format!("[receiver] {m}")))?;
                }
            }
        }
        Ok(())
    }

    /// Reads the navigation data the scenario names.
    pub fn nav_text(&self, base_dir: &Path) -> Result<(String, String), SimError> {
        if self.nav == BUILTIN_NAV {
            return Ok((BUILTIN_NAV_TEXT.to_string(), BUILTIN_NAV.to_string()));
        }
        let p = base_dir.join(&self.nav);
        let text = std::fs::read_to_string(&p).map_err(|e| SimError::Io {
            path: p.clone(),
            message: format!("{e} (the scenario's `nav` is relative to the scenario file; `{BUILTIN_NAV}` uses the shipped file)"),
        })?;
        Ok((text, p.display().to_string()))
    }
}

fn parse_calendar(c: &str) -> Result<GpsTime, SimError> {
    let err = || {
        SimError::Scenario(format!(
            "[start] gps_calendar = \"{c}\": expected \"YYYY-MM-DD HH:MM:SS\" (GPS time scale)"
        ))
    };
    let c = c.trim().replace('T', " ");
    let (date, time) = c.split_once(' ').ok_or_else(err)?;
    let d: Vec<&str> = date.split('-').collect();
    let t: Vec<&str> = time.trim().split(':').collect();
    if d.len() != 3 || t.len() != 3 {
        return Err(err());
    }
    let y: i32 = d[0].parse().map_err(|_| err())?;
    let mo: u32 = d[1].parse().map_err(|_| err())?;
    let da: u32 = d[2].parse().map_err(|_| err())?;
    let h: u32 = t[0].parse().map_err(|_| err())?;
    let mi: u32 = t[1].parse().map_err(|_| err())?;
    let s: f64 = t[2].parse().map_err(|_| err())?;
    if !(1980..=2200).contains(&y)
        || !(1..=12).contains(&mo)
        || !(1..=31).contains(&da)
        || h > 23
        || mi > 59
        || !(0.0..60.0).contains(&s)
    {
        return Err(err());
    }
    Ok(GpsTime::from_calendar(y, mo, da, h, mi, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    const WITH_INS: &str = r#"
duration_s = 2.0
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci8"
fs_hz = 2.048e6
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[ins]
rate_hz = 50.0
accel_bias_enu_mps2 = [0.01, 0.01, 0.0]
band_limit_alpha_rad_s = 2.0
"#;

    #[test]
    fn ins_table_is_kept_as_given_and_round_trips() {
        let sc = Scenario::from_toml(WITH_INS).unwrap_or_else(|e| panic!("{e}"));
        let ins = sc.ins.clone().unwrap_or_else(|| panic!("no [ins]"));
        assert_eq!(ins.get("rate_hz").and_then(|v| v.as_float()), Some(50.0));
        assert_eq!(
            ins.get("accel_bias_enu_mps2")
                .and_then(|v| v.as_array())
                .map(|a| a.len()),
            Some(3)
        );
        // TOML and JSON round trips keep the table.
        let text = toml::to_string(&sc).unwrap_or_else(|e| panic!("{e}"));
        let back = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(back.ins, sc.ins);
        let json = serde_json::to_string(&sc).unwrap_or_else(|e| panic!("{e}"));
        let back: Scenario = serde_json::from_str(&json).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back.ins, sc.ins);
        // Without the table the field is None, and the rest of the scenario is unchanged.
        let plain = WITH_INS.split("[ins]").next().unwrap_or_default();
        let sc2 = Scenario::from_toml(plain).unwrap_or_else(|e| panic!("{e}"));
        assert!(sc2.ins.is_none());
        assert_eq!(sc2.duration_s, sc.duration_s);
    }
}
