//! Per-cell statistics of the trials.

use super::grid::{Cell, Trial};
use super::params::USABLE_PDOP;
use crate::report::median;

/// Statistics of one cell.
#[derive(Debug, Clone, Copy)]
pub struct CellStats {
    /// The cell.
    pub cell: Cell,
    /// Trials.
    pub trials: usize,
    /// Fraction of geometries whose Jacobian at the truth has rank 4.
    pub rank4: f64,
    /// Fraction with PDOP at the truth at most [`USABLE_PDOP`] (the geometry allows a fix).
    pub allows: f64,
    /// Fraction where the solver returned a fix with PDOP at most [`USABLE_PDOP`].
    pub available: f64,
    /// Median PDOP over the rank-4 geometries (NaN if none).
    pub median_pdop: f64,
    /// Median HDOP over the rank-4 geometries (NaN if none).
    pub median_hdop: f64,
    /// RMS 3D error of the fixes, m (NaN if none).
    pub rms_error_m: f64,
}

/// Statistics of `trials` of `cell`.
pub fn stats(cell: Cell, trials: &[Trial]) -> CellStats {
    let n = trials.len().max(1) as f64;
    let dops: Vec<_> = trials.iter().filter_map(|t| t.dop).collect();
    let errors: Vec<f64> = trials.iter().filter_map(|t| t.fix_error_m).collect();
    let rms = if errors.is_empty() {
        f64::NAN
    } else {
        (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt()
    };
    CellStats {
        cell,
        trials: trials.len(),
        rank4: dops.len() as f64 / n,
        allows: dops.iter().filter(|d| d.pdop <= USABLE_PDOP).count() as f64 / n,
        available: errors.len() as f64 / n,
        median_pdop: median(&dops.iter().map(|d| d.pdop).collect::<Vec<_>>()),
        median_hdop: median(&dops.iter().map(|d| d.hdop).collect::<Vec<_>>()),
        rms_error_m: rms,
    }
}

/// The statistics of (`n_sat`, `n_lm`), if in the grid.
pub fn find(all: &[CellStats], n_sat: usize, n_lm: usize) -> Option<&CellStats> {
    all.iter()
        .find(|s| s.cell.n_sat == n_sat && s.cell.n_lm == n_lm)
}
