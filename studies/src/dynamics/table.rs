//! The study table: one row per case.

use super::params::MG_MPS2;
use super::result::CaseResult;
use crate::report::{fmt, Table};

pub(super) fn table(results: &[CaseResult]) -> Table {
    let mut t = Table::new(&[
        "manoeuvre",
        "C/N0 (dB-Hz)",
        "lead-in (s)",
        "order",
        "Bn (Hz)",
        "aiding",
        "bias (mg)",
        "sats at start",
        "tracked min",
        "tracked mean",
        "kept",
        "lock drops",
        "lost",
        "phase std (cycle)",
        "disc. std (cycle)",
        "mean abs phase err (deg)",
        "predicted (deg)",
        "growth (deg/s)",
        "predicted growth (deg/s)",
        "PRR std (m/s)",
        "hand-over df rms (Hz)",
    ]);
    for r in results {
        t.push(vec![
            r.spec.manoeuvre.label(),
            fmt(r.spec.cn0_dbhz, 0),
            fmt(r.spec.lead_in_s, 0),
            r.case.order.to_string(),
            r.case.bn_hz.to_string(),
            r.case.aiding.label().to_string(),
            fmt(r.case.bias_mps2() / MG_MPS2, 1),
            format!("{}/{}", r.tracked_at_start, r.satellites),
            r.tracked_min.to_string(),
            fmt(r.tracked_mean, 1),
            r.kept.to_string(),
            r.lock_drops.to_string(),
            r.channels_lost.to_string(),
            fmt(r.phase_std_cycles, 4),
            fmt(r.disc_std_cycles, 4),
            fmt(r.disc_mean_abs_deg, 2),
            fmt(r.predicted_mean_abs_deg, 2),
            fmt(r.growth_abs_deg_s, 3),
            fmt(r.predicted_growth_deg_s, 3),
            fmt(r.prr_std_mps, 3),
            fmt(r.handover_df_rms_hz, 2),
        ]);
    }
    t
}
