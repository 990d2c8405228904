//! `gpsrx study dynamics`: high-dynamics tracking, unaided and INS-aided (seed 004, Sec. IV).
//!
//! Seed 004 flew a 10 g manoeuvre through a GPS signal simulator: an unaided 2nd-order PLL kept
//! as few as 4 satellites (Fig. 12), the INS-aided one kept all of them (Fig. 15), and with two
//! INS whose accelerometer biases differ by 2x the aided 2nd-order loop's phase error std was
//! the same (Table 3: 0.085-0.101 cycle). This study reproduces the experiment on simulated IF:
//!
//! - **Scenarios**: one per (manoeuvre, C/N0). A vehicle cruising at [`SPEED_MPS`] for
//!   [`LEAD_IN_S`] (channels started from truth pull in and hand over), then a jerk-limited
//!   manoeuvre (a level turn at `N g` for [`TURN_S`], or a longitudinal acceleration step at
//!   `N g` for [`STEP_S`]; acceleration ramped over [`RAMP_S`] in and out), then a cruise to
//!   [`DURATION_S`]. Every visible satellite at one C/N0, complex float samples at [`FS_HZ`]
//!   generated in memory by [`gpsrx_samples::sim`], a white-FM oscillator of Allan deviation
//!   [`ALLAN_DEVIATION_1S`] at 1 s. Each scenario is simulated once and tracked by every
//!   loop/aiding case (cases in parallel, [`super::run_cases`]).
//! - **Aiding**: the receiver's own feed-forward
//!   ([`crate::pipeline::aiding::InsFeedForward`], the path of `gpsrx run --ins`) fed by an INS
//!   made from the truth trajectory by [`gpsrx_ins_aiding::simulate_ins`] with an accelerometer
//!   bias `B` (INS 1, magnitude [`INS1_BIAS_MPS2`]) or `2B` (INS 2), along `(1, 1, 1)/sqrt(3)` in
//!   east-north-up; the navigation data are the scenario's RINEX file; a fix at `t = 0` gives
//!   the feed-forward the receiver position and clock drift, as a navigation solution would.
//! - **Theory** (seed 004 eqs. 12-16, `oracles.md`): the bias makes a velocity error `B t`, a
//!   Doppler error ramp `B_V t / lambda` with `B_V = B . u` its line-of-sight part. A
//!   1st-order loop (`omega0 = Bn/0.25`) then lags by a growing
//!   `theta_1(t) = 360 B_V t / (lambda omega0)` deg; a 2nd-order loop (`omega0 = Bn/0.53`)
//!   settles at the constant `theta_2 = 360 B_V / (lambda omega0^2)` deg, which a mean removal
//!   takes out of the std, so the std does not depend on the bias; a 3rd-order loop has no
//!   error at all. (Seed 004 Table 1 writes the 1st-order, bias, "speed input" entry as the
//!   constant `(1 + B_V/lambda)/omega_n`; the derivation above, confirmed here by the
//!   measured growth, gives the ramp: the bias is a Doppler *ramp*, not a step.)
//!
//! Per case: satellites tracked (channel in `Track` with the PLL lock indicator on) every
//! [`TICK_S`] through the manoeuvre window (min, mean, kept throughout), loss-of-lock events,
//! the phase error std against the simulator's true carrier phase, the Costas discriminator's
//! std (what seed 004 Table 3 measured with `atan(Q/I)`), the mean discriminator error against
//! `theta_1`/`theta_2`, and the pseudorange-rate error std.

use super::if_sim::{self, Truth};
use super::report::{fmt, LinePlot, Series, StudyReport, Table};
use super::{run_cases, CommonStudyArgs};
use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::tracker::{track, AidSource};
use anyhow::Context;
use gpsrx_dsp::constants::{LAMBDA_L1_M, SPEED_OF_LIGHT_MPS};
use gpsrx_ins_aiding::{
    read_ins_csv, simulate_ins, write_ins_csv, InsErrorConfig, InsTrack, TruthState,
};
use gpsrx_nav::rinex_nav::{parse_rinex_nav, NavData};
use gpsrx_samples::sim::trajectory::G0_MPS2;
use gpsrx_samples::sim::Simulator;
use gpsrx_samples::{SampleError, SampleFormat, SampleSource};
use gpsrx_tracking::loop_filter::BN_OVER_OMEGA0;
use gpsrx_tracking::{Channel, ChannelEpoch, ChannelStart, ChannelState};
use num_complex::Complex32;
use rayon::prelude::*;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// `gpsrx study dynamics` options.
#[derive(Debug, Clone, clap::Args)]
pub struct DynamicsArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
}

/// GPS time of week of the first sample (week 2190, 2022-01-01 14:00 GPS time: 12 satellites
/// above 5 deg at Seoul, 10 of them healthy; G22 and G28 are flagged unhealthy), s.
pub const START_TOW_S: f64 = 568_800.0;
/// Sampling rate of the simulated IF (complex baseband), Hz.
pub const FS_HZ: f64 = 2.048e6;
/// Vehicle speed before the manoeuvre, m/s (an aircraft: a 10 g turn at 200 m/s turns at
/// `a / v` = 0.49 rad/s, so the line-of-sight jerk is `a^2 / v` = 48 m/s^3).
pub const SPEED_MPS: f64 = 200.0;
/// Cruise before the manoeuvre, s.
pub const LEAD_IN_S: f64 = 4.0;
/// Acceleration ramp in and out of the manoeuvre (bounded jerk), s.
pub const RAMP_S: f64 = 1.0;
/// Length of a turn segment (ramp-in included), s.
pub const TURN_S: f64 = 8.0;
/// Length of an acceleration-step segment (ramp-in included), s.
pub const STEP_S: f64 = 4.0;
/// Recording length, s.
pub const DURATION_S: f64 = 15.0;
/// Allan deviation of the receiver oscillator at 1 s (white FM): a quiet OCXO-class
/// oscillator. `oracles.md`: the oscillator jitter of a 2nd-order loop is about
/// `144 sigma_A f_L1 / Bn` = 1.1 deg at 2 Hz, comparable to the thermal jitter.
pub const ALLAN_DEVIATION_1S: f64 = 1.0e-11;
/// Nominal receiver clock drift, s/s (shifts every Doppler by `-f_L1 d` = -47 Hz).
pub const CLOCK_DRIFT_S_S: f64 = 3.0e-8;
/// Accelerometer bias magnitude of INS 1, m/s^2 (about 5 mg; INS 2 has twice it). INS 2's
/// 2nd-order steady-state error `360 B_V / (lambda omega0^2)` is up to 5.9 deg at 3 Hz and 13
/// deg at 2 Hz (the narrowest Bn): clearly visible in the mean, not lock-breaking.
pub const INS1_BIAS_MPS2: f64 = 0.05;
/// INS output rate, Hz.
pub const INS_RATE_HZ: f64 = 100.0;
/// Sampling interval of the satellites-tracked count, s.
pub const TICK_S: f64 = 0.1;
/// Bandwidth of the 2nd-order loop of the headline comparison, Hz. Seed 004 used 0.4 Hz, which
/// cannot follow the satellites' own line-of-sight acceleration (up to about 0.18 m/s^2)
/// unaided: the steady-state error `0.2809 a / Bn^2` is 1.7 cycles at 0.4 Hz, 23 deg at 2 Hz
/// (at the lock indicator's 22.8 deg threshold) and 10 deg at 3 Hz, the narrowest unaided loop
/// that holds every satellite before the manoeuvre.
pub const HEADLINE_BN_HZ: f64 = 3.0;
/// Bandwidth of the aided 1st-order loops, Hz: wide enough that INS 2's growing error
/// `theta_1(t)` stays inside the Costas discriminator's linear range to the end of the run.
pub const ORDER1_BN_HZ: f64 = 18.0;
/// Fewest samples for a per-channel statistic.
const MIN_SAMPLES: usize = 100;
/// Epochs in Track over which the hand-over frequency error is averaged (20 ms at T = 1 ms).
const HANDOVER_EPOCHS: usize = 20;
/// Block length of the cycle-slip test ([`if_sim::half_cycle_slips`]), epochs (20 ms).
const SLIP_BLOCK_EPOCHS: usize = 20;

