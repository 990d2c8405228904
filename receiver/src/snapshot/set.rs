//! A snapshot set as one job: its input, navigation data, a-priori and options in one
//! [`SnapshotSetSpec`], run by [`run_set`] and written by [`write_set`]. `gpsrx snapshot`,
//! `gpsrx batch` (`[[snapshots]]` entries) and the Python package (`gpsrx.snapshot`, and
//! snapshot tasks of `gpsrx.batch`) all go through here.
//!
//! # Inputs ([`read_set`])
//!
//! - a SnapperGPS JSON file (`.json`; [`super::snappergps`]): many snapshots, each with its
//!   device timestamp;
//! - a SigMF recording with several captures (one per snapshot, [`super::input::read_sigmf_set`]):
//!   each capture's `core:datetime` is its snapshot's approximate time;
//! - any other recording (raw with `format`/`fs_hz`/`if_hz`, WAV, or SigMF with one capture):
//!   one snapshot, its time from `time` or else from the SigMF `core:datetime`.
//!
//! `time` (`WEEK:TOW`) given with time-tagged snapshots moves every tag by the same amount, so
//! that the first snapshot's tag becomes `time`.

use super::driver::{Seed, SnapshotOptions, SnapshotOutcome, SnapshotProcessor};
use super::input::{read_raw_snapshot, read_sigmf_set, SampleSpec, Snapshot};
use super::output::{self, Score, Truth};
use super::smooth::{smooth_track, SmoothOptions, DEFAULT_RANGE_SIGMA_M};
use super::snappergps::read_snappergps;
use super::SnapshotError;
use gpsrx_nav::pvt::HeightConstraint;
use gpsrx_nav::{GpsTime, Llh, NavData, Vector3};
use gpsrx_samples::SampleFormat;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Default sigma of the height constraint, m (the a-priori height).
pub const DEFAULT_HEIGHT_SIGMA_M: f64 = 30.0;
/// Default largest receiver speed, m/s.
pub const DEFAULT_MAX_SPEED_MPS: f64 = 50.0;

fn default_height_sigma() -> f64 {
    DEFAULT_HEIGHT_SIGMA_M
}
fn default_max_speed() -> f64 {
    DEFAULT_MAX_SPEED_MPS
}

/// One snapshot set and how to position it (the keys of a `[[snapshots]]` table of a batch
/// manifest and the arguments of `gpsrx.snapshot`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SnapshotSetSpec {
    /// Name in a batch summary and of its output directory (default: the file stem).
    #[serde(default)]
    pub name: String,
    /// The snapshots (module docs: inputs).
    pub path: PathBuf,
    /// RINEX navigation file (or `builtin:brdc0010.22n`); without one no satellite can be
    /// predicted ([`SnapshotError::NoEphemerides`]).
    #[serde(default)]
    pub nav: Option<String>,
    /// Approximate position `[lat_deg, lon_deg, h_m]` (supported error: about 100 km).
    pub approx_llh: [f64; 3],
    /// GPS time of the first sample, `WEEK:TOW` (module docs).
    #[serde(default)]
    pub time: Option<String>,
    /// Sample format of a raw recording (`ri1_lsb`, `ri2_lsb`, `ci8`, ...).
    #[serde(default)]
    pub format: Option<String>,
    /// Value map of a 2-bit format's codes 00, 01, 10, 11.
    #[serde(default)]
    pub map: Option<[f32; 4]>,
    /// Sampling rate of a raw recording, Hz.
    #[serde(default)]
    pub fs_hz: Option<f64>,
    /// Intermediate frequency of a raw recording, Hz.
    #[serde(default)]
    pub if_hz: f64,
    /// Sigma of the height constraint to the a-priori height, m (0: none).
    #[serde(default = "default_height_sigma")]
    pub height_sigma_m: f64,
    /// Largest receiver speed, m/s.
    #[serde(default = "default_max_speed")]
    pub max_speed_mps: f64,
    /// Coherent integration of the search, ms (default: automatic).
    #[serde(default)]
    pub coherent_ms: Option<u32>,
    /// Look for the satellites the searches missed with the coherent test too
    /// ([`super::coherent`]).
    #[serde(default)]
    pub coherent_look: bool,
    /// Acceleration sigma of the track smoother, m/s^2 (`None`: each snapshot alone).
    #[serde(default)]
    pub smooth_accel_mps2: Option<f64>,
    /// A SnapperGPS truth JSON file to score against.
    #[serde(default)]
    pub truth: Option<PathBuf>,
    /// Ellipsoidal height of the `truth` track, m.
    #[serde(default)]
    pub truth_h_m: f64,
    /// One static reference position to score against, ECEF m.
    #[serde(default)]
    pub truth_ecef_m: Option<[f64; 3]>,
}

