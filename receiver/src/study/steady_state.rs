//! Placeholder: being written.

use super::report::StudyReport;
use super::CommonStudyArgs;

/// `gpsrx study` options of this study.
#[derive(Debug, Clone, clap::Args)]
pub struct SteadyStateArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
}

/// Runs the study.
pub fn run(_args: &SteadyStateArgs, _progress: bool) -> anyhow::Result<StudyReport> {
    anyhow::bail!("this study is not available yet")
}
