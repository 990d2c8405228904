//! The command line of `gpsrx run`.

use super::{LoopArgs, SourceArgs};
use gpsrx_receiver::config::{self, ReceiverConfig};
use std::path::PathBuf;

/// Ionosphere model switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IonoModel {
    /// Broadcast Klobuchar (decoded from subframe 4 page 18, or from --nav).
    Klobuchar,
    /// No correction.
    None,
}

/// Troposphere model switch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TropoModel {
    /// Saastamoinen, standard atmosphere.
    Saastamoinen,
    /// No correction.
    None,
}

/// `gpsrx run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// The recording and how to read it.
    #[command(flatten)]
    pub source: SourceArgs,
    /// Loop settings.
    #[command(flatten)]
    pub loops: LoopArgs,
    /// Output directory (created if needed).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Print the summary as JSON on standard output (for scripts) instead of text.
    #[arg(long)]
    pub json: bool,
    /// Do not draw the PNG plots (track.png, skyplot.png, cn0.png, dop.png, dr.png) into
    /// the output directory (config file: `plots = false` in `[run]`).
    #[arg(long)]
    pub no_plots: bool,
    /// After the summary, print where the run's wall time went, stage by stage (cold start,
    /// channels, background search, reading, navigation, outputs), with the process's CPU
    /// time and peak memory (with --json the stage times are in the summary's `profile`).
    #[arg(long)]
    pub profile: bool,
    /// Who drives the channels: `scalar` (each channel's own loops) or `vector` (after the
    /// first valid fix a navigation filter predicts every satellite's Doppler and feeds it
    /// forward into the carrier NCOs; back to scalar when its health test fails; a channel it
    /// checks is kept down to `vector_cn0_lost_dbhz`, 19 dB-Hz). With `--ins` the INS's motion
    /// drives the prediction between updates. Config file: `[tracking] mode`; `[vector]` tunes
    /// the filter [default: scalar].
    #[arg(long, value_name = "MODE")]
    pub tracking: Option<gpsrx_tracking::TrackingMode>,
    /// RINEX 2/3 navigation file: ephemerides before (or instead of) decoding them.
    #[arg(long, value_name = "FILE")]
    pub nav: Option<PathBuf>,
    /// Ionosphere correction [default: klobuchar].
    #[arg(long, value_enum)]
    pub iono: Option<IonoModel>,
    /// Troposphere correction (`none` for simulated files without troposphere)
    /// [default: saastamoinen].
    #[arg(long, value_enum)]
    pub tropo: Option<TropoModel>,
    /// Elevation mask, degrees [default: 5].
    #[arg(long, value_name = "DEG")]
    pub elevation_mask: Option<f64>,
    /// Observable and fix rate, Hz, 1 to 50 [default: 10].
    #[arg(long, value_name = "HZ")]
    pub rate: Option<f64>,
    /// Full GPS week of the recording: labels times until subframe 1 gives the week, and
    /// resolves the broadcast 10-bit week (default: from the SigMF core:datetime, else the
    /// navigation file; else unknown, and no output is dated until subframe 1 is decoded).
    #[arg(long, value_name = "WEEK")]
    pub week: Option<u32>,
    /// Approximate GPS time of the first sample, `WEEK:TOW` (full week 1024-4096, time of week
    /// 0-604800 s; within a minute), e.g. `2190:538200`. With --approx-llh and --nav the first
    /// fix comes from the code phases alone, about a second after the start, instead of after
    /// the first decoded time of week (1.2-7.2 s) [default: the SigMF core:datetime of the
    /// recording].
    #[arg(long = "time", value_name = "WEEK:TOW", value_parser = parse_week_tow)]
    pub approx_time: Option<gpsrx_nav::time::GpsTime>,
    /// Approximate position `LAT,LON,H` (degrees, degrees, metres above the ellipsoid; within
    /// 100 km), e.g. `37.57,126.98,40`: with --nav and a time (--time or the SigMF
    /// core:datetime) the first fix comes from the code phases alone (coarse time). A wrong
    /// one gives no wrong fix: the first fix then waits for frame sync.
    #[arg(long, value_name = "LAT,LON,H", value_parser = parse_llh, allow_hyphen_values = true)]
    pub approx_llh: Option<[f64; 3]>,
    /// Doppler search half-width of the acquisition, Hz [default: 5000; 15000 or more for a
    /// front end with a large LO offset, or --doppler-center].
    #[arg(long, value_name = "HZ")]
    pub doppler_max: Option<f64>,
    /// Centre of the acquisition's Doppler search, Hz: a known front-end frequency offset
    /// [default: 0].
    #[arg(long, value_name = "HZ", allow_hyphen_values = true)]
    pub doppler_center: Option<f64>,
    /// Acquisition coherent integration, ms, 1 to 10 [default: 1]. Weak signals (below about
    /// 35 dB-Hz): 10, with --acq-noncoherent 10 or more.
    #[arg(long, value_name = "MS")]
    pub acq_coherent_ms: Option<u32>,
    /// Acquisition non-coherent sum of this many coherent blocks [default: 10].
    #[arg(long, value_name = "N")]
    pub acq_noncoherent: Option<u32>,
    /// Probability that a PRN absent from the signal is reported as a satellite, over the whole
    /// run [default: 0.00001]. The background search spends it over its repeated searches.
    #[arg(long, value_name = "P")]
    pub acq_pfa: Option<f64>,
    /// CPU time the background search for missing satellites may spend per second of signal,
    /// s [default: 0.005; 1.6 s may go at once, at the start]: raise it to find weak
    /// satellites sooner, lower it for speed; 0 searches only for satellites just lost.
    #[arg(long, value_name = "S")]
    pub search_budget: Option<f64>,
    /// Satellites tracked from which the first 10 ms x 50 search of a PRN nothing is
    /// predicted of waits 5 minutes [default: 8]; 33: never (weak satellites beside strong
    /// ones found at once, for the CPU of a deep round over every absent PRN).
    #[arg(long, value_name = "N")]
    pub defer_deep_search: Option<usize>,
    /// RAIM false-alarm probability [default: 0.001].
    #[arg(long, value_name = "P")]
    pub raim_pfa: Option<f64>,
    /// Largest PDOP of a valid fix [default: 20]: worse geometries are written flagged
    /// (quality `none`), as their errors are the code noise times the PDOP.
    #[arg(long, value_name = "PDOP")]
    pub max_pdop: Option<f64>,
    /// Landmark range observations, CSV `tow_s,x_m,y_m,z_m,range_m,sigma_m` (seed 001): added to
    /// the fixes without a clock term, so 3 satellites and 1 landmark give a fix.
    #[arg(long, value_name = "FILE")]
    pub landmarks: Option<PathBuf>,
    /// Use satellites whose ephemeris says they are unhealthy (some simulators copy a health
    /// flag that the real satellite had at the time).
    #[arg(long)]
    pub allow_unhealthy: bool,
    /// INS output, CSV `t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps[,gps_tow_s]` (ECEF; `t_s` from
    /// the first IF sample; >= 10 Hz): its velocity is fed forward into every carrier and code
    /// loop (seed 004). Give `--nav` too for aiding before the ephemerides are decoded.
    #[arg(long, value_name = "FILE")]
    pub ins: Option<PathBuf>,
    /// Read `--ins` but do not aid the loops (to compare aided and unaided runs).
    #[arg(long, requires = "ins")]
    pub no_aiding: bool,
    /// First-order band limiter alpha/(s+alpha) on the feed-forward, rad/s (seed 004 eq. 8):
    /// reproduces an INS of limited dynamic range.
    #[arg(long, value_name = "RAD_S", requires = "ins")]
    pub ins_band_limit: Option<f64>,
    /// Longest gap allowed between INS rows, s.
    #[arg(long, value_name = "S", default_value_t = 0.5)]
    pub ins_max_gap: f64,
    /// Dead-reckoning log, CSV `t_s,gyro_v,odo_pulses` (raw, seed 000) or
    /// `t_s,yaw_rate_dps,speed_mps` (`t_s` from the first IF sample): fused with the fixes into
    /// `fused.csv`, `fused.nmea`, `fused.geojson`, `fused.kml`; the calibrated sensor parameters
    /// go to `dr_params.toml`. Nominal parameters from the config file's `[dr]` table.
    #[arg(long, value_name = "FILE")]
    pub dr: Option<PathBuf>,
    /// Longitudinal accelerometer log, CSV `t_s,a_long_mps2`: seed 002's speed filter, column
    /// `speed_filter_mps` of `fused.csv`.
    #[arg(long, value_name = "FILE")]
    pub accel: Option<PathBuf>,
    /// DR filter: seed 000's proposed 8-state filter (position and carrier velocity) or the
    /// conventional 4-state one (position only) [default: proposed].
    #[arg(long, value_enum, requires = "dr")]
    pub dr_filter: Option<DrFilterChoice>,
    /// Initial DR sensor parameters: a `dr_params.toml` written by a previous run (seed 000:
    /// saves the ~900 s calibration); overrides the config file's `[dr]` values.
    #[arg(long, value_name = "FILE", requires = "dr")]
    pub dr_params: Option<PathBuf>,
}