/// A manoeuvre after the lead-in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Manoeuvre {
    /// Level turn to the left at this centripetal acceleration, g.
    Turn(f64),
    /// Longitudinal acceleration step of this size, g.
    Step(f64),
}

impl Manoeuvre {
    /// Acceleration, g.
    pub fn g(&self) -> f64 {
        match self {
            Self::Turn(g) | Self::Step(g) => *g,
        }
    }

    /// Short name: `10 g turn`.
    pub fn label(&self) -> String {
        match self {
            Self::Turn(g) => format!("{g} g turn"),
            Self::Step(g) => format!("{g} g step"),
        }
    }

    /// Length of the manoeuvre segment, s.
    fn segment_s(&self) -> f64 {
        match self {
            Self::Turn(_) => TURN_S,
            Self::Step(_) => STEP_S,
        }
    }

    /// The window the statistics cover: from the start of the ramp-in to the end of the
    /// ramp-out, s.
    pub fn window_s(&self) -> (f64, f64) {
        (LEAD_IN_S, LEAD_IN_S + self.segment_s() + RAMP_S)
    }

    fn segments_toml(&self) -> String {
        let seg = match self {
            Self::Turn(g) => format!(
                "{{ type = \"turn\", duration_s = {TURN_S:?}, accel_g = {g:?}, direction = \"left\" }}"
            ),
            Self::Step(g) => format!(
                "{{ type = \"accelerate\", duration_s = {STEP_S:?}, accel_mps2 = {:?} }}",
                g * G0_MPS2
            ),
        };
        let rest = DURATION_S - LEAD_IN_S - self.segment_s() + 2.0;
        format!(
            "[{{ type = \"cruise\", duration_s = {LEAD_IN_S:?} }}, {seg}, {{ type = \"cruise\", duration_s = {rest:?} }}]"
        )
    }
}

/// How a case's carrier loop is aided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aiding {
    /// No feed-forward.
    Unaided,
    /// INS with accelerometer bias `B`.
    Ins1,
    /// INS with accelerometer bias `2B`.
    Ins2,
}

impl Aiding {
    /// Name in the table and the summary.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Unaided => "unaided",
            Self::Ins1 => "INS 1",
            Self::Ins2 => "INS 2",
        }
    }

    fn key(&self) -> &'static str {
        match self {
            Self::Unaided => "unaided",
            Self::Ins1 => "ins1",
            Self::Ins2 => "ins2",
        }
    }

    /// Accelerometer bias magnitude, m/s^2 (0 unaided).
    pub fn bias_mps2(&self) -> f64 {
        match self {
            Self::Unaided => 0.0,
            Self::Ins1 => INS1_BIAS_MPS2,
            Self::Ins2 => 2.0 * INS1_BIAS_MPS2,
        }
    }
}

/// Unit direction of the accelerometer bias, east-north-up.
fn bias_direction_enu() -> [f64; 3] {
    let k = 1.0 / 3f64.sqrt();
    [k, k, k]
}

/// One scenario: a manoeuvre at one C/N0.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ScenarioSpec {
    manoeuvre: Manoeuvre,
    cn0_dbhz: f64,
}

/// One tracking run over a scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Case {
    order: u8,
    bn_hz: f64,
    aiding: Aiding,
}

/// The grid: scenarios and, for each, the cases.
fn grid(quick: bool) -> (Vec<ScenarioSpec>, Vec<Case>) {
    let (manoeuvres, cn0s, loops): (Vec<Manoeuvre>, Vec<f64>, Vec<(u8, f64)>) = if quick {
        (
            vec![Manoeuvre::Turn(10.0)],
            vec![45.0],
            vec![(2, HEADLINE_BN_HZ)],
        )
    } else {
        let loops = [2u8, 3]
            .iter()
            .flat_map(|&o| [2.0, HEADLINE_BN_HZ, 5.0, 10.0, 18.0].map(|bn| (o, bn)))
            .collect();
        (
            vec![
                Manoeuvre::Turn(1.0),
                Manoeuvre::Turn(5.0),
                Manoeuvre::Turn(10.0),
                Manoeuvre::Turn(20.0),
                Manoeuvre::Step(10.0),
            ],
            vec![35.0, 45.0],
            loops,
        )
    };
    let scenarios = manoeuvres
        .iter()
        .flat_map(|&m| {
            cn0s.iter().map(move |&c| ScenarioSpec {
                manoeuvre: m,
                cn0_dbhz: c,
            })
        })
        .collect();
    let mut cases: Vec<Case> = loops
        .iter()
        .flat_map(|&(order, bn_hz)| {
            [Aiding::Unaided, Aiding::Ins1, Aiding::Ins2].map(|aiding| Case {
                order,
                bn_hz,
                aiding,
            })
        })
        .collect();
    for aiding in [Aiding::Ins1, Aiding::Ins2] {
        cases.push(Case {
            order: 1,
            bn_hz: ORDER1_BN_HZ,
            aiding,
        });
    }
    (scenarios, cases)
}

/// The scenario file of a spec (motion receiver near Seoul, every visible satellite).
fn scenario_toml(spec: &ScenarioSpec, seed: u64, prns: Option<&[u8]>) -> String {
    let prns = prns.map_or(String::new(), |p| format!("prns = {p:?}\n"));
    format!(
        r#"description = "gpsrx study dynamics: {label} at {cn0} dB-Hz"
duration_s = {DURATION_S:?}
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
allan_deviation_1s = {ALLAN_DEVIATION_1S:e}
[satellites]
{prns}cn0_all_dbhz = {cn0:?}
[truth]
rate_hz = 1.0
"#,
        label = spec.manoeuvre.label(),
        cn0 = spec.cn0_dbhz,
        segments = spec.manoeuvre.segments_toml(),
    )
}

/// Complex baseband samples held in memory, read like a recording. Each scenario is generated
/// once (246 MB at 2.048 MHz for 15 s) and replayed for its 5 to 32 cases, which costs far less
/// than generating it again per case with [`if_sim::SimSource`].
struct MemSource<'a> {
    data: &'a [Complex32],
    pos: usize,
    format: SampleFormat,
}

