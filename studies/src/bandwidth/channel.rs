//! The channel configuration of a cell and whether it can run.

use super::{Cell, DLL_BN_HZ, EL_SPACING_CHIPS};
use gpsrx_tracking::{loop_analysis, ChannelConfig, LoopConfig, LoopFilter};

/// The channel configuration of a cell: PLL of `order` and `bn_hz` without FLL, 1st-order
/// carrier-aided DLL at [`DLL_BN_HZ`], d = [`EL_SPACING_CHIPS`], integration `t_s`. The pull-in
/// loop is a PLL of the same Bn at T = 1 ms, of order `min(order, 2)`: the channel starts from
/// truth, so no wide or FLL-assisted pull-in is needed, but a 3rd-order loop pulling in from
/// the random initial carrier phase overshoots (damping ratio 0.22) past the Costas +-90 deg
/// and can be thrown into a slipping limit cycle (G16 at 35 dB-Hz, Bn 0.5 Hz: its phase swung by
/// tens of cycles over 140 s), and at low prompt SNR it is not even linearly stable (atan slope
/// below 0.38). A channel is released only below 20 dB-Hz (the default 25 dB-Hz would release
/// the 25 dB-Hz channels on estimator scatter).
pub fn cell_channel_config(order: u8, bn_hz: f64, t_s: f64) -> ChannelConfig {
    let track = LoopConfig {
        pll_order: order,
        pll_bw_hz: bn_hz,
        fll_order: 0,
        fll_bw_hz: 0.0,
        dll_order: 1,
        dll_bw_hz: DLL_BN_HZ,
        t_coh_s: t_s,
        el_spacing_chips: EL_SPACING_CHIPS,
        ..LoopConfig::default()
    };
    ChannelConfig {
        pull_in: LoopConfig {
            pll_order: order.min(2),
            t_coh_s: 1e-3,
            ..track
        },
        track,
        min_pull_in_s: 0.5,
        fll_assist_s: 0.0,
        cn0_lost_dbhz: 20.0,
        weak_track: None,
        weak_pull_in: None,
        ..ChannelConfig::default()
    }
}

/// Whether a cell can run, and if not why.
#[derive(Debug, Clone, PartialEq)]
pub enum CellStatus {
    /// Valid configuration.
    Run,
    /// `LoopConfig::validate` rejects it; `stable` says whether the digital loop would be.
    Rejected {
        /// The validation message.
        reason: String,
        /// Whether the digital closed loop would be stable.
        stable: bool,
    },
}

/// Checks a cell's configuration.
pub fn cell_status(cell: &Cell) -> CellStatus {
    let cfg = cell_channel_config(cell.order, cell.bn_hz, cell.t_s());
    match cfg.validate() {
        Ok(()) => CellStatus::Run,
        Err(e) => CellStatus::Rejected {
            reason: e.to_string(),
            stable: LoopFilter::pll(cell.order, cell.bn_hz)
                .map(|f| loop_analysis::is_stable(&f, cell.t_s()))
                .unwrap_or(false),
        },
    }
}
