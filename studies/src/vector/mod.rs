//! `gpsrx study vector`: scalar, scalar INS-aided, vector and vector + INS tracking side by side
//! (issue 29), on simulated IF tracked by the receiver library (the path of `gpsrx run`).
//!
//! - **Threshold** (a fade): every satellite, at 32-38 dB-Hz by elevation, fades at a fixed
//!   rate from 10 s; a satellite's threshold is its true C/N0 (the simulator's) at its last
//!   observables with a pseudorange, and a mode's gain is the median scalar threshold less its
//!   own (per satellite too), against the 2.4-6.2 dB of Lashley, Bevly and Hung (PLANS 2010).
//! - **Blockage**: every signal blocked for 3 s on a static receiver: the time from the return
//!   to the first valid fix, the largest 3-D error of the fixes in the 3 s after it, the
//!   channels released (searched again).
//! - **Dynamics**: an aircraft at 250 m/s in a level turn at 4 and 10 g (6 s, the acceleration
//!   ramped over 1 s), satellites at 30-45 dB-Hz: the satellites in phase lock in the second
//!   before the turn that stay in tracking and in phase lock (95 % of the reports) through it.
//!
//! The INS of the aided modes is the simulator's truth with an accelerometer bias of 1 mg on
//! every east-north-up axis, logged at 50 Hz ([`cases::biased_ins`]). Every case (scenario x mode) is
//! simulated and tracked on its own, in parallel ([`super::run_cases`]). The conclusions
//! ([`conclusions`]) are computed from the results; `--quick` runs one fade (1 dB/s), the
//! blockage and the 10 g turn.

pub mod cases;
pub mod conclusions;
pub mod measure;

use super::report::{fmt, StudyReport, Table};
use super::{run_cases, CommonStudyArgs};
use cases::{Mode, Test};
use gpsrx_receiver::output::plots::{LinePlot, Series};
use measure::{run_case, Case, CaseResult};

/// `gpsrx study vector` options.
#[derive(Debug, Clone, clap::Args)]
pub struct VectorArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
}

/// Runs the study.
pub fn run(args: &VectorArgs, progress: bool) -> anyhow::Result<StudyReport> {
    let tests = cases::tests(args.common.quick);
    let results = measure_all(&tests, args.common.seed, progress)?;
    Ok(report(&results, &tests, args.common.seed))
}

/// Every mode on every test, noise seed `seed`, in parallel.
pub fn measure_all(
    tests: &[Test],
    seed: u64,
    progress: bool,
) -> anyhow::Result<Vec<(Case, CaseResult)>> {
    let all: Vec<Case> = tests
        .iter()
        .flat_map(|&test| Mode::ALL.map(|mode| Case { test, mode }))
        .collect();
    let measured = run_cases(&all, "vector", progress, |c| run_case(c, seed));
    all.into_iter()
        .zip(measured)
        .map(|(case, r)| Ok((case, r?)))
        .collect()
}

/// The report of `results`.
pub fn report(results: &[(Case, CaseResult)], tests: &[Test], seed: u64) -> StudyReport {
    StudyReport {
        title: "Vector tracking: scalar, INS-aided, vector and vector + INS (issue 29)".into(),
        intro_md: INTRO.into(),
        table: table(results, tests),
        conclusions_md: conclusions::conclusions_md(results, tests, seed),
        summary: serde_json::json!({
            "seed": seed,
            "cases": results
                .iter()
                .map(|(c, r)| serde_json::json!({ "case": c, "result": r }))
                .collect::<Vec<_>>(),
        }),
        plots: plots(results, tests),
    }
}

const INTRO: &str = "Each scenario simulated on its own and tracked by the receiver library in four modes: `scalar` (`gpsrx run`), `scalar + INS` (`--ins`, seed 004's feed-forward), `vector` (`--tracking vector`: the navigation filter drives every channel) and `vector + INS` (`--tracking vector --ins`: the INS's motion drives the filter's prediction). The INS is the truth with a 1 mg accelerometer bias. Threshold: each satellite's true C/N0 at its last observables while every satellite fades; gain against scalar (median). Blockage: every signal blocked 3 s; the first valid fix after the return and the largest 3-D error of the fixes in the 3 s after it. Turn: satellites in phase lock before the turn that stay locked through it.";

