//! Command-line arguments of `gpsrx`.

mod acquire;
mod bench;
mod run;
mod snapshot;
mod track;

pub use acquire::AcquireArgs;
pub use bench::BenchArgs;
pub use run::{DrFilterChoice, IonoModel, RunArgs, TropoModel};
pub use snapshot::SnapshotArgs;
pub use track::TrackArgs;

use clap::{Args, Parser, Subcommand};
use gpsrx_receiver::ReceiverConfig;
use gpsrx_samples::{SampleFormat, SourceConfig};
use std::path::PathBuf;

/// gpsrx: a GPS L1 C/A software receiver with INS-aided tracking loops.
#[derive(Debug, Parser)]
#[command(name = "gpsrx", version)]
pub struct Cli {
    /// More log output (or set GPSRX_LOG=debug).
    #[arg(short, long, global = true)]
    pub verbose: bool,
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The exit status of `gpsrx run`, shown by `gpsrx run --help`.
pub const RUN_EXIT_STATUS: &str = "Exit status:
  0  at least one valid fix (also when standard output is closed early, e.g. by `| head`)
  1  an error: bad input, a file that cannot be read or written (one line on standard error)
  2  the recording was processed to the end but gave no valid fix (the summary says why)";

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate GPS L1 C/A IF samples (and truth files) from a scenario file.
    Simulate(SimulateArgs),
    /// Describe a recording: size, duration, statistics, histogram and spectrum.
    Info(InfoArgs),
    /// Simulate the built-in demo scenario and show what was made.
    Demo(DemoArgs),
    /// Search a recording for satellites (FFT parallel code-phase search).
    Acquire(AcquireArgs),
    /// Acquire and track satellites; write every integration interval to CSV.
    Track(TrackArgs),
    /// Process a recording into position fixes and standard files (RINEX, NMEA, GeoJSON, KML, CSV).
    #[command(after_help = RUN_EXIT_STATUS)]
    Run(Box<RunArgs>),
    /// Process the recordings, snapshot sets (and study grids) of a manifest one after
    /// another: one summary table.
    #[command(after_help = BATCH_EXIT_STATUS)]
    Batch(BatchArgs),
    /// Position snapshots of a few milliseconds each (coarse-time navigation): SnapperGPS
    /// JSON files, SigMF recordings with one capture per snapshot, or one raw snapshot; writes
    /// snapshots.csv and GeoJSON/KML/GPX tracks.
    Snapshot(SnapshotArgs),
    /// Print the default configuration file (`gpsrx config --default > gpsrx.toml`).
    Config(ConfigArgs),
    /// Loop studies: steady-state errors, bandwidth vs noise, high dynamics (seed 004).
    Study(gpsrx_studies::StudyArgs),
    /// Measure this machine: correlator kernels, acquisition, end-to-end real-time factor.
    Bench(BenchArgs),
}

/// The exit status of `gpsrx batch`, shown by `gpsrx batch --help`.
pub const BATCH_EXIT_STATUS: &str = "Exit status:
  0  at least one recording gave a valid fix, or one study case ran (the others' errors are in
     the summary: a bad recording does not stop the batch)
  1  the manifest cannot be used, or every entry failed (an error or no valid fix)";

