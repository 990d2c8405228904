//! IF-level simulations for the studies: simulate a scenario into memory, start channels from the
//! simulator's truth, track, and compare every integration interval with the truth.
//!
//! - [`scenario_toml`] / [`simulator`]: a scenario (static or moving receiver) as the simulator's
//!   own TOML, so every key is checked by its `deny_unknown_fields` parser.
//! - [`SimSource`]: the simulated samples as a [`SampleSource`], generated in memory on the fly
//!   (work units in parallel, floats without quantisation): no file, bounded memory, and the same
//!   seed gives the same samples for every run over the same scenario.
//! - [`Truth`]: per satellite, the true code phase (chips) and carrier phase (cycles) at every
//!   code period (1 ms node), interpolated linearly in between, which is how the simulator
//!   itself builds the signal between its nodes; it also gives a perfect Doppler aid.
//! - [`start_from_truth`], [`channels_from_truth`]: channel starts as from a perfect acquisition.
//! - [`track_vs_truth`]: runs channels over a source with [`track`] and returns, per channel and
//!   per integration interval, the NCO-minus-truth carrier phase, the Doppler error and the code
//!   error ([`EpochVsTruth`]).
//! - [`folded_phase_deg`], [`half_cycle_slips`], [`std_dev`]: what the studies compute from them.
//!
//! Phase errors are those of the replica (NCO) carrier phase at the first sample of each
//! integration against the simulator's true carrier phase at that instant, not the
//! discriminator output: `phase_diff = phi_NCO(t_k) - phi_true(t_k)` (cycles). It contains a
//! constant (the unknown initial phase) and, for a Costas loop, the half-cycle ambiguity, which
//! [`folded_phase_deg`] removes.

use anyhow::Context;
use gpsrx_dsp::constants::CA_CODE_LENGTH;
use gpsrx_dsp::Prn;
use gpsrx_receiver::pipeline::channels::{track, AidSource};
use gpsrx_samples::sim::{Scenario, SimSatellite, Simulator};
use gpsrx_samples::{SampleError, SampleFormat, SampleSource};
use gpsrx_tracking::{Channel, ChannelConfig, ChannelStart, ChannelState, ConfigError, DopplerAid};
use num_complex::Complex32;
use rayon::prelude::*;
use std::collections::VecDeque;
use std::path::Path;

/// Start time of the study scenarios: GPS week 2190, TOW 538194 s (2022-01-01 05:29:54 GPS), for
/// which the shipped navigation file `builtin:brdc0010.22n` holds ephemerides.
pub const START_WEEK: u32 = 2190;
/// See [`START_WEEK`].
pub const START_TOW_S: f64 = 538_194.0;
/// The static receiver of the study scenarios (Seoul), latitude, longitude (deg), height (m).
pub const SEOUL_LLH: [f64; 3] = [37.5665, 126.9780, 40.0];

/// A receiver oscillator for the simulator's two-state clock model (`gpsrx_samples::sim::clock`):
/// white FM of Allan deviation `allan_deviation_1s` at 1 s (q1 = sigma_1^2 = h0 / 2) and
/// random-walk FM of power-law coefficient `h_m2` (q2 = 2 pi^2 h_-2), so that
/// `sigma_y^2(tau) = sigma_1^2 / tau + (2 pi^2 / 3) h_-2 tau`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oscillator {
    /// Name in the reports.
    pub name: &'static str,
    /// White-FM Allan deviation at 1 s.
    pub allan_deviation_1s: f64,
    /// Random-walk FM coefficient h_-2, 1/s.
    pub h_m2: f64,
}

impl Oscillator {
    /// A perfect clock (bias only).
    pub const NONE: Oscillator = Oscillator {
        name: "none",
        allan_deviation_1s: 0.0,
        h_m2: 0.0,
    };
    /// A TCXO: sigma_y(1 s) = 1.09e-10, sigma_y(10 s) = 1.44e-10.
    pub const TCXO: Oscillator = Oscillator {
        name: "TCXO",
        allan_deviation_1s: 1e-10,
        h_m2: 3e-22,
    };
    /// An OCXO: sigma_y(1 s) = 1.09e-12, sigma_y(10 s) = 1.44e-12.
    pub const OCXO: Oscillator = Oscillator {
        name: "OCXO",
        allan_deviation_1s: 1e-12,
        h_m2: 3e-26,
    };

