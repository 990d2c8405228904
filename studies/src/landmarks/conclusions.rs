//! Conclusions computed from the cell statistics (no fixed text: every claim is a comparison
//! of numbers in the table).

use super::params::{LANDMARKS, SATELLITES};
use super::summary::{find, CellStats};
use crate::report::fmt;
use std::fmt::Write;

fn pct(v: f64) -> String {
    format!("{} %", fmt(100.0 * v, 1))
}

/// The conclusions section.
pub fn conclusions_md(all: &[CellStats]) -> String {
    let mut md = String::from("## Conclusions (computed from the table)\n\n");
    let n3: Vec<Option<&CellStats>> = LANDMARKS.map(|l| find(all, 3, l)).collect();
    if let [Some(a), Some(b), Some(c)] = n3[..] {
        let verb = if b.available > a.available {
            "raises"
        } else {
            "does not raise"
        };
        let _ = writeln!(
            md,
            "- With 3 satellites: fix available in {} of the geometries without a landmark, {} \
             with one and {} with two; one street-level landmark {verb} the availability.",
            pct(a.available),
            pct(b.available),
            pct(c.available)
        );
    }
    for n_sat in [4, 6] {
        let cells: Vec<Option<&CellStats>> = LANDMARKS.map(|l| find(all, n_sat, l)).collect();
        if let [Some(a), Some(b), Some(c)] = cells[..] {
            let falls = b.median_hdop < a.median_hdop && c.median_hdop < b.median_hdop;
            let _ = writeln!(
                md,
                "- With {n_sat} satellites the median HDOP is {} / {} / {} with 0 / 1 / 2 \
                 landmarks ({}), the median PDOP {} / {} / {}.",
                fmt(a.median_hdop, 2),
                fmt(b.median_hdop, 2),
                fmt(c.median_hdop, 2),
                if falls {
                    "falls with every landmark"
                } else {
                    "does not fall with every landmark"
                },
                fmt(a.median_pdop, 2),
                fmt(b.median_pdop, 2),
                fmt(c.median_pdop, 2)
            );
        }
    }
    for n_lm in LANDMARKS {
        let first = SATELLITES
            .clone()
            .find(|&n| find(all, n, n_lm).is_some_and(|s| s.available >= 0.95));
        let _ = writeln!(
            md,
            "- {n_lm} landmark(s): {}.",
            match first {
                Some(n) => format!("at least 95 % availability from {n} satellites"),
                None => "95 % availability is not reached in the grid".into(),
            }
        );
    }
    md
}