impl SampleSource for MemSource<'_> {
    fn fs_hz(&self) -> f64 {
        FS_HZ
    }

    fn format(&self) -> &SampleFormat {
        &self.format
    }

    fn total_samples(&self) -> Option<u64> {
        Some(self.data.len() as u64)
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let n = out.len().min(self.data.len() - self.pos);
        out[..n].copy_from_slice(&self.data[self.pos..self.pos + n]);
        let first = self.pos as u64;
        self.pos += n;
        Ok((first, n))
    }

    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}

/// A simulated scenario, ready to be tracked many times.
struct Prepared {
    spec: ScenarioSpec,
    samples: Vec<Complex32>,
    /// Per satellite (in the simulator's order): true code and carrier phase.
    truth: Truth,
    /// Per satellite: the channel start from truth.
    starts: Vec<ChannelStart>,
    /// Per satellite: unit vector receiver -> satellite (east, north, up) mid-window.
    los_enu: Vec<[f64; 3]>,
    /// Feed-forwards of INS 1 and INS 2.
    feedforwards: [InsFeedForward; 2],
}

impl Prepared {
    /// True carrier phase (cycles) of satellite `sat` at receiver time `t_s`, linear between
    /// 1 ms nodes (the curvature error `a T^2 / (8 lambda)` is 6e-5 cycle at 10 g).
    fn truth_cycles(&self, sat: usize, t_s: f64) -> f64 {
        self.truth.sats[sat].carrier_cycles(t_s)
    }

    /// True mean Doppler of satellite `sat` over `[t0_s, t1_s]`, Hz.
    fn truth_doppler_hz(&self, sat: usize, t0_s: f64, t1_s: f64) -> f64 {
        self.truth.sats[sat].mean_doppler_hz(t0_s, t1_s)
    }
}

/// Simulates a scenario into memory and prepares truth, channel starts and the INS aiding.
fn prepare(spec: &ScenarioSpec, seed: u64, tmp: &Path) -> anyhow::Result<Prepared> {
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
    let (w0, w1) = spec.manoeuvre.window_s();
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
    let feedforwards = [
        feedforward(&sim, &nav, Aiding::Ins1, seed, tmp)?,
        feedforward(&sim, &nav, Aiding::Ins2, seed, tmp)?,
    ];
    Ok(Prepared {
        spec: *spec,
        samples,
        truth,
        starts,
        los_enu,
        feedforwards,
    })
}

/// The INS of `aiding` made from the simulator's truth (bias only: the effect studied), as the
/// receiver's feed-forward would use it after a fix at `t = 0`.
fn feedforward(
    sim: &Simulator,
    nav: &NavData,
    aiding: Aiding,
    seed: u64,
    tmp: &Path,
) -> anyhow::Result<InsFeedForward> {
    let b = aiding.bias_mps2();
    let d = bias_direction_enu();
    let cfg = InsErrorConfig {
        rate_hz: INS_RATE_HZ,
        accel_bias_enu_mps2: [b * d[0], b * d[1], b * d[2]],
        seed,
        ..InsErrorConfig::default()
    };
    let env = &sim.env;
    let truth = |t: f64| {
        let s = env.trajectory.state(env.clock.true_time(t));
        TruthState {
            t_s: t,
            gps_tow_s: None,
            pos_m: s.pos_m,
            vel_mps: s.vel_mps,
        }
    };
    let samples = simulate_ins(&truth, DURATION_S + 0.5, &cfg)?;
    let track = ins_track(&samples, &tmp.join(format!("{}.csv", aiding.key())))?;
    let ff = InsFeedForward::new(track, Some(nav.clone()), env.start.week, None);
    ff.set_time_origin(env.start);
    ff.set_fix(
        0.0,
        truth(0.0).pos_m,
        Some(CLOCK_DRIFT_S_S * SPEED_OF_LIGHT_MPS),
    );
    Ok(ff)
}

/// An [`InsTrack`] from samples, through the INS file format (the crate has no constructor
/// from samples).
fn ins_track(samples: &[gpsrx_ins_aiding::InsSample], path: &Path) -> anyhow::Result<InsTrack> {
    write_ins_csv(path, samples)?;
    Ok(read_ins_csv(path, 0.5)?)
}

/// What one channel saw.
#[derive(Debug, Clone, Default)]
struct ChannelLog {
    /// Tracked (Track state and PLL lock) at the end of each tick.
    ticks: Vec<bool>,
    tracked: bool,
    lock_drops: u32,
    lost: bool,
    /// In the window, while tracked: NCO minus true carrier phase, cycles.
    phase_cycles: Vec<f64>,
    /// Costas discriminator output, cycles.
    disc_cycles: Vec<f64>,
    /// NCO minus true Doppler, times lambda, m/s.
    prr_mps: Vec<f64>,
    /// In the window, in the Track state (locked or not: the Costas discriminator `atan(Q/I)`
    /// is the phase error up to +-90 deg): receive time (s) and discriminator (cycles), for the
    /// mean error and its growth.
    track_t_s: Vec<f64>,
    track_disc_cycles: Vec<f64>,
    /// NCO minus true carrier phase at those epochs, cycles (not folded: a cycle slip shows as
    /// a jump of half a cycle or more).
    track_phase_cycles: Vec<f64>,
    /// Sum and count of the NCO-minus-true Doppler over the first [`HANDOVER_EPOCHS`] epochs in
    /// Track (the frequency error the tracking loop starts with), Hz.
    handover_df_sum_hz: f64,
    handover_epochs: usize,
}

/// The result of one case.
#[derive(Debug, Clone)]
struct CaseResult {
    spec: ScenarioSpec,
    case: Case,
    satellites: usize,
    tracked_at_start: usize,
    tracked_min: usize,
    tracked_mean: f64,
    kept: usize,
    tracked_at_end: usize,
    lock_drops: u32,
    channels_lost: usize,
    phase_std_cycles: f64,
    disc_std_cycles: f64,
    disc_mean_abs_deg: f64,
    predicted_mean_abs_deg: f64,
    growth_abs_deg_s: f64,
    predicted_growth_deg_s: f64,
    /// Satellites in the bias statistics.
    bias_channels: usize,
    /// RMS over channels of the NCO frequency error at the pull-in -> track hand-over, Hz.
    handover_df_rms_hz: f64,
    prr_std_mps: f64,
    /// Satellites tracked per tick over the whole run.
    tracked_per_tick: Vec<usize>,
}

