//! The command line of `gpsrx track`.

use super::{AcquireArgs, LoopArgs};
use std::path::PathBuf;

/// `gpsrx track`.
#[derive(Debug, Clone, clap::Args)]
pub struct TrackArgs {
    /// The recording, how to read it, and the acquisition settings (`--prn` limits the PRNs).
    #[command(flatten)]
    pub acquisition: AcquireArgs,
    /// Loop settings.
    #[command(flatten)]
    pub loops: LoopArgs,
    /// Write every integration interval of every channel to this CSV file.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}
