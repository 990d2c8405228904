//! The per-cell table (`study.md`, `study.csv` and `threshold.csv`).

use super::result::{Agreement, CellResult};
use crate::report::{fmt, Table};

/// The columns: the issue's `order`, `bn_hz`, `t_coh_ms`, `dynamics`, `measured_dbhz`,
/// `theory_dbhz` (the rule of thumb), then the comparison and the other theories.
pub const COLUMNS: [&str; 24] = [
    "order",
    "bn_hz",
    "t_coh_ms",
    "dynamics",
    "aided",
    "stress_deg",
    "measured_dbhz",
    "theory_dbhz",
    "delta_db",
    "within_3db",
    "theory_atan_dbhz",
    "atan_delta_db",
    "within_3db_atan",
    "detector_dbhz",
    "theory_slope_dbhz",
    "stable_dbhz",
    "expected_dbhz",
    "within_3db_expected",
    "bn_real_hz",
    "theory_real_dbhz",
    "below_threshold",
    "loop_dbhz",
    "loop_delta_db",
    "loop_within_3db",
];

/// A threshold or `none` (no C/N0 up to the scan's top, or no root of the rule).
fn level(v: Option<f64>) -> String {
    v.map_or_else(|| "none".to_string(), |x| fmt(x, 1))
}

fn agreement(a: Option<Agreement>) -> (String, String) {
    match a {
        None => ("-".into(), "-".into()),
        Some(Agreement::Delta(d)) => (fmt(d, 1), yes_no(a)),
        Some(_) => ("-".into(), yes_no(a)),
    }
}

fn yes_no(a: Option<Agreement>) -> String {
    match a {
        Some(a) if a.agrees() => "yes".into(),
        Some(_) => "no".into(),
        None => "-".into(),
    }
}

/// What the first failing run of the scan saw: `C/N0: held %, slips`; `rejected: ...` for a
/// refused loop.
fn below(r: &CellResult) -> String {
    if let Some(why) = &r.rejected {
        return format!("not run: {why}");
    }
    match r.measured.and_then(|m| m.first_failure) {
        Some((cn0, out)) => format!(
            "{}: {:.0} % held; {} half-cycle slips",
            fmt(cn0, 1),
            100.0 * out.held_fraction,
            out.half_cycle_slips
        ),
        None => "held to the scan's bottom".into(),
    }
}

/// The table of `results`.
pub fn build_table(results: &[CellResult]) -> Table {
    let mut t = Table::new(&COLUMNS);
    for r in results {
        let c = &r.cell;
        let (delta, within) = agreement(r.vs_rule());
        let (_, within_exp) = agreement(r.vs_expected());
        let (atan_delta, atan_within) = agreement(r.vs_atan_rule());
        let (loop_delta, loop_within) = agreement(r.loop_vs_rule());
        let run = r.rejected.is_none();
        t.push(vec![
            c.order.to_string(),
            fmt(c.bn_hz, 1),
            c.t_coh_ms.to_string(),
            c.dynamics.name(),
            c.dynamics.aided().to_string(),
            fmt(r.theory.stress_deg, 1),
            if run {
                level(r.measured_dbhz())
            } else {
                "-".into()
            },
            level(r.theory.rule_dbhz),
            delta,
            within,
            level(r.theory.rule_atan_dbhz),
            atan_delta,
            atan_within,
            level(r.theory.detector_dbhz),
            level(r.theory.rule_slope_dbhz),
            r.theory
                .stable_dbhz
                .map_or_else(|| "-".to_string(), |x| fmt(x, 1)),
            level(r.theory.expected_dbhz()),
            within_exp,
            fmt(r.theory.realised_bn_hz, 2),
            level(r.theory.rule_realised_dbhz),
            below(r),
            if run {
                level(r.loop_dbhz())
            } else {
                "-".into()
            },
            loop_delta,
            loop_within,
        ]);
    }
    t
}
