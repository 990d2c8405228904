//! `gpsrx simulate`: scenario file -> IF recording + truth files.

use crate::cli::SimulateArgs;
use anyhow::Context;
use gpsrx_samples::sim::{Scenario, SimReport, Simulator};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};

/// Runs `gpsrx simulate`.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let (mut scenario, base) = match (&args.scenario, args.default) {
        (Some(p), false) => Scenario::load(p)?,
        (None, true) => (Scenario::default_scenario()?, PathBuf::new()),
        _ => {
            anyhow::bail!("give a scenario file (e.g. samples/scenarios/default.toml) or --default")
        }
    };
    if let Some(d) = args.duration {
        scenario.duration_s = d;
    }
    if let Some(s) = args.seed {
        scenario.seed = s;
    }
    if let Some(f) = &args.format {
        scenario.output.format = f.clone();
    }
    if let Some(fs) = args.fs {
        scenario.output.fs_hz = fs;
    }
    let report = simulate(&scenario, &base, &args.out, !args.json)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report);
    }
    Ok(())
}

/// Prepares and runs a scenario into `out`, with a progress bar when `progress` is set.
pub fn simulate(
    scenario: &Scenario,
    base: &Path,
    out: &Path,
    progress: bool,
) -> anyhow::Result<SimReport> {
    let sim = Simulator::new(scenario, base).context("cannot prepare the scenario")?;
    let bar = if progress {
        ProgressBar::new(1000)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("simulating {bar:40} {percent:>3}% {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let report = sim
        .run(out, &|f| bar.set_position((f * 1000.0) as u64))
        .with_context(|| format!("simulation into {} failed", out.display()))?;
    bar.finish_and_clear();
    Ok(report)
}

/// Prints a human summary of a run.
pub fn print_report(r: &SimReport) {
    println!("satellites ({}):", r.satellites.len());
    println!("  PRN  elev(deg)  C/N0(dB-Hz)");
    for (prn, el, cn0) in &r.satellites {
        println!("  G{prn:02}  {el:9.1}  {cn0:11.1}");
    }
    println!(
        "recording: {} ({}, {:.3} MHz, {:.1} s, {} samples, {:.1} MB, {} clipped)",
        r.data_path.display(),
        r.format,
        r.fs_hz / 1e6,
        r.duration_s,
        r.samples,
        r.bytes as f64 / 1e6,
        r.clipped
    );
    println!("metadata:  {}", r.meta_path.display());
    println!(
        "truth:     {} and {}",
        r.truth_path.display(),
        r.truth_sv_path.display()
    );
    println!(
        "simulated {:.1} s in {:.2} s: {:.1}x real time ({:.1} Msamples/s)",
        r.duration_s,
        r.wall_s,
        r.realtime_factor,
        r.samples as f64 / r.wall_s.max(1e-9) / 1e6
    );
}
