//! Seed 004 Table 2 in absolute m/s: the pseudorange-rate error std of an unaided 2nd-order
//! PLL at Bn = 1 and 4 Hz (T = 1 ms), with a stated receiver oscillator (none, OCXO, TCXO:
//! [`crate::if_sim::Oscillator`]), against seed 004's 0.031-0.040 m/s (1 Hz) and 0.052-0.070
//! m/s (4 Hz). Unaided because a perfect aid from the true carrier phase would carry the
//! oscillator's phase too (what an INS cannot do).

use super::plan::Case;
use super::track::run_case;
use super::{cell_theory, cell_window_s, Cell, MAX_SETTLE_S};
use crate::if_sim::Oscillator;
use crate::run_cases;
use std::fmt::Write as _;

/// One row: an oscillator at one C/N0.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AbsoluteRow {
    /// Oscillator name.
    pub oscillator: &'static str,
    /// Its Allan deviation at 1 s.
    pub adev_1s: f64,
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
    /// Pseudorange-rate error std over 1 s at Bn = 1 Hz, m/s.
    pub bn1_1s_mps: f64,
    /// The same at Bn = 4 Hz, m/s.
    pub bn4_1s_mps: f64,
    /// Over 0.1 s at Bn = 1 Hz, m/s.
    pub bn1_0p1s_mps: f64,
    /// Over 0.1 s at Bn = 4 Hz, m/s.
    pub bn4_0p1s_mps: f64,
}

fn cell(cn0_dbhz: f64, bn_hz: f64) -> Cell {
    Cell {
        cn0_dbhz,
        order: 2,
        bn_hz,
        t_ms: 1,
    }
}

/// Runs the oscillators x C/N0 recordings (`quick`: 45 dB-Hz only).
pub(super) fn run_absolute(
    seed: u64,
    window_s: f64,
    quick: bool,
    progress: bool,
) -> anyhow::Result<Vec<AbsoluteRow>> {
    let cn0s: &[f64] = if quick { &[45.0] } else { &[40.0, 45.0] };
    let oscillators = [Oscillator::NONE, Oscillator::OCXO, Oscillator::TCXO];
    let mut jobs = Vec::new();
    for osc in oscillators {
        for &cn0 in cn0s {
            let cells: Vec<(Cell, f64)> = [1.0, 4.0]
                .iter()
                .map(|&bn| {
                    let c = cell(cn0, bn);
                    let settle = cell_theory(&c).settle_s;
                    (
                        c,
                        if settle.is_finite() {
                            settle
                        } else {
                            MAX_SETTLE_S
                        },
                    )
                })
                .collect();
            let duration_s = cells
                .iter()
                .map(|(c, s)| s + cell_window_s(c, window_s))
                .fold(0.0, f64::max)
                .ceil();
            jobs.push((
                osc,
                Case {
                    cn0_dbhz: cn0,
                    duration_s,
                    cells,
                    seed,
                },
            ));
        }
    }
    let out = run_cases(&jobs, "table 2 (m/s)", progress, |(osc, case)| {
        run_case(case, false, osc)
    });
    jobs.iter()
        .zip(out)
        .map(|((osc, case), m)| {
            let m = m?;
            Ok(AbsoluteRow {
                oscillator: osc.name,
                adev_1s: osc.allan_deviation(1.0),
                cn0_dbhz: case.cn0_dbhz,
                bn1_1s_mps: m[0].pr_rate_1s_mps,
                bn4_1s_mps: m[1].pr_rate_1s_mps,
                bn1_0p1s_mps: m[0].pr_rate_mps,
                bn4_0p1s_mps: m[1].pr_rate_mps,
            })
        })
        .collect()
}

