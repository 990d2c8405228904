//! Measurement: a cell's channel traces against truth, reduced to its error statistics.

use super::{Cell, LONG_INTERVAL_S, OBS_INTERVAL_S};
use crate::if_sim::{self, differenced_rate, folded_phase_deg, half_cycle_slips, ChannelTrace};
use gpsrx_dsp::constants::LAMBDA_L1_M;
use gpsrx_tracking::ChannelState;

/// Measured statistics of one cell (all satellites pooled; only channels that held lock).
#[derive(Debug, Clone, Default)]
pub struct CellMeasured {
    /// Channels run.
    pub channels: usize,
    /// Channels that reached tracking and held lock (no Lost state, no half-cycle slip, code
    /// error within half a chip) over the measurement.
    pub locked: usize,
    /// Half-cycle slips over all channels.
    pub slips: usize,
    /// Channels released (Lost) or never handed over to tracking.
    pub lost: usize,
    /// Phase jitter, deg.
    pub phase_deg: f64,
    /// NCO frequency error std, Hz.
    pub doppler_hz: f64,
    /// Pseudorange-rate error std over 0.1 s, m/s.
    pub pr_rate_mps: f64,
    /// Over 1 s, m/s.
    pub pr_rate_1s_mps: f64,
    /// Code error std, chips.
    pub code_chips: f64,
    /// Mean NCO Doppler error (bias), Hz.
    pub doppler_bias_hz: f64,
    /// Measured integration intervals per channel (mean).
    pub epochs: usize,
}

/// Pooled standard deviation of groups, each about its own mean:
/// `sqrt(sum_g sum_i (x_gi - mean_g)^2 / (N - G))`.
fn pooled_std(groups: &[Vec<f64>]) -> f64 {
    let (mut ss, mut n, mut g) = (0.0, 0usize, 0usize);
    for v in groups.iter().filter(|v| v.len() >= 2) {
        let m = if_sim::mean(v);
        ss += v.iter().map(|x| (x - m).powi(2)).sum::<f64>();
        n += v.len();
        g += 1;
    }
    if n > g {
        (ss / (n - g) as f64).sqrt()
    } else {
        f64::NAN
    }
}

/// Reduces the traces of one cell's channels to its statistics, measuring from `settle_s` after
/// each channel's hand-over to tracking.
pub fn measure_cell(
    cell: &Cell,
    traces: &[&ChannelTrace],
    settle_s: f64,
    detrend: bool,
) -> CellMeasured {
    let t = cell.t_s();
    let mut m = CellMeasured {
        channels: traces.len(),
        ..CellMeasured::default()
    };
    let (mut phase, mut dopp, mut rate, mut rate1, mut code) =
        (vec![], vec![], vec![], vec![], vec![]);
    let mut epochs = 0;
    for tr in traces {
        let Some(t_track) = tr
            .epochs
            .iter()
            .find(|e| e.state == ChannelState::Track)
            .map(|e| e.t_s)
        else {
            m.lost += 1;
            continue;
        };
        let lost = tr.final_state == ChannelState::Lost
            || tr.epochs.iter().any(|e| e.state == ChannelState::Lost);
        let t0 = t_track + settle_s;
        let sel: Vec<_> = tr
            .epochs
            .iter()
            .filter(|e| {
                e.t_s >= t0 && e.state == ChannelState::Track && (e.t_coh_s - t).abs() < 1e-9
            })
            .collect();
        let d: Vec<f64> = sel.iter().map(|e| e.phase_diff_cycles).collect();
        let block = ((0.1 / t).round() as usize).max(1);
        let slips = half_cycle_slips(&d, block);
        let code_lost = sel.iter().any(|e| e.code_error_chips.abs() > 0.5);
        m.slips += slips;
        if lost {
            m.lost += 1;
        }
        if lost || slips > 0 || code_lost || sel.len() < 20 {
            continue;
        }
        m.locked += 1;
        epochs += sel.len();
        phase.push(folded_phase_deg(&d, detrend));
        dopp.push(sel.iter().map(|e| e.doppler_error_hz).collect::<Vec<_>>());
        let m_obs = ((OBS_INTERVAL_S / t).round() as usize).max(1);
        let m_long = ((LONG_INTERVAL_S / t).round() as usize).max(1);
        let to_mps = |v: Vec<f64>| v.into_iter().map(|x| x * LAMBDA_L1_M).collect::<Vec<_>>();
        rate.push(to_mps(differenced_rate(&d, m_obs, t)));
        rate1.push(to_mps(differenced_rate(&d, m_long, t)));
        code.push(sel.iter().map(|e| e.code_error_chips).collect::<Vec<_>>());
    }
    m.epochs = epochs.checked_div(m.locked).unwrap_or(0);
    m.phase_deg = pooled_std(&phase);
    m.doppler_hz = pooled_std(&dopp);
    m.pr_rate_mps = pooled_std(&rate);
    m.pr_rate_1s_mps = pooled_std(&rate1);
    m.code_chips = pooled_std(&code);
    let all: Vec<f64> = dopp.concat();
    m.doppler_bias_hz = if_sim::mean(&all);
    m
}
