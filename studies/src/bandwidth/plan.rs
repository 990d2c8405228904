//! The plan: which recordings to simulate and the cells tracked over each.

use super::{Cell, MAX_SETTLE_S};

/// A group of cells tracked over one recording.
#[derive(Debug, Clone)]
pub(super) struct Case {
    pub(super) cn0_dbhz: f64,
    pub(super) duration_s: f64,
    /// The cells and their settling times.
    pub(super) cells: Vec<(Cell, f64)>,
    pub(super) seed: u64,
}

/// Measurement window of a cell, s: `window_s`, stretched to `window_s / Bn` (Bn in Hz) for
/// loops narrower than 1 Hz, whose errors are correlated for longer (a std estimated from a
/// window D has a relative error of about `1/sqrt(8 Bn D)` per satellite).
pub fn cell_window_s(cell: &Cell, window_s: f64) -> f64 {
    window_s * (1.0 / cell.bn_hz).max(1.0)
}

/// Recording length a cell needs, s: 2 s for the start and hand-over, its settling time (at
/// most [`MAX_SETTLE_S`]) and its measurement window.
fn needed_duration_s(settle_s: f64, window_s: f64) -> f64 {
    2.0 + settle_s.min(MAX_SETTLE_S) + window_s
}

/// Groups the cells that can run into recordings: per C/N0, the cells whose needed duration
/// rounds up to the same multiple of 8 s share one recording (both T and both orders: the same
/// samples, common random numbers). Noise is independent across C/N0 and recording lengths.
pub(super) fn cases(cells: &[(Cell, f64)], seed: u64, window_s: f64) -> Vec<Case> {
    let mut out: Vec<Case> = Vec::new();
    for &(c, settle) in cells {
        let need = needed_duration_s(settle, cell_window_s(&c, window_s));
        let duration_s = (need / 8.0).ceil() * 8.0;
        match out
            .iter_mut()
            .find(|k| k.cn0_dbhz == c.cn0_dbhz && k.duration_s == duration_s)
        {
            Some(k) => k.cells.push((c, settle.min(MAX_SETTLE_S))),
            None => out.push(Case {
                cn0_dbhz: c.cn0_dbhz,
                duration_s,
                cells: vec![(c, settle.min(MAX_SETTLE_S))],
                seed: seed
                    .wrapping_mul(1_000_003)
                    .wrapping_add((c.cn0_dbhz * 10.0).round() as u64)
                    .wrapping_add((duration_s as u64) << 20),
            }),
        }
    }
    // Longest recordings first, so that the parallel cases finish together.
    out.sort_by(|a, b| {
        (b.duration_s * b.cells.len() as f64).total_cmp(&(a.duration_s * a.cells.len() as f64))
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bandwidth::{cell_status, full_grid, quick_grid, CellStatus};

    #[test]
    fn grids_and_rejections() {
        let g = full_grid();
        assert_eq!(g.len(), 6 * 2 * 7 * 2);
        let rejected: Vec<&Cell> = g
            .iter()
            .filter(|c| cell_status(c) != CellStatus::Run)
            .collect();
        // T = 20 ms with Bn 15 and 25 Hz (Bn T 0.3, 0.5), both orders, every C/N0.
        assert_eq!(rejected.len(), 6 * 2 * 2);
        assert!(rejected.iter().all(|c| c.t_ms == 20 && c.bn_hz >= 15.0));
        // Order 2 at Bn T = 0.5 is unstable, order 3 at 0.3 is stable (tracking/README.md).
        let st = |order, bn| {
            cell_status(&Cell {
                cn0_dbhz: 40.0,
                order,
                bn_hz: bn,
                t_ms: 20,
            })
        };
        assert!(matches!(
            st(2, 25.0),
            CellStatus::Rejected { stable: false, .. }
        ));
        assert!(matches!(
            st(3, 15.0),
            CellStatus::Rejected { stable: true, .. }
        ));
        // The quick grid: one recording per C/N0 (1 and 20 ms cells share it).
        let quick: Vec<(Cell, f64)> = quick_grid().iter().map(|c| (*c, 5.0)).collect();
        assert_eq!(cases(&quick, 1, 8.0).len(), 2);
    }
}
