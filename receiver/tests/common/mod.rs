//! Helpers shared by the integration tests.

use clap::Parser;
use gpsrx_receiver::cli::{Cli, Command};
use gpsrx_receiver::commands::run::run_file;
use gpsrx_receiver::output::Fix;
use std::path::Path;

/// `gpsrx run DATA --out OUT EXTRA...` through the command-line parser; returns the fixes.
pub fn run(data: &Path, out: &Path, extra: &[&str]) -> Vec<Fix> {
    let mut argv = vec![
        "gpsrx",
        "run",
        data.to_str().unwrap_or_default(),
        "--out",
        out.to_str().unwrap_or_default(),
    ];
    argv.extend_from_slice(extra);
    let cli = Cli::try_parse_from(argv).unwrap_or_else(|e| panic!("{e}"));
    let Command::Run(args) = cli.command else {
        panic!("not run")
    };
    run_file(&args, false).unwrap_or_else(|e| panic!("{e:#}")).1
}
