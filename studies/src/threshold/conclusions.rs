//! The conclusions, computed from the results: how many cells agree with theory, and for every
//! cell more than 3 dB from the rule of thumb what the measurement says about why.

use super::params::{AGREE_DB, SCAN_TOP_DBHZ};
use super::result::{Agreement, CellResult};
use super::theory::loop_gain;
use crate::bandwidth::costas_atan_stats;
use crate::report::fmt;
use std::f64::consts::PI;
use std::fmt::Write as _;

fn cell_name(r: &CellResult) -> String {
    let c = &r.cell;
    format!(
        "order {}, Bn {} Hz, T {} ms, {}",
        c.order,
        fmt(c.bn_hz, 1),
        c.t_coh_ms,
        c.dynamics.name()
    )
}

fn fmt_level(v: Option<f64>) -> String {
    v.map_or_else(|| "none".to_string(), |x| fmt(x, 1))
}

fn pct(k: usize, n: usize) -> f64 {
    100.0 * k as f64 / n.max(1) as f64
}

/// What the first failing run below the threshold saw, in words.
fn failure_words(r: &CellResult) -> String {
    match r.measured.and_then(|m| m.first_failure) {
        Some((cn0, out)) => {
            let snr_db = cn0 + 10.0 * r.cell.t_coh_s().log10();
            format!(
                "one step below, at {} dB-Hz (prompt SNR C/N0 T = {} dB), lock was held {:.0} % of \
                 the window and the loop {}",
                fmt(cn0, 1),
                fmt(snr_db, 1),
                100.0 * out.held_fraction,
                if out.half_cycle_slips == 0 {
                    "did not slip: the lock detector, not the loop, gave up".to_string()
                } else {
                    format!("slipped {} half cycles", out.half_cycle_slips)
                }
            )
        }
        None => "the scan reached its bottom without a failure".into(),
    }
}

/// The same (Bn, T, dynamics) with another order, if it agrees with its rule.
fn agreeing_sibling<'a>(r: &CellResult, all: &'a [CellResult]) -> Option<&'a CellResult> {
    all.iter().find(|o| {
        o.cell.order != r.cell.order
            && o.cell.bn_hz == r.cell.bn_hz
            && o.cell.t_coh_ms == r.cell.t_coh_ms
            && o.cell.dynamics == r.cell.dynamics
            && o.vs_rule().is_some_and(|a| a.agrees())
    })
}

