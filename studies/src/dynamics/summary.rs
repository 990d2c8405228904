//! The study report: `study.json`'s summary and rows, and the assembled [`StudyReport`].

use super::aiding::bias_direction_enu;
use super::conclusions::conclusions_md;
use super::grid_md::grid_md;
use super::headline::{Headline, Trio, TEN_G};
use super::intro::intro_md;
use super::params::{
    CLOCK_DRIFT_S_S, FS_HZ, HEADLINE_BN_HZ, INS_RATE_HZ, MG_MPS2, NARROW_DEFAULT_BIAS_MG,
    NARROW_INS1_BIAS_MG, ORDER1_BN_HZ, OSCILLATOR, RAMP_S, SPEED_MPS, START_TOW_S, STEP_S, TAIL_S,
    TICK_S, TURN_S, WIDE_INS1_BIAS_MPS2,
};
use super::plots::plots;
use super::result::{CaseResult, NotRun};
use super::seed_tables::{fig12_15, table3_rows};
use super::table::table;
use super::DynamicsArgs;
use crate::report::StudyReport;
use serde_json::json;

fn result_json(r: &CaseResult) -> serde_json::Value {
    let num = json_num;
    json!({
        "manoeuvre": r.spec.manoeuvre.label(),
        "g": r.spec.manoeuvre.g(),
        "cn0_dbhz": r.spec.cn0_dbhz,
        "lead_in_s": r.spec.lead_in_s,
        "order": r.case.order,
        "bn_hz": r.case.bn_hz,
        "aiding": r.case.aiding.key(),
        "bias_mps2": r.case.bias_mps2(),
        "ins1_bias_mps2": r.case.ins1_bias_mps2,
        "satellites": r.satellites,
        "tracked_at_start": r.tracked_at_start,
        "tracked_min": r.tracked_min,
        "tracked_mean": num(r.tracked_mean),
        "kept": r.kept,
        "tracked_at_end": r.tracked_at_end,
        "lock_drops": r.lock_drops,
        "channels_lost": r.channels_lost,
        "phase_std_cycles": num(r.phase_std_cycles),
        "disc_std_cycles": num(r.disc_std_cycles),
        "disc_std_per_sat_cycles": r.prns.iter().zip(&r.disc_std_per_sat)
            .map(|(p, v)| json!({"prn": p, "std_cycles": num(*v)}))
            .collect::<Vec<_>>(),
        "lead_in_accel_max_mps2": num(r.lead_in_accel_max_mps2),
        "lost_before_prns": r.lost_before_prns,
        "mean_abs_phase_error_deg": num(r.disc_mean_abs_deg),
        "predicted_mean_abs_phase_error_deg": num(r.predicted_mean_abs_deg),
        "phase_error_growth_deg_s": num(r.growth_abs_deg_s),
        "predicted_phase_error_growth_deg_s": num(r.predicted_growth_deg_s),
        "bias_stats_satellites": r.bias_channels,
        "handover_df_rms_hz": num(r.handover_df_rms_hz),
        "prr_std_mps": num(r.prr_std_mps),
    })
}

/// A JSON number, or null when not finite.
fn json_num(v: f64) -> serde_json::Value {
    if v.is_finite() {
        json!(v)
    } else {
        serde_json::Value::Null
    }
}

/// A trio (unaided, INS 1, INS 2) and its INS 2 / INS 1 std ratios.
fn trio_json(t: &Trio<'_>) -> serde_json::Value {
    let mode = |r: Option<&CaseResult>| r.map(result_json).unwrap_or(serde_json::Value::Null);
    json!({
        "unaided": mode(t.unaided),
        "ins1": mode(t.ins1),
        "ins2": mode(t.ins2),
        "disc_std_ratio_ins2_ins1": json_num(t.ratio(|r| r.disc_std_cycles)),
        "phase_std_ratio_ins2_ins1": json_num(t.ratio(|r| r.phase_std_cycles)),
        "mean_abs_phase_error_ratio_ins2_ins1": json_num(t.ratio(|r| r.disc_mean_abs_deg)),
        "growth_ratio_ins2_ins1": json_num(t.ratio(|r| r.growth_abs_deg_s)),
    })
}

