//! One case: a scenario tracked in one mode by the receiver library (the path of `gpsrx run`),
//! measured against the simulator's truth.

use super::cases::{
    biased_ins, Mode, Test, AFTER_BLOCKAGE_S, BLOCKAGE_S, FS_HZ, START_TOW_S, TURN_S, TURN_START_S,
};
use crate::if_sim::SimSource;
use gpsrx_receiver::pipeline::{FixQuality, InsAiding, MemorySink};
use gpsrx_receiver::{Assistance, Receiver, ReceiverConfig};
use gpsrx_samples::sim::Simulator;
use gpsrx_tracking::{ChannelState, TrackingMode};
use std::collections::{BTreeMap, BTreeSet};

/// A case: a scenario and a mode.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Case {
    /// The scenario.
    pub test: Test,
    /// The mode.
    pub mode: Mode,
}

/// What a case measured (the fields of its test; the others are empty).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct CaseResult {
    /// Fade: per satellite, its true C/N0 at its last observables (the threshold), dB-Hz.
    pub thresholds_dbhz: Vec<(u8, f64)>,
    /// Blockage: the first valid fix, s after the signals return (None: none within
    /// [`AFTER_BLOCKAGE_S`]).
    pub back_s: Option<f64>,
    /// Blockage: the largest 3-D error of the valid fixes within [`AFTER_BLOCKAGE_S`] of the
    /// return, m.
    pub max_error_after_m: Option<f64>,
    /// Blockage: (seconds after the return, 3-D error m) of those fixes.
    pub errors_after: Vec<(f64, f64)>,
    /// Blockage: the satellites whose channel was released (searched again).
    pub lost: Vec<u8>,
    /// Turn: the satellites in phase lock in the second before it.
    pub locked_before: Vec<u8>,
    /// Turn: those of them in tracking and in phase lock (95 % of the reports) through it and
    /// the second after.
    pub locked_through: Vec<u8>,
    /// Seconds the navigation filter drove the channels (vector modes).
    pub vector_s: Option<f64>,
    /// Times the INS's integrity monitor rejected its aid (modes with an INS; the INS is
    /// good, so any is a false alarm).
    pub ins_rejections: Option<usize>,
}

/// Tracks `case` on its scenario (noise seed `seed`).
pub fn run_case(case: &Case, seed: u64) -> anyhow::Result<CaseResult> {
    let sim = case.test.simulator(seed)?;
    let mut config = ReceiverConfig::default();
    config.run.week = Some(2190);
    // The built-in navigation file flags a satellite unhealthy (a flag the simulator copies).
    config.run.allow_unhealthy = true;
    if case.mode.is_vector() {
        config.tracking.mode = TrackingMode::Vector;
    }
    let nav =
        gpsrx_nav::rinex_nav::parse_rinex_nav(gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT)?;
    let ins = if case.mode.has_ins() {
        Some(InsAiding {
            track: biased_ins(&sim)?,
            band_limit_rad_s: None,
        })
    } else {
        None
    };
    let assistance = Assistance {
        nav: Some(nav),
        ins,
        ..Assistance::default()
    };
    let mut rx = Receiver::new(&config, FS_HZ, assistance)?;
    let mut sink = MemorySink::new();
    if matches!(case.test, Test::Turn { .. } | Test::Blockage) {
        sink = sink.with_channel_epochs();
    }
    let summary = rx.run(&mut SimSource::new(&sim), &mut sink)?;
    let mut r = CaseResult {
        vector_s: summary.vector.map(|v| v.vector_s),
        ins_rejections: summary.ins_aiding.map(|a| a.rejections),
        ..CaseResult::default()
    };
    match case.test {
        Test::Fade { .. } => r.thresholds_dbhz = thresholds(&sim, &sink),
        Test::Blockage => blockage(&sim, &sink, &mut r),
        Test::Turn { .. } => {
            r.locked_before = locked_in(&sink, TURN_START_S - 1.0, TURN_START_S)
                .into_iter()
                .collect();
            let through = locked_in(&sink, TURN_START_S, TURN_START_S + TURN_S + 1.0);
            r.locked_through = r
                .locked_before
                .iter()
                .copied()
                .filter(|p| through.contains(p))
                .collect();
        }
    }
    Ok(r)
}

/// Per satellite, the true C/N0 at its last observables with a pseudorange, dB-Hz.
fn thresholds(sim: &Simulator, sink: &MemorySink) -> Vec<(u8, f64)> {
    let mut last: BTreeMap<u8, f64> = BTreeMap::new();
    for o in &sink.observables {
        // Stream time from the receiver time (within a millisecond of it).
        let t = o.epoch.time.tow_s - START_TOW_S;
        for s in o.epoch.sats.iter().filter(|s| s.pseudorange_m.is_some()) {
            last.insert(s.prn, t);
        }
    }
    last.into_iter()
        .filter_map(|(prn, t)| {
            let sat = sim.satellites.iter().find(|s| s.prn.get() == prn)?;
            let (_, slow) = sim.observe(sat, t);
            Some((prn, sim.cn0_dbhz(sat, slow.el_rad, t)))
        })
        .collect()
}

/// The fixes after the blockage against the static truth, and the channels released.
fn blockage(sim: &Simulator, sink: &MemorySink, r: &mut CaseResult) {
    let (_, truth) = sim.receiver_truth(BLOCKAGE_S.0);
    let end = BLOCKAGE_S.1;
    r.errors_after = sink
        .fixes
        .iter()
        .filter(|f| f.fix.quality != FixQuality::None)
        .filter(|f| (end..=end + AFTER_BLOCKAGE_S).contains(&f.t_stream_s))
        .map(|f| {
            (
                f.t_stream_s - end,
                (f.solution.pos_ecef_m - truth.pos_m).norm(),
            )
        })
        .collect();
    r.back_s = r.errors_after.first().map(|e| e.0);
    r.max_error_after_m = r.errors_after.iter().map(|e| e.1).reduce(f64::max);
    let lost: BTreeSet<u8> = sink
        .channel_epochs
        .iter()
        .filter(|(_, e)| e.state == ChannelState::Lost && e.t_rx_s > BLOCKAGE_S.0 - 0.5)
        .map(|(_, e)| e.prn)
        .collect();
    r.lost = lost.into_iter().collect();
}

/// The satellites whose every report from `t0_s` to `t1_s` was in tracking and at least 95 of
/// 100 with phase lock.
pub fn locked_in(sink: &MemorySink, t0_s: f64, t1_s: f64) -> BTreeSet<u8> {
    let mut per: BTreeMap<u8, (usize, usize, usize)> = BTreeMap::new();
    for (_, e) in sink
        .channel_epochs
        .iter()
        .filter(|(_, e)| (t0_s..t1_s).contains(&e.t_rx_s))
    {
        let c = per.entry(e.prn).or_default();
        c.0 += 1;
        c.1 += usize::from(e.state == ChannelState::Track);
        c.2 += usize::from(e.pll_lock);
    }
    per.into_iter()
        .filter(|(_, (n, tracked, locked))| tracked == n && locked * 100 >= n * 95)
        .map(|(prn, _)| prn)
        .collect()
}
