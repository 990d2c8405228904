//! One row of the study: a cell with its theory and measurement.

use super::{
    Cell, CellMeasured, CellStatus, CellTheory, BNT_LIMIT, THRESHOLD_SIGMA_DEG, TOLERANCE,
};

/// One row of the study.
#[derive(Debug, Clone)]
pub struct CellResult {
    /// The cell.
    pub cell: Cell,
    /// Whether it ran.
    pub status: CellStatus,
    /// Theory.
    pub theory: CellTheory,
    /// Measurement (default when not run).
    pub measured: CellMeasured,
    /// Length of the recording it ran on, s (NaN when not run).
    pub duration_s: f64,
}

impl CellResult {
    /// All channels held lock.
    pub fn locked(&self) -> bool {
        self.status == CellStatus::Run
            && self.measured.channels > 0
            && self.measured.locked == self.measured.channels
    }

    /// Measured / formula phase jitter.
    pub fn ratio(&self) -> f64 {
        self.measured.phase_deg / self.theory.phase_formula_deg
    }

    /// Above the tracking threshold by the rule of thumb (`3 sigma_formula <= 45` deg).
    pub fn above_threshold(&self) -> bool {
        self.theory.phase_formula_deg <= THRESHOLD_SIGMA_DEG
    }

    /// In the region where the formula should hold: above threshold and `Bn T <= 0.1`.
    pub fn in_formula_region(&self) -> bool {
        self.status == CellStatus::Run
            && self.above_threshold()
            && self.cell.bn_t() <= BNT_LIMIT + 1e-12
    }

    /// Within [`TOLERANCE`] of the formula (None when not locked).
    pub fn within_tolerance(&self) -> Option<bool> {
        self.locked()
            .then(|| (self.ratio() - 1.0).abs() <= TOLERANCE)
    }
}
