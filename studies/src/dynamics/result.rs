//! The metrics of one case, summarised from its channel logs.

use super::bias::bias_theory;
use super::grid::{Case, ScenarioSpec};
use super::params::TICK_S;
use super::scenario::Prepared;
use super::stats::pooled_std;
use super::track::ChannelLog;
use crate::if_sim;

/// The result of one case.
#[derive(Debug, Clone)]
pub(super) struct CaseResult {
    pub(super) spec: ScenarioSpec,
    pub(super) case: Case,
    pub(super) satellites: usize,
    pub(super) tracked_at_start: usize,
    pub(super) tracked_min: usize,
    pub(super) tracked_mean: f64,
    pub(super) kept: usize,
    pub(super) tracked_at_end: usize,
    pub(super) lock_drops: u32,
    pub(super) channels_lost: usize,
    pub(super) phase_std_cycles: f64,
    pub(super) disc_std_cycles: f64,
    pub(super) disc_mean_abs_deg: f64,
    pub(super) predicted_mean_abs_deg: f64,
    pub(super) growth_abs_deg_s: f64,
    pub(super) predicted_growth_deg_s: f64,
    /// Satellites in the bias statistics.
    pub(super) bias_channels: usize,
    /// RMS over channels of the NCO frequency error at the pull-in -> track hand-over, Hz.
    pub(super) handover_df_rms_hz: f64,
    pub(super) prr_std_mps: f64,
    /// Satellites tracked per tick over the whole run.
    pub(super) tracked_per_tick: Vec<usize>,
}

pub(super) fn summarise(p: &Prepared, case: &Case, logs: &[ChannelLog]) -> CaseResult {
    let (w0, w1) = p.spec.manoeuvre.window_s();
    let n_ticks = logs.first().map_or(0, |l| l.ticks.len());
    let per_tick: Vec<usize> = (0..n_ticks)
        .map(|k| logs.iter().filter(|l| l.ticks[k]).count())
        .collect();
    // Tick k reports the state at its end, (k + 1) TICK_S.
    let tick_of = |t: f64| ((t / TICK_S).round() as usize).saturating_sub(1);
    let (k0, k1) = (tick_of(w0), tick_of(w1).min(n_ticks.saturating_sub(1)));
    let window = &per_tick[k0 + 1..=k1];
    let kept = logs
        .iter()
        .filter(|l| l.ticks[k0..=k1].iter().all(|&t| t))
        .count();
    // Offset and Costas half cycles removed (if_sim::folded_phase_deg), in cycles.
    let folded: Vec<Vec<f64>> = logs
        .iter()
        .map(|l| {
            if_sim::folded_phase_deg(&l.phase_cycles, false)
                .iter()
                .map(|d| d / 360.0)
                .collect()
        })
        .collect();
    let bias = bias_theory(p, case, logs);
    CaseResult {
        spec: p.spec,
        case: *case,
        satellites: logs.len(),
        tracked_at_start: per_tick[k0],
        tracked_min: window.iter().copied().min().unwrap_or(0),
        tracked_mean: window.iter().sum::<usize>() as f64 / window.len().max(1) as f64,
        kept,
        tracked_at_end: per_tick.last().copied().unwrap_or(0),
        lock_drops: logs.iter().map(|l| l.lock_drops).sum(),
        channels_lost: logs.iter().filter(|l| l.lost).count(),
        phase_std_cycles: pooled_std(folded.iter().map(|v| v.as_slice())),
        disc_std_cycles: pooled_std(logs.iter().map(|l| l.disc_cycles.as_slice())),
        disc_mean_abs_deg: bias.mean_abs_deg,
        predicted_mean_abs_deg: bias.predicted_deg,
        growth_abs_deg_s: bias.growth_deg_s,
        predicted_growth_deg_s: bias.predicted_growth_deg_s,
        bias_channels: bias.channels,
        handover_df_rms_hz: {
            let v: Vec<f64> = logs
                .iter()
                .filter(|l| l.handover_epochs > 0)
                .map(|l| l.handover_df_sum_hz / l.handover_epochs as f64)
                .collect();
            if v.is_empty() {
                f64::NAN
            } else {
                (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
            }
        },
        prr_std_mps: pooled_std(logs.iter().map(|l| l.prr_mps.as_slice())),
        tracked_per_tick: per_tick,
    }
}