/// The summary of `study.json`: setup, the 10 g turn's headline cases, Table 3 and every row.
fn summary_json(args: &DynamicsArgs, results: &[CaseResult], wall_s: f64) -> serde_json::Value {
    let h = Headline::new(results);
    let table3: Vec<serde_json::Value> = table3_rows(results)
        .iter()
        .map(|r| {
            let (lo, hi) = r.sat_ratio_range();
            json!({
                "cn0_dbhz": r.cn0_dbhz,
                "order": r.order,
                "ins1_bias_mps2": r.ins1_bias_mps2,
                "satellites": r.ins1.satellites,
                "kept_ins1": r.ins1.kept,
                "kept_ins2": r.ins2.kept,
                "disc_std_ins1_cycles": json_num(r.ins1.disc_std_cycles),
                "disc_std_ins2_cycles": json_num(r.ins2.disc_std_cycles),
                "disc_std_ratio_ins2_ins1": json_num(r.disc_ratio()),
                "phase_std_ratio_ins2_ins1": json_num(r.phase_ratio()),
                "sat_ratio_min": json_num(lo),
                "sat_ratio_max": json_num(hi),
                "largest_offset_ins1_cycles": json_num(r.offset_bound_cycles(1.0)),
                "largest_offset_ins2_cycles": json_num(r.offset_bound_cycles(2.0)),
            })
        })
        .collect();
    json!({
        "study": "dynamics",
        "quick": args.common.quick,
        "seed": args.common.seed,
        "cases": results.len(),
        "wall_s": wall_s,
        "setup": {
            "fs_hz": FS_HZ,
            "start_tow_s": START_TOW_S,
            "speed_mps": SPEED_MPS,
            "ramp_s": RAMP_S,
            "turn_s": TURN_S,
            "step_s": STEP_S,
            "tail_s": TAIL_S,
            "oscillator": {
                "name": OSCILLATOR.name,
                "allan_deviation_1s": OSCILLATOR.allan_deviation_1s,
                "random_walk_fm_h_m2": OSCILLATOR.h_m2,
            },
            "clock_drift_s_s": CLOCK_DRIFT_S_S,
            "narrow_ins1_bias_mg": NARROW_INS1_BIAS_MG,
            "narrow_default_ins1_bias_mg": NARROW_DEFAULT_BIAS_MG,
            "wide_ins1_bias_mps2": WIDE_INS1_BIAS_MPS2,
            "bias_direction_enu": bias_direction_enu(),
            "ins_rate_hz": INS_RATE_HZ,
            "tick_s": TICK_S,
        },
        "ten_g": {
            "manoeuvre": TEN_G.label(),
            "cn0_dbhz": h.cn0_dbhz,
            "bn_hz": HEADLINE_BN_HZ,
            "ins1_bias_mps2": NARROW_DEFAULT_BIAS_MG * MG_MPS2,
            "satellites": h.order2.unaided.map(|r| r.satellites),
            "lead_in_s": h.order2.unaided.map(|r| r.spec.lead_in_s),
            "order2": trio_json(&h.order2),
            "order3": trio_json(&h.order3),
            "order1": {
                "bn_hz": ORDER1_BN_HZ,
                "cases": trio_json(&h.order1),
            },
        },
        "table3": table3,
        "rows": results.iter().map(result_json).collect::<Vec<_>>(),
    })
}

/// The cases not run, grouped by loop and reason (one line each).
fn not_run_md(not_run: &[NotRun]) -> String {
    let mut lines: Vec<String> = not_run
        .iter()
        .map(|n| {
            format!(
                "order {} Bn {} Hz {}: {}",
                n.case.order,
                n.case.bn_hz,
                n.case.aiding.label(),
                n.why
            )
        })
        .collect();
    lines.sort();
    lines.dedup();
    if lines.is_empty() {
        return String::new();
    }
    format!(
        "**Not run** ({} cases over {} scenario(s): the receiver rejects these loops when it \
configures a channel, so `gpsrx run` could not use them either): {}.",
        not_run.len(),
        {
            let mut s: Vec<String> = not_run
                .iter()
                .map(|n| {
                    format!(
                        "{} {} {}",
                        n.spec.manoeuvre.label(),
                        n.spec.cn0_dbhz,
                        n.spec.lead_in_s
                    )
                })
                .collect();
            s.sort();
            s.dedup();
            s.len()
        },
        lines.join("; ")
    )
}

pub(super) fn build_report(
    args: &DynamicsArgs,
    results: &[CaseResult],
    not_run: &[NotRun],
    wall_s: f64,
) -> StudyReport {
    let figs = fig12_15(results);
    let figs_md = if figs.rows.is_empty() {
        String::new()
    } else {
        format!(
            "**Seed 004 Figs. 12/15: satellites through the 10 g turn at Bn = {HEADLINE_BN_HZ} \
Hz** (INS 1 {NARROW_DEFAULT_BIAS_MG} mg, INS 2 twice; plots `tracked_10g_*.png`).\n\n{}",
            figs.to_markdown()
        )
    };
    StudyReport {
        title: "High dynamics: unaided vs INS-aided carrier tracking (seed 004)".into(),
        intro_md: intro_md(args),
        table: table(results),
        conclusions_md: [
            figs_md,
            conclusions_md(results),
            grid_md(results),
            not_run_md(not_run),
            format!("Wall time of this run: {wall_s:.0} s."),
        ]
        .iter()
        .map(|p| p.trim())
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("\n\n"),
        summary: {
            let mut j = summary_json(args, results, wall_s);
            j["not_run"] = not_run
                .iter()
                .map(|n| {
                    json!({
                        "manoeuvre": n.spec.manoeuvre.label(),
                        "cn0_dbhz": n.spec.cn0_dbhz,
                        "order": n.case.order,
                        "bn_hz": n.case.bn_hz,
                        "aiding": n.case.aiding.key(),
                        "why": n.why,
                    })
                })
                .collect();
            j
        },
        plots: plots(results),
    }
}
