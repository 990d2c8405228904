//! Helpers shared by the integration tests.

use clap::Parser;
use gpsrx_cli::cli::{Cli, Command};
use gpsrx_cli::commands::run::{run_file, RunReport};
use gpsrx_receiver::output::Fix;
use std::path::Path;

/// `gpsrx run DATA --out OUT EXTRA...` through the command-line parser; returns the fixes.
pub fn run(data: &Path, out: &Path, extra: &[&str]) -> Vec<Fix> {
    run_report(data, out, extra).1
}

/// [`run`], returning the run's report (the summary `gpsrx run` prints) too.
pub fn run_report(data: &Path, out: &Path, extra: &[&str]) -> (RunReport, Vec<Fix>) {
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
    run_file(&args, false).unwrap_or_else(|e| panic!("{e:#}"))
}

/// `truth.csv` rows: (GPS TOW, ECEF position, ECEF velocity).
pub fn truth(dir: &Path) -> Vec<(f64, [f64; 3], [f64; 3])> {
    let mut rdr = csv::Reader::from_path(dir.join("truth.csv")).unwrap_or_else(|e| panic!("{e}"));
    rdr.deserialize::<std::collections::HashMap<String, f64>>()
        .map(|r| {
            let r = r.unwrap_or_else(|e| panic!("{e}"));
            let g = |k: &str| r[k];
            (
                g("tow_s"),
                [g("x_m"), g("y_m"), g("z_m")],
                [g("vx_mps"), g("vy_mps"), g("vz_mps")],
            )
        })
        .collect()
}