    /// Allan deviation at `tau_s` (the two-state model's).
    pub fn allan_deviation(&self, tau_s: f64) -> f64 {
        (self.allan_deviation_1s.powi(2) / tau_s
            + 2.0 * std::f64::consts::PI.powi(2) / 3.0 * self.h_m2 * tau_s)
            .sqrt()
    }
}

/// A scenario in the simulator's TOML: `duration_s`, noise `seed`, complex float samples at
/// `fs_hz` (zero IF), the `[receiver]` table body `receiver` (e.g. `kind = "static"` and its
/// position) and the `[satellites]` table body `satellites` (PRNs and C/N0). The receiver
/// clock has a bias and no drift or noise (Allan deviation 0), so that the loops see only the
/// thermal noise and the geometry; ionosphere and troposphere are on (as in the simulator's
/// default). `extra` is appended verbatim (e.g. `[[outages]]` tables).
pub fn scenario_toml(
    duration_s: f64,
    seed: u64,
    fs_hz: f64,
    receiver: &str,
    satellites: &str,
    extra: &str,
) -> String {
    scenario_toml_with_oscillator(
        duration_s,
        seed,
        fs_hz,
        receiver,
        satellites,
        extra,
        &Oscillator::NONE,
    )
}

/// [`scenario_toml`] with the receiver clock driven by `osc`.
pub fn scenario_toml_with_oscillator(
    duration_s: f64,
    seed: u64,
    fs_hz: f64,
    receiver: &str,
    satellites: &str,
    extra: &str,
    osc: &Oscillator,
) -> String {
    format!(
        "duration_s = {duration_s}\nseed = {seed}\nnav = \"builtin:brdc0010.22n\"\n\
         [start]\nweek = {START_WEEK}\ntow_s = {START_TOW_S:.1}\n\
         [output]\nformat = \"cf32_le\"\nfs_hz = {fs_hz}\n\
         [receiver]\n{receiver}\n\
         [clock]\nbias_s = 1.0e-4\ndrift_s_s = 0.0\nallan_deviation_1s = {:e}\n\
         random_walk_fm_h_m2 = {:e}\n\
         [satellites]\n{satellites}\n\
         [truth]\nrate_hz = 1.0\n{extra}\n",
        osc.allan_deviation_1s, osc.h_m2
    )
}

/// The `[receiver]` body of a static receiver at `llh` (deg, deg, m).
pub fn static_receiver(llh: [f64; 3]) -> String {
    format!(
        "kind = \"static\"\nllh_deg = [{}, {}, {}]",
        llh[0], llh[1], llh[2]
    )
}

/// A `[satellites]` body: these PRNs, each at its own C/N0 (dB-Hz), with navigation data (the
/// channels need data-bit edges for bit synchronisation and 20 ms integrations).
pub fn satellites_with_cn0(prn_cn0: &[(u8, f64)]) -> String {
    let prns: Vec<String> = prn_cn0.iter().map(|(p, _)| p.to_string()).collect();
    let cn0: Vec<String> = prn_cn0
        .iter()
        .map(|(p, c)| format!("{{ prn = {p}, dbhz = {c} }}"))
        .collect();
    format!(
        "elevation_mask_deg = 0.0\nprns = [{}]\ncn0 = [{}]\nnav_data = true",
        prns.join(", "),
        cn0.join(", ")
    )
}

/// Parses and prepares a scenario (the navigation file is the shipped one, so no directory is
/// needed).
pub fn simulator(toml_text: &str) -> anyhow::Result<Simulator> {
    let sc = Scenario::from_toml(toml_text).map_err(|e| anyhow::anyhow!("scenario: {e}"))?;
    Simulator::new(&sc, Path::new(".")).context("cannot prepare the simulation")
}

