//! The command line of `gpsrx bench`.

use std::path::PathBuf;

/// `gpsrx bench`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchArgs {
    /// Short runs (a few seconds in all; rougher numbers): correlators timed for 10 ms each,
    /// 3 acquisition runs, a 1 s end-to-end recording.
    #[arg(long)]
    pub quick: bool,
    /// Length of the simulated end-to-end recording, s [default: 60, or 1 with --quick].
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Skip the end-to-end run (correlators and acquisition only).
    #[arg(long)]
    pub no_end_to_end: bool,
    /// Keep the simulated recording and the run's outputs in this directory (default: a
    /// temporary directory, removed).
    #[arg(long, value_name = "DIR")]
    pub keep: Option<PathBuf>,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Correlator ceiling `auto`, `avx512`, `avx2` or `scalar` (optionally `/auto`, `/f32` or `/i16`):
    /// only kernels up to that instruction set are timed, and the end-to-end runs use it
    /// (`avx2` on an AVX-512 machine: what an AVX2-only CPU would do).
    #[arg(long, value_name = "ISA[/ARITH]")]
    pub correlator: Option<gpsrx_tracking::CorrelatorChoice>,
    /// Time the correlator kernels only (no simulation, acquisition or end-to-end run).
    #[arg(long)]
    pub correlators_only: bool,
}
