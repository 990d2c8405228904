//! Integration tests of the seed studies: one test binary (one link) for the crate.

/// `gpsrx study ...` as the command line parses it, for the tests that start from arguments.
#[derive(Debug, clap::Parser)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, clap::Subcommand)]
enum Command {
    Study(gpsrx_studies::StudyArgs),
}

mod study_bandwidth;
mod study_dr;
mod study_dynamics;
mod study_steady_state;
