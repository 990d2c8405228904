//! The report: the table, its notes and the JSON summary.

use super::conclusions::{conclusions, range_of};
use super::grid::cn0_t;
use super::intro::intro;
use super::plots::plots;
use super::{
    table_two_ratios, CellMeasured, CellResult, CellStatus, RunInfo, BNT_LIMIT, DLL_BN_HZ,
    EL_SPACING_CHIPS, FS_HZ, HIGH_SNR_CN0_T, MAX_SETTLE_S, PRNS, THRESHOLD_SIGMA_DEG, TOLERANCE,
};
use crate::report::{fmt, StudyReport, Table};
use gpsrx_tracking::config::MAX_BN_T;
use serde_json::json;

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.to_string()
}

pub(super) fn note(r: &CellResult) -> String {
    match &r.status {
        CellStatus::Rejected { stable, .. } => format!(
            "not run: Bn T = {:.2} > {MAX_BN_T} (LoopConfig::validate); digital loop {}",
            r.cell.bn_t(),
            if *stable { "stable" } else { "unstable" }
        ),
        CellStatus::Run => {
            let m = &r.measured;
            let mut parts = Vec::new();
            if !r.above_threshold() {
                parts.push("below threshold (3 sigma > 45 deg)".to_string());
            }
            if m.lost > 0 {
                parts.push(format!("{}/{} lost", m.lost, m.channels));
            }
            if m.slips > 0 {
                parts.push(format!("{} half-cycle slips", m.slips));
            }
            if m.locked < m.channels && m.lost == 0 && m.slips == 0 {
                parts.push(format!("{}/{} locked", m.locked, m.channels));
            }
            if !r.theory.linear_stable {
                parts.push(format!(
                    "linearised loop unstable at atan slope {:.2}",
                    r.theory.atan_slope
                ));
            } else if r.theory.settle_s > MAX_SETTLE_S {
                parts.push(format!(
                    "needs {:.0} s to settle, measured after {MAX_SETTLE_S} s",
                    r.theory.settle_s
                ));
            }
            if r.cell.bn_t() > BNT_LIMIT + 1e-12 {
                parts.push(format!(
                    "Bn T > {BNT_LIMIT}: realised Bn {:.2} x design",
                    r.theory.bn_realised_ratio
                ));
            }
            parts.join("; ")
        }
    }
}

fn cell_json(r: &CellResult) -> serde_json::Value {
    let f = |v: f64| if v.is_finite() { json!(v) } else { json!(null) };
    json!({
        "cn0_dbhz": r.cell.cn0_dbhz,
        "order": r.cell.order,
        "bn_hz": r.cell.bn_hz,
        "t_ms": r.cell.t_ms,
        "bn_t": r.cell.bn_t(),
        "ratio": f(r.ratio()),
        "loop_theory_ratio": f(r.theory.phase_loop_deg / r.theory.phase_formula_deg),
        "measured_over_loop_theory": f(r.measured.phase_deg / r.theory.phase_loop_deg),
        "bn_realised_ratio": f(r.theory.bn_realised_ratio),
        "digital_loop_ratio": f(r.theory.phase_digital_ratio),
        "locked": r.locked(),
    })
}

const COLUMNS: [&str; 23] = [
    "cn0_dbhz",
    "order",
    "bn_hz",
    "t_ms",
    "bn_t",
    "phase_jitter_deg",
    "phase_jitter_formula_deg",
    "ratio",
    "phase_jitter_loop_deg",
    "doppler_std_hz",
    "doppler_theory_hz",
    "pr_rate_std_mps",
    "pr_rate_theory_mps",
    "pr_rate_1s_std_mps",
    "pr_rate_1s_theory_mps",
    "code_std_chips",
    "code_formula_chips",
    "code_envelope_chips",
    "locked",
    "within_20pct",
    "epochs",
    "settle_s",
    "note",
];