impl SnapshotSetSpec {
    /// A set at `path` with navigation data `nav` and the a-priori `approx_llh`, the other
    /// settings at their defaults.
    pub fn new(path: impl Into<PathBuf>, nav: Option<String>, approx_llh: [f64; 3]) -> Self {
        let path = path.into();
        Self {
            name: default_name(&path),
            path,
            nav,
            approx_llh,
            time: None,
            format: None,
            map: None,
            fs_hz: None,
            if_hz: 0.0,
            height_sigma_m: DEFAULT_HEIGHT_SIGMA_M,
            max_speed_mps: DEFAULT_MAX_SPEED_MPS,
            coherent_ms: None,
            coherent_look: false,
            smooth_accel_mps2: None,
            truth: None,
            truth_h_m: 0.0,
            truth_ecef_m: None,
        }
    }

    /// The a-priori position, checked.
    pub fn apriori(&self) -> Result<Llh, SnapshotError> {
        let [lat, lon, h] = self.approx_llh;
        if !(lat.is_finite() && lon.is_finite() && h.is_finite())
            || lat.abs() > 90.0
            || lon.abs() > 360.0
            || h.abs() > 1e6
        {
            return Err(SnapshotError::Option(format!(
                "approximate position {:?}: give latitude within +-90 deg, longitude within \
                 +-360 deg and |height| below 1000 km",
                self.approx_llh
            )));
        }
        Ok(Llh::from_degrees(lat, lon, h))
    }

    /// The options of the processor, checked.
    pub fn options(&self, apriori: &Llh) -> Result<SnapshotOptions, SnapshotError> {
        let bad = |m: String| Err(SnapshotError::Option(m));
        if !(self.max_speed_mps.is_finite() && (0.0..=2000.0).contains(&self.max_speed_mps)) {
            return bad(format!(
                "largest speed {} m/s: give 0 to 2000 m/s",
                self.max_speed_mps
            ));
        }
        if !(self.height_sigma_m.is_finite() && self.height_sigma_m >= 0.0) {
            return bad(format!(
                "height sigma {} m: give a non-negative number of metres",
                self.height_sigma_m
            ));
        }
        if self.coherent_ms == Some(0) {
            return bad("coherent integration 0 ms: give 1 ms or more".into());
        }
        let mut opts = SnapshotOptions::default();
        opts.measure.coherent_ms = self.coherent_ms;
        opts.measure.max_speed_mps = self.max_speed_mps;
        opts.measure.coherent_predicted = self.coherent_look;
        opts.solve.height = (self.height_sigma_m > 0.0).then_some(HeightConstraint {
            h_m: apriori.h_m,
            sigma_m: self.height_sigma_m,
        });
        Ok(opts)
    }

    /// The smoother's settings, checked (`None`: no smoothing).
    pub fn smoothing(&self) -> Result<Option<SmoothOptions>, SnapshotError> {
        match self.smooth_accel_mps2 {
            None => Ok(None),
            Some(a) if a.is_finite() && a > 0.0 => Ok(Some(SmoothOptions {
                accel_sigma_mps2: a,
                range_sigma_m: DEFAULT_RANGE_SIGMA_M,
            })),
            Some(a) => Err(SnapshotError::Option(format!(
                "smoothing acceleration {a}: give a positive acceleration in m/s^2"
            ))),
        }
    }

    /// The GPS time given, if any.
    pub fn gps_time(&self) -> Result<Option<GpsTime>, SnapshotError> {
        self.time.as_deref().map(parse_week_tow).transpose()
    }

    /// The sample format with the 2-bit map applied.
    pub fn sample_format(&self) -> Result<Option<SampleFormat>, SnapshotError> {
        let Some(name) = &self.format else {
            return Ok(None);
        };
        let bad = |e: String| SnapshotError::Option(format!("sample format {name:?}: {e}"));
        let mut f: SampleFormat = name
            .parse()
            .map_err(|e: gpsrx_samples::SampleError| bad(e.to_string()))?;
        if let Some(m) = self.map {
            let SampleFormat::Packed2 { map, .. } = &mut f else {
                return Err(bad("a value map applies to the 2-bit formats only".into()));
            };
            *map = m;
            f.validate().map_err(|e| bad(e.to_string()))?;
        }
        Ok(Some(f))
    }

