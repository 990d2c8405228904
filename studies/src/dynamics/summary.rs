//! The study report: `study.json`'s summary and rows, and the assembled [`StudyReport`].

use super::aiding::bias_direction_enu;
use super::conclusions::conclusions_md;
use super::grid_md::grid_md;
use super::headline::Headline;
use super::intro::intro_md;
use super::manoeuvre::Manoeuvre;
use super::params::{
    ALLAN_DEVIATION_1S, DURATION_S, FS_HZ, HEADLINE_BN_HZ, INS1_BIAS_MPS2, INS_RATE_HZ, LEAD_IN_S,
    ORDER1_BN_HZ, RAMP_S, SPEED_MPS, START_TOW_S, STEP_S, TICK_S, TURN_S,
};
use super::plots::plots;
use super::result::CaseResult;
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
        "order": r.case.order,
        "bn_hz": r.case.bn_hz,
        "aiding": r.case.aiding.key(),
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

pub(super) fn build_report(
    args: &DynamicsArgs,
    results: &[CaseResult],
    wall_s: f64,
) -> StudyReport {
    let h = Headline::new(results);
    let mode_json = |r: Option<&CaseResult>| r.map(result_json).unwrap_or(serde_json::Value::Null);
    let summary = json!({
        "study": "dynamics",
        "quick": args.common.quick,
        "seed": args.common.seed,
        "cases": results.len(),
        "wall_s": wall_s,
        "setup": {
            "fs_hz": FS_HZ,
            "start_tow_s": START_TOW_S,
            "speed_mps": SPEED_MPS,
            "lead_in_s": LEAD_IN_S,
            "ramp_s": RAMP_S,
            "turn_s": TURN_S,
            "step_s": STEP_S,
            "duration_s": DURATION_S,
            "allan_deviation_1s": ALLAN_DEVIATION_1S,
            "ins1_bias_mps2": INS1_BIAS_MPS2,
            "ins2_bias_mps2": 2.0 * INS1_BIAS_MPS2,
            "bias_direction_enu": bias_direction_enu(),
            "ins_rate_hz": INS_RATE_HZ,
            "tick_s": TICK_S,
        },
        "ten_g": {
            "manoeuvre": Manoeuvre::Turn(10.0).label(),
            "cn0_dbhz": h.unaided.map(|r| r.spec.cn0_dbhz),
            "order": 2,
            "bn_hz": HEADLINE_BN_HZ,
            "satellites": h.unaided.map(|r| r.satellites),
            "unaided": mode_json(h.unaided),
            "ins1": mode_json(h.ins1),
            "ins2": mode_json(h.ins2),
            "phase_std_ratio_ins2_ins1": json_num(h.std_ratio()),
            "order1": {
                "bn_hz": ORDER1_BN_HZ,
                "ins1": mode_json(h.order1_ins1),
                "ins2": mode_json(h.order1_ins2),
                "mean_abs_phase_error_ratio_ins2_ins1": json_num(h.order1_mean_ratio()),
                "growth_ratio_ins2_ins1": json_num(h.order1_growth_ratio()),
            },
        },
        "rows": results.iter().map(result_json).collect::<Vec<_>>(),
    });
    StudyReport {
        title: "High dynamics: unaided vs INS-aided carrier tracking (seed 004)".into(),
        intro_md: intro_md(args),
        table: table(results),
        conclusions_md: [
            conclusions_md(&h),
            grid_md(results),
            format!("Wall time of this run: {wall_s:.0} s."),
        ]
        .iter()
        .map(|p| p.trim())
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("\n\n"),
        summary,
        plots: plots(results),
    }
}