fn table(results: &[(Case, CaseResult)], tests: &[Test]) -> Table {
    let mut t = Table::new(&[
        "test",
        "mode",
        "threshold median (dB-Hz)",
        "gain over scalar (dB)",
        "first valid fix after the return (s)",
        "3-D max in the 3 s after (m)",
        "channels released",
        "locked through the turn",
        "vector (s)",
    ]);
    for test in tests {
        for mode in Mode::ALL {
            let Some(r) = conclusions::find(results, test, mode) else {
                continue;
            };
            let th: Vec<f64> = r.thresholds_dbhz.iter().map(|x| x.1).collect();
            let gain = (mode != Mode::Scalar)
                .then(|| conclusions::threshold_gain(results, test, mode))
                .flatten()
                .map_or(f64::NAN, |g| g.0);
            let (fade, blockage, turn) = match test {
                Test::Fade { .. } => (true, false, false),
                Test::Blockage => (false, true, false),
                Test::Turn { .. } => (false, false, true),
            };
            t.push(vec![
                test.label(),
                mode.label().to_string(),
                if fade {
                    fmt(super::report::median(&th), 1)
                } else {
                    "-".into()
                },
                if fade { fmt(gain, 1) } else { "-".into() },
                if blockage {
                    fmt(r.back_s.unwrap_or(f64::NAN), 2)
                } else {
                    "-".into()
                },
                if blockage {
                    fmt(r.max_error_after_m.unwrap_or(f64::NAN), 1)
                } else {
                    "-".into()
                },
                if blockage {
                    r.lost.len().to_string()
                } else {
                    "-".into()
                },
                if turn {
                    format!("{} of {}", r.locked_through.len(), r.locked_before.len())
                } else {
                    "-".into()
                },
                fmt(r.vector_s.unwrap_or(f64::NAN), 1),
            ]);
        }
    }
    t
}

fn plots(results: &[(Case, CaseResult)], tests: &[Test]) -> Vec<LinePlot> {
    let mut out = Vec::new();
    let series = |mode: Mode, points: Vec<(f64, f64)>| Series {
        name: mode.label().to_string(),
        points,
        reference: false,
    };
    if let Some(test) = tests.iter().find(|t| matches!(t, Test::Fade { .. })) {
        // Satellites in the order of their scalar threshold.
        let order: Vec<u8> = conclusions::find(results, test, Mode::Scalar)
            .map(|r| {
                let mut v = r.thresholds_dbhz.clone();
                v.sort_by(|a, b| b.1.total_cmp(&a.1));
                v.into_iter().map(|x| x.0).collect()
            })
            .unwrap_or_default();
        let curves = Mode::ALL
            .into_iter()
            .filter_map(|mode| {
                let r = conclusions::find(results, test, mode)?;
                let pts = order
                    .iter()
                    .enumerate()
                    .filter_map(|(k, p)| {
                        let th = r.thresholds_dbhz.iter().find(|x| x.0 == *p)?;
                        Some(((k + 1) as f64, th.1))
                    })
                    .collect();
                Some(series(mode, pts))
            })
            .collect();
        out.push(LinePlot {
            file_name: "threshold.png".into(),
            title: format!("Tracking threshold per satellite ({})", test.label()),
            x_label: "satellite (by scalar threshold, highest first)".into(),
            y_label: "true C/N0 at the last observables (dB-Hz)".into(),
            series: curves,
            ..LinePlot::default()
        });
    }
    if tests.contains(&Test::Blockage) {
        let curves = Mode::ALL
            .into_iter()
            .filter_map(|mode| {
                let r = conclusions::find(results, &Test::Blockage, mode)?;
                Some(series(mode, r.errors_after.clone()))
            })
            .collect();
        out.push(LinePlot {
            file_name: "blockage.png".into(),
            title: "Valid fixes after a 3 s blockage of every satellite".into(),
            x_label: "time after the signals return (s)".into(),
            y_label: "3-D error (m)".into(),
            series: curves,
            ..LinePlot::default()
        });
    }
    let turns: Vec<(f64, &Test)> = tests
        .iter()
        .filter_map(|t| match t {
            Test::Turn { g } => Some((*g, t)),
            _ => None,
        })
        .collect();
    if !turns.is_empty() {
        let curves = Mode::ALL
            .into_iter()
            .map(|mode| {
                let pts = turns
                    .iter()
                    .filter_map(|(g, t)| {
                        let r = conclusions::find(results, t, mode)?;
                        Some((*g, r.locked_through.len() as f64))
                    })
                    .collect();
                series(mode, pts)
            })
            .collect();
        out.push(LinePlot {
            file_name: "turns.png".into(),
            title: "Satellites locked through a level turn at 250 m/s".into(),
            x_label: "turning acceleration (g)".into(),
            y_label: "satellites locked through the turn".into(),
            series: curves,
            ..LinePlot::default()
        });
    }
    out
}