/// Tracks every satellite of `p` with the loops and aiding of `case`.
fn run_case(p: &Prepared, case: &Case) -> anyhow::Result<CaseResult> {
    // The default pull-in, then the case's PLL (no FLL), a 1 Hz 1st-order carrier-aided DLL,
    // T = 1 ms.
    let cfg = if_sim::track_config(case.order, case.bn_hz, 1e-3, 1.0);
    let channels = p
        .starts
        .iter()
        .map(|s| Channel::new(s, FS_HZ, &cfg))
        .collect::<Result<Vec<_>, _>>()?;
    let n_ticks = (DURATION_S / TICK_S).round() as usize;
    let mut logs = vec![
        ChannelLog {
            ticks: vec![false; n_ticks],
            ..ChannelLog::default()
        };
        channels.len()
    ];
    let (w0, w1) = p.spec.manoeuvre.window_s();
    let mut src = MemSource {
        data: &p.samples,
        pos: 0,
        format: SampleFormat::Cf32Le,
    };
    let ff = match case.aiding {
        Aiding::Unaided => None,
        Aiding::Ins1 => Some(&p.feedforwards[0]),
        Aiding::Ins2 => Some(&p.feedforwards[1]),
    };
    let aid_fn = |prn: u8, t: f64| ff.and_then(|f| f.aid(prn, t));
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

/// Mean and sum of squared deviations.
fn mean_ss(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (m, v.iter().map(|x| (x - m).powi(2)).sum())
}

/// Pooled standard deviation of several series, each about its own mean:
/// `sqrt(sum_i sum_k (x_ik - mean_i)^2 / sum_i (n_i - 1))`; series shorter than
/// [`MIN_SAMPLES`] are left out; NaN when none is left.
fn pooled_std<'a>(series: impl Iterator<Item = &'a [f64]>) -> f64 {
    let (mut ss, mut dof) = (0.0, 0.0);
    for v in series.filter(|v| v.len() >= MIN_SAMPLES) {
        ss += mean_ss(v).1;
        dof += v.len() as f64 - 1.0;
    }
    if dof > 0.0 {
        (ss / dof).sqrt()
    } else {
        f64::NAN
    }
}

/// Least-squares line `y = a + s t`: returns (mean of y, slope s).
fn mean_and_slope(t: &[f64], y: &[f64]) -> (f64, f64) {
    let n = t.len() as f64;
    let (tm, ym) = (t.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sty, mut stt) = (0.0, 0.0);
    for (ti, yi) in t.iter().zip(y) {
        sty += (ti - tm) * (yi - ym);
        stt += (ti - tm) * (ti - tm);
    }
    (ym, if stt > 0.0 { sty / stt } else { f64::NAN })
}

/// The INS-bias error of an aided case, measured and predicted, averaged over the satellites
/// that were in Track for at least half of the window without a cycle slip (NaN unaided, or
/// when there is none).
#[derive(Debug, Clone, Copy)]
struct BiasStats {
    /// Mean over satellites of |mean discriminator error|, deg.
    mean_abs_deg: f64,
    /// Its theory, deg.
    predicted_deg: f64,
    /// Mean over satellites of |least-squares slope of the discriminator error|, deg/s.
    growth_deg_s: f64,
    /// Its theory, deg/s.
    predicted_growth_deg_s: f64,
    /// Satellites used.
    channels: usize,
}

/// [`BiasStats`] of a case.
///
/// Theory (seed 004 eqs. 12-16, re-derived): the bias `B` gives a Doppler error
/// `B_V t / lambda` with `B_V = B . u` (`u` receiver to satellite, `t` from the INS start).
/// 1st order: error `360 B_V t / (lambda omega0)` deg, mean at the mean time of the epochs
/// used, growth `360 B_V / (lambda omega0)` deg/s; 2nd order: constant
/// `360 B_V / (lambda omega0^2)`, no growth; 3rd order: none. The measured mean also holds any
/// constant frequency offset the loop carries (a 1st-order loop keeps the one it was handed
/// over with); the growth does not.
fn bias_theory(p: &Prepared, case: &Case, logs: &[ChannelLog]) -> BiasStats {
    let none = BiasStats {
        mean_abs_deg: f64::NAN,
        predicted_deg: f64::NAN,
        growth_deg_s: f64::NAN,
        predicted_growth_deg_s: f64::NAN,
        channels: 0,
    };
    if case.aiding == Aiding::Unaided {
        return none;
    }
    let (w0, w1) = p.spec.manoeuvre.window_s();
    let min_epochs = (0.5 * (w1 - w0) * 1e3) as usize;
    let d = bias_direction_enu();
    let b = case.aiding.bias_mps2();
    let omega0 = case.bn_hz / BN_OVER_OMEGA0[usize::from(case.order.clamp(1, 3)) - 1];
    let mut acc = [0.0; 4];
    let mut n = 0.0;
    for (l, u) in logs.iter().zip(&p.los_enu) {
        if l.track_t_s.len() < min_epochs.max(MIN_SAMPLES)
            || if_sim::half_cycle_slips(&l.track_phase_cycles, SLIP_BLOCK_EPOCHS) > 0
        {
            continue;
        }
        let (m, slope) = mean_and_slope(&l.track_t_s, &l.track_disc_cycles);
        let b_v = b * (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]);
        let t_mean = l.track_t_s.iter().sum::<f64>() / l.track_t_s.len() as f64;
        let (pred, pred_growth) = match case.order {
            1 => (
                360.0 * b_v * t_mean / (LAMBDA_L1_M * omega0),
                360.0 * b_v / (LAMBDA_L1_M * omega0),
            ),
            2 => (360.0 * b_v / (LAMBDA_L1_M * omega0 * omega0), 0.0),
            _ => (0.0, 0.0),
        };
        for (a, v) in acc
            .iter_mut()
            .zip([m * 360.0, pred, slope * 360.0, pred_growth])
        {
            *a += v.abs();
        }
        n += 1.0;
    }
    if n > 0.0 {
        BiasStats {
            mean_abs_deg: acc[0] / n,
            predicted_deg: acc[1] / n,
            growth_deg_s: acc[2] / n,
            predicted_growth_deg_s: acc[3] / n,
            channels: n as usize,
        }
    } else {
        none
    }
}

