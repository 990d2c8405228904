//! The grid of cells: C/N0, PLL order, noise bandwidth and integration time.

use super::formulas::lin;

/// One grid cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
    /// PLL order (2 or 3).
    pub order: u8,
    /// PLL noise bandwidth, Hz.
    pub bn_hz: f64,
    /// Integration time, ms.
    pub t_ms: u32,
}

impl Cell {
    /// Integration time, s.
    pub fn t_s(&self) -> f64 {
        f64::from(self.t_ms) * 1e-3
    }

    /// `Bn T`.
    pub fn bn_t(&self) -> f64 {
        self.bn_hz * self.t_s()
    }
}

/// The full grid: C/N0 {25, ..., 50} x order {2, 3} x Bn {0.5, 1, 2, 4, 10, 15, 25} Hz x
/// T {1, 20} ms.
pub fn full_grid() -> Vec<Cell> {
    let mut v = Vec::new();
    for cn0 in [25.0, 30.0, 35.0, 40.0, 45.0, 50.0] {
        for t_ms in [1, 20] {
            for order in [2, 3] {
                for bn in [0.5, 1.0, 2.0, 4.0, 10.0, 15.0, 25.0] {
                    v.push(Cell {
                        cn0_dbhz: cn0,
                        order,
                        bn_hz: bn,
                        t_ms,
                    });
                }
            }
        }
    }
    v
}

/// The `--quick` grid: C/N0 {35, 45} x order 2 x Bn {1, 4, 10} Hz x T 1 ms, and
/// 35 dB-Hz, order 2, Bn 2 Hz, T 20 ms.
pub fn quick_grid() -> Vec<Cell> {
    let mut v = Vec::new();
    for cn0 in [35.0, 45.0] {
        for bn in [1.0, 4.0, 10.0] {
            v.push(Cell {
                cn0_dbhz: cn0,
                order: 2,
                bn_hz: bn,
                t_ms: 1,
            });
        }
    }
    v.push(Cell {
        cn0_dbhz: 35.0,
        order: 2,
        bn_hz: 2.0,
        t_ms: 20,
    });
    v
}

/// `C/N0 T` (linear) of a cell: the prompt SNR the discriminators work at.
pub(super) fn cn0_t(cell: &Cell) -> f64 {
    lin(cell.cn0_dbhz) * cell.t_s()
}

/// Prompt SNR (`C/N0 T`) from which the atan discriminator is close to linear (slope
/// `1 - exp(-3)` = 0.95) and the formulas are expected to hold.
pub const HIGH_SNR_CN0_T: f64 = 3.0;
