//! The study table and `study.json`.

use super::summary::CellStats;
use crate::report::{fmt, Table};

/// One row per cell.
pub fn table(all: &[CellStats]) -> Table {
    let mut t = Table::new(&[
        "satellites",
        "landmarks",
        "geometries",
        "rank 4 (%)",
        "PDOP <= 10 at truth (%)",
        "fix available (%)",
        "median PDOP",
        "median HDOP",
        "fix 3D RMS (m)",
    ]);
    for s in all {
        t.push(vec![
            s.cell.n_sat.to_string(),
            s.cell.n_lm.to_string(),
            s.trials.to_string(),
            fmt(100.0 * s.rank4, 1),
            fmt(100.0 * s.allows, 1),
            fmt(100.0 * s.available, 1),
            fmt(s.median_pdop, 2),
            fmt(s.median_hdop, 2),
            fmt(s.rms_error_m, 2),
        ]);
    }
    t
}

fn num(v: f64) -> serde_json::Value {
    if v.is_finite() {
        serde_json::json!(v)
    } else {
        serde_json::Value::Null
    }
}

/// `study.json`: every cell's numbers.
pub fn summary_json(all: &[CellStats], seed: u64) -> serde_json::Value {
    serde_json::json!({
        "seed": seed,
        "cells": all.iter().map(|s| serde_json::json!({
            "satellites": s.cell.n_sat,
            "landmarks": s.cell.n_lm,
            "geometries": s.trials,
            "rank4_fraction": num(s.rank4),
            "allows_fraction": num(s.allows),
            "available_fraction": num(s.available),
            "median_pdop": num(s.median_pdop),
            "median_hdop": num(s.median_hdop),
            "rms_error_m": num(s.rms_error_m),
        })).collect::<Vec<_>>(),
    })
}