/// The simulator's samples as a [`SampleSource`], generated in memory as they are read.
///
/// Work units ([`Simulator::chunk_samples`] samples, 100 code periods) are generated a batch at
/// a time in parallel; the samples are the simulator's output units before quantisation (complex
/// floats, noise standard deviation `noise_sigma` per component), so there is no quantisation
/// loss. Reports the format as `cf32_le` (what the samples are).
#[derive(Debug)]
pub struct SimSource<'a> {
    sim: &'a Simulator,
    format: SampleFormat,
    fs_hz: f64,
    next_chunk: u64,
    ready: VecDeque<Vec<Complex32>>,
    current: Vec<Complex32>,
    pos: usize,
    next_index: u64,
    batch: u64,
}

impl<'a> SimSource<'a> {
    /// A source over the whole recording of `sim`.
    pub fn new(sim: &'a Simulator) -> Self {
        Self {
            sim,
            format: SampleFormat::Cf32Le,
            fs_hz: sim.scenario.output.fs_hz,
            next_chunk: 0,
            ready: VecDeque::new(),
            current: Vec::new(),
            pos: 0,
            next_index: 0,
            batch: (rayon::current_num_threads() as u64 * 2).max(2),
        }
    }

    fn refill(&mut self) {
        let end = (self.next_chunk + self.batch).min(self.sim.chunk_count());
        let sim = self.sim;
        let bufs: Vec<Vec<Complex32>> = (self.next_chunk..end)
            .into_par_iter()
            .map(|ci| {
                let mut v = Vec::new();
                sim.generate_chunk(ci, &mut v);
                v
            })
            .collect();
        self.next_chunk = end;
        self.ready.extend(bufs);
    }
}

impl SampleSource for SimSource<'_> {
    fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    fn format(&self) -> &SampleFormat {
        &self.format
    }

    fn total_samples(&self) -> Option<u64> {
        Some(self.sim.total_samples())
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let first = self.next_index;
        let mut n = 0;
        while n < out.len() {
            if self.pos >= self.current.len() {
                if self.ready.is_empty() {
                    if self.next_chunk >= self.sim.chunk_count() {
                        break;
                    }
                    self.refill();
                }
                match self.ready.pop_front() {
                    Some(b) => {
                        self.current = b;
                        self.pos = 0;
                    }
                    None => break,
                }
                continue;
            }
            let k = (out.len() - n).min(self.current.len() - self.pos);
            out[n..n + k].copy_from_slice(&self.current[self.pos..self.pos + k]);
            self.pos += k;
            n += k;
        }
        self.next_index += n as u64;
        Ok((first, n))
    }

    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}

/// One satellite's true code and carrier phase at nodes `k * step_s` (k = 0, 1, ...), linearly
/// interpolated in between.
#[derive(Debug, Clone)]
pub struct SatTruth {
    /// The satellite.
    pub prn: Prn,
    step_s: f64,
    chips: Vec<f64>,
    cycles: Vec<f64>,
}

impl SatTruth {
    /// Evaluates the simulator's propagation model ([`Simulator::observe`]) at every node from
    /// 0 to `duration_s` plus two nodes (in parallel).
    pub fn new(sim: &Simulator, sat: &SimSatellite, step_s: f64, duration_s: f64) -> Self {
        let n = (duration_s / step_s).ceil() as usize + 3;
        let obs: Vec<(f64, f64)> = (0..n)
            .into_par_iter()
            .map(|k| {
                let (o, _) = sim.observe(sat, k as f64 * step_s);
                (o.chips, o.carrier_cycles)
            })
            .collect();
        Self {
            prn: sat.prn,
            step_s,
            chips: obs.iter().map(|o| o.0).collect(),
            cycles: obs.iter().map(|o| o.1).collect(),
        }
    }

    fn interp(&self, v: &[f64], t_s: f64) -> f64 {
        let x = (t_s / self.step_s).max(0.0);
        let i = (x.floor() as usize).min(v.len().saturating_sub(2));
        let f = x - i as f64;
        v[i] + (v[i + 1] - v[i]) * f
    }

