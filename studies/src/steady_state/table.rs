//! The report: the table, the summary JSON, the text and the plots.

use gpsrx_tracking::loop_analysis;
use gpsrx_tracking::loop_filter::{omega0, LoopFilter};
use serde_json::json;

use super::conclusions::{conclusions_md, intro_md};
use super::plan::is_main;
use super::plots::plots;
use super::text::{closed_text, magnitude_text, measured_text, short, sig};
use super::{
    stability_limit_bn_t, AidParams, Aiding, Cell, CellResult, ClosedForm, Input, SteadyStateArgs,
    ABS_TOL_CYCLES, MAIN_T_COH_S, REL_TOL, TARGET_END_ERROR_CYCLES, TARGET_ERROR_CYCLES,
};
use crate::report::{StudyReport, Table};

pub(super) fn build_report(
    args: &SteadyStateArgs,
    cfgs: &[(f64, f64)],
    results: &[CellResult],
    not_run: &[(f64, f64, u8, String)],
) -> StudyReport {
    let mut table = Table::new(&[
        "bn_hz",
        "t_coh_ms",
        "input",
        "order",
        "aiding",
        "magnitude",
        "closed_form",
        "measured",
        "agree",
        "max_abs_error_cycles",
    ]);
    let mut cell_json = Vec::new();
    let mut per_cfg = Vec::new();
    for &(bn, t) in cfgs {
        let mut rows: Vec<&CellResult> = results
            .iter()
            .filter(|r| r.cell.bn_hz == bn && r.cell.t_coh_s == t)
            .collect();
        rows.sort_by_key(|r| {
            (
                r.cell.input.degree(),
                Aiding::ALL.iter().position(|a| *a == r.cell.aiding),
                r.cell.order,
            )
        });
        for r in &rows {
            table.push(vec![
                short(bn),
                short(t * 1e3),
                r.cell.input.name().into(),
                r.cell.order.to_string(),
                r.cell.aiding.name().into(),
                magnitude_text(r),
                closed_text(r.closed),
                measured_text(r),
                if r.agree { "yes" } else { "no" }.into(),
                sig(r.max_abs_error_cycles),
            ]);
            if is_main(args, bn, t) {
                cell_json.push(json!({
                    "input": r.cell.input.name(),
                    "order": r.cell.order,
                    "aiding": r.cell.aiding.name(),
                    "magnitude": r.magnitude,
                    "magnitude_unit": r.cell.input.unit(),
                    "closed_kind": if matches!(r.closed, ClosedForm::Bounded(_)) { "bounded" } else { "growing" },
                    "closed_value": r.closed.value(),
                    "value_unit": r.closed.unit(),
                    "measured_value": r.measured,
                    "agree": r.agree,
                    "max_abs_error_cycles": r.max_abs_error_cycles,
                    "window_s": [r.window.0, r.window.1],
                }));
            }
        }
        let skipped: Vec<&(f64, f64, u8, String)> =
            not_run.iter().filter(|n| n.0 == bn && n.1 == t).collect();
        for (_, _, order, why) in &skipped {
            table.push(vec![
                short(bn),
                short(t * 1e3),
                "all".into(),
                order.to_string(),
                "all".into(),
                "-".into(),
                "-".into(),
                why.clone(),
                "n/a".into(),
                "-".into(),
            ]);
        }
        let bn_digital: Vec<Option<f64>> = (1..=3u8)
            .map(|o| {
                LoopFilter::pll(o, bn)
                    .ok()
                    .and_then(|f| loop_analysis::noise_bandwidth_hz(&f, t))
            })
            .collect();
        per_cfg.push(json!({
            "bn_hz": bn,
            "t_coh_s": t,
            "bn_t": bn * t,
            "main": is_main(args, bn, t),
            "cells_total": rows.len(),
            "cells_agree": rows.iter().filter(|r| r.agree).count(),
            "cells_not_run": skipped.len() * Input::ALL.len() * Aiding::ALL.len(),
            "digital_noise_bandwidth_hz": bn_digital,
            "accepted_by_loop_config": (1..=3u8)
                .map(|order| Cell { bn_hz: bn, t_coh_s: t, order, input: Input::Step,
                    aiding: Aiding::Unaided, aid: AidParams { alpha_rad_s: args.alpha_rad_s,
                    b_v_mps2: args.b_v_mps2 } }.accepted_by_config())
                .collect::<Vec<_>>(),
        }));
    }
    let main_rows: Vec<&CellResult> = results
        .iter()
        .filter(|r| is_main(args, r.cell.bn_hz, r.cell.t_coh_s))
        .collect();
    let (total, agree) = (
        main_rows.len(),
        main_rows.iter().filter(|r| r.agree).count(),
    );
    let others = |key: &str| -> u64 {
        per_cfg
            .iter()
            .filter(|c| c["main"] == false)
            .map(|c| c[key].as_u64().unwrap_or(0))
            .sum()
    };
    let summary = json!({
        "study": "steady-state",
        "quick": args.common.quick,
        "cells_total": total,
        "cells_agree": agree,
        "bn_hz": args.bn_hz,
        "t_coh_s": MAIN_T_COH_S,
        "alpha_rad_s": args.alpha_rad_s,
        "b_v_mps2": args.b_v_mps2,
        "omega0_rad_s": (1..=3u8).map(|o| omega0(o, args.bn_hz)).collect::<Vec<_>>(),
        "stability_limit_bn_t": (1..=3u8).map(stability_limit_bn_t).collect::<Vec<_>>(),
        "tolerance": {"relative": REL_TOL, "absolute_cycles_where_zero": ABS_TOL_CYCLES},
        "target_error_cycles": TARGET_ERROR_CYCLES,
        "target_end_error_cycles": TARGET_END_ERROR_CYCLES,
        "cells": cell_json,
        "other_cells_total": others("cells_total"),
        "other_cells_agree": others("cells_agree"),
        "other_cells_not_run": others("cells_not_run"),
        "configs": per_cfg,
    });
    StudyReport {
        title: "Steady-state phase error of PLLs of order 1-3, unaided and INS-aided".into(),
        intro_md: intro_md(args),
        table,
        conclusions_md: conclusions_md(args, (total, agree), &per_cfg, results),
        summary,
        plots: plots(&main_rows, args),
    }
}