/// The markdown subsection, its comparison with seed 004 computed from the rows.
pub(super) fn absolute_md(rows: &[AbsoluteRow]) -> String {
    let mut s = String::from(
        "\n### Seed 004 Table 2 in m/s, with a stated oscillator\n\n\
         Unaided 2nd-order PLL, T = 1 ms, static; the receiver clock of the simulation is the \
         two-state oscillator model (white FM + random-walk FM). Paper (not measured here): \
         seed 004 reports 0.031-0.040 m/s at Bn = 1 Hz and 0.052-0.070 m/s at 4 Hz.\n\n\
         | oscillator | sigma_y(1 s) | C/N0 | Bn 1 Hz, 1 s (m/s) | Bn 4 Hz, 1 s (m/s) | ratio | \
         Bn 1 Hz, 0.1 s (m/s) | Bn 4 Hz, 0.1 s (m/s) |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {:.2e} | {} | {:.4} | {:.4} | {:.2} | {:.4} | {:.4} |",
            r.oscillator,
            r.adev_1s,
            r.cn0_dbhz,
            r.bn1_1s_mps,
            r.bn4_1s_mps,
            r.bn4_1s_mps / r.bn1_1s_mps,
            r.bn1_0p1s_mps,
            r.bn4_0p1s_mps
        );
    }
    s += &absolute_discussion(rows);
    s
}

/// Seed 004's pseudorange-rate error std at Bn = 1 Hz and 4 Hz, m/s (paper, not measured here).
const PAPER_1HZ_MPS: (f64, f64) = (0.031, 0.040);
/// The same at 4 Hz.
const PAPER_4HZ_MPS: (f64, f64) = (0.052, 0.070);

/// What the rows show, each statement computed from them: which rows fall within seed 004's
/// ranges, how far the paper's 1 Hz value is from each, and whether the 1 s error grows or falls
/// from 1 Hz to 4 Hz with each oscillator.
fn absolute_discussion(rows: &[AbsoluteRow]) -> String {
    let mut s = String::new();
    let in_paper = |r: &&AbsoluteRow| {
        (PAPER_1HZ_MPS.0..=PAPER_1HZ_MPS.1).contains(&r.bn1_1s_mps)
            || (PAPER_4HZ_MPS.0..=PAPER_4HZ_MPS.1).contains(&r.bn4_1s_mps)
    };
    let matching: Vec<String> = rows
        .iter()
        .filter(in_paper)
        .map(|r| format!("{} at {} dB-Hz", r.oscillator, r.cn0_dbhz))
        .collect();
    let _ = writeln!(
        s,
        "\nWithin seed 004's ranges (1 s Doppler): {}.",
        if matching.is_empty() {
            "none of these cases".to_string()
        } else {
            matching.join(", ")
        }
    );
    let paper_mid = 0.5 * (PAPER_1HZ_MPS.0 + PAPER_1HZ_MPS.1);
    let per_row: Vec<String> = rows
        .iter()
        .map(|r| {
            let q = r.bn4_1s_mps / r.bn1_1s_mps;
            if !q.is_finite() {
                let missing: Vec<&str> = [(r.bn1_1s_mps, "1"), (r.bn4_1s_mps, "4")]
                    .iter()
                    .filter(|(v, _)| !v.is_finite())
                    .map(|(_, bn)| *bn)
                    .collect();
                return format!(
                    "{} at {} dB-Hz: no 1 s error at Bn {} Hz (no channel held lock), so no trend",
                    r.oscillator,
                    r.cn0_dbhz,
                    missing.join(" and ")
                );
            }
            let trend = if q > 1.0 {
                "grows"
            } else if q < 1.0 {
                "falls"
            } else {
                "does not change"
            };
            let scale = paper_mid / r.bn1_1s_mps;
            let level = if scale >= 1.0 {
                format!("the paper's 1 Hz value is {scale:.0} x this")
            } else {
                format!("this is {:.1} x the paper's 1 Hz value", 1.0 / scale)
            };
            format!(
                "{} at {} dB-Hz: the 1 s error {trend} from 1 Hz to 4 Hz ({q:.2}); {level}",
                r.oscillator, r.cn0_dbhz
            )
        })
        .collect();
    if !per_row.is_empty() {
        let _ = writeln!(s, "\n{}.", per_row.join("; "));
    }
    s
}