/// `gpsrx batch`.
#[derive(Debug, Args)]
pub struct BatchArgs {
    /// The manifest: TOML (`[[recording]]` tables with `path`, `format`, `fs_hz`, `nav`,
    /// `options`; `[[snapshots]]` sets with `path`, `nav`, `approx_llh` and the options of
    /// `gpsrx snapshot`; `[[study]]` grids) or CSV (a header with a `path` column; other columns are
    /// receiver options such as `tropo` or `rate_hz`). Relative paths are relative to it.
    pub manifest: PathBuf,
    /// Output directory: `summary.csv`, one directory of `gpsrx run` files per recording (of
    /// `gpsrx snapshot` files per snapshot set), and `study-NAME.csv` per study grid.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// `gpsrx config`.
#[derive(Debug, Args)]
pub struct ConfigArgs {
    /// Print the default, commented gpsrx.toml.
    #[arg(long)]
    pub default: bool,
}

/// Options that say how to read a recording; shared by every subcommand that reads one.
#[derive(Debug, Clone, Args)]
pub struct SourceArgs {
    /// The recording (raw samples, .wav, or SigMF .sigmf-meta/.sigmf-data).
    pub file: PathBuf,
    /// Sample format: ci8, cu8, ci16_le, cf32_le, cf64_le, ri8, ri16_le, rf32_le, ci2, ri2, ci1,
    /// ri1, ri1_lsb
    /// (default: from SigMF or WAV metadata).
    #[arg(long)]
    pub format: Option<String>,
    /// Sampling rate, Hz (default: from SigMF or WAV metadata).
    #[arg(long, value_name = "HZ")]
    pub fs: Option<f64>,
    /// Intermediate frequency, Hz (real IF is mixed down to baseband).
    #[arg(
        long = "if",
        value_name = "HZ",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub if_hz: f64,
    /// Read the samples as I - jQ (some front ends invert Q).
    #[arg(long)]
    pub invert_q: bool,
    /// Skip this many seconds from the start of the file.
    #[arg(long, value_name = "S", default_value_t = 0.0)]
    pub skip: f64,
    /// Read at most this many seconds.
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
}

impl SourceArgs {
    /// The sample-source configuration these options describe.
    pub fn to_config(&self) -> anyhow::Result<SourceConfig> {
        let format = match &self.format {
            Some(f) => Some(f.parse::<SampleFormat>()?),
            None => None,
        };
        Ok(SourceConfig {
            path: self.file.clone(),
            format,
            fs_hz: self.fs,
            if_hz: self.if_hz,
            invert_q: self.invert_q,
            skip_s: self.skip,
            duration_s: self.duration,
        })
    }
}

/// `gpsrx simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML); see samples/scenarios/README.md. Omit with --default.
    pub scenario: Option<PathBuf>,
    /// Use the built-in default scenario.
    #[arg(long, conflicts_with = "scenario")]
    pub default: bool,
    /// Output directory: the recording, its .sigmf-meta, truth.csv and truth_sv.csv go there
    /// (and ins.csv when the scenario has an `[ins]` table).
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Override the scenario's duration, s.
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Override the scenario's noise seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Override the output format.
    #[arg(long)]
    pub format: Option<String>,
    /// Override the sampling rate, Hz.
    #[arg(long, value_name = "HZ")]
    pub fs: Option<f64>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// `gpsrx info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// The recording and how to read it.
    #[command(flatten)]
    pub source: SourceArgs,
    /// Samples read for statistics (the size and duration always cover the whole file).
    #[arg(long, default_value_t = 4_000_000)]
    pub max_samples: u64,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `gpsrx demo`.
#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Keep the simulated files in this directory (default: a temporary directory, removed).
    #[arg(long, value_name = "DIR")]
    pub keep: Option<PathBuf>,
    /// Shorten the demo recording, s (default: the scenario's 40 s).
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
}

/// Tracking-loop options, shared by `track` and (later) `run`; each overrides the config file.
#[derive(Debug, Clone, Default, Args)]
pub struct LoopArgs {
    /// Configuration file (TOML) with a `[tracking]` table: `pull_in` and `track` loop settings,
    /// `min_pull_in_s`, `fll_assist_s`, `cn0_lost_dbhz`, `cn0_window_s`, `lost_estimates`.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// PLL order after pull-in: 1, 2 or 3 (0: FLL only).
    #[arg(long, value_name = "N")]
    pub pll_order: Option<u8>,
    /// PLL noise bandwidth after pull-in, Hz.
    #[arg(long, value_name = "HZ")]
    pub pll_bw: Option<f64>,
    /// FLL order after pull-in: 0 (none), 1 or 2.
    #[arg(long, value_name = "N")]
    pub fll_order: Option<u8>,
    /// FLL noise bandwidth after pull-in, Hz.
    #[arg(long, value_name = "HZ")]
    pub fll_bw: Option<f64>,
    /// DLL order: 1 or 2.
    #[arg(long, value_name = "N")]
    pub dll_order: Option<u8>,
    /// DLL noise bandwidth, Hz.
    #[arg(long, value_name = "HZ")]
    pub dll_bw: Option<f64>,
    /// Coherent integration after bit sync, ms: 1, 2, 4, 5, 10 or 20.
    #[arg(long, value_name = "MS")]
    pub t_coh: Option<f64>,
    /// Early-late spacing, chips (0.1 to 1).
    #[arg(long, value_name = "CHIPS")]
    pub el_spacing: Option<f64>,
    /// PLL noise bandwidth while the loop is aided by an INS feed-forward (`run --ins`), Hz:
    /// the aid removes the dynamics, so a narrower loop lets through less noise
    /// (default: the same loops aided or not).
    #[arg(long, value_name = "HZ")]
    pub aided_pll_bw: Option<f64>,
    /// PLL order while aided: 1, 2 or 3 (default: as unaided). Seed 004: use 2 or more, a
    /// 1st-order aided loop drifts with the INS bias.
    #[arg(long, value_name = "N")]
    pub aided_pll_order: Option<u8>,
    /// Correlator kernel: the widest instruction set `auto`, `avx512`, `avx2` or `scalar`,
    /// optionally with the arithmetic (`avx2/i16`); overrides `[tracking] correlator`.
    /// `avx2` on an AVX-512 machine runs what an AVX2-only CPU would.
    #[arg(long, value_name = "ISA[/ARITH]")]
    pub correlator: Option<gpsrx_tracking::CorrelatorChoice>,
}