    /// True code phase at receiver time `t_s` (s since the first sample), chips counted from the
    /// reference subframe boundary (take it modulo 1023 for the phase within the code).
    pub fn chips(&self, t_s: f64) -> f64 {
        self.interp(&self.chips, t_s)
    }

    /// True carrier phase at `t_s`, cycles (`-Phi/lambda`: grows when the range shrinks, so its
    /// rate is the Doppler).
    pub fn carrier_cycles(&self, t_s: f64) -> f64 {
        self.interp(&self.cycles, t_s)
    }

    /// Mean Doppler over `[t0_s, t1_s]`, Hz: `(phi(t1) - phi(t0)) / (t1 - t0)`.
    pub fn mean_doppler_hz(&self, t0_s: f64, t1_s: f64) -> f64 {
        (self.carrier_cycles(t1_s) - self.carrier_cycles(t0_s)) / (t1_s - t0_s)
    }

    /// A perfect Doppler aid at `t_s`: central differences over one node either side,
    /// `f = (phi(t+h) - phi(t-h))/(2h)`, `df/dt = (phi(t+h) - 2 phi(t) + phi(t-h))/h^2`.
    pub fn aid(&self, t_s: f64) -> DopplerAid {
        let h = self.step_s;
        let t = t_s.max(h);
        let (a, b, c) = (
            self.carrier_cycles(t - h),
            self.carrier_cycles(t),
            self.carrier_cycles(t + h),
        );
        DopplerAid {
            doppler_hz: (c - a) / (2.0 * h),
            doppler_rate_hz_s: (c - 2.0 * b + a) / (h * h),
            coast: false,
            checked: false,
            source: gpsrx_tracking::AidSource::Ins,
        }
    }
}

/// The truth of every simulated satellite.
#[derive(Debug, Clone)]
pub struct Truth {
    /// One per simulated satellite, in the simulator's order.
    pub sats: Vec<SatTruth>,
}

impl Truth {
    /// Nodes every code period (1 ms) over the whole recording.
    pub fn new(sim: &Simulator) -> Self {
        let d = sim.scenario.duration_s;
        Self {
            sats: sim
                .satellites
                .iter()
                .map(|s| SatTruth::new(sim, s, 1e-3, d))
                .collect(),
        }
    }

    /// The truth of `prn`, if simulated.
    pub fn get(&self, prn: u8) -> Option<&SatTruth> {
        self.sats.iter().find(|s| s.prn.get() == prn)
    }

    /// A perfect Doppler aid for the tracker's aiding port (`None` for an unknown PRN).
    pub fn aid(&self, prn: u8, t_s: f64) -> Option<DopplerAid> {
        self.get(prn).map(|s| s.aid(t_s))
    }
}

/// A channel start from truth, as from a perfect acquisition: the first C/A code period that
/// starts after sample 0 (rounded to the nearest sample) and the true Doppler plus `df_hz`
/// (an initial frequency error).
pub fn start_from_truth(
    sim: &Simulator,
    sat: &SimSatellite,
    fs_hz: f64,
    df_hz: f64,
) -> ChannelStart {
    let (o, _) = sim.observe(sat, 0.0);
    let (o2, _) = sim.observe(sat, 1e-3);
    let rate = (o2.chips - o.chips) / 1e-3;
    let to_start =
        (CA_CODE_LENGTH as f64 - o.chips.rem_euclid(CA_CODE_LENGTH as f64)) / rate * fs_hz;
    let doppler = (o2.carrier_cycles - o.carrier_cycles) / 1e-3;
    ChannelStart {
        prn: sat.prn,
        code_start_sample: to_start.round() as u64,
        doppler_hz: doppler + df_hz,
        cn0_dbhz: f64::NAN,
    }
}

