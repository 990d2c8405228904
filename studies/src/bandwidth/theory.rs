//! Theory of a cell: the formulas and the linearised digital loops, and its settling time.

use super::{
    costas_atan_stats, dll_jitter_chips, envelope_dll_stats, pll_jitter_deg, stable_with_slope,
    transient_decay_time_s, Cell, LoopNoiseGains, DLL_BN_HZ, EL_SPACING_CHIPS, LONG_INTERVAL_S,
    OBS_INTERVAL_S,
};
use gpsrx_dsp::constants::LAMBDA_L1_M;
use gpsrx_tracking::{loop_analysis, LoopFilter};

/// Theoretical values for one cell (NaN where the loop is not run).
#[derive(Debug, Clone, Copy, Default)]
pub struct CellTheory {
    /// Oracle PLL formula, deg.
    pub phase_formula_deg: f64,
    /// Linearised digital loop with the atan discriminator's statistics, deg.
    pub phase_loop_deg: f64,
    /// Realised noise bandwidth of the digital loop / design Bn.
    pub bn_realised_ratio: f64,
    /// The digital loop's NCO-phase jitter (at the interval start, formula's discriminator
    /// noise) over the formula: `sqrt(sum h_phi^2 / (2 Bn T))`.
    pub phase_digital_ratio: f64,
    /// NCO frequency error std (digital loop, formula's discriminator noise), Hz.
    pub doppler_hz: f64,
    /// Pseudorange-rate error std from the carrier phase change over 0.1 s, m/s.
    pub pr_rate_mps: f64,
    /// The same over 1 s, m/s.
    pub pr_rate_1s_mps: f64,
    /// Oracle DLL formula (E-L power), chips.
    pub code_formula_chips: f64,
    /// Linearised DLL with the normalised envelope discriminator's statistics, chips.
    pub code_envelope_chips: f64,
    /// Slope of the atan discriminator at the prompt SNR, `1 - exp(-CN0 T)`.
    pub atan_slope: f64,
    /// Whether the linearised loop with that slope is stable (a 3rd-order loop needs a
    /// discriminator gain above about `1/(a3 b3)` = 0.38).
    pub linear_stable: bool,
    /// Settling time after the hand-over, s (NaN if the linearised loop is unstable):
    /// [`SETTLE_MARGIN_S`] plus the time after which the linearised loop's impulse response stays
    /// below [`SETTLE_FRACTION`] of its peak.
    pub settle_s: f64,
}

/// Start-up transients (random initial carrier phase, the hand-over) must decay to this fraction
/// of their size before errors are measured (about 8 time constants of the slowest mode).
pub const SETTLE_FRACTION: f64 = 3e-4;
/// Margin added to the settling time, s.
pub const SETTLE_MARGIN_S: f64 = 1.0;
/// Longest settling time the study waits for, s.
pub const MAX_SETTLE_S: f64 = 100.0;

/// Theory of a cell: the formulas and the linearised digital loops (module docs).
pub fn cell_theory(cell: &Cell) -> CellTheory {
    let t = cell.t_s();
    let nan = CellTheory {
        phase_formula_deg: pll_jitter_deg(cell.bn_hz, cell.cn0_dbhz, t),
        code_formula_chips: dll_jitter_chips(DLL_BN_HZ, EL_SPACING_CHIPS, cell.cn0_dbhz, t),
        phase_loop_deg: f64::NAN,
        bn_realised_ratio: f64::NAN,
        phase_digital_ratio: f64::NAN,
        doppler_hz: f64::NAN,
        pr_rate_mps: f64::NAN,
        pr_rate_1s_mps: f64::NAN,
        code_envelope_chips: f64::NAN,
        atan_slope: f64::NAN,
        linear_stable: false,
        settle_s: f64::NAN,
    };
    let Ok(filter) = LoopFilter::pll(cell.order, cell.bn_hz) else {
        return nan;
    };
    if !loop_analysis::is_stable(&filter, t) {
        return nan;
    }
    let unit = LoopNoiseGains::new(filter.clone(), cell.bn_hz, t, 1.0);
    let atan = costas_atan_stats(cell.cn0_dbhz, t);
    let code = envelope_dll_stats(cell.cn0_dbhz, t, EL_SPACING_CHIPS);
    let code_loop = LoopFilter::dll(1, DLL_BN_HZ)
        .map(|f| LoopNoiseGains::new(f, DLL_BN_HZ, t, code.slope).phase_gain())
        .unwrap_or(f64::NAN);
    let base = CellTheory {
        bn_realised_ratio: unit.noise_bandwidth_hz() / cell.bn_hz,
        phase_digital_ratio: (unit.phase_gain() / (2.0 * cell.bn_t())).sqrt(),
        code_envelope_chips: (code.noise_var * code_loop).sqrt(),
        atan_slope: atan.slope,
        ..nan
    };
    if !stable_with_slope(&filter, t, atan.slope) {
        return base;
    }
    let real = LoopNoiseGains::new(filter.clone(), cell.bn_hz, t, atan.slope);
    let m_obs = ((OBS_INTERVAL_S / t).round() as usize).max(1);
    let m_long = ((LONG_INTERVAL_S / t).round() as usize).max(1);
    let v = atan.noise_var;
    CellTheory {
        phase_loop_deg: (v * real.phase_gain()).sqrt() * 360.0,
        doppler_hz: (v * real.freq_gain()).sqrt(),
        pr_rate_mps: (v * real.rate_gain(m_obs)).sqrt() * LAMBDA_L1_M,
        pr_rate_1s_mps: (v * real.rate_gain(m_long)).sqrt() * LAMBDA_L1_M,
        linear_stable: true,
        settle_s: SETTLE_MARGIN_S
            + transient_decay_time_s(&filter, cell.bn_hz, t, atan.slope, SETTLE_FRACTION),
        ..base
    }
}