impl LoopArgs {
    /// The configuration: defaults, then the config file (`--config`), then these options.
    pub fn receiver_config(&self) -> anyhow::Result<ReceiverConfig> {
        let mut config = match &self.config {
            Some(path) => ReceiverConfig::load(path)?,
            None => ReceiverConfig::default(),
        };
        config.tracking = self.apply(config.tracking)?;
        Ok(config)
    }

    /// The channel configuration: defaults, then the config file, then these options.
    pub fn channel_config(&self) -> anyhow::Result<gpsrx_tracking::ChannelConfig> {
        Ok(self.receiver_config()?.tracking)
    }

    /// `cfg` with these options applied, validated.
    fn apply(
        &self,
        mut cfg: gpsrx_tracking::ChannelConfig,
    ) -> anyhow::Result<gpsrx_tracking::ChannelConfig> {
        let t = &mut cfg.track;
        if let Some(v) = self.pll_order {
            t.pll_order = v;
        }
        if let Some(v) = self.pll_bw {
            t.pll_bw_hz = v;
        }
        if let Some(v) = self.fll_order {
            t.fll_order = v;
        }
        if let Some(v) = self.fll_bw {
            t.fll_bw_hz = v;
        }
        if let Some(v) = self.dll_order {
            t.dll_order = v;
        }
        if let Some(v) = self.dll_bw {
            t.dll_bw_hz = v;
        }
        if let Some(v) = self.t_coh {
            t.t_coh_s = v * 1e-3;
        }
        if let Some(v) = self.el_spacing {
            t.el_spacing_chips = v;
        }
        if self.aided_pll_bw.is_some() || self.aided_pll_order.is_some() {
            let mut a = cfg.aided_track.unwrap_or(cfg.track);
            if let Some(v) = self.aided_pll_bw {
                a.pll_bw_hz = v;
            }
            if let Some(v) = self.aided_pll_order {
                a.pll_order = v;
            }
            cfg.aided_track = Some(a);
        }
        if let Some(c) = self.correlator {
            cfg.correlator = c.isa;
            if let Some(a) = c.arithmetic {
                cfg.correlator_arithmetic = a;
            }
        }
        cfg.validate()
            .map_err(|e| anyhow::anyhow!("tracking configuration: {e}"))?;
        Ok(cfg)
    }
}

#[cfg(test)]
mod correlator_option_tests {
    use super::LoopArgs;
    use gpsrx_tracking::{CorrelatorArithmetic, CorrelatorIsa};

    #[test]
    fn correlator_option_overrides_the_config_file() {
        let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let path = dir.path().join("gpsrx.toml");
        std::fs::write(
            &path,
            "[tracking]\ncorrelator = \"scalar\"\ncorrelator_arithmetic = \"i16\"\n",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let mut args = LoopArgs {
            config: Some(path.clone()),
            ..LoopArgs::default()
        };
        let t = args.channel_config().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(t.correlator, CorrelatorIsa::Scalar);
        assert_eq!(t.correlator_arithmetic, CorrelatorArithmetic::I16);
        // `--correlator avx2` keeps the file's arithmetic; `avx512/f32` sets both.
        args.correlator = Some("avx2".parse().unwrap_or_else(|e| panic!("{e}")));
        let t = args.channel_config().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(t.correlator, CorrelatorIsa::Avx2);
        assert_eq!(t.correlator_arithmetic, CorrelatorArithmetic::I16);
        args.correlator = Some("avx512/f32".parse().unwrap_or_else(|e| panic!("{e}")));
        let t = args.channel_config().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(t.correlator, CorrelatorIsa::Avx512);
        assert_eq!(t.correlator_arithmetic, CorrelatorArithmetic::F32);
        // A bad value in the file is an error that names the valid ones.
        std::fs::write(&path, "[tracking]\ncorrelator = \"neon\"\n")
            .unwrap_or_else(|e| panic!("{e}"));
        let err = LoopArgs {
            config: Some(path),
            ..LoopArgs::default()
        }
        .channel_config()
        .err()
        .map(|e| format!("{e:#}"))
        .unwrap_or_default();
        assert!(err.contains("correlator") && err.contains("avx2"), "{err}");
    }
}
