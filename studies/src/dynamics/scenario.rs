//! Simulation of a scenario: its scenario file, the IF samples in memory, truth, channel starts
//! and the INS feed-forwards, ready to be tracked by every case.

use super::grid::{Case, ScenarioSpec};
use super::ins::feedforward;
use super::params::{CLOCK_DRIFT_S_S, FS_HZ, OSCILLATOR, RAMP_S, SPEED_MPS, START_TOW_S};
use crate::if_sim::{self, Truth};
use gpsrx_nav::rinex_nav::parse_rinex_nav;
use gpsrx_receiver::pipeline::aiding::InsFeedForward;
use gpsrx_tracking::ChannelStart;
use num_complex::Complex32;
use rayon::prelude::*;
use std::path::Path;

/// The scenario file of a spec (motion receiver near Seoul, every visible satellite, the
/// receiver oscillator [`OSCILLATOR`]).
pub(super) fn scenario_toml(spec: &ScenarioSpec, seed: u64, prns: Option<&[u8]>) -> String {
    let prns = prns.map_or(String::new(), |p| format!("prns = {p:?}\n"));
    format!(
        r#"description = "gpsrx study dynamics: {label} at {cn0} dB-Hz"
duration_s = {duration:?}
seed = {seed}
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = {START_TOW_S:?}
[output]
format = "cf32_le"
fs_hz = {FS_HZ:?}
[receiver]
kind = "motion"
start_llh_deg = [37.5665, 126.9780, 1000.0]
heading_deg = 0.0
speed_mps = {SPEED_MPS:?}
transition_s = {RAMP_S:?}
segments = {segments}
[clock]
bias_s = 1.0e-4
drift_s_s = {CLOCK_DRIFT_S_S:e}
allan_deviation_1s = {allan:e}
random_walk_fm_h_m2 = {h_m2:e}
[satellites]
{prns}cn0_all_dbhz = {cn0:?}
[truth]
rate_hz = 1.0
"#,
        label = spec.manoeuvre.label(),
        cn0 = spec.cn0_dbhz,
        segments = spec.manoeuvre.segments_toml(spec.lead_in_s),
        duration = spec.duration_s(),
        allan = OSCILLATOR.allan_deviation_1s,
        h_m2 = OSCILLATOR.h_m2,
    )
}

/// A simulated scenario, ready to be tracked many times.
pub(super) struct Prepared {
    pub(super) spec: ScenarioSpec,
    pub(super) samples: Vec<Complex32>,
    /// Per satellite (in the simulator's order): true code and carrier phase.
    pub(super) truth: Truth,
    /// Per satellite: the channel start from truth.
    pub(super) starts: Vec<ChannelStart>,
    /// Per satellite: unit vector receiver -> satellite (east, north, up) mid-window.
    pub(super) los_enu: Vec<[f64; 3]>,
    /// Feed-forwards of the INS the cases use, by accelerometer bias magnitude (m/s^2).
    pub(super) feedforwards: Vec<(f64, InsFeedForward)>,
}

impl Prepared {
    /// True carrier phase (cycles) of satellite `sat` at receiver time `t_s`, linear between
    /// 1 ms nodes (the curvature error `a T^2 / (8 lambda)` is 6e-5 cycle at 10 g).
    pub(super) fn truth_cycles(&self, sat: usize, t_s: f64) -> f64 {
        self.truth.sats[sat].carrier_cycles(t_s)
    }

    /// True mean Doppler of satellite `sat` over `[t0_s, t1_s]`, Hz.
    pub(super) fn truth_doppler_hz(&self, sat: usize, t0_s: f64, t1_s: f64) -> f64 {
        self.truth.sats[sat].mean_doppler_hz(t0_s, t1_s)
    }

    /// The feed-forward of `case`'s INS (None unaided).
    pub(super) fn feedforward(&self, case: &Case) -> Option<&InsFeedForward> {
        let b = case.bias_mps2();
        (b > 0.0)
            .then(|| self.feedforwards.iter().find(|(x, _)| *x == b))
            .flatten()
            .map(|(_, f)| f)
    }
}

/// Simulates a scenario into memory and prepares truth, channel starts and the INS aiding of
/// `cases`.
pub(super) fn prepare(spec: &ScenarioSpec, cases: &[Case], seed: u64) -> anyhow::Result<Prepared> {
    let mut sim = if_sim::simulator(&scenario_toml(spec, seed, None))?;
    // Unhealthy satellites are left out: a receiver does not use them, and the feed-forward
    // rejects their ephemerides.
    let healthy: Vec<u8> = sim
        .satellites
        .iter()
        .filter(|s| s.ephemeris.sv_health == 0)
        .map(|s| s.prn.get())
        .collect();
    if healthy.len() < sim.satellites.len() {
        sim = if_sim::simulator(&scenario_toml(spec, seed, Some(&healthy)))?;
    }
    let mut samples = vec![Complex32::new(0.0, 0.0); sim.total_samples() as usize];
    samples
        .par_chunks_mut(sim.chunk_samples())
        .enumerate()
        .for_each_init(Vec::new, |buf, (k, out)| {
            sim.generate_chunk(k as u64, buf);
            out.copy_from_slice(&buf[..out.len()]);
        });
    let truth = Truth::new(&sim);
    let starts = sim
        .satellites
        .iter()
        .map(|s| if_sim::start_from_truth(&sim, s, FS_HZ, 0.0))
        .collect();
    let (w0, w1) = spec.window_s();
    let los_enu = sim
        .satellites
        .iter()
        .map(|s| {
            let (_, slow) = sim.observe(s, 0.5 * (w0 + w1));
            let (se, ce) = slow.el_rad.sin_cos();
            let (sa, ca) = slow.az_rad.sin_cos();
            [ce * sa, ce * ca, se]
        })
        .collect();
    let (nav_text, nav_name) = sim.scenario.nav_text(Path::new("."))?;
    let nav = parse_rinex_nav(&nav_text).map_err(|e| anyhow::anyhow!("{nav_name}: {e}"))?;
    let mut biases: Vec<f64> = cases
        .iter()
        .map(Case::bias_mps2)
        .filter(|&b| b > 0.0)
        .collect();
    biases.sort_by(f64::total_cmp);
    biases.dedup();
    let feedforwards = biases
        .iter()
        .map(|&b| Ok((b, feedforward(&sim, &nav, b, spec.duration_s(), seed)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(Prepared {
        spec: *spec,
        samples,
        truth,
        starts,
        los_enu,
        feedforwards,
    })
}