fn summarise(p: &Prepared, case: &Case, logs: &[ChannelLog]) -> CaseResult {
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

/// Runs the study.
pub fn run(args: &DynamicsArgs, progress: bool) -> anyhow::Result<StudyReport> {
    let started = Instant::now();
    let (scenarios, cases) = grid(args.common.quick);
    let tmp = tempfile::tempdir().context("cannot create a temporary directory")?;
    let mut results = Vec::new();
    for (k, spec) in scenarios.iter().enumerate() {
        let p = prepare(spec, args.common.seed, tmp.path())?;
        let what = format!(
            "dynamics {}/{}: {} at {} dB-Hz",
            k + 1,
            scenarios.len(),
            spec.manoeuvre.label(),
            spec.cn0_dbhz
        );
        for r in run_cases(&cases, &what, progress, |c| run_case(&p, c)) {
            results.push(r?);
        }
    }
    Ok(build_report(
        args,
        &results,
        started.elapsed().as_secs_f64(),
    ))
}

/// The headline configuration: 10 g turn at the highest C/N0 of the grid.
fn headline(results: &[CaseResult], order: u8, bn_hz: f64, aiding: Aiding) -> Option<&CaseResult> {
    let cn0 = results
        .iter()
        .map(|r| r.spec.cn0_dbhz)
        .fold(f64::NEG_INFINITY, f64::max);
    results.iter().find(|r| {
        r.spec.manoeuvre == Manoeuvre::Turn(10.0)
            && r.spec.cn0_dbhz == cn0
            && r.case.order == order
            && r.case.bn_hz == bn_hz
            && r.case.aiding == aiding
    })
}

fn result_json(r: &CaseResult) -> serde_json::Value {
    let num = json_num;
    json!({
        "manoeuvre": r.spec.manoeuvre.label(),
        "g": r.spec.manoeuvre.g(),
        "cn0_dbhz": r.spec.cn0_dbhz,
        "order": r.case.order,
        "bn_hz": r.case.bn_hz,
        "aiding": r.case.aiding.key(),
        "satellites": r.satellites,
        "tracked_at_start": r.tracked_at_start,
        "tracked_min": r.tracked_min,
        "tracked_mean": num(r.tracked_mean),
        "kept": r.kept,
        "tracked_at_end": r.tracked_at_end,
        "lock_drops": r.lock_drops,
        "channels_lost": r.channels_lost,
        "phase_std_cycles": num(r.phase_std_cycles),
        "disc_std_cycles": num(r.disc_std_cycles),
        "mean_abs_phase_error_deg": num(r.disc_mean_abs_deg),
        "predicted_mean_abs_phase_error_deg": num(r.predicted_mean_abs_deg),
        "phase_error_growth_deg_s": num(r.growth_abs_deg_s),
        "predicted_phase_error_growth_deg_s": num(r.predicted_growth_deg_s),
        "bias_stats_satellites": r.bias_channels,
        "handover_df_rms_hz": num(r.handover_df_rms_hz),
        "prr_std_mps": num(r.prr_std_mps),
    })
}

fn table(results: &[CaseResult]) -> Table {
    let mut t = Table::new(&[
        "manoeuvre",
        "C/N0 (dB-Hz)",
        "order",
        "Bn (Hz)",
        "aiding",
        "sats at start",
        "tracked min",
        "tracked mean",
        "kept",
        "lock drops",
        "lost",
        "phase std (cycle)",
        "disc. std (cycle)",
        "mean abs phase err (deg)",
        "predicted (deg)",
        "growth (deg/s)",
        "predicted growth (deg/s)",
        "PRR std (m/s)",
        "hand-over df rms (Hz)",
    ]);
    for r in results {
        t.push(vec![
            r.spec.manoeuvre.label(),
            fmt(r.spec.cn0_dbhz, 0),
            r.case.order.to_string(),
            fmt(r.case.bn_hz, 0),
            r.case.aiding.label().to_string(),
            format!("{}/{}", r.tracked_at_start, r.satellites),
            r.tracked_min.to_string(),
            fmt(r.tracked_mean, 1),
            r.kept.to_string(),
            r.lock_drops.to_string(),
            r.channels_lost.to_string(),
            fmt(r.phase_std_cycles, 4),
            fmt(r.disc_std_cycles, 4),
            fmt(r.disc_mean_abs_deg, 2),
            fmt(r.predicted_mean_abs_deg, 2),
            fmt(r.growth_abs_deg_s, 3),
            fmt(r.predicted_growth_deg_s, 3),
            fmt(r.prr_std_mps, 3),
            fmt(r.handover_df_rms_hz, 2),
        ]);
    }
    t
}

fn plots(results: &[CaseResult]) -> Vec<LinePlot> {
    let mut out = Vec::new();
    // The 2nd-order aided curves last, so that they are drawn on top.
    let cases = [
        (1u8, ORDER1_BN_HZ, Aiding::Ins1),
        (1, ORDER1_BN_HZ, Aiding::Ins2),
        (2, HEADLINE_BN_HZ, Aiding::Unaided),
        (2, HEADLINE_BN_HZ, Aiding::Ins1),
        (2, HEADLINE_BN_HZ, Aiding::Ins2),
    ];
    let series: Vec<Series> = cases
        .iter()
        .filter_map(|&(o, bn, a)| headline(results, o, bn, a))
        .map(|r| Series {
            name: format!(
                "order {} Bn {} Hz {}",
                r.case.order,
                r.case.bn_hz,
                r.case.aiding.label()
            ),
            points: r
                .tracked_per_tick
                .iter()
                .enumerate()
                .map(|(k, &n)| ((k + 1) as f64 * TICK_S, n as f64))
                .collect(),
            reference: false,
        })
        .collect();
    let cn0 = results
        .iter()
        .map(|r| r.spec.cn0_dbhz)
        .fold(f64::NEG_INFINITY, f64::max);
    let (w0, w1) = Manoeuvre::Turn(10.0).window_s();
    out.push(LinePlot {
        file_name: "tracked_10g.png".into(),
        title: format!(
            "Satellites tracked, 10 g turn {w0}-{w1} s, {cn0} dB-Hz (overlapping curves hide each other)"
        ),
        x_label: "time (s)".into(),
        y_label: "satellites in Track with PLL lock".into(),
        series,
        ..LinePlot::default()
    });
    let turn_g = |r: &CaseResult| match r.spec.manoeuvre {
        Manoeuvre::Turn(g) => Some(g),
        Manoeuvre::Step(_) => None,
    };
    let by_g = |order: u8, bn: f64, a: Aiding, y: &dyn Fn(&CaseResult) -> f64| Series {
        name: format!("order {order} Bn {bn} Hz {}", a.label()),
        points: results
            .iter()
            .filter(|r| {
                r.spec.cn0_dbhz == cn0
                    && r.case.order == order
                    && r.case.bn_hz == bn
                    && r.case.aiding == a
            })
            .filter_map(|r| turn_g(r).map(|g| (g, y(r))))
            .collect(),
        reference: false,
    };
    let modes = [Aiding::Unaided, Aiding::Ins1, Aiding::Ins2];
    out.push(LinePlot {
        file_name: "phase_std_vs_g.png".into(),
        title: format!(
            "Phase error std vs turn acceleration (order 2, Bn {HEADLINE_BN_HZ} Hz, {cn0} dB-Hz; INS 1 and 2 coincide)"
        ),
        x_label: "turn acceleration (g)".into(),
        y_label: "phase error std over locked intervals (cycle)".into(),
        log_y: true,
        series: modes
            .iter()
            .map(|&a| by_g(2, HEADLINE_BN_HZ, a, &|r| r.phase_std_cycles))
            .collect(),
        ..LinePlot::default()
    });
    out.push(LinePlot {
        file_name: "min_tracked_vs_g.png".into(),
        title: format!("Fewest satellites tracked in the turn, {cn0} dB-Hz"),
        x_label: "turn acceleration (g)".into(),
        y_label: "min satellites tracked".into(),
        series: min_tracked_series(results, cn0),
        ..LinePlot::default()
    });
    out
}

/// Fewest satellites tracked in the turns vs g: unaided loops of order 2 and 3 at the wider
/// bandwidths of the grid, and the fewest over the aided cases of order >= 2 that were tracking
/// every satellite when the manoeuvre began.
fn min_tracked_series(results: &[CaseResult], cn0: f64) -> Vec<Series> {
    let turns =
        |r: &&CaseResult| r.spec.cn0_dbhz == cn0 && matches!(r.spec.manoeuvre, Manoeuvre::Turn(_));
    let mut out = Vec::new();
    for order in [2u8, 3] {
        for bn in [5.0, 10.0, 18.0] {
            let points: Vec<(f64, f64)> = results
                .iter()
                .filter(turns)
                .filter(|r| {
                    r.case.aiding == Aiding::Unaided && r.case.order == order && r.case.bn_hz == bn
                })
                .map(|r| (r.spec.manoeuvre.g(), r.tracked_min as f64))
                .collect();
            if !points.is_empty() {
                out.push(Series {
                    name: format!("unaided, order {order}, Bn {bn} Hz"),
                    points,
                    reference: false,
                });
            }
        }
    }
    let mut gs: Vec<f64> = results
        .iter()
        .filter(turns)
        .map(|r| r.spec.manoeuvre.g())
        .collect();
    gs.sort_by(f64::total_cmp);
    gs.dedup();
    out.push(Series {
        name: "aided (INS 1 or 2, order >= 2, every Bn tracking all at the start): fewest".into(),
        points: gs
            .iter()
            .map(|&g| {
                let min = results
                    .iter()
                    .filter(turns)
                    .filter(|r| {
                        r.spec.manoeuvre.g() == g
                            && r.case.aiding != Aiding::Unaided
                            && r.case.order >= 2
                            && r.tracked_at_start == r.satellites
                    })
                    .map(|r| r.tracked_min)
                    .min()
                    .unwrap_or(0);
                (g, min as f64)
            })
            .collect(),
        reference: false,
    });
    out
}

/// The cases the summary and the conclusions single out (10 g turn, highest C/N0).
struct Headline<'a> {
    unaided: Option<&'a CaseResult>,
    ins1: Option<&'a CaseResult>,
    ins2: Option<&'a CaseResult>,
    order1_ins1: Option<&'a CaseResult>,
    order1_ins2: Option<&'a CaseResult>,
}