/// The explanation of a cell that is more than 3 dB from the rule (computed from its numbers).
fn explain(r: &CellResult, all: &[CellResult]) -> String {
    let th = &r.theory;
    let m = r.measured_dbhz();
    let mut s = match r.vs_rule() {
        Some(Agreement::Delta(d)) if d > 0.0 => {
            let mut s = format!(
                "measured {} dB-Hz, {} dB above the rule's {} dB-Hz",
                fmt(m.unwrap_or(f64::NAN), 1),
                fmt(d, 1),
                fmt(th.rule_dbhz.unwrap_or(f64::NAN), 1)
            );
            let by_detector = th.detector_dbhz.is_some_and(|f| {
                f > th.rule_dbhz.unwrap_or(f64::INFINITY) && (m.unwrap_or(f64::NAN) - f).abs() <= AGREE_DB
            });
            let by_realised = th
                .rule_realised_dbhz
                .is_some_and(|x| (m.unwrap_or(f64::NAN) - x).abs() <= AGREE_DB);
            let by_stability = th.stable_dbhz.is_some_and(|f| {
                f > th.rule_dbhz.unwrap_or(f64::INFINITY) && (m.unwrap_or(f64::NAN) - f).abs() <= AGREE_DB
            });
            let slipped = r
                .measured
                .and_then(|x| x.first_failure)
                .is_some_and(|(_, o)| o.half_cycle_slips > 0);
            if by_stability && (slipped || !by_detector) {
                let gain = loop_gain(th.stable_dbhz.unwrap_or(f64::NAN), r.cell.t_coh_s());
                let _ = write!(
                    s,
                    ": the 3rd-order loop is only conditionally stable, and below {} dB-Hz the \
                     loop gain the Costas atan slope leaves (< {} of the design: the slope \
                     1 - exp(-C/N0 T) is normalised only down to 0.05) makes the linearised loop \
                     unstable: it slips whatever its jitter",
                    fmt(th.stable_dbhz.unwrap_or(f64::NAN), 1),
                    fmt(gain, 2)
                );
            } else if by_detector {
                let _ = write!(
                    s,
                    ": the receiver's lock detector sets it (its floor, {} dB-Hz, is within {} dB \
                     of the measurement: below it the detector's estimate, even averaged over \
                     its longest memory, is too noisy to read lock 95 % of the time)",
                    fmt(th.detector_dbhz.unwrap_or(f64::NAN), 1),
                    fmt(AGREE_DB, 0)
                );
            } else if th.rule_slope_dbhz.is_some_and(|x| {
                x > th.rule_dbhz.unwrap_or(f64::INFINITY) && (m.unwrap_or(f64::NAN) - x).abs() <= AGREE_DB
            }) {
                let _ = write!(
                    s,
                    ": the stress error grows as the Costas slope 1 - exp(-C/N0 T) below 0.05 \
                     lowers the loop gain (theta_e / gain); with it the rule gives {} dB-Hz",
                    fmt(th.rule_slope_dbhz.unwrap_or(f64::NAN), 1)
                );
            } else if by_realised {
                let _ = write!(
                    s,
                    ": the digital loop's realised noise bandwidth is {} Hz (Bn T = {}), not {} Hz; \
                     the rule with it gives {} dB-Hz",
                    fmt(th.realised_bn_hz, 2),
                    fmt(r.cell.bn_hz * r.cell.t_coh_s(), 3),
                    fmt(r.cell.bn_hz, 1),
                    fmt(th.rule_realised_dbhz.unwrap_or(f64::NAN), 1)
                );
            } else {
                s += ": the loop loses lock above the rule (neither the lock detector's floor nor \
                      the realised bandwidth accounts for it)";
            }
            s
        }
        Some(Agreement::Delta(d)) => format!(
            "measured {} dB-Hz, {} dB below the rule's {} dB-Hz: the loop holds with more than \
             3 sigma of margin lost (RMS phase error at the threshold {} deg, so 3 sigma = {} deg \
             + stress {} deg against the rule's 45): the rule is conservative here",
            fmt(m.unwrap_or(f64::NAN), 1),
            fmt(-d, 1),
            fmt(th.rule_dbhz.unwrap_or(f64::NAN), 1),
            fmt(r.measured.and_then(|x| x.at_threshold).map_or(f64::NAN, |o| o.rms_error_deg), 1),
            fmt(3.0 * r.measured.and_then(|x| x.at_threshold).map_or(f64::NAN, |o| o.rms_error_deg), 1),
            fmt(th.stress_deg, 1)
        ),
        Some(Agreement::MeasuredNone) => format!(
            "never held lock, not even at {} dB-Hz, although the rule gives {} dB-Hz (stress {} deg)",
            fmt(SCAN_TOP_DBHZ, 0),
            fmt(th.rule_dbhz.unwrap_or(f64::NAN), 1),
            fmt(th.stress_deg, 1)
        ),
        Some(Agreement::TheoryNone) => format!(
            "held down to {} dB-Hz although its stress error ({} deg) leaves the rule no margin: \
             the Costas discriminator slips only at 90 deg, the rule's 45 deg is a margin",
            fmt(m.unwrap_or(f64::NAN), 1),
            fmt(th.stress_deg, 1)
        ),
        _ => String::new(),
    };
    if !matches!(r.vs_rule(), Some(Agreement::TheoryNone)) {
        let _ = write!(s, "; {}", failure_words(r));
    }
    s += &atan_words(r);
    match r.loop_vs_rule() {
        Some(Agreement::Delta(d)) => {
            let _ = write!(
                s,
                "; the loop itself ran slip-free down to {} dB-Hz ({} dB from the rule)",
                fmt(r.loop_dbhz().unwrap_or(f64::NAN), 1),
                fmt(d, 1)
            );
        }
        Some(Agreement::MeasuredNone) => {
            s += "; the loop itself slipped even at the top of the scan"
        }
        _ => {}
    }
    if let Some(o) = agreeing_sibling(r, all) {
        let _ = write!(
            s,
            "; the order-{} loop of the same Bn, T and dynamics agrees with its rule (measured {} \
             dB-Hz), so the order-{} loop itself departs",
            o.cell.order,
            fmt(o.measured_dbhz().unwrap_or(f64::NAN), 1),
            r.cell.order
        );
    }
    s
}