/// A channel configuration with the default pull-in (wide, FLL-assisted, T = 1 ms) and this
/// tracking loop: PLL of `order` (1-3) and noise bandwidth `bn_hz` without FLL, 1st-order
/// carrier-aided DLL of `dll_bn_hz`, integration `t_coh_s`, E-L spacing 1 chip, no weak-signal
/// loops; the rest as [`ChannelConfig::default`].
pub fn track_config(order: u8, bn_hz: f64, t_coh_s: f64, dll_bn_hz: f64) -> ChannelConfig {
    let base = ChannelConfig::default();
    ChannelConfig {
        track: gpsrx_tracking::LoopConfig {
            pll_order: order,
            pll_bw_hz: bn_hz,
            dll_bw_hz: dll_bn_hz,
            t_coh_s,
            ..base.track
        },
        // A loop study measures the loops it names: no switch to the weak-signal loops, no
        // weak-signal pull-in.
        weak_track: None,
        weak_pull_in: None,
        ..base
    }
}

/// One channel per simulated satellite, started from truth with configuration `cfg`.
pub fn channels_from_truth(
    sim: &Simulator,
    fs_hz: f64,
    cfg: &ChannelConfig,
) -> Result<Vec<Channel>, ConfigError> {
    sim.satellites
        .iter()
        .map(|s| Channel::new(&start_from_truth(sim, s, fs_hz, 0.0), fs_hz, cfg))
        .collect()
}

/// One channel to run in [`track_vs_truth`].
#[derive(Debug, Clone, Copy)]
pub struct ChannelSpec {
    /// The satellite (must be simulated).
    pub prn: u8,
    /// Its loops.
    pub config: ChannelConfig,
    /// Initial Doppler error, Hz (0: a perfect start).
    pub doppler_offset_hz: f64,
}

/// One integration interval of a channel compared with truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochVsTruth {
    /// Receiver time of the interval's first sample, s.
    pub t_s: f64,
    /// Integration time, s.
    pub t_coh_s: f64,
    /// Channel state during the interval.
    pub state: ChannelState,
    /// The channel's phase-lock indicator.
    pub pll_lock: bool,
    /// The channel's C/N0 estimate, dB-Hz.
    pub cn0_dbhz: f64,
    /// NCO carrier phase minus true carrier phase at `t_s`, cycles: a constant (initial phase,
    /// Costas half cycles) plus the tracking error.
    pub phase_diff_cycles: f64,
    /// NCO frequency held over the interval minus the true mean Doppler over it, Hz.
    pub doppler_error_hz: f64,
    /// Replica code phase minus true code phase at `t_s`, chips, wrapped into +-511.5.
    pub code_error_chips: f64,
}

/// What [`track_vs_truth`] returns per channel.
#[derive(Debug, Clone)]
pub struct ChannelTrace {
    /// The satellite.
    pub prn: u8,
    /// Index of the channel's [`ChannelSpec`].
    pub spec_index: usize,
    /// Every integration interval, in time order.
    pub epochs: Vec<EpochVsTruth>,
    /// The channel's state when the source ended.
    pub final_state: ChannelState,
}

/// Wraps a code-phase difference into +-511.5 chips.
pub fn wrap_code_chips(d: f64) -> f64 {
    let n = CA_CODE_LENGTH as f64;
    (d + 0.5 * n).rem_euclid(n) - 0.5 * n
}