impl<'a> Headline<'a> {
    fn new(results: &'a [CaseResult]) -> Self {
        let h = |o, bn, a| headline(results, o, bn, a);
        Self {
            unaided: h(2, HEADLINE_BN_HZ, Aiding::Unaided),
            ins1: h(2, HEADLINE_BN_HZ, Aiding::Ins1),
            ins2: h(2, HEADLINE_BN_HZ, Aiding::Ins2),
            order1_ins1: h(1, ORDER1_BN_HZ, Aiding::Ins1),
            order1_ins2: h(1, ORDER1_BN_HZ, Aiding::Ins2),
        }
    }

    /// `f(b) / f(a)`, NaN when either case is missing.
    fn ratio(a: Option<&CaseResult>, b: Option<&CaseResult>, f: fn(&CaseResult) -> f64) -> f64 {
        match (a, b) {
            (Some(a), Some(b)) => f(b) / f(a),
            _ => f64::NAN,
        }
    }

    /// INS 2 / INS 1 phase error std of the 2nd-order loop.
    fn std_ratio(&self) -> f64 {
        Self::ratio(self.ins1, self.ins2, |r| r.phase_std_cycles)
    }

    /// INS 2 / INS 1 mean |phase error| of the 1st-order loop.
    fn order1_mean_ratio(&self) -> f64 {
        Self::ratio(self.order1_ins1, self.order1_ins2, |r| r.disc_mean_abs_deg)
    }

    /// INS 2 / INS 1 phase error growth of the 1st-order loop.
    fn order1_growth_ratio(&self) -> f64 {
        Self::ratio(self.order1_ins1, self.order1_ins2, |r| r.growth_abs_deg_s)
    }
}

/// A JSON number, or null when not finite.
fn json_num(v: f64) -> serde_json::Value {
    if v.is_finite() {
        json!(v)
    } else {
        serde_json::Value::Null
    }
}

fn build_report(args: &DynamicsArgs, results: &[CaseResult], wall_s: f64) -> StudyReport {
    let h = Headline::new(results);
    let mode_json = |r: Option<&CaseResult>| r.map(result_json).unwrap_or(serde_json::Value::Null);
    let summary = json!({
        "study": "dynamics",
        "quick": args.common.quick,
        "seed": args.common.seed,
        "cases": results.len(),
        "wall_s": wall_s,
        "setup": {
            "fs_hz": FS_HZ,
            "start_tow_s": START_TOW_S,
            "speed_mps": SPEED_MPS,
            "lead_in_s": LEAD_IN_S,
            "ramp_s": RAMP_S,
            "turn_s": TURN_S,
            "step_s": STEP_S,
            "duration_s": DURATION_S,
            "allan_deviation_1s": ALLAN_DEVIATION_1S,
            "ins1_bias_mps2": INS1_BIAS_MPS2,
            "ins2_bias_mps2": 2.0 * INS1_BIAS_MPS2,
            "bias_direction_enu": bias_direction_enu(),
            "ins_rate_hz": INS_RATE_HZ,
            "tick_s": TICK_S,
        },
        "ten_g": {
            "manoeuvre": Manoeuvre::Turn(10.0).label(),
            "cn0_dbhz": h.unaided.map(|r| r.spec.cn0_dbhz),
            "order": 2,
            "bn_hz": HEADLINE_BN_HZ,
            "satellites": h.unaided.map(|r| r.satellites),
            "unaided": mode_json(h.unaided),
            "ins1": mode_json(h.ins1),
            "ins2": mode_json(h.ins2),
            "phase_std_ratio_ins2_ins1": json_num(h.std_ratio()),
            "order1": {
                "bn_hz": ORDER1_BN_HZ,
                "ins1": mode_json(h.order1_ins1),
                "ins2": mode_json(h.order1_ins2),
                "mean_abs_phase_error_ratio_ins2_ins1": json_num(h.order1_mean_ratio()),
                "growth_ratio_ins2_ins1": json_num(h.order1_growth_ratio()),
            },
        },
        "rows": results.iter().map(result_json).collect::<Vec<_>>(),
    });
    StudyReport {
        title: "High dynamics: unaided vs INS-aided carrier tracking (seed 004)".into(),
        intro_md: intro_md(args),
        table: table(results),
        conclusions_md: [
            conclusions_md(&h),
            grid_md(results),
            format!("Wall time of this run: {wall_s:.0} s."),
        ]
        .iter()
        .map(|p| p.trim())
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("\n\n"),
        summary,
        plots: plots(results),
    }
}