    /// The truth to score against, if one is given.
    pub fn read_truth(&self) -> Result<Option<Truth>, SnapshotError> {
        if let Some(p) = &self.truth {
            return output::read_truth_track(p, self.truth_h_m).map(Some);
        }
        Ok(self
            .truth_ecef_m
            .map(|[x, y, z]| Truth::Static(Llh::from_ecef(&Vector3::new(x, y, z)))))
    }

    /// The navigation data (`builtin:` names the simulator's built-in file).
    pub fn read_nav(&self) -> Result<NavData, SnapshotError> {
        use gpsrx_samples::sim::scenario::{BUILTIN_NAV, BUILTIN_NAV_TEXT};
        let nav_error = |path: &str, reason: String| SnapshotError::Nav {
            path: PathBuf::from(path),
            reason,
        };
        match self.nav.as_deref() {
            None => Ok(NavData::default()),
            Some(BUILTIN_NAV) => gpsrx_nav::rinex_nav::parse_rinex_nav(BUILTIN_NAV_TEXT)
                .map_err(|e| nav_error(BUILTIN_NAV, e.to_string())),
            Some(p) => {
                gpsrx_nav::read_rinex_nav(Path::new(p)).map_err(|e| nav_error(p, e.to_string()))
            }
        }
    }
}

/// Parses `WEEK:TOW` (full GPS week, seconds of week).
pub fn parse_week_tow(text: &str) -> Result<GpsTime, SnapshotError> {
    let bad = |why: &str| {
        SnapshotError::Option(format!(
            "time {text:?}: {why} (give WEEK:TOW, e.g. 2190:538200: full GPS week, seconds of week)"
        ))
    };
    let (w, tow) = text.split_once(':').ok_or_else(|| bad("no colon"))?;
    let week: u32 = w
        .trim()
        .parse()
        .map_err(|_| bad("the week is not a whole number"))?;
    let tow: f64 = tow
        .trim()
        .parse()
        .map_err(|_| bad("the time of week is not a number"))?;
    if !(0.0..604_800.0).contains(&tow) {
        return Err(bad("the time of week must be in [0, 604800) s"));
    }
    if week < 1024 {
        return Err(bad("the week modulo 1024 is ambiguous"));
    }
    Ok(GpsTime::new(week, tow))
}

/// The file name without its extension.
fn default_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| path.display().to_string())
}

/// Reads the snapshots of `spec` (module docs: inputs).
pub fn read_set(spec: &SnapshotSetSpec) -> Result<Vec<Snapshot>, SnapshotError> {
    let p = &spec.path;
    let ext = |e: &str| p.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    if ext("json") {
        return read_snappergps(p);
    }
    if let Some(set) = read_sigmf_set(p)? {
        return Ok(set);
    }
    let sample_spec = SampleSpec {
        format: spec.sample_format()?,
        fs_hz: spec.fs_hz,
        if_hz: spec.if_hz,
        invert_q: false,
    };
    let time = match spec.gps_time()? {
        Some(t) => Some(t),
        None => gpsrx_samples::sigmf::recording_start(p)
            .ok()
            .flatten()
            .map(|s| s.time),
    };
    Ok(vec![read_raw_snapshot(p, &sample_spec, time)?])
}

/// The result of a set.
#[derive(Debug, Clone, PartialEq)]
pub struct SetResult {
    /// One row per input snapshot, in input order.
    pub outcomes: Vec<SnapshotOutcome>,
    /// Horizontal error of each row against the truth (empty without a truth).
    pub errors: Vec<Option<f64>>,
    /// Whether a truth was given.
    pub scored: bool,
    /// The fix rate and error percentiles ([`output::score`]; NaN errors without a truth).
    pub score: Score,
    /// Fixes moved by the smoother (`None`: not smoothed).
    pub smoothed: Option<usize>,
    /// Seconds of samples in the set.
    pub signal_s: f64,
    /// Wall-clock seconds of the positioning (reading and writing left out).
    pub elapsed_s: f64,
}