/// Runs one channel per `spec` over `src` (all in one pass, see [`track`]), every channel
/// started from truth, with the Doppler `aid` if given, and compares each integration interval
/// with `truth`.
pub fn track_vs_truth(
    src: &mut dyn SampleSource,
    sim: &Simulator,
    truth: &Truth,
    specs: &[ChannelSpec],
    aid: Option<AidSource<'_>>,
) -> anyhow::Result<Vec<ChannelTrace>> {
    let fs = src.fs_hz();
    let mut channels = Vec::with_capacity(specs.len());
    let mut traces = Vec::with_capacity(specs.len());
    let mut sat_truth = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let sat = sim
            .satellites
            .iter()
            .find(|s| s.prn.get() == spec.prn)
            .with_context(|| format!("G{:02} is not simulated", spec.prn))?;
        let st = truth
            .get(spec.prn)
            .with_context(|| format!("no truth for G{:02}", spec.prn))?;
        let start = start_from_truth(sim, sat, fs, spec.doppler_offset_hz);
        channels.push(
            Channel::new(&start, fs, &spec.config)
                .with_context(|| format!("channel {i} (G{:02})", spec.prn))?,
        );
        sat_truth.push(st);
        traces.push(ChannelTrace {
            prn: spec.prn,
            spec_index: i,
            epochs: Vec::new(),
            final_state: ChannelState::PullIn,
        });
    }
    let final_channels = track(src, channels, aid, |i, e| {
        let st = sat_truth[i];
        let t1 = e.t_rx_s + e.t_coh_s;
        let code_error_chips = wrap_code_chips(
            e.code_phase_chips - st.chips(e.t_rx_s).rem_euclid(CA_CODE_LENGTH as f64),
        );
        traces[i].epochs.push(EpochVsTruth {
            t_s: e.t_rx_s,
            t_coh_s: e.t_coh_s,
            state: e.state,
            pll_lock: e.pll_lock,
            cn0_dbhz: e.cn0_dbhz,
            phase_diff_cycles: e.carrier_phase_cycles - st.carrier_cycles(e.t_rx_s),
            doppler_error_hz: e.doppler_hz - st.mean_doppler_hz(e.t_rx_s, t1),
            code_error_chips,
        });
    })?;
    for (t, ch) in traces.iter_mut().zip(&final_channels) {
        t.final_state = ch.state();
    }
    Ok(traces)
}

/// Mean of `v` (NaN when empty).
pub fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.iter().sum::<f64>() / v.len() as f64
}

/// Sample standard deviation of `v` (n - 1 in the denominator; NaN for fewer than two values).
pub fn std_dev(v: &[f64]) -> f64 {
    if v.len() < 2 {
        return f64::NAN;
    }
    let m = mean(v);
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() as f64 - 1.0)).sqrt()
}

/// Circular mean of phases modulo `period` cycles: `arg(sum exp(j 2 pi x/period)) period/(2 pi)`.
fn circular_mean(v: &[f64], period: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI / period;
    let (s, c) = v.iter().fold((0.0, 0.0), |(s, c), x| {
        (s + (w * x).sin(), c + (w * x).cos())
    });
    s.atan2(c) / w
}

/// Carrier phase errors in degrees from NCO-minus-truth phase differences (cycles) of a Costas
/// loop: the constant offset is removed modulo the half-cycle ambiguity and each value folded
/// into +-1/4 cycle, `f_k = ((d_k - m + 1/4) mod 1/2) - 1/4` with `m` the circular mean of
/// `d` modulo 1/2 cycle; then the mean of `f` (and with `detrend`, a least-squares straight
/// line: the slowly varying steady-state error of an unaided loop under the satellite's own
/// LOS acceleration) is removed. Values in degrees (x 360).
pub fn folded_phase_deg(phase_diff_cycles: &[f64], detrend: bool) -> Vec<f64> {
    if phase_diff_cycles.is_empty() {
        return Vec::new();
    }
    let m = circular_mean(phase_diff_cycles, 0.5);
    let folded: Vec<f64> = phase_diff_cycles
        .iter()
        .map(|d| (d - m + 0.25).rem_euclid(0.5) - 0.25)
        .collect();
    let n = folded.len() as f64;
    let fm = mean(&folded);
    let slope = if detrend && folded.len() > 2 {
        let tm = (n - 1.0) / 2.0;
        let sxx: f64 = (0..folded.len()).map(|i| (i as f64 - tm).powi(2)).sum();
        let sxy: f64 = folded
            .iter()
            .enumerate()
            .map(|(i, y)| (i as f64 - tm) * y)
            .sum();
        sxy / sxx
    } else {
        0.0
    };
    let tm = (n - 1.0) / 2.0;
    folded
        .iter()
        .enumerate()
        .map(|(i, y)| (y - fm - slope * (i as f64 - tm)) * 360.0)
        .collect()
}