fn intro_md(args: &DynamicsArgs) -> String {
    format!(
        "Simulated IF (complex float, {fs} MHz, every visible satellite at one C/N0, data bits on) \
of a vehicle cruising at {SPEED_MPS} m/s for {LEAD_IN_S} s, then a jerk-limited manoeuvre \
(acceleration ramped over {RAMP_S} s in and out): a level left turn at N g for {TURN_S} s, or a \
longitudinal acceleration step of N g for {STEP_S} s; {DURATION_S} s in all. Receiver \
oscillator: white FM, Allan deviation {ALLAN_DEVIATION_1S:e} at 1 s, drift {CLOCK_DRIFT_S_S:e} s/s. \
Channels start from truth at t = 0 (default FLL-assisted pull-in, then the case's PLL, no FLL, \
T = 1 ms, 1 Hz carrier-aided DLL). Aided cases use the receiver's INS feed-forward \
(`gpsrx run --ins` path) with an INS made from the truth by the INS error model: accelerometer \
bias |B| = {b1} m/s^2 (INS 1) or {b2} m/s^2 (INS 2) along (1, 1, 1)/sqrt(3) east-north-up, \
{INS_RATE_HZ} Hz; a fix at t = 0 gives it the position and clock drift. Seed {seed}{quick}.\n\n\
Columns: *tracked* = channels in Track with the PLL lock indicator on, sampled every {TICK_S} s \
over the manoeuvre window (ramp-in start to ramp-out end), min and mean; *kept* = tracked at \
every sample of the window; *lock drops* = lock-indicator drops from the window start to the end \
of the run; *lost* = channels released (C/N0 below 25 dB-Hz for 1 s). Over the window, while \
tracked: *phase std* = NCO minus true carrier phase, offset and Costas half-cycle removed per \
satellite, pooled; *disc. std* = the Costas discriminator atan(Q/I) (what seed 004 Table 3 \
measured); *mean abs phase err* = |mean discriminator| averaged over satellites, against \
*predicted* = the bias theory: 1st order 360 B_V t / (lambda omega0) (growing, at the mean \
time), 2nd order 360 B_V / (lambda omega0^2), 3rd order 0, with B_V = B . u per satellite \
(unit vector u to the satellite, t from the INS start at t = 0); *growth* = least-squares slope \
of the discriminator over the window against 1st order 360 B_V / (lambda omega0), else 0 (these \
four over the satellites in Track, locked or not, for at least half of the window without a \
cycle slip; aided cases only); *PRR std* = (NCO Doppler - true Doppler) x lambda; *hand-over df \
rms* = NCO frequency error over each channel's first 20 ms in Track, rms over channels.",
        fs = FS_HZ / 1e6,
        b1 = INS1_BIAS_MPS2,
        b2 = 2.0 * INS1_BIAS_MPS2,
        seed = args.common.seed,
        quick = if args.common.quick {
            " (--quick: the 10 g turn at 45 dB-Hz only)"
        } else {
            ""
        },
    )
}

fn conclusions_md(h: &Headline<'_>) -> String {
    let (Some(u), Some(i1), Some(i2)) = (h.unaided, h.ins1, h.ins2) else {
        return String::new();
    };
    let mut s = format!(
        "**10 g turn, {cn0} dB-Hz, 2nd-order PLL at Bn = {bn} Hz.** Unaided, the loop kept as few \
as {umin} of {n} satellites (mean {umean:.1}; {ukept} kept throughout, {udrops} lock drops, {ulost} \
channels lost): a 2nd-order loop's steady-state error is 0.2809 a / Bn^2, {ss:.0} cycles for 10 g \
along the line of sight at {bn} Hz, and the turn swings every satellite's line-of-sight \
acceleration through +-10 g cos(elevation). Seed 004 Fig. 12 saw its 0.4 Hz loop drop to 4 \
satellites (its manoeuvre and geometry are not given; a 0.4 Hz loop cannot follow even the \
satellites' own line-of-sight acceleration of up to 0.18 m/s^2 here, 1.7 cycles of error, so \
{bn} Hz is the narrowest unaided 2nd-order loop that holds every satellite before the manoeuvre). \
Aided by INS 1 the loop kept {k1} of {n} (min {m1}, {d1n} lock drops), by INS 2 {k2} \
of {n} (min {m2}, {d2n} lock drops): seed 004 Fig. 15 kept >= 8, all it had.\n\n\
**INS 1 vs INS 2 (seed 004 Table 3).** The aided 2nd-order loop's phase error std against truth \
is {p1:.4} vs {p2:.4} cycle (ratio {std_ratio:.2}); the discriminator std (Table 3's measure) \
{d1:.4} vs {d2:.4} cycle. The bias changes only the *mean* error, {e1:.2} vs {e2:.2} deg (theory \
360 B_V / (lambda omega0^2): {t1:.2} vs {t2:.2} deg), a constant held by the loop's integrator \
(growth {g1:.3} and {g2:.3} deg/s): what is left is thermal and oscillator noise, the same for \
both INS, as in Table 3 (0.085-0.101 cycle there, a real front end at 0.4 Hz; ours {d1:.3} cycle \
at {cn0} dB-Hz and T = 1 ms). The loop is linear and both INS see the same noise, so the two stds \
agree to the digits shown.\n\n",
        cn0 = u.spec.cn0_dbhz,
        bn = u.case.bn_hz,
        umin = u.tracked_min,
        n = u.satellites,
        umean = u.tracked_mean,
        ukept = u.kept,
        udrops = u.lock_drops,
        ulost = u.channels_lost,
        ss = 0.2809 * 10.0 * G0_MPS2 / (u.case.bn_hz * u.case.bn_hz) / LAMBDA_L1_M,
        k1 = i1.kept,
        m1 = i1.tracked_min,
        d1n = i1.lock_drops,
        k2 = i2.kept,
        m2 = i2.tracked_min,
        d2n = i2.lock_drops,
        p1 = i1.phase_std_cycles,
        p2 = i2.phase_std_cycles,
        std_ratio = h.std_ratio(),
        d1 = i1.disc_std_cycles,
        d2 = i2.disc_std_cycles,
        e1 = i1.disc_mean_abs_deg,
        e2 = i2.disc_mean_abs_deg,
        t1 = i1.predicted_mean_abs_deg,
        t2 = i2.predicted_mean_abs_deg,
        g1 = i1.growth_abs_deg_s,
        g2 = i2.growth_abs_deg_s,
    );
    if let (Some(a), Some(b)) = (h.order1_ins1, h.order1_ins2) {
        s += &format!(
            "**1st-order aided loop (Bn = {bn} Hz).** Its error grows with the INS velocity error \
B_V t: {g1:.3} deg/s with INS 1 and {g2:.3} deg/s with INS 2 (ratio {gr:.2}; theory \
360 B_V / (lambda omega0): {tg1:.3} and {tg2:.3} deg/s); mean |phase error| over the manoeuvre \
{e1:.2} and {e2:.2} deg (ratio {er:.2}; theory {t1:.2} and {t2:.2} deg, the rest is the \
frequency offset the loop was handed over with, which a 1st-order loop never removes); \
satellites kept {k1} and {k2} of {n}, lock drops {l1} and {l2}. The error scales with the bias \
and keeps growing, so an aided loop needs order >= 2: seed 004's conclusion (its Table 1 gives \
the 1st-order bias entry as a constant; the bias is a Doppler ramp, and the measured growth \
confirms the ramp).\n\n",
            bn = a.case.bn_hz,
            g1 = a.growth_abs_deg_s,
            g2 = b.growth_abs_deg_s,
            gr = h.order1_growth_ratio(),
            tg1 = a.predicted_growth_deg_s,
            tg2 = b.predicted_growth_deg_s,
            e1 = a.disc_mean_abs_deg,
            e2 = b.disc_mean_abs_deg,
            er = h.order1_mean_ratio(),
            t1 = a.predicted_mean_abs_deg,
            t2 = b.predicted_mean_abs_deg,
            k1 = a.kept,
            k2 = b.kept,
            n = a.satellites,
            l1 = a.lock_drops,
            l2 = b.lock_drops,
        );
    }
    s
}