/// `--dr-filter`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DrFilterChoice {
    /// Seed 000's 8-state filter: position and carrier-velocity updates, gyro and odometer
    /// calibration.
    Proposed,
    /// The conventional 4-state filter (seed 000 eq. 7): position updates only.
    Conventional,
}

impl From<IonoModel> for config::IonoModel {
    fn from(m: IonoModel) -> Self {
        match m {
            IonoModel::Klobuchar => config::IonoModel::Klobuchar,
            IonoModel::None => config::IonoModel::None,
        }
    }
}

impl From<TropoModel> for config::TropoModel {
    fn from(m: TropoModel) -> Self {
        match m {
            TropoModel::Saastamoinen => config::TropoModel::Saastamoinen,
            TropoModel::None => config::TropoModel::None,
        }
    }
}

impl RunArgs {
    /// The receiver configuration: defaults, then the config file, then these options;
    /// validated.
    pub fn receiver_config(&self) -> anyhow::Result<ReceiverConfig> {
        let mut c = self.loops.receiver_config()?;
        let r = &mut c.run;
        let set = |field: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *field = v;
            }
        };
        set(&mut r.rate_hz, self.rate);
        set(&mut r.elevation_mask_deg, self.elevation_mask);
        set(&mut r.raim_pfa, self.raim_pfa);
        set(&mut r.max_pdop, self.max_pdop);
        set(&mut r.acq_pfa, self.acq_pfa);
        set(&mut r.search_budget_s, self.search_budget);
        if let Some(v) = self.defer_deep_search {
            r.defer_deep_search_from = v;
        }
        set(&mut r.doppler_max_hz, self.doppler_max);
        set(&mut r.doppler_center_hz, self.doppler_center);
        if let Some(v) = self.acq_coherent_ms {
            r.acq_coherent_ms = v;
        }
        if let Some(v) = self.acq_noncoherent {
            r.acq_noncoherent = v;
        }
        if let Some(v) = self.iono {
            r.iono = v.into();
        }
        if let Some(v) = self.tropo {
            r.tropo = v.into();
        }
        if self.week.is_some() {
            r.week = self.week;
        }
        if self.approx_time.is_some() {
            r.approx_time = self.approx_time;
        }
        if self.approx_llh.is_some() {
            r.approx_llh = self.approx_llh;
        }
        r.allow_unhealthy |= self.allow_unhealthy;
        r.plots &= !self.no_plots;
        if let Some(mode) = self.tracking {
            c.tracking.mode = mode;
        }
        c.validate()?;
        Ok(c)
    }
}

