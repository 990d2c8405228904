//! The command line of `gpsrx acquire`.

use super::SourceArgs;
use std::path::PathBuf;

/// `gpsrx acquire`.
#[derive(Debug, Clone, clap::Args)]
pub struct AcquireArgs {
    /// The recording and how to read it.
    #[command(flatten)]
    pub source: SourceArgs,
    /// Coherent integration T, ms (1 to 10).
    #[arg(long, value_name = "MS", default_value_t = 1)]
    pub coherent_ms: u32,
    /// Non-coherent sum of this many coherent blocks (fewer if the recording is shorter).
    #[arg(long, value_name = "N", default_value_t = 10)]
    pub noncoherent: u32,
    /// Half-width of the Doppler search, Hz (use 15000 or more for a front end with a large LO
    /// offset, or --doppler-center).
    #[arg(long, value_name = "HZ", default_value_t = 5000.0)]
    pub doppler_max: f64,
    /// Centre of the Doppler search, Hz (a known front-end frequency offset).
    #[arg(
        long,
        value_name = "HZ",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub doppler_center: f64,
    /// Doppler bin width, Hz (default 1/(2T); at most 2/(3T)).
    #[arg(long, value_name = "HZ")]
    pub doppler_step: Option<f64>,
    /// Probability that the search of one PRN reports a satellite in noise alone.
    #[arg(long, value_name = "P", default_value_t = 1e-5)]
    pub pfa: f64,
    /// Search only these PRNs (comma-separated, e.g. 1,7,30).
    #[arg(long, value_name = "PRNS", value_delimiter = ',')]
    pub prn: Vec<u8>,
    /// With T >= 2 ms, do not run the second pass with blocks shifted by T/2 (bit-edge guard).
    #[arg(long)]
    pub no_bit_offsets: bool,
    /// Report a detection at least this many dB below a stronger one (at a Doppler a whole number
    /// of kHz away) as a cross-correlation; 0 turns the check off.
    #[arg(long, value_name = "DB", default_value_t = 15.0)]
    pub xcorr_margin: f64,
    /// Milliseconds of prompts after a detection for the fine Doppler and C/N0 (0 = none).
    #[arg(long, value_name = "MS", default_value_t = 100)]
    pub refine_ms: u32,
    /// Assisted search: RINEX navigation file (needs --approx-llh and --time).
    #[arg(long, value_name = "FILE", requires_all = ["approx_llh", "time"])]
    pub nav: Option<PathBuf>,
    /// Assisted search: approximate receiver position LAT,LON,H (degrees, degrees, metres).
    #[arg(
        long,
        value_name = "LAT,LON,H",
        allow_hyphen_values = true,
        requires = "nav"
    )]
    pub approx_llh: Option<String>,
    /// Assisted search: GPS time of the first sample read, WEEK:TOW (full week, seconds).
    #[arg(long, value_name = "WEEK:TOW", requires = "nav")]
    pub time: Option<String>,
    /// Assisted search: Doppler window around each prediction, +- Hz (receiver clock drift and
    /// position error).
    #[arg(long, value_name = "HZ", default_value_t = 1000.0)]
    pub doppler_uncertainty: f64,
    /// Assisted search: skip satellites below this elevation, degrees.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub elevation_mask: f64,
    /// List the PRNs that were not detected too.
    #[arg(long)]
    pub all: bool,
    /// Print a JSON array instead of a table.
    #[arg(long)]
    pub json: bool,
}
