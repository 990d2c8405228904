//! Number and cell formatting for the table and the report text.

use gpsrx_tracking::phase_sim::LAMBDA_M;
use std::fmt::Write as _;

use super::{Aiding, CellResult, ClosedForm, Input};
use crate::report::fmt;

/// A parameter value: at most 3 decimals, trailing zeros dropped (`10`, `0.05`, `20`).
pub(super) fn short(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    s.to_string()
}

/// Four significant digits, or scientific notation for small values; "0" for exact zero.
pub(super) fn sig(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if v.abs() >= 1e-4 && v.abs() < 1e4 {
        let d = (3 - v.abs().log10().floor() as i32).max(0) as usize;
        fmt(v, d)
    } else {
        format!("{v:.3e}")
    }
}

pub(super) fn magnitude_text(r: &CellResult) -> String {
    let i = r.cell.input;
    let mut s = format!("{} {}", sig(r.magnitude), i.unit());
    if i != Input::Step {
        let los = ["", "m/s", "m/s^2", "m/s^3"][i.degree() as usize];
        let _ = write!(s, " ({} {los} LOS)", sig(r.magnitude * LAMBDA_M));
    }
    if r.cell.aiding == Aiding::BiasedIns {
        let _ = write!(s, "; B_V {} m/s^2", short(r.cell.aid.b_v_mps2));
    }
    s
}

pub(super) fn closed_text(c: ClosedForm) -> String {
    match c {
        ClosedForm::Bounded(v) => sig(v),
        ClosedForm::Growing { rate, .. } => format!("unbounded, {} {}", sig(rate), c.unit()),
    }
}

pub(super) fn measured_text(r: &CellResult) -> String {
    match r.closed {
        ClosedForm::Bounded(_) => sig(r.measured),
        c => format!("{} {}", sig(r.measured), c.unit()),
    }
}
