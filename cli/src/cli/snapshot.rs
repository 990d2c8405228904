//! The command line of `gpsrx snapshot`.

use std::path::PathBuf;

/// `gpsrx snapshot`.
#[derive(Debug, Clone, clap::Args)]
pub struct SnapshotArgs {
    /// The snapshots: a SnapperGPS JSON file (`.json`: many snapshots with their timestamps),
    /// a SigMF recording with one capture per snapshot (each capture's `core:datetime` its
    /// approximate time), or a raw/WAV/SigMF recording holding one snapshot (needs --time
    /// unless SigMF gives `core:datetime`).
    pub input: PathBuf,
    /// RINEX navigation file (broadcast ephemerides of the day; RINEX 2 or 3). Needed: without
    /// it the command says so.
    #[arg(long, value_name = "FILE")]
    pub nav: Option<PathBuf>,
    /// GPS time of the first sample, WEEK:TOW (full week, seconds of week): for a raw
    /// recording; with a SnapperGPS file it replaces the first timestamp (the others keep
    /// their spacing).
    #[arg(long, value_name = "WEEK:TOW")]
    pub time: Option<String>,
    /// Approximate position LAT,LON,H (degrees, degrees, metres); supported error: up to
    /// about 100 km (and 60 s of time) together.
    #[arg(long, value_name = "LAT,LON,H", allow_hyphen_values = true)]
    pub approx_llh: String,
    /// Sample format of a raw recording (e.g. ri1_lsb, ri2_lsb, ci8); default from metadata.
    #[arg(long)]
    pub format: Option<String>,
    /// Sampling rate of a raw recording, Hz.
    #[arg(long, value_name = "HZ")]
    pub fs: Option<f64>,
    /// Intermediate frequency of a raw recording, Hz (real samples: 0 < IF < fs/2, or IF = fs
    /// for a spectrum folded around 0 Hz).
    #[arg(long = "if", value_name = "HZ", default_value_t = 0.0)]
    pub if_hz: f64,
    /// 2-bit value map of the codes 00,01,10,11 (e.g. 0,1,-2,-1 for two's complement).
    #[arg(long, value_name = "V0,V1,V2,V3", allow_hyphen_values = true)]
    pub map: Option<String>,
    /// Constrain the height to that of --approx-llh with this sigma, m (0: no constraint;
    /// use 0 for an aircraft or when the height is not known to tens of metres).
    #[arg(long, value_name = "M", default_value_t = 30.0)]
    pub height_sigma: f64,
    /// Largest receiver speed, m/s (widens the Doppler checks: 50 m/s adds 263 Hz).
    #[arg(long, value_name = "M/S", default_value_t = 50.0)]
    pub max_speed: f64,
    /// Smooth the horizontal track across consecutive snapshots (a Rauch-Tung-Striebel
    /// smoother, constant velocity) with this acceleration sigma, m/s^2 (a walker about 0.5).
    /// Off by default: every snapshot is positioned alone.
    #[arg(long, value_name = "M/S2")]
    pub smooth_accel: Option<f64>,
    /// Coherent integration, ms (default: 1 ms below 40 ms of samples, else 10 ms).
    #[arg(long, value_name = "MS")]
    pub coherent_ms: Option<u32>,
    /// Look for the satellites the searches missed (at the code phases a first fix predicts)
    /// with a coherent test over the whole snapshot too, the data-bit edge hypothesised: about
    /// 1.5 dB more sensitive than the non-coherent one (off by default: see the README).
    #[arg(long)]
    pub coherent_look: bool,
    /// Output directory: snapshots.csv and track.geojson, track.kml, track.gpx.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Score against a truth: a SnapperGPS truth JSON file (time, latitude, longitude); adds
    /// the errors to snapshots.csv, prints the median and 95th percentile, draws errors.png.
    #[arg(long, value_name = "FILE")]
    pub truth: Option<PathBuf>,
    /// Ellipsoidal height of the --truth track, m.
    #[arg(long, value_name = "M", default_value_t = 0.0)]
    pub truth_h: f64,
    /// Score against one static reference position, ECEF X,Y,Z in metres.
    #[arg(
        long,
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        conflicts_with = "truth"
    )]
    pub truth_ecef: Option<String>,
}
