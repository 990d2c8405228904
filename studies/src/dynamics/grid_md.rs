//! The conclusions of `study.md` across the whole grid: who kept every satellite, the bias
//! effect by loop order, and the pull-in to track hand-over.

use super::aiding::Aiding;
use super::grid::ScenarioSpec;
use super::result::CaseResult;

/// A short name of a case: `10 g turn 45 dB-Hz order 3 Bn 18 Hz`.
fn case_name(r: &CaseResult) -> String {
    format!(
        "{} {} dB-Hz order {} Bn {} Hz",
        r.spec.manoeuvre.label(),
        r.spec.cn0_dbhz,
        r.case.order,
        r.case.bn_hz
    )
}

/// The bias effect by loop order over the grid: INS 2 / INS 1 mean error of the 2nd-order loop,
/// and the largest INS 2 - INS 1 difference of the 3rd-order loop's mean error.
fn bias_md(results: &[CaseResult]) -> String {
    let pairs = |order: u8| -> Vec<(&CaseResult, &CaseResult)> {
        results
            .iter()
            .filter(|a| a.case.order == order && a.case.aiding == Aiding::Ins1)
            .filter_map(|a| {
                results
                    .iter()
                    .find(|b| {
                        b.spec == a.spec
                            && b.case.order == order
                            && b.case.bn_hz == a.case.bn_hz
                            && b.case.aiding == Aiding::Ins2
                    })
                    .map(|b| (a, b))
            })
            .filter(|(a, b)| a.disc_mean_abs_deg.is_finite() && b.disc_mean_abs_deg.is_finite())
            .collect()
    };
    let ratios: Vec<f64> = pairs(2)
        .iter()
        .filter(|(a, _)| a.disc_mean_abs_deg > 0.05)
        .map(|(a, b)| b.disc_mean_abs_deg / a.disc_mean_abs_deg)
        .collect();
    let diff3 = pairs(3)
        .iter()
        .map(|(a, b)| (b.disc_mean_abs_deg - a.disc_mean_abs_deg).abs())
        .fold(0.0, f64::max);
    if ratios.is_empty() {
        return String::new();
    }
    format!(
        "The bias shows in the mean error of the 2nd-order loop (INS 2 / INS 1 = {:.2} on average \
over {} pairs, theory 2, at {:.2}-{:.2}) and in the growth of the 1st-order loop; with order 3, \
INS 1 and INS 2 agree within {diff3:.2} deg (the growth some narrow 3rd-order rows show is their \
hand-over transient still decaying, the same with either INS).\n\n",
        ratios.iter().sum::<f64>() / ratios.len() as f64,
        ratios.len(),
        ratios.iter().copied().fold(f64::INFINITY, f64::min),
        ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )
}

/// What the whole grid shows (empty for the quick grid's single scenario).
pub(super) fn grid_md(results: &[CaseResult]) -> String {
    let mut scenarios: Vec<ScenarioSpec> = Vec::new();
    for r in results {
        if !scenarios.contains(&r.spec) {
            scenarios.push(r.spec);
        }
    }
    if scenarios.len() < 2 {
        return String::new();
    }
    let mut s = String::from("**Across the grid.** ");
    let survivors: Vec<String> = results
        .iter()
        .filter(|r| r.case.aiding == Aiding::Unaided && r.kept == r.satellites)
        .map(case_name)
        .collect();
    s += &format!(
        "Unaided, {} of {} cases kept every satellite through the manoeuvre: {}. ",
        survivors.len(),
        results
            .iter()
            .filter(|r| r.case.aiding == Aiding::Unaided)
            .count(),
        if survivors.is_empty() {
            "none".to_string()
        } else {
            survivors.join("; ")
        }
    );
    let aided: Vec<&CaseResult> = results
        .iter()
        .filter(|r| r.case.aiding != Aiding::Unaided && r.case.order >= 2)
        .collect();
    let dropped: Vec<String> = aided
        .iter()
        .filter(|r| r.kept < r.tracked_at_start)
        .map(|r| format!("{} {}", case_name(r), r.case.aiding.label()))
        .collect();
    s += &format!(
        "Aided (order >= 2), {} of {} cases kept every satellite they were tracking when the \
manoeuvre began{}.\n\n",
        aided.len() - dropped.len(),
        aided.len(),
        if dropped.is_empty() {
            String::new()
        } else {
            format!(" (not: {})", dropped.join("; "))
        }
    );
    s += &bias_md(results);
    let mut cn0s: Vec<f64> = scenarios.iter().map(|c| c.cn0_dbhz).collect();
    cn0s.sort_by(f64::total_cmp);
    cn0s.dedup();
    s += "**Pull-in to track hand-over** (not a dynamics effect, but it limits the narrow loops; \
channels start from truth): ";
    let parts: Vec<String> = cn0s
        .iter()
        .map(|&c| {
            let at = results.iter().filter(|r| r.spec.cn0_dbhz == c);
            let df: Vec<f64> = at
                .clone()
                .map(|r| r.handover_df_rms_hz)
                .filter(|v| v.is_finite())
                .collect();
            let short = at.clone().filter(|r| r.tracked_at_start < r.satellites);
            let mut loops: Vec<String> = short
                .clone()
                .map(|r| format!("order {} Bn {}", r.case.order, r.case.bn_hz))
                .collect();
            loops.sort();
            loops.dedup();
            format!(
                "at {c} dB-Hz the tracking loops start with an NCO frequency error of {:.1} Hz rms \
(mean over cases) and {} of {} cases had lost satellites before the manoeuvre began ({})",
                df.iter().sum::<f64>() / df.len().max(1) as f64,
                short.count(),
                at.count(),
                if loops.is_empty() {
                    "none".to_string()
                } else {
                    loops.join(", ")
                }
            )
        })
        .collect();
    s += &parts.join("; ");
    s += ". The listed loops lose those satellites in the transient after the hand-over, before \
any manoeuvre. The *sats at start* column shows who was tracking when the manoeuvre began; \
*kept* counts from those.";
    s
}