/// `--time WEEK:TOW`: a full GPS week and a time of week, checked against their ranges.
pub fn parse_week_tow(text: &str) -> Result<gpsrx_nav::time::GpsTime, String> {
    let bad = || {
        format!(
            "'{text}': give the full GPS week and the time of week in seconds as WEEK:TOW, e.g. 2190:538200"
        )
    };
    let (w, tow) = text.trim().split_once(':').ok_or_else(bad)?;
    let week: u32 = w.trim().parse().map_err(|_| bad())?;
    let tow_s: f64 = tow.trim().parse().map_err(|_| bad())?;
    let t = gpsrx_nav::time::GpsTime { week, tow_s };
    config::check_approx_time(&t)?;
    Ok(t)
}

/// `--approx-llh LAT,LON,H`: degrees, degrees, metres, checked against their ranges.
pub fn parse_llh(text: &str) -> Result<[f64; 3], String> {
    let bad = || {
        format!(
            "'{text}': give latitude and longitude in degrees and the height in metres as LAT,LON,H, e.g. 37.57,126.98,40"
        )
    };
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    let [lat, lon, h] = parts[..] else {
        return Err(bad());
    };
    let llh = [lat, lon, h];
    config::check_approx_llh(&llh)?;
    Ok(llh)
}

#[cfg(test)]
mod tracking_option_tests {
    use crate::cli::{Cli, Command};
    use clap::Parser;
    use gpsrx_tracking::TrackingMode;

    fn run_args(extra: &[&str]) -> Result<Box<super::RunArgs>, String> {
        let mut argv = vec!["gpsrx", "run", "rec.ci8", "--fs", "2e6", "--out", "o"];
        argv.extend_from_slice(extra);
        match Cli::try_parse_from(argv) {
            Ok(Cli {
                command: Command::Run(a),
                ..
            }) => Ok(a),
            Ok(_) => Err("not a run".into()),
            Err(e) => Err(e.to_string()),
        }
    }

    #[test]
    fn tracking_defaults_to_scalar_and_takes_vector() {
        let a = run_args(&[]).unwrap_or_else(|e| panic!("{e}"));
        let c = a.receiver_config().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(c.tracking.mode, TrackingMode::Scalar);
        let a = run_args(&["--tracking", "vector"]).unwrap_or_else(|e| panic!("{e}"));
        let c = a.receiver_config().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(c.tracking.mode, TrackingMode::Vector);
        let err = run_args(&["--tracking", "vectorish"])
            .err()
            .unwrap_or_default();
        assert!(err.contains("scalar") && err.contains("vector"), "{err}");
    }
}