/// Number of half-cycle slips in NCO-minus-truth phase differences (cycles): the differences
/// are averaged over blocks of `block` epochs, each block mean is assigned to its half-cycle
/// branch `round((mean - m) / (1/2))` (`m` the circular mean modulo 1/2 cycle), and every change
/// of branch between consecutive blocks counts. A locked Costas loop stays on one branch.
pub fn half_cycle_slips(phase_diff_cycles: &[f64], block: usize) -> usize {
    let block = block.max(1);
    if phase_diff_cycles.len() < block {
        return 0;
    }
    let m = circular_mean(phase_diff_cycles, 0.5);
    let branches: Vec<i64> = phase_diff_cycles
        .chunks_exact(block)
        .map(|c| ((mean(c) - m) / 0.5).round() as i64)
        .collect();
    branches.windows(2).filter(|w| w[0] != w[1]).count()
}

/// Rate errors from phase differences: `(d_{j+m} - d_j) / (m T)` for `j = 0, m, 2m, ...`
/// (non-overlapping, as a receiver that outputs the carrier-phase change over its observable
/// interval `m T`), in the units of `d` per second.
pub fn differenced_rate(d: &[f64], m: usize, t_s: f64) -> Vec<f64> {
    let m = m.max(1);
    d.iter()
        .step_by(m)
        .collect::<Vec<_>>()
        .windows(2)
        .map(|w| (w[1] - w[0]) / (m as f64 * t_s))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folding_removes_offset_and_half_cycles() {
        // Offset 0.3 cycle, a half-cycle jump halfway, +-0.01 cycle alternating noise.
        let d: Vec<f64> = (0..100)
            .map(|i| 0.3 + if i >= 50 { 0.5 } else { 0.0 } + if i % 2 == 0 { 0.01 } else { -0.01 })
            .collect();
        let f = folded_phase_deg(&d, false);
        assert!(f.iter().all(|x| (x.abs() - 3.6).abs() < 1e-9), "{f:?}");
        assert_eq!(half_cycle_slips(&d, 10), 1);
        assert_eq!(half_cycle_slips(&d[..50], 10), 0);
        // A linear drift is removed with detrend.
        let d: Vec<f64> = (0..100).map(|i| 0.1 + 1e-4 * i as f64).collect();
        let f = folded_phase_deg(&d, true);
        assert!(f.iter().all(|x| x.abs() < 1e-9));
    }

    #[test]
    fn differenced_rate_and_wrap() {
        let d: Vec<f64> = (0..11).map(|i| 2.0 * i as f64 * 1e-3).collect();
        let r = differenced_rate(&d, 5, 1e-3);
        assert_eq!(r.len(), 2);
        assert!(r.iter().all(|x| (x - 2.0).abs() < 1e-9));
        assert!((wrap_code_chips(1022.9) + 0.1).abs() < 1e-9);
        assert!((wrap_code_chips(-0.2) + 0.2).abs() < 1e-9);
        assert!((std_dev(&[1.0, 3.0]) - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn sim_source_delivers_the_simulators_samples_in_order() -> anyhow::Result<()> {
        let text = scenario_toml(
            0.25,
            3,
            2.5e6,
            &static_receiver(SEOUL_LLH),
            &satellites_with_cn0(&[(26, 45.0)]),
            "",
        );
        let sim = simulator(&text)?;
        let mut src = SimSource::new(&sim);
        let mut all = Vec::new();
        let mut buf = vec![Complex32::new(0.0, 0.0); 100_003];
        loop {
            let (first, n) = src.read(&mut buf)?;
            if n == 0 {
                break;
            }
            assert_eq!(first, all.len() as u64);
            all.extend_from_slice(&buf[..n]);
        }
        assert_eq!(all.len() as u64, sim.total_samples());
        let mut chunk = Vec::new();
        sim.generate_chunk(1, &mut chunk);
        let c = sim.chunk_samples();
        assert_eq!(&all[c..c + chunk.len()], &chunk[..]);
        // Truth: interpolation between nodes reproduces the model within a micro-cycle.
        let truth = Truth::new(&sim);
        let (o, _) = sim.observe(&sim.satellites[0], 0.1234567);
        let st = &truth.sats[0];
        assert!((st.carrier_cycles(0.1234567) - o.carrier_cycles).abs() < 1e-5);
        assert!((st.chips(0.1234567) - o.chips).abs() < 1e-6);
        Ok(())
    }
}
