//! The cells of the study: PLL order, noise bandwidth, integration time and dynamics.

use super::Dynamics;
use gpsrx_tracking::LoopConfig;

/// Noise bandwidths of the full grid, Hz.
pub const BN_HZ: [f64; 5] = [0.4, 1.0, 3.0, 10.0, 18.0];
/// Integration times of the full grid, ms.
pub const T_COH_MS: [u32; 2] = [1, 20];
/// The stated dynamics of the full grid (each with the orders it is run with,
/// [`Dynamics::orders`]).
pub const DYNAMICS: [Dynamics; 5] = [
    Dynamics::Static,
    Dynamics::AccelUnaided { g: 1.0 },
    Dynamics::JerkUnaided { g_per_s: 10.0 },
    Dynamics::InsBias { mg: 1.0 },
    Dynamics::InsVelocity { mps: 0.05 },
];

/// One cell: a carrier loop and the dynamics it must follow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// PLL order, 1-3.
    pub order: u8,
    /// Noise bandwidth Bn, Hz.
    pub bn_hz: f64,
    /// Predetection integration time T, ms.
    pub t_coh_ms: u32,
    /// The residual dynamics.
    pub dynamics: Dynamics,
}

impl Cell {
    /// T in seconds.
    pub fn t_coh_s(&self) -> f64 {
        f64::from(self.t_coh_ms) * 1e-3
    }

    /// The tracking loop of the cell: a PLL of `order` and `bn_hz` without FLL, Costas
    /// discriminator, integration `t_coh_s` (the DLL fields are not used).
    pub fn loop_config(&self) -> LoopConfig {
        LoopConfig {
            pll_order: self.order,
            pll_bw_hz: self.bn_hz,
            fll_order: 0,
            fll_bw_hz: 0.0,
            t_coh_s: self.t_coh_s(),
            ..LoopConfig::default()
        }
    }

    /// Why the receiver refuses this loop (`LoopConfig::validate`), if it does.
    pub fn rejected(&self) -> Option<String> {
        self.loop_config().validate().err().map(|e| e.to_string())
    }

    /// A number that identifies the cell (the same in the quick and the full grid), for the
    /// noise seeds.
    pub fn key(&self) -> u64 {
        let dyn_index = DYNAMICS
            .iter()
            .position(|d| d == &self.dynamics)
            .unwrap_or(DYNAMICS.len()) as u64;
        (u64::from(self.order) << 40)
            ^ (((self.bn_hz * 10.0).round() as u64) << 24)
            ^ (u64::from(self.t_coh_ms) << 8)
            ^ dyn_index
    }
}

/// Every (order, Bn, T, dynamics) the study can set up, rejected loops included.
pub fn full_grid() -> Vec<Cell> {
    let mut cells = Vec::new();
    for dynamics in DYNAMICS {
        for &order in dynamics.orders() {
            for t_coh_ms in T_COH_MS {
                for bn_hz in BN_HZ {
                    cells.push(Cell {
                        order,
                        bn_hz,
                        t_coh_ms,
                        dynamics,
                    });
                }
            }
        }
    }
    cells
}

/// The `--quick` grid: the static loops at Bn 0.4, 3 and 18 Hz (T = 1 ms) and 0.4, 3 and
/// 10 Hz (T = 20 ms) of every order, and one cell of each other dynamic.
pub fn quick_grid() -> Vec<Cell> {
    let mut cells = Vec::new();
    for order in 1..=3 {
        for (t_coh_ms, bns) in [(1, [0.4, 3.0, 18.0]), (20, [0.4, 3.0, 10.0])] {
            for bn_hz in bns {
                cells.push(Cell {
                    order,
                    bn_hz,
                    t_coh_ms,
                    dynamics: Dynamics::Static,
                });
            }
        }
    }
    for (order, bn_hz, t_coh_ms, dynamics) in [
        (2, 18.0, 1, DYNAMICS[1]),
        (3, 18.0, 1, DYNAMICS[2]),
        (2, 1.0, 20, DYNAMICS[3]),
        (1, 3.0, 1, DYNAMICS[4]),
    ] {
        cells.push(Cell {
            order,
            bn_hz,
            t_coh_ms,
            dynamics,
        });
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_have_distinct_keys_and_the_quick_grid_is_part_of_the_full_one() {
        let full = full_grid();
        let quick = quick_grid();
        assert!(quick.len() >= 12);
        for c in &quick {
            assert!(full.contains(c), "{c:?}");
        }
        let mut keys: Vec<u64> = full.iter().map(Cell::key).collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), full.len());
        // 18 Hz at 20 ms is Bn T = 0.36: refused by the receiver.
        let c = Cell {
            order: 2,
            bn_hz: 18.0,
            t_coh_ms: 20,
            dynamics: Dynamics::Static,
        };
        assert!(c.rejected().is_some_and(|e| e.contains("pll_bw_hz")));
    }
}