/// What the rule with the receiver's own discriminator noise says of a cell, in words.
fn atan_words(r: &CellResult) -> String {
    match (r.vs_atan_rule(), r.theory.rule_atan_dbhz) {
        (Some(Agreement::Delta(d)), Some(a)) => {
            let t = r.cell.t_coh_s();
            let rho = 10f64.powf(a / 10.0) * t;
            let stats = costas_atan_stats(a, t);
            let kaplan = (1.0 + 1.0 / (2.0 * rho)) / (2.0 * rho) / (4.0 * PI * PI);
            format!(
                "; the rule with the atan discriminator's own noise through the digital loop \
                 gives {} dB-Hz ({} dB from the measurement{}): there (prompt SNR {} dB) the \
                 atan's variance per unit slope is {}x that of Kaplan's squaring loss, and the \
                 digital loop's phase noise gain that of Bn = {} Hz",
                fmt(a, 1),
                fmt(d, 1),
                if d.abs() <= AGREE_DB {
                    ", within 3 dB"
                } else {
                    ", still more than 3 dB"
                },
                fmt(10.0 * rho.log10(), 1),
                fmt(stats.noise_var / (stats.slope * stats.slope) / kaplan, 2),
                fmt(r.theory.realised_bn_hz, 2)
            )
        }
        _ => String::new(),
    }
}

/// Why a loop's own threshold is far from the rule, from its numbers.
fn loop_reason(r: &CellResult, a: Agreement) -> String {
    let th = &r.theory;
    match (a, r.loop_dbhz()) {
        (Agreement::Delta(d), Some(l)) if d < 0.0 => format!(
            ": at {} dB-Hz the Costas slope 1 - exp(-C/N0 T) leaves the loop {} of its design \
             gain (the slope is normalised only down to 0.05), its bandwidth collapses with it \
             and, with nothing to follow, it does not slip; the rule's linear-loop jitter does \
             not apply",
            fmt(l, 1),
            fmt(loop_gain(l, r.cell.t_coh_s()), 3)
        ),
        (Agreement::Delta(_), Some(l))
            if th.stable_dbhz.is_some_and(|f| (l - f).abs() <= AGREE_DB) =>
        {
            format!(
                ": within {} dB of the 3rd-order stability floor, {} dB-Hz",
                fmt(AGREE_DB, 0),
                fmt(th.stable_dbhz.unwrap_or(f64::NAN), 1)
            )
        }
        (Agreement::Delta(_), Some(l))
            if th.rule_slope_dbhz.is_some_and(|x| {
                x > th.rule_dbhz.unwrap_or(f64::INFINITY) && (l - x).abs() <= AGREE_DB
            }) =>
        {
            format!(
                ": the stress error grows as the Costas slope 1 - exp(-C/N0 T) below 0.05 lowers \
                 the loop gain (theta_e / gain); with it the rule gives {} dB-Hz",
                fmt(th.rule_slope_dbhz.unwrap_or(f64::NAN), 1)
            )
        }
        (Agreement::Delta(_), Some(l))
            if th.rule_atan_dbhz.is_some_and(|x| (l - x).abs() <= AGREE_DB) =>
        {
            format!(
                ": within {} dB of the rule with the atan noise, {} dB-Hz",
                fmt(AGREE_DB, 0),
                fmt(th.rule_atan_dbhz.unwrap_or(f64::NAN), 1)
            )
        }
        (Agreement::Delta(_), Some(_)) => ": above the rule, unexplained by the floors".into(),
        _ => String::new(),
    }
}

/// How many of `run` agree by `compare`, and the measured-minus-theory deltas where both have
/// a threshold.
fn tally(
    run: &[&CellResult],
    compare: impl Fn(&CellResult) -> Option<Agreement>,
) -> (usize, Vec<f64>) {
    let outcomes: Vec<Option<Agreement>> = run.iter().map(|r| compare(r)).collect();
    let agree = outcomes
        .iter()
        .filter(|a| a.is_some_and(|a| a.agrees()))
        .count();
    let deltas = outcomes
        .iter()
        .filter_map(|a| match a {
            Some(Agreement::Delta(d)) => Some(*d),
            _ => None,
        })
        .collect();
    (agree, deltas)
}