/// Reads and positions the set of `spec`; `progress` is told each snapshot of the first pass.
/// A bad snapshot is a row of quality `none`; only an unusable input, navigation file, truth
/// or option is an error.
pub fn run_set(
    spec: &SnapshotSetSpec,
    progress: impl FnMut(&SnapshotOutcome),
) -> Result<SetResult, SnapshotError> {
    let llh = spec.apriori()?;
    let opts = spec.options(&llh)?;
    let smoothing = spec.smoothing()?;
    let time = spec.gps_time()?;
    let nav = spec.read_nav()?;
    let truth = spec.read_truth()?;
    let snapshots = read_set(spec)?;
    if snapshots.is_empty() {
        return Err(SnapshotError::Input {
            path: spec.path.clone(),
            reason: "it holds no snapshot".into(),
        });
    }
    // A given time with time-tagged snapshots: every tag moved by the same amount.
    let tag_correction_s = match (time, snapshots[0].approx_time) {
        (Some(t), Some(tag)) => t.diff_s(tag),
        _ => 0.0,
    };
    let seed = Seed {
        pos_ecef_m: llh.to_ecef(),
        time_correction_s: tag_correction_s,
        time,
    };
    let mut processor = SnapshotProcessor::new(&nav, opts)?;
    let started = std::time::Instant::now();
    let mut outcomes = processor.run(&snapshots, seed, progress);
    let smoothed = smoothing.map(|s| smooth_track(&mut outcomes, &s));
    let elapsed_s = started.elapsed().as_secs_f64();
    let errors = truth
        .as_ref()
        .map_or_else(Vec::new, |t| t.errors(&outcomes));
    let score = output::score(&outcomes, &errors);
    let signal_s = snapshots
        .iter()
        .map(|s| s.samples.len() as f64 / s.fs_hz)
        .sum();
    Ok(SetResult {
        outcomes,
        errors,
        scored: truth.is_some(),
        score,
        smoothed,
        signal_s,
        elapsed_s,
    })
}

/// Writes `snapshots.csv`, the tracks and, when scored, `errors.png` into `dir` (created).
pub fn write_set(dir: &Path, r: &SetResult) -> Result<(), SnapshotError> {
    std::fs::create_dir_all(dir).map_err(|e| SnapshotError::Input {
        path: dir.to_path_buf(),
        reason: format!("cannot create the output directory: {e}"),
    })?;
    output::write_csv(&dir.join("snapshots.csv"), &r.outcomes, &r.errors)?;
    output::write_tracks(dir, &r.outcomes)?;
    if r.scored {
        output::draw_errors(&dir.join("errors.png"), &r.outcomes, &r.errors)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spec_from_toml_takes_defaults_and_refuses_unknown_keys() {
        let s: SnapshotSetSpec = toml::from_str(
            "path = \"walk.json\"\nnav = \"w.nav\"\napprox_llh = [52.0, -1.2, 112.0]\n\
             smooth_accel_mps2 = 0.5",
        )
        .expect("valid");
        assert_eq!(s.height_sigma_m, DEFAULT_HEIGHT_SIGMA_M);
        assert_eq!(s.max_speed_mps, DEFAULT_MAX_SPEED_MPS);
        assert_eq!(s.smooth_accel_mps2, Some(0.5));
        let e = toml::from_str::<SnapshotSetSpec>(
            "path = \"a.json\"\napprox_llh = [0.0, 0.0, 0.0]\nheight_sigma = 3",
        )
        .expect_err("unknown key");
        assert!(e.to_string().contains("height_sigma"), "{e}");
    }

    #[test]
    fn bad_values_are_refused_with_what_to_give() {
        let mut s = SnapshotSetSpec::new("a.json", None, [95.0, 0.0, 0.0]);
        assert!(s.apriori().is_err());
        s.approx_llh = [52.0, -1.2, 100.0];
        let llh = s.apriori().expect("valid");
        s.max_speed_mps = -1.0;
        assert!(s.options(&llh).is_err());
        s.max_speed_mps = 10.0;
        s.smooth_accel_mps2 = Some(0.0);
        assert!(s.smoothing().is_err());
        assert_eq!(
            parse_week_tow("2190:538200").expect("valid"),
            GpsTime::new(2190, 538_200.0)
        );
        for bad in ["2190", "142:10", "2190:604800", "x:1"] {
            let e = parse_week_tow(bad).expect_err(bad).to_string();
            assert!(e.contains("WEEK:TOW"), "{e}");
        }
        s.format = Some("ci8".into());
        s.map = Some([1.0, 3.0, -3.0, -1.0]);
        assert!(s.sample_format().is_err());
    }
}
