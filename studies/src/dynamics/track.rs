//! Tracking one case over a prepared scenario, logging what every channel saw.

use super::aiding::Aiding;
use super::grid::Case;
use super::mem_source::MemSource;
use super::params::{FS_HZ, TICK_S};
use super::result::{summarise, CaseResult};
use super::scenario::Prepared;
use crate::if_sim;
use gpsrx_dsp::constants::LAMBDA_L1_M;
use gpsrx_receiver::pipeline::channels::{track, AidSource};
use gpsrx_samples::SampleFormat;
use gpsrx_tracking::{Channel, ChannelConfig, ChannelEpoch, ChannelState, LoopConfig};

/// Epochs in Track over which the hand-over frequency error is averaged (20 ms at T = 1 ms).
const HANDOVER_EPOCHS: usize = 20;

/// What one channel saw.
#[derive(Debug, Clone, Default)]
pub(super) struct ChannelLog {
    /// Tracked (Track state and PLL lock) at the end of each tick.
    pub(super) ticks: Vec<bool>,
    pub(super) tracked: bool,
    pub(super) lock_drops: u32,
    pub(super) lost: bool,
    /// In the window, while tracked: NCO minus true carrier phase, cycles.
    pub(super) phase_cycles: Vec<f64>,
    /// Costas discriminator output, cycles.
    pub(super) disc_cycles: Vec<f64>,
    /// NCO minus true Doppler, times lambda, m/s.
    pub(super) prr_mps: Vec<f64>,
    /// In the window, in the Track state (locked or not: the Costas discriminator `atan(Q/I)`
    /// is the phase error up to +-90 deg): receive time (s) and discriminator (cycles), for the
    /// mean error and its growth.
    pub(super) track_t_s: Vec<f64>,
    pub(super) track_disc_cycles: Vec<f64>,
    /// NCO minus true carrier phase at those epochs, cycles (not folded: a cycle slip shows as
    /// a jump of half a cycle or more).
    pub(super) track_phase_cycles: Vec<f64>,
    /// Sum and count of the NCO-minus-true Doppler over the first [`HANDOVER_EPOCHS`] epochs in
    /// Track (the frequency error the tracking loop starts with), Hz.
    pub(super) handover_df_sum_hz: f64,
    pub(super) handover_epochs: usize,
}

/// The channel configuration of `case`, as `gpsrx run` sets it up: unaided
/// (`--no-aiding --pll-order N --pll-bw B`), the default pull-in, then the case's PLL as the
/// tracking loops (no FLL, 1 Hz 1st-order carrier-aided DLL, T = 1 ms); aided
/// (`--ins --aided-pll-order N --aided-pll-bw B`), the default tracking loops (3rd order,
/// 18 Hz) with the case's PLL as `aided_track`, which the channel takes (in stages, from the
/// pull-in loop) once the feed-forward is on. No weak-signal loops in either: the study measures
/// the loops it names.
pub(super) fn case_config(case: &Case) -> ChannelConfig {
    if case.aiding == Aiding::Unaided {
        return if_sim::track_config(case.order, case.bn_hz, 1e-3, 1.0);
    }
    let defaults = ChannelConfig::default().track;
    let mut cfg = if_sim::track_config(defaults.pll_order, defaults.pll_bw_hz, 1e-3, 1.0);
    cfg.aided_track = Some(LoopConfig {
        pll_order: case.order,
        pll_bw_hz: case.bn_hz,
        ..cfg.track
    });
    cfg
}

/// Tracks every satellite of `p` with the loops and aiding of `case`.
pub(super) fn run_case(p: &Prepared, case: &Case) -> anyhow::Result<CaseResult> {
    let cfg = case_config(case);
    let channels = p
        .starts
        .iter()
        .map(|s| Channel::new(s, FS_HZ, &cfg))
        .collect::<Result<Vec<_>, _>>()?;
    let n_ticks = (p.spec.duration_s() / TICK_S).round() as usize;
    let mut logs = vec![
        ChannelLog {
            ticks: vec![false; n_ticks],
            ..ChannelLog::default()
        };
        channels.len()
    ];
    let (w0, w1) = p.spec.window_s();
    let mut src = MemSource {
        data: &p.samples,
        pos: 0,
        format: SampleFormat::Cf32Le,
    };
    let ff = p.feedforward(case);
    if ff.is_none() && case.aiding != Aiding::Unaided {
        anyhow::bail!("no INS prepared for {case:?}: prepare() was given other cases");
    }
    let aid_fn = |prn: gpsrx_dsp::Prn, t: f64| ff.and_then(|f| f.aid(prn.get(), t));
    let aid: Option<AidSource<'_>> = ff.map(|_| &aid_fn as AidSource<'_>);
    track(&mut src, channels, aid, |i, e: &ChannelEpoch| {
        let log = &mut logs[i];
        let tracked = e.state == ChannelState::Track && e.pll_lock;
        if log.tracked && !tracked && e.t_rx_s >= w0 {
            log.lock_drops += 1;
        }
        log.tracked = tracked;
        log.lost |= e.state == ChannelState::Lost;
        let tick = (e.t_rx_s / TICK_S).floor() as usize;
        if let Some(t) = log.ticks.get_mut(tick) {
            *t = tracked;
        }
        let t0 = e.t_rx_s;
        let doppler_error_hz = || e.doppler_hz - p.truth_doppler_hz(i, t0, t0 + e.t_coh_s);
        if tracked && (w0..=w1).contains(&t0) {
            log.phase_cycles
                .push(e.carrier_phase_cycles - p.truth_cycles(i, t0));
            log.disc_cycles.push(e.phase_error_cycles);
            log.prr_mps.push(doppler_error_hz() * LAMBDA_L1_M);
        }
        let in_track = e.state == ChannelState::Track;
        if in_track && log.handover_epochs < HANDOVER_EPOCHS {
            log.handover_df_sum_hz += doppler_error_hz();
            log.handover_epochs += 1;
        }
        if in_track && (w0..=w1).contains(&e.t_rx_s) {
            log.track_t_s.push(e.t_rx_s);
            log.track_disc_cycles.push(e.phase_error_cycles);
            log.track_phase_cycles
                .push(e.carrier_phase_cycles - p.truth_cycles(i, e.t_rx_s));
        }
    })?;
    Ok(summarise(p, case, &logs))
}
