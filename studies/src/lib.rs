//! `gpsrx study ...`: loop-bandwidth, steady-state and high-dynamics studies (seed 004), and
//! GPS/DR fusion (seeds 000 and 002), landmark ranges with few satellites (seed 001).
//!
//! Each study runs its cases in parallel (rayon) behind a progress bar and writes `study.md`,
//! `study.csv`, `study.json` and PNG plots to `--out DIR` (see [`report`]). `--quick` runs a
//! small grid that finishes in well under a minute (used by the tests).

pub mod bandwidth;
pub mod dr;
pub mod dynamics;
pub mod grid;
pub mod if_sim;
pub mod landmarks;
pub mod report;
pub mod steady_state;
pub mod threshold;
pub mod vector;

use anyhow::Context;
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;

/// `gpsrx study`.
#[derive(Debug, Args)]
pub struct StudyArgs {
    /// Which study.
    #[command(subcommand)]
    pub study: StudyKind,
}

/// The studies.
#[derive(Debug, Subcommand)]
pub enum StudyKind {
    /// Steady-state phase error of PLLs of order 1-3 under step, ramp, parabola and cubic phase
    /// inputs, unaided and aided (perfect, band-limited, biased INS), against the closed forms.
    SteadyState(steady_state::SteadyStateArgs),
    /// Phase jitter, Doppler and code error against the thermal-noise formulas over a grid of
    /// C/N0, loop order, Bn and integration time.
    Bandwidth(bandwidth::BandwidthArgs),
    /// Simulated manoeuvres of 1-20 g: satellites kept, loss-of-lock events and errors,
    /// unaided and aided by INS of two qualities.
    Dynamics(dynamics::DynamicsArgs),
    /// GPS/DR integration with carrier velocity (seed 000: proposed 8-state vs conventional
    /// 4-state filter, outages, a tilted gyro) and the accelerometer speed filter (seed 002) on a
    /// simulated urban drive.
    Dr(dr::DrArgs),
    /// Street-level landmark ranges with 3-9 satellites (seed 001): fix availability and
    /// PDOP/HDOP with 0-2 landmarks, Monte Carlo over geometries.
    Landmarks(landmarks::LandmarksArgs),
    /// Tracking threshold: the lowest C/N0 at which carrier lock is held 95 % of 30 s, PLL
    /// orders 1-3, Bn 0.4-18 Hz, T 1 and 20 ms, static and under stated dynamics, against the
    /// rule of thumb 3 sigma + theta_e <= 45 deg, cross-checked on IF samples, and the DLL's
    /// code jitter against theory; also writes threshold.csv and dll.csv.
    Threshold(threshold::ThresholdArgs),
    /// Scalar, INS-aided, vector and vector + INS tracking side by side (issue 29): the
    /// tracking threshold on a fading sky (against Lashley et al.'s 2.4-6.2 dB), the time back
    /// to a fix after a 3 s blockage, the satellites held through 4 and 10 g turns.
    Vector(vector::VectorArgs),
}

/// Options every study has.
#[derive(Debug, Clone, Args)]
pub struct CommonStudyArgs {
    /// Output directory for study.md, study.csv, study.json and the plots (created if needed).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// A small grid that finishes in under a minute.
    #[arg(long)]
    pub quick: bool,
    /// Noise seed (the same seed gives the same numbers).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Runs `gpsrx study ...`.
pub fn run(args: &StudyArgs) -> anyhow::Result<()> {
    let mut extra_csv = None;
    let (report, out) = match &args.study {
        StudyKind::SteadyState(a) => (steady_state::run(a, true)?, &a.common.out),
        StudyKind::Bandwidth(a) => (bandwidth::run(a, true)?, &a.common.out),
        StudyKind::Dynamics(a) => (dynamics::run(a, true)?, &a.common.out),
        StudyKind::Dr(a) => (dr::run(a, true)?, &a.common.out),
        StudyKind::Landmarks(a) => (landmarks::run(a, true)?, &a.common.out),
        StudyKind::Vector(a) => (vector::run(a, true)?, &a.common.out),
        StudyKind::Threshold(a) => {
            let (report, dll) = threshold::run_with_dll(a, true)?;
            extra_csv = Some(dll);
            (report, &a.common.out)
        }
    };
    let written = report.write(out)?;
    if let Some(dll) = extra_csv {
        report.table.write_csv(&out.join(threshold::CSV_NAME))?;
        dll.write_csv(&out.join(threshold::DLL_CSV_NAME))?;
    }
    let plots = std::fs::read_dir(out)
        .map(|d| {
            d.filter_map(Result::ok)
                .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
                .count()
        })
        .unwrap_or(written.plots.len());
    // A closed pipe (`| head`) or a full disk is an error to report, not a panic: the
    // binary ends quietly on a broken pipe.
    let mut stdout = std::io::stdout().lock();
    let mut print = || -> std::io::Result<()> {
        writeln!(stdout, "{}", report.table.to_markdown())?;
        if !report.conclusions_md.trim().is_empty() {
            writeln!(stdout, "{}\n", report.conclusions_md.trim_end())?;
        }
        writeln!(
            stdout,
            "wrote {}, {}, {} and {plots} plot(s) in {}",
            file_name(&written.markdown),
            file_name(&written.csv),
            file_name(&written.json),
            out.display()
        )?;
        stdout.flush()
    };
    print().context("cannot write to standard output")?;
    Ok(())
}

fn file_name(p: &std::path::Path) -> String {
    p.file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Runs `f` on every case in parallel, in the order given, with a progress bar (hidden unless
/// `progress`) labelled `what`.
pub fn run_cases<C, R, F>(cases: &[C], what: &str, progress: bool, f: F) -> Vec<R>
where
    C: Sync,
    R: Send,
    F: Fn(&C) -> R + Sync,
{
    let bar = if progress {
        ProgressBar::new(cases.len() as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{what} {{bar:40}} {{pos}}/{{len}} cases {{elapsed}} (eta {{eta}})"
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let out = cases
        .par_iter()
        .map(|c| {
            let r = f(c);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    out
}
