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
            // Relative fall from 0 to 2 landmarks: which DOP the landmarks help more.
            let h_fall = 1.0 - c.median_hdop / a.median_hdop;
            let p_fall = 1.0 - c.median_pdop / a.median_pdop;
            let more = if h_fall > p_fall {
                "the horizontal more than the whole position"
            } else {
                "the horizontal no more than the whole position"
            };
            let _ = writeln!(
                md,
                "- With {n_sat} satellites the median HDOP is {} / {} / {} with 0 / 1 / 2 \
                 landmarks ({}), the median PDOP {} / {} / {}: two landmarks lower the HDOP by \
                 {} and the PDOP by {}, so they help {more}.",
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
                fmt(c.median_pdop, 2),
                pct(h_fall),
                pct(p_fall)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::landmarks::grid::Cell;

    /// Every cell of the grid: availability `avail(n_sat, n_lm)`, HDOP `3 / (1 + n_lm)` times
    /// `4 / n_sat`, PDOP twice that.
    fn grid(avail: impl Fn(usize, usize) -> f64) -> Vec<CellStats> {
        let mut v = Vec::new();
        for n_sat in SATELLITES {
            for n_lm in LANDMARKS {
                let hdop = 3.0 / (1.0 + n_lm as f64) * 4.0 / n_sat as f64;
                v.push(CellStats {
                    cell: Cell { n_sat, n_lm },
                    trials: 100,
                    rank4: 1.0,
                    allows: 1.0,
                    available: avail(n_sat, n_lm),
                    median_pdop: 2.0 * hdop,
                    median_hdop: hdop,
                    rms_error_m: 3.0,
                });
            }
        }
        v
    }

    fn base(n_sat: usize, n_lm: usize) -> f64 {
        match (n_sat, n_lm) {
            (3, 0) => 0.0,
            (3, 1) => 0.72,
            (3, _) => 0.925,
            (4, 0) => 0.75,
            _ => 1.0,
        }
    }

    #[test]
    fn the_conclusions_follow_the_cells() {
        let mut all = grid(base);
        let md = conclusions_md(&all);
        assert!(
            md.contains("0.0 % of the geometries without a landmark, 72.0 %"),
            "{md}"
        );
        assert!(
            md.contains("one street-level landmark raises the availability"),
            "{md}"
        );
        assert!(md.contains("(falls with every landmark)"), "{md}");
        // HDOP 3 -> 1 (66.7 %), PDOP 6 -> 2 (66.7 %) with 4 satellites: not more.
        assert!(
            md.contains("lower the HDOP by 66.7 % and the PDOP by 66.7 %"),
            "{md}"
        );
        assert!(md.contains("help the horizontal no more than"), "{md}");
        let mut lifted = all.clone();
        for c in lifted.iter_mut().filter(|c| c.cell.n_lm == 2) {
            c.median_pdop *= 2.0;
        }
        let md2 = conclusions_md(&lifted);
        assert!(
            md2.contains("help the horizontal more than the whole position"),
            "{md2}"
        );
        assert!(
            md.contains("- 0 landmark(s): at least 95 % availability from 5 satellites"),
            "{md}"
        );
        assert!(
            md.contains("- 2 landmark(s): at least 95 % availability from 4 satellites"),
            "{md}"
        );
        // One landmark no longer helps with 3 satellites; the second landmark no longer lowers
        // the HDOP with 4; nothing reaches 95 % without a landmark.
        all = grid(|s, l| match (s, l) {
            (3, 1) => 0.0,
            (_, 0) => 0.5,
            _ => base(s, l),
        });
        for c in all
            .iter_mut()
            .filter(|c| c.cell.n_sat == 4 && c.cell.n_lm == 2)
        {
            c.median_hdop = 5.0;
        }
        let md = conclusions_md(&all);
        assert!(
            md.contains("one street-level landmark does not raise"),
            "{md}"
        );
        assert!(md.contains("(does not fall with every landmark)"), "{md}");
        assert!(
            md.contains("- 0 landmark(s): 95 % availability is not reached in the grid"),
            "{md}"
        );
        // A cell missing from the grid: its sentence is left out, not guessed.
        all.retain(|c| !(c.cell.n_sat == 3 && c.cell.n_lm == 1));
        assert!(!conclusions_md(&all).contains("With 3 satellites"));
    }
}
