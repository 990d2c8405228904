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
    print_truth_summary(&report.truth_sv_path)?;
    if args.keep.is_none() {
        println!("(temporary files removed; use --keep DIR to keep them)");
    }
    Ok(())
}

/// Prints what a receiver should find at the first sample: the truth of every satellite.
fn print_truth_summary(truth_sv: &std::path::Path) -> anyhow::Result<()> {
    let mut rdr = csv::Reader::from_path(truth_sv)
        .with_context(|| format!("cannot read {}", truth_sv.display()))?;
    let headers = rdr.headers()?.clone();
    let col = |name: &str| {
        headers
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("{name} missing in truth_sv.csv"))
    };
    let (t, prn, cp, dop, cn0, pr) = (
        col("t_s")?,
        col("prn")?,
        col("code_phase_chips")?,
        col("doppler_hz")?,
        col("cn0_dbhz")?,
        col("pseudorange_m")?,
    );
    println!("\ntruth at the first sample (what acquisition should find):");
    println!("  PRN  code phase(chips)  Doppler(Hz)  C/N0(dB-Hz)  pseudorange(m)");
    for rec in rdr.records() {
        let rec = rec?;
        if rec.get(t).and_then(|v| v.parse::<f64>().ok()) != Some(0.0) {
            break;
        }
        let f = |i: usize| {
            rec.get(i)
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or(f64::NAN)
        };
        println!(
            "  G{:02}  {:17.3}  {:11.1}  {:11.1}  {:14.1}",
            rec.get(prn).unwrap_or("?").parse::<u8>().unwrap_or(0),
            f(cp),
            f(dop),
            f(cn0),
            f(pr)
        );
    }
    Ok(())
}
