//! The metrics of one case, summarised from its channel logs.

use super::bias::bias_theory;
use super::grid::{Case, ScenarioSpec};
use super::params::TICK_S;
use super::scenario::Prepared;
use super::stats::pooled_std;
use super::track::ChannelLog;
use crate::if_sim;
use gpsrx_dsp::constants::LAMBDA_L1_M;

/// A case of the grid that was not run: the receiver rejects its loops.
#[derive(Debug, Clone)]
pub(super) struct NotRun {
    pub(super) spec: ScenarioSpec,
    pub(super) case: Case,
    /// The receiver's reason.
    pub(super) why: String,
}

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
    /// Per satellite (simulator order): the discriminator std over its tracked epochs in the
    /// window, cycles (NaN with fewer than [`super::stats::MIN_SAMPLES`]).
    pub(super) disc_std_per_sat: Vec<f64>,
    /// The satellites' PRNs (simulator order).
    pub(super) prns: Vec<u8>,
    /// PRNs not tracked when the manoeuvre began.
    pub(super) lost_before_prns: Vec<u8>,
    /// Largest line-of-sight acceleration of a satellite during the lead-in (the satellites'
    /// own motion and the Earth's rotation: the vehicle cruises straight), m/s^2.
    pub(super) lead_in_accel_max_mps2: f64,
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

/// Line-of-sight acceleration of satellite `sat` over the lead-in, m/s^2: the change of its
/// true Doppler (0.5 s means) from 1 s after the start to 1 s before the manoeuvre, times
/// lambda.
fn lead_in_accel_mps2(p: &Prepared, sat: usize) -> f64 {
    let (t_a, t_b) = (1.0, p.spec.lead_in_s - 1.0);
    let d = |t: f64| p.truth_doppler_hz(sat, t - 0.25, t + 0.25);
    ((d(t_b) - d(t_a)) / (t_b - t_a) * LAMBDA_L1_M).abs()
}

pub(super) fn summarise(p: &Prepared, case: &Case, logs: &[ChannelLog]) -> CaseResult {
    let (w0, w1) = p.spec.window_s();
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
        disc_std_per_sat: logs
            .iter()
            .map(|l| pooled_std(std::iter::once(l.disc_cycles.as_slice())))
            .collect(),
        prns: p.truth.sats.iter().map(|s| s.prn.get()).collect(),
        lost_before_prns: logs
            .iter()
            .zip(&p.truth.sats)
            .filter(|(l, _)| !l.ticks[k0])
            .map(|(_, s)| s.prn.get())
            .collect(),
        lead_in_accel_max_mps2: (0..logs.len())
            .map(|i| lead_in_accel_mps2(p, i))
            .fold(0.0, f64::max),
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

/// A hand-made result for the report tests: every satellite tracked and kept, the given
/// discriminator std, the rest neutral.
#[cfg(test)]
pub(super) fn test_result(spec: ScenarioSpec, case: Case, n: usize, disc_std: f64) -> CaseResult {
    CaseResult {
        spec,
        case,
        satellites: n,
        tracked_at_start: n,
        tracked_min: n,
        tracked_mean: n as f64,
        kept: n,
        tracked_at_end: n,
        lock_drops: 0,
        channels_lost: 0,
        phase_std_cycles: 0.01,
        disc_std_cycles: disc_std,
        disc_std_per_sat: vec![disc_std; n],
        prns: (1..=n as u8).collect(),
        lost_before_prns: Vec::new(),
        lead_in_accel_max_mps2: 0.1,
        disc_mean_abs_deg: f64::NAN,
        predicted_mean_abs_deg: f64::NAN,
        growth_abs_deg_s: f64::NAN,
        predicted_growth_deg_s: f64::NAN,
        bias_channels: 0,
        handover_df_rms_hz: 0.1,
        prr_std_mps: 0.01,
        tracked_per_tick: vec![n; 10],
    }
}