/// `measured minus theory over the K cells with both thresholds: mean M dB, from LO to HI dB`
/// (empty without any).
fn spread_words(deltas: &[f64]) -> String {
    if deltas.is_empty() {
        return String::new();
    }
    let mean = deltas.iter().sum::<f64>() / deltas.len() as f64;
    let lo = deltas.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = deltas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    format!(
        "measured minus theory over the {} cells with both thresholds: mean {} dB, from {} to {} \
         dB",
        deltas.len(),
        fmt(mean, 1),
        fmt(lo, 1),
        fmt(hi, 1)
    )
}

/// The conclusions of `results` (Markdown).
pub fn conclusions_md(results: &[CellResult]) -> String {
    let run: Vec<&CellResult> = results.iter().filter(|r| r.rejected.is_none()).collect();
    let n = run.len();
    let (agree, deltas) = tally(&run, CellResult::vs_rule);
    let both_none = run
        .iter()
        .filter(|r| r.vs_rule() == Some(Agreement::BothNone))
        .count();
    let agree_exp = run
        .iter()
        .filter(|r| r.vs_expected().is_some_and(|a| a.agrees()))
        .count();
    let (agree_atan, atan_deltas) = tally(&run, CellResult::vs_atan_rule);
    let mut s = String::from("## Conclusions\n\n");
    let _ = writeln!(
        s,
        "- **{agree_atan} of {n} cells ({:.0} %) hold lock to within {} dB of the rule of thumb \
         with the receiver's own discriminator noise** (`theory_atan_dbhz`: `3 sigma + theta_e \
         <= 45` deg with the atan discriminator's exact variance and slope through the \
         linearised digital loop); {}.",
        pct(agree_atan, n),
        fmt(AGREE_DB, 0),
        spread_words(&atan_deltas),
    );
    let _ = writeln!(
        s,
        "- **{agree} of {n} cells ({:.0} %) hold lock to within {} dB of the rule of thumb with \
         Kaplan's thermal formula** (`theory_dbhz`; {both_none} of them with no threshold in \
         either); {agree_exp} of {n} ({:.0} %) are within \
         {} dB of the expected threshold (`expected_dbhz`: the highest of the rule with the stress \
         over the Costas slope, the 3rd-order stability floor and the lock detector's floor).",
        pct(agree, n),
        fmt(AGREE_DB, 0),
        pct(agree_exp, n),
        fmt(AGREE_DB, 0),
    );
    if !deltas.is_empty() {
        let _ = writeln!(s, "- Against Kaplan's rule, {}.", spread_words(&deltas));
    }
    let loop_agree = run
        .iter()
        .filter(|r| r.loop_vs_rule().is_some_and(|a| a.agrees()))
        .count();
    let loop_agree_atan = run
        .iter()
        .filter(|r| {
            r.measured
                .map(|m| Agreement::of(m.loop_threshold_dbhz, r.theory.rule_atan_dbhz))
                .is_some_and(|a| a.agrees())
        })
        .count();
    let loop_agree_exp = run
        .iter()
        .filter(|r| match (r.loop_dbhz(), r.theory.loop_expected_dbhz()) {
            (Some(l), Some(e)) => l - e <= AGREE_DB,
            (None, None) => true,
            _ => false,
        })
        .count();
    let loop_off: Vec<String> = run
        .iter()
        .filter_map(|r| match r.loop_vs_rule() {
            Some(a) if !a.agrees() => Some(format!(
                "{} ({} vs {} dB-Hz{})",
                cell_name(r),
                fmt_level(r.loop_dbhz()),
                fmt_level(r.theory.rule_dbhz),
                loop_reason(r, a)
            )),
            _ => None,
        })
        .collect();
    let _ = writeln!(
        s,
        "- **The loops themselves** (slip-free against the truth for {:.0} % of the window, whatever the lock detector says): {loop_agree_atan} of {n} ({:.0} %) within {} dB of the rule with the atan noise; {loop_agree} of {n} ({:.0} %) within {} dB of Kaplan's rule, \
         {loop_agree_exp} of {n} within {} dB of the rule with the slope and stability floor or \
         below it (holding better than theory){}.",
        100.0 * super::params::HOLD_FRACTION,
        pct(loop_agree_atan, n),
        fmt(AGREE_DB, 0),
        pct(loop_agree, n),
        fmt(AGREE_DB, 0),
        fmt(AGREE_DB, 0),
        if loop_off.is_empty() {
            String::new()
        } else {
            format!("; more than 3 dB from Kaplan's rule: {}", loop_off.join("; "))
        }
    );
    let rejected: Vec<&CellResult> = results.iter().filter(|r| r.rejected.is_some()).collect();
    if !rejected.is_empty() {
        let _ = writeln!(
            s,
            "- Not run, refused by the receiver's loop validation: {}.",
            rejected
                .iter()
                .map(|r| format!(
                    "{} ({})",
                    cell_name(r),
                    r.rejected.as_deref().unwrap_or_default()
                ))
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    let off: Vec<&&CellResult> = run
        .iter()
        .filter(|r| r.vs_rule().is_some_and(|a| !a.agrees()))
        .collect();
    if off.is_empty() {
        let _ = writeln!(
            s,
            "- Every cell run is within {} dB of the rule.",
            fmt(AGREE_DB, 0)
        );
    } else {
        let _ = writeln!(
            s,
            "\nCells more than {} dB from Kaplan's rule:\n",
            fmt(AGREE_DB, 0)
        );
        for r in off {
            let _ = writeln!(s, "- {}: {}.", cell_name(r), explain(r, results));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::super::measure::Measured;
    use super::super::result::cell_theory;
    use super::super::sim::RunOutcome;
    use super::super::{Cell, Dynamics};
    use super::*;

    fn result(order: u8, bn_hz: f64, measured: Option<f64>) -> CellResult {
        let cell = Cell {
            order,
            bn_hz,
            t_coh_ms: 1,
            dynamics: Dynamics::Static,
        };
        let out = RunOutcome {
            held_fraction: 0.5,
            half_cycle_slips: 4,
            slip_free_fraction: 0.5,
            rms_error_deg: 10.0,
        };
        CellResult {
            cell,
            rejected: None,
            theory: cell_theory(&cell),
            measured: Some(Measured {
                threshold_dbhz: measured,
                at_threshold: Some(out),
                first_failure: measured.map(|m| (m - 0.5, out)),
                loop_threshold_dbhz: measured,
                loop_first_failure: measured.map(|m| (m - 0.5, out)),
                runs: 10,
            }),
        }
    }

    /// The conclusions follow the numbers: a measured threshold moved from the rule (27.1
    /// dB-Hz at 18 Hz, T = 1 ms) to 8 dB above it changes the count and adds an explanation
    /// naming the cell; a loop that never held is reported as such.
    #[test]
    fn conclusions_change_when_a_measured_value_changes() {
        let rule = cell_theory(&result(2, 18.0, None).cell)
            .rule_dbhz
            .unwrap_or(f64::NAN);
        let good = vec![
            result(2, 18.0, Some(rule + 0.5)),
            result(3, 18.0, Some(rule)),
        ];
        let a = conclusions_md(&good);
        assert!(a.contains("2 of 2 cells (100 %)"), "{a}");
        assert!(
            a.contains("2 of 2 cells (100 %) hold lock to within 3 dB of the rule of thumb with the receiver's own"),
            "{a}"
        );
        assert!(a.contains("Every cell run is within 3 dB"), "{a}");
        let bad = vec![
            result(2, 18.0, Some(rule + 0.5)),
            result(3, 18.0, Some(rule + 8.0)),
        ];
        let b = conclusions_md(&bad);
        assert_ne!(a, b);
        assert!(b.contains("1 of 2 cells (50 %)"), "{b}");
        assert!(
            b.contains("1 of 2 cells (50 %) hold lock to within 3 dB of the rule of thumb with the receiver's own"),
            "{b}"
        );
        assert!(b.contains("still more than 3 dB"), "{b}");
        assert!(
            b.contains("order 3, Bn 18.0 Hz, T 1 ms, static: measured"),
            "{b}"
        );
        assert!(b.contains("8.0 dB above the rule"), "{b}");
        assert!(b.contains("slipped 4 half cycles"), "{b}");
        assert!(b.contains("the order-2 loop of the same Bn"), "{b}");
        let none = vec![result(2, 18.0, None)];
        let c = conclusions_md(&none);
        assert!(c.contains("never held lock"), "{c}");
    }
}
