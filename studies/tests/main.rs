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

/// Runs `gpsrx study ARGS... --out OUT` as the command line would, panicking with the error
/// (the tests then check the files in `out`).
fn run_study(args: &[&str], out: &std::path::Path) {
    use clap::Parser;
    let tail = ["--out", out.to_str().unwrap_or_default()];
    let argv = ["gpsrx", "study"].iter().chain(args).chain(&tail).copied();
    let cli = Cli::try_parse_from(argv).unwrap_or_else(|e| panic!("{e}"));
    let Command::Study(args) = cli.command;
    gpsrx_studies::run(&args).unwrap_or_else(|e| panic!("{e:#}"));
}

mod study_bandwidth;
mod study_dr;
mod study_dynamics;
mod study_landmarks;
mod study_steady_state;
mod study_threshold;
mod study_vector;
