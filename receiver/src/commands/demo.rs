//! `gpsrx demo`: simulate the built-in scenario and show what was made. Needs no file.

use crate::cli::DemoArgs;
use crate::commands::simulate::{print_report, simulate};
use anyhow::Context;
use gpsrx_samples::sim::Scenario;
use std::path::PathBuf;

/// Runs `gpsrx demo`.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let mut scenario = Scenario::default_scenario()?;
    if let Some(d) = args.duration {
        scenario.duration_s = d;
    }
    let tmp;
    let dir: PathBuf = match &args.keep {
        Some(d) => d.clone(),
        None => {
            tmp = tempfile::tempdir().context("cannot create a temporary directory")?;
            tmp.path().to_path_buf()
        }
    };
    println!("gpsrx demo: {}", scenario.description);
    println!(
        "simulating {:.0} s of {} at {:.3} MHz into {}",
        scenario.duration_s,
        scenario.output.format,
        scenario.output.fs_hz / 1e6,
        dir.display()
    );
    let report = simulate(&scenario, &PathBuf::new(), &dir, true)?;
    print_report(&report);
    let info = gpsrx_samples::info::inspect(
        &gpsrx_samples::SourceConfig {
            path: report.data_path.clone(),
            format: None,
            fs_hz: None,
            if_hz: 0.0,
            invert_q: false,
            skip_s: 0.0,
            duration_s: None,
        },
        1_000_000,
    )?;
    println!("\n{info}");
    if args.keep.is_none() {
        println!("(temporary files removed; use --keep DIR to keep them)");
    }
    Ok(())
}