pub(super) fn build_report(results: &[CellResult], info: &RunInfo) -> StudyReport {
    let mut table = Table::new(&COLUMNS);
    for r in results {
        let (m, t) = (&r.measured, &r.theory);
        let run = r.status == CellStatus::Run;
        table.push(vec![
            fmt(r.cell.cn0_dbhz, 0),
            r.cell.order.to_string(),
            fmt(r.cell.bn_hz, 1),
            r.cell.t_ms.to_string(),
            fmt(r.cell.bn_t(), 4),
            fmt(m.phase_deg_or_nan(run), 3),
            fmt(t.phase_formula_deg, 3),
            fmt(if run { r.ratio() } else { f64::NAN }, 3),
            fmt(t.phase_loop_deg, 3),
            fmt(m.or_nan(run, m.doppler_hz), 4),
            fmt(t.doppler_hz, 4),
            fmt(m.or_nan(run, m.pr_rate_mps), 4),
            fmt(t.pr_rate_mps, 4),
            fmt(m.or_nan(run, m.pr_rate_1s_mps), 5),
            fmt(t.pr_rate_1s_mps, 5),
            fmt(m.or_nan(run, m.code_chips), 5),
            fmt(t.code_formula_chips, 5),
            fmt(t.code_envelope_chips, 5),
            if run { yes_no(r.locked()) } else { "-".into() },
            match r.within_tolerance() {
                Some(b) => yes_no(b),
                None => "n.a.".into(),
            },
            m.epochs.to_string(),
            fmt(if run { r.theory.settle_s } else { f64::NAN }, 1),
            note(r),
        ]);
    }

    // Summary.
    let region: Vec<&CellResult> = results.iter().filter(|r| r.in_formula_region()).collect();
    let region_locked: Vec<&&CellResult> = region.iter().filter(|r| r.locked()).collect();
    let region_within = region_locked
        .iter()
        .filter(|r| r.within_tolerance() == Some(true))
        .count();
    let worst = region_locked
        .iter()
        .max_by(|a, b| (a.ratio() - 1.0).abs().total_cmp(&(b.ratio() - 1.0).abs()));
    let region_not_locked: Vec<serde_json::Value> = region
        .iter()
        .filter(|r| !r.locked())
        .map(|r| cell_json(r))
        .collect();
    let outside_tol: Vec<serde_json::Value> = region_locked
        .iter()
        .filter(|r| r.within_tolerance() == Some(false))
        .map(|r| cell_json(r))
        .collect();
    let beyond: Vec<&CellResult> = results
        .iter()
        .filter(|r| r.status == CellStatus::Run && r.cell.bn_t() > BNT_LIMIT + 1e-12)
        .collect();
    let rejected: Vec<serde_json::Value> = results
        .iter()
        .filter_map(|r| match &r.status {
            CellStatus::Rejected { stable, .. } => Some(json!({
                "cn0_dbhz": r.cell.cn0_dbhz, "order": r.cell.order, "bn_hz": r.cell.bn_hz,
                "t_ms": r.cell.t_ms, "bn_t": r.cell.bn_t(), "digital_loop_stable": stable,
            })),
            CellStatus::Run => None,
        })
        .collect();
    let not_locked: Vec<serde_json::Value> = results
        .iter()
        .filter(|r| r.status == CellStatus::Run && !r.locked())
        .map(|r| {
            let mut v = cell_json(r);
            v["note"] = json!(note(r));
            v
        })
        .collect();
    let ratios = table_two_ratios(results);
    let below_threshold_locked: Vec<serde_json::Value> = results
        .iter()
        .filter(|r| r.locked() && !r.above_threshold())
        .map(cell_json)
        .collect();
    let summary = json!({
        "study": "bandwidth",
        "quick": info.quick,
        "seed": info.seed,
        "aided_by_truth_doppler": info.aided,
        "window_s": info.window_s,
        "recordings": info.recordings,
        "recorded_s": info.recorded_s,
        "fs_hz": FS_HZ,
        "prns_per_cn0": PRNS,
        "dll": {"order": 1, "bn_hz": DLL_BN_HZ, "el_spacing_chips": EL_SPACING_CHIPS,
                "discriminator": "normalised early-minus-late envelope"},
        "tolerance": TOLERANCE,
        "bnt_limit": BNT_LIMIT,
        "threshold_sigma_deg": THRESHOLD_SIGMA_DEG,
        "cells_total": results.len(),
        "cells_run": results.iter().filter(|r| r.status == CellStatus::Run).count(),
        "cells_rejected": rejected,
        "cells_not_locked": not_locked,
        "formula_region": {
            "description": "Bn T <= 0.1 and formula sigma <= 15 deg (3 sigma <= 45 deg)",
            "cells": region.len(),
            "locked": region_locked.len(),
            "within_20pct": region_within,
            "worst": worst.map(|r| cell_json(r)),
            "worst_ratio": worst.map(|r| r.ratio()),
            "outside_20pct": outside_tol,
            "not_locked": region_not_locked,
            "by_prompt_snr": {
                "cn0_t_ge_3": region_counts(&region, true),
                "cn0_t_lt_3": region_counts(&region, false),
            },
        },
        "beyond_bnt_0p1": beyond.iter().map(|r| {
            let mut v = cell_json(r);
            v["note"] = json!(note(r));
            v
        }).collect::<Vec<_>>(),
        "locked_below_threshold": below_threshold_locked,
        "pr_rate_ratio_4hz_over_1hz": ratios,
        "seed004_table2": {"bn_1hz_mps": [0.03134, 0.04001, 0.03885],
                           "bn_4hz_mps": [0.05183, 0.06877, 0.07015],
                           "ratios": [0.05183 / 0.03134, 0.06877 / 0.04001, 0.07015 / 0.03885]},
        "wall_s": info.wall_s,
    });

    let intro_md = intro(info);
    let conclusions_md = conclusions(results, &ratios, info);
    StudyReport {
        title: "Loop bandwidth study: thermal noise of the PLL, Doppler and DLL".into(),
        intro_md,
        table,
        conclusions_md,
        summary,
        plots: plots(results),
    }
}

impl CellMeasured {
    fn or_nan(&self, run: bool, v: f64) -> f64 {
        if run && self.locked > 0 {
            v
        } else {
            f64::NAN
        }
    }

    fn phase_deg_or_nan(&self, run: bool) -> f64 {
        self.or_nan(run, self.phase_deg)
    }
}

/// Counts of formula-region cells at high (`C/N0 T >= 3`) or low prompt SNR: cells, locked,
/// within 20 %, and the range of measured / formula over the locked ones.
fn region_counts(region: &[&CellResult], high: bool) -> serde_json::Value {
    let cells: Vec<&&CellResult> = region
        .iter()
        .filter(|r| (cn0_t(&r.cell) >= HIGH_SNR_CN0_T) == high)
        .collect();
    let locked: Vec<&&&CellResult> = cells.iter().filter(|r| r.locked()).collect();
    let (lo, hi) = range_of(locked.iter().map(|r| r.ratio()));
    let f = |v: f64| if v.is_finite() { json!(v) } else { json!(null) };
    json!({
        "cells": cells.len(),
        "locked": locked.len(),
        "within_20pct": locked.iter().filter(|r| r.within_tolerance() == Some(true)).count(),
        "ratio_min": f(lo),
        "ratio_max": f(hi),
    })
}