/// A short name of a case: `10 g turn 45 dB-Hz order 3 Bn 18 Hz`.
fn case_name(r: &CaseResult) -> String {
    format!(
        "{} {} dB-Hz order {} Bn {} Hz",
        r.spec.manoeuvre.label(),
        r.spec.cn0_dbhz,
        r.case.order,
        r.case.bn_hz
    )
}

/// The bias effect by loop order over the grid: INS 2 / INS 1 mean error of the 2nd-order loop,
/// and the largest INS 2 - INS 1 difference of the 3rd-order loop's mean error.
fn bias_md(results: &[CaseResult]) -> String {
    let pairs = |order: u8| -> Vec<(&CaseResult, &CaseResult)> {
        results
            .iter()
            .filter(|a| a.case.order == order && a.case.aiding == Aiding::Ins1)
            .filter_map(|a| {
                results
                    .iter()
                    .find(|b| {
                        b.spec == a.spec
                            && b.case.order == order
                            && b.case.bn_hz == a.case.bn_hz
                            && b.case.aiding == Aiding::Ins2
                    })
                    .map(|b| (a, b))
            })
            .filter(|(a, b)| a.disc_mean_abs_deg.is_finite() && b.disc_mean_abs_deg.is_finite())
            .collect()
    };
    let ratios: Vec<f64> = pairs(2)
        .iter()
        .filter(|(a, _)| a.disc_mean_abs_deg > 0.05)
        .map(|(a, b)| b.disc_mean_abs_deg / a.disc_mean_abs_deg)
        .collect();
    let diff3 = pairs(3)
        .iter()
        .map(|(a, b)| (b.disc_mean_abs_deg - a.disc_mean_abs_deg).abs())
        .fold(0.0, f64::max);
    if ratios.is_empty() {
        return String::new();
    }
    format!(
        "The bias shows in the mean error of the 2nd-order loop (INS 2 / INS 1 = {:.2} on average \
over {} pairs, theory 2, at {:.2}-{:.2}) and in the growth of the 1st-order loop; with order 3, \
INS 1 and INS 2 agree within {diff3:.2} deg (the growth some narrow 3rd-order rows show is their \
hand-over transient still decaying, the same with either INS).\n\n",
        ratios.iter().sum::<f64>() / ratios.len() as f64,
        ratios.len(),
        ratios.iter().copied().fold(f64::INFINITY, f64::min),
        ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )
}

/// What the whole grid shows (empty for the quick grid's single scenario).
fn grid_md(results: &[CaseResult]) -> String {
    let mut scenarios: Vec<ScenarioSpec> = Vec::new();
    for r in results {
        if !scenarios.contains(&r.spec) {
            scenarios.push(r.spec);
        }
    }
    if scenarios.len() < 2 {
        return String::new();
    }
    let mut s = String::from("**Across the grid.** ");
    let survivors: Vec<String> = results
        .iter()
        .filter(|r| r.case.aiding == Aiding::Unaided && r.kept == r.satellites)
        .map(case_name)
        .collect();
    s += &format!(
        "Unaided, {} of {} cases kept every satellite through the manoeuvre: {}. ",
        survivors.len(),
        results
            .iter()
            .filter(|r| r.case.aiding == Aiding::Unaided)
            .count(),
        if survivors.is_empty() {
            "none".to_string()
        } else {
            survivors.join("; ")
        }
    );
    let aided: Vec<&CaseResult> = results
        .iter()
        .filter(|r| r.case.aiding != Aiding::Unaided && r.case.order >= 2)
        .collect();
    let dropped: Vec<String> = aided
        .iter()
        .filter(|r| r.kept < r.tracked_at_start)
        .map(|r| format!("{} {}", case_name(r), r.case.aiding.label()))
        .collect();
    s += &format!(
        "Aided (order >= 2), {} of {} cases kept every satellite they were tracking when the \
manoeuvre began{}.\n\n",
        aided.len() - dropped.len(),
        aided.len(),
        if dropped.is_empty() {
            String::new()
        } else {
            format!(" (not: {})", dropped.join("; "))
        }
    );
    s += &bias_md(results);
    let mut cn0s: Vec<f64> = scenarios.iter().map(|c| c.cn0_dbhz).collect();
    cn0s.sort_by(f64::total_cmp);
    cn0s.dedup();
    s += "**Pull-in to track hand-over** (not a dynamics effect, but it limits the narrow loops; \
channels start from truth): ";
    let parts: Vec<String> = cn0s
        .iter()
        .map(|&c| {
            let at = results.iter().filter(|r| r.spec.cn0_dbhz == c);
            let df: Vec<f64> = at
                .clone()
                .map(|r| r.handover_df_rms_hz)
                .filter(|v| v.is_finite())
                .collect();
            let short = at.clone().filter(|r| r.tracked_at_start < r.satellites);
            let mut loops: Vec<String> = short
                .clone()
                .map(|r| format!("order {} Bn {}", r.case.order, r.case.bn_hz))
                .collect();
            loops.sort();
            loops.dedup();
            format!(
                "at {c} dB-Hz the tracking loops start with an NCO frequency error of {:.1} Hz rms \
(mean over cases) and {} of {} cases had lost satellites before the manoeuvre began ({})",
                df.iter().sum::<f64>() / df.len().max(1) as f64,
                short.count(),
                at.count(),
                if loops.is_empty() {
                    "none".to_string()
                } else {
                    loops.join(", ")
                }
            )
        })
        .collect();
    s += &parts.join("; ");
    s += ". The listed loops lose those satellites in the transient after the hand-over, before \
any manoeuvre. The *sats at start* column shows who was tracking when the manoeuvre began; \
*kept* counts from those.";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooled_std_and_slope() {
        // Two series with their own means: the pooled std ignores the means.
        let a: Vec<f64> = (0..200)
            .map(|k| 1.0 + if k % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        let b: Vec<f64> = a.iter().map(|x| x + 5.0).collect();
        let s = pooled_std([a.as_slice(), b.as_slice()].into_iter());
        assert!((s - 0.1 * (200.0f64 / 199.0).sqrt()).abs() < 1e-12, "{s}");
        assert!(pooled_std([&a[..10]].into_iter()).is_nan());
        let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 - 0.5 * t).collect();
        let (m, slope) = mean_and_slope(&t, &y);
        assert!((slope + 0.5).abs() < 1e-12 && (m - (2.0 - 0.5 * 2.45)).abs() < 1e-12);
    }

    #[test]
    fn manoeuvre_windows_and_grid() {
        assert_eq!(Manoeuvre::Turn(10.0).window_s(), (4.0, 13.0));
        assert_eq!(Manoeuvre::Step(10.0).window_s(), (4.0, 9.0));
        let (s, c) = grid(true);
        assert_eq!((s.len(), c.len()), (1, 5));
        let (s, c) = grid(false);
        assert_eq!((s.len(), c.len()), (10, 32));
        for spec in &s {
            let sc =
                gpsrx_samples::sim::Scenario::from_toml(&scenario_toml(spec, 1, Some(&[1, 3])));
            assert!(sc.is_ok(), "{:?}", sc.err());
        }
    }
}
