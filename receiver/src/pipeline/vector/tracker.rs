//! Vector tracking over a run: when the navigation filter takes the channels and when it gives
//! them back, and what it is fed.
//!
//! - **Scalar until the first valid fix.** The first least-squares fix that passes the
//!   integrity test (RAIM, PDOP) with at least [`MIN_START_SATELLITES`] satellites and a
//!   velocity good to [`MAX_START_VELOCITY_SIGMA_MPS`] per axis starts the filter from its
//!   position, velocity, clock and covariance ([`NavFilter::from_solution`]); from then on the
//!   filter's prediction is fed forward into every channel ([`VectorPort`]). (A fix of 4
//!   satellites has a velocity good to 1-5 m/s only: 5-25 Hz of feed-forward error, enough to
//!   throw a 20 ms loop into a false lock 25 Hz off.)
//! - **Vector.** Every epoch of observables (the navigation rate, `[run] rate_hz`) predicts
//!   the filter to the epoch and updates it with the pseudoranges and Dopplers of the tracked
//!   channels (`measure`), each weighted by its C/N0 (`noise`), each tested (`ekf`).
//! - **Not under hard dynamics** (`dynamics`): the filter takes the channels only once the
//!   fixes' velocities have shown less than 3 m/s^2 for 1 s, and, without an INS, hands them
//!   back as soon as they show more (its feed-forward is a prediction 0.2-0.3 s ahead of its
//!   last measurement, on a constant velocity).
//! - **With an INS** (`--ins`) the INS's motion drives the prediction, both the filter's
//!   (`super::ekf`, "With an INS") and the channels' between updates (`super::feed`): the
//!   channels' aid follows a manoeuvre as the INS sees it, corrected by the measurements, and
//!   the filter keeps the channels through it. Before the first fix and after a hand-back the
//!   channels take the INS feed-forward of seed 004 (`crate::pipeline::aiding`).
//! - **Through an outage** the filter predicts: a satellite whose measurement it admitted
//!   within `[vector] max_coast_s` (5 s) has its channel held on the prediction while its
//!   signal is blocked (`super::feed`), and a blockage of every satellite is bridged the same
//!   way: the filter predicts on its motion and clock models alone (its covariance grows),
//!   and the channels are there the moment the signals return.
//! - **At a collapse** of several satellites' prompt power at once (a blockage, lost
//!   samples: `crate::pipeline::timing::code_jump`), the filter goes back to its state at the
//!   last epoch before the onset and takes no measurement for `QUARANTINE_S`: the epochs
//!   just after it hold channels whose lock detectors have not yet seen the signal go (the
//!   weaker ones, whose fall the fade detector cannot flag), and their noise, admitted under
//!   a car's process noise (1 m/s per 0.1 s), threw the velocity 2.4 m/s off (12 Hz of
//!   feed-forward error carried through the blockage).
//! - **Back to scalar** when the filter's health test fails [`UNHEALTHY_EPOCHS`] epochs in a
//!   row, or when no row was admitted for `max_coast_s` (the channels lost everything): an
//!   epoch is unhealthy when it had measurements and none was admitted, when more
//!   pseudoranges or more Dopplers were excluded than admitted (a filter whose velocity went
//!   wrong, under an INS whose motion is 50 ms late in a 10 g turn, kept admitting the
//!   pseudoranges while it excluded 6 of 8 Dopplers, and stayed 4 m/s off after the turn), or
//!   when the 3-D position sigma is above [`MAX_POSITION_SIGMA_M`]; and at once when the
//!   Dopplers of [`BREAK_SATELLITES`] satellites are [`BREAK_NIS`] off its prediction in one
//!   epoch (a 31 ms cut inside a 10 g turn with an INS: the INS looked up 31 ms off, 3 m/s;
//!   the lost-sample detectors missed it there, and the filter, re-converging on the INS's
//!   motion within 0.3 s, held the channels on a receiver time 31 ms wrong: fixes up to 60 m
//!   off for 6 s, until frame sync).
//!   Fewer than 4 satellites do not make it unhealthy: the filter coasts on its prediction
//!   through a partial blockage (its covariance grows, the sigma test ends it). The next valid
//!   fix starts the filter again.
//!
//! The least-squares fixes stay the receiver's output; the filter only drives the channels.
//!
//! # Time
//!
//! The observables are dated by the receiver clock; the channels ask for their aid at stream
//! time (seconds from the first sample). Each epoch that has a fix pairs the two (the fix
//! report carries the stream time of its epoch); an epoch without one takes the offset of the
//! last pair (a whole-millisecond step of the receiver clock moves it by 1 ms, nothing for a
//! Doppler prediction).

use super::dynamics::AccelWatch;
use super::ekf::{ClockModel, FilterParams, NavFilter, RowKind, BIAS};
use super::feed::{InsAnchor, Snapshot, VectorPort, CHECKED_S};
use super::measure::{epoch_rows, RowModel};
use super::noise::LoopNoise;
use super::take_in::TakeIn;
use super::vouch::Vouchers;
use crate::config::{IonoModel, ReceiverConfig, TropoModel};
use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::navigation::NavigationProcessor;
use crate::pipeline::sink::{FixQuality, FixReport, ObsEpoch};
use gpsrx_core::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::atmosphere::KlobucharParams;
use gpsrx_nav::ephemeris::{Ephemeris, HealthPolicy};
use gpsrx_nav::pvt::{chi_square_quantile, PvtOptions, PvtSolution};
use gpsrx_nav::rinex_nav::NavData;
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::ChannelEpoch;
use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

/// Unhealthy epochs in a row that hand the channels back to their scalar loops.
pub const UNHEALTHY_EPOCHS: u32 = 3;
/// A Doppler row this far out (NIS) is a break of the prediction, not noise (10 sigma).
pub const BREAK_NIS: f64 = 100.0;
/// Satellites whose Dopplers break at once that end vector tracking at once (module docs).
pub const BREAK_SATELLITES: usize = 3;
/// 3-D position sigma above which the filter is unhealthy, m.
pub const MAX_POSITION_SIGMA_M: f64 = 100.0;
/// Fewest satellites of a fix that starts the filter (RAIM can check it).
pub const MIN_START_SATELLITES: usize = 5;
/// Largest per-axis velocity sigma of a fix that starts the filter, m/s.
pub const MAX_START_VELOCITY_SIGMA_MPS: f64 = 0.5;
/// After a collapse, how long the filter takes no measurement, s (module docs): the lock
/// detector's power-change test restarts it from five 20 ms tests, so a channel whose signal
/// went reports no lock 0.1-0.2 s after.
pub const QUARANTINE_S: f64 = 0.3;
/// How long after the valid fix that ends a doubt on the time (samples possibly lost) the
/// prediction still gives no bit edges or SV times, s: the channels moved onto their codes
/// again pull in for a second (after a 5 s cut a satellite timed 0.2 s after the time came
/// back put fixes 9 m off, 3 sigma, for 0.8 s).
pub const DOUBT_SETTLE_S: f64 = 2.0;
/// How far back the filter's states are kept for a rollback, s.
const HISTORY_S: f64 = 1.0;

/// What the navigation processor emitted in a round that vector tracking takes.
#[derive(Debug, Clone)]
pub enum Captured {
    /// An epoch of observables.
    Observables(ObsEpoch),
    /// The least-squares fix of the epoch just before.
    Fix {
        /// Stream time of the epoch, s.
        t_stream_s: f64,
        /// The solution.
        solution: Box<PvtSolution>,
        /// It is a valid fix (integrity and geometry passed).
        valid: bool,
    },
}

impl Captured {
    /// The capture of a fix report.
    pub fn fix(report: &FixReport) -> Self {
        Captured::Fix {
            t_stream_s: report.t_stream_s,
            solution: Box::new(report.solution.clone()),
            valid: report.fix.quality != FixQuality::None,
        }
    }
}

/// Whether a valid fix may start the filter (module docs).
fn starts_the_filter(sol: &PvtSolution) -> bool {
    let velocity_ok = sol.vel_covariance.is_some_and(|c| {
        (0..3).all(|i| c[(i, i)].is_finite() && c[(i, i)].sqrt() <= MAX_START_VELOCITY_SIGMA_MPS)
    });
    sol.n_sv >= MIN_START_SATELLITES && velocity_ok && sol.vel_ecef_mps.is_some()
}

/// The filter after an epoch, kept for a rollback ([`VectorTracking::collapse`]).
#[derive(Debug, Clone)]
struct Saved {
    /// Stream time of the epoch, s.
    t_stream_s: f64,
    filter: NavFilter,
    /// Receiver time and stream time of the update.
    last: Option<(GpsTime, f64)>,
}

/// Vector tracking over a run.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct VectorSummary {
    /// Seconds of signal the filter drove the channels.
    pub vector_s: f64,
    /// Times the filter took the channels (scalar to vector).
    pub engagements: usize,
    /// Times it gave them back (vector to scalar).
    pub disengagements: usize,
    /// Filter updates.
    pub updates: usize,
    /// Measurement rows excluded by the innovation test.
    pub rejected_rows: usize,
    /// Measurement rows admitted.
    pub admitted_rows: usize,
}

/// The navigation filter that drives the channels, and its handover (module docs).
#[derive(Debug)]
pub struct VectorTracking {
    params: FilterParams,
    opts: PvtOptions,
    iono_model: IonoModel,
    track: LoopNoise,
    weak: Option<(LoopNoise, f64)>,
    allow_unhealthy: bool,
    assist: Option<NavData>,
    filter: Option<NavFilter>,
    /// Receiver time and stream time of the last update.
    last: Option<(GpsTime, f64)>,
    /// Stream time of the last update that admitted a row.
    last_admitted_s: f64,
    /// Stream time of each satellite's last admitted row.
    admitted_s: BTreeMap<u8, f64>,
    /// The channels the prediction vouches for before the filter measures them.
    vouchers: Vouchers,
    /// Before the filter starts: the last valid fix, as a prediction of code and SV time.
    fix_prediction: Option<Snapshot>,
    /// Data-bit edges for the channels vouched for, not yet handed to them.
    bit_edges: Vec<(usize, u8, usize)>,
    /// The filter taken (true) or given back (false) since the last call of
    /// [`VectorTracking::take_switches`], at stream time s.
    switches: Vec<(f64, bool)>,
    /// The satellites taken in from the prediction.
    take_in: TakeIn,
    /// `[run] elevation_mask_deg`.
    mask_deg: f64,
    /// `[run] prns` (empty: all): the satellites that may be taken in.
    prns: Vec<u8>,
    /// Stream time of samples possibly lost (a carrier-phase jump or a collapse, s): no bit
    /// edges or SV times from the prediction until `DOUBT_SETTLE_S` after a valid fix of
    /// a later epoch (`doubt_ends_s`).
    time_doubt_s: Option<f64>,
    /// When the doubt ends, once a valid fix of a later epoch came, s of stream time.
    doubt_ends_s: Option<f64>,
    /// `[vector] max_coast_s`.
    max_coast_s: f64,
    /// The filter after each of its last epochs.
    history: VecDeque<Saved>,
    /// No measurement is taken up to this stream time (after a collapse), s.
    quarantine_until_s: f64,
    /// Receiver time and stream time of the last epoch with a fix (module docs, "Time").
    pair: Option<(GpsTime, f64)>,
    unhealthy_in_row: u32,
    /// The acceleration from the valid fixes' velocities.
    dynamics: AccelWatch,
    port: VectorPort,
    summary: VectorSummary,
    /// With an INS (`--ins`): its motion drives the prediction (`super::ekf`, "With an INS").
    ins: Option<Arc<InsFeedForward>>,
    /// `[vector] ins_accel_psd_m2_s3`.
    ins_accel_psd_m2_s3: f64,
}

impl VectorTracking {
    /// Vector tracking as `config` sets it, with the `--nav` ephemerides (used until a
    /// satellite's own are decoded).
    pub fn new(config: &ReceiverConfig, assist: Option<NavData>) -> Self {
        let v = &config.vector;
        let gate = chi_square_quantile(1.0 - v.gate_pfa, 1.0).unwrap_or(10.83);
        let t = &config.tracking;
        Self {
            params: FilterParams {
                accel_psd_m2_s3: v.accel_psd_m2_s3,
                clock: ClockModel {
                    h0: v.clock_h0,
                    h_2: v.clock_h_2,
                },
                gate,
            },
            opts: PvtOptions {
                tropo: config.run.tropo == TropoModel::Saastamoinen,
                elevation_mask_deg: config.run.elevation_mask_deg,
                ..PvtOptions::default()
            },
            iono_model: config.run.iono,
            track: LoopNoise::of(&t.track),
            weak: t.weak_track.map(|w| (LoopNoise::of(&w), t.weak_enter_dbhz)),
            allow_unhealthy: config.run.allow_unhealthy,
            assist,
            filter: None,
            last: None,
            last_admitted_s: 0.0,
            admitted_s: BTreeMap::new(),
            vouchers: Vouchers::default(),
            fix_prediction: None,
            bit_edges: Vec::new(),
            switches: Vec::new(),
            take_in: TakeIn::default(),
            mask_deg: config.run.elevation_mask_deg,
            prns: config.run.prns.clone(),
            time_doubt_s: None,
            doubt_ends_s: None,
            max_coast_s: v.max_coast_s,
            history: VecDeque::new(),
            quarantine_until_s: f64::NEG_INFINITY,
            pair: None,
            unhealthy_in_row: 0,
            dynamics: AccelWatch::default(),
            port: VectorPort::default(),
            summary: VectorSummary::default(),
            ins: None,
            ins_accel_psd_m2_s3: v.ins_accel_psd_m2_s3,
        }
    }

    /// Propagates the filter with an INS's motion (module docs, "With an INS").
    pub fn with_ins(mut self, ins: Option<Arc<InsFeedForward>>) -> Self {
        self.ins = ins;
        self
    }

    /// The aiding port for the channels' next round.
    pub fn port(&self) -> &VectorPort {
        &self.port
    }

    /// The filter, while it drives the channels.
    pub fn filter(&self) -> Option<&NavFilter> {
        self.filter.as_ref()
    }

    /// What vector tracking did so far.
    pub fn summary(&self) -> VectorSummary {
        self.summary.clone()
    }

    /// Report `e` of channel `channel`, compared with the prediction (`super::vouch`): the
    /// filter's, else the last valid fix's. With `give_edges` (a satellite never timed before:
    /// one timed before checks its new bit edges against its kept time, which is how samples
    /// lost unseen are caught) and no doubt on the time, the bit edges the prediction puts on
    /// a channel it vouches for are queued for it ([`VectorTracking::take_bit_edges`]).
    pub fn vouch(&mut self, channel: usize, e: &ChannelEpoch, give_edges: bool) {
        let snap = self.port.snapshot.as_ref().or(self.fix_prediction.as_ref());
        let edge = snap.and_then(|snap| self.vouchers.observe(snap, e));
        if let (Some(edge), None, true) = (edge, self.time_doubt_s, give_edges) {
            self.bit_edges.push((channel, e.prn, edge));
        }
    }

    /// Samples may have been lost at stream time `t_s` (a carrier-phase jump common to the
    /// satellites, or a collapse of their prompt power): the prediction's time may be off by
    /// them, so it gives no data-bit edges or SV times until `DOUBT_SETTLE_S` after a
    /// valid fix of a later epoch (the receiver time re-established, and the channels moved
    /// onto their codes again settled), and the last fix's prediction is dropped.
    pub fn doubt_time(&mut self, t_s: f64) {
        self.time_doubt_s = Some(self.time_doubt_s.map_or(t_s, |t| t.max(t_s)));
        self.doubt_ends_s = None;
        self.fix_prediction = None;
        self.bit_edges.clear();
    }

    /// Channels to start for satellites above the horizon that no channel tracks
    /// (`tracked`), where the filter's prediction puts their signals after the samples read
    /// so far (`end_sample`): only while the filter drives the channels and its time is not
    /// in doubt (`super::take_in`).
    pub fn take_in(
        &mut self,
        end_sample: u64,
        fs_hz: f64,
        tracked: &dyn Fn(u8) -> bool,
    ) -> Vec<gpsrx_tracking::ChannelStart> {
        match (&self.port.snapshot, self.time_doubt_s) {
            (Some(snap), None) => {
                let limits = (self.mask_deg, self.prns.as_slice());
                self.take_in
                    .starts(snap, end_sample, fs_hz, limits, tracked)
            }
            _ => Vec::new(),
        }
    }

    /// The data-bit edges the prediction put on the channels it vouched for since the last
    /// call: `(channel, PRN, ms_count modulo 20 of a bit's first code period)`, for
    /// `Channel::assume_bit_edge`.
    pub fn take_bit_edges(&mut self) -> Vec<(usize, u8, usize)> {
        std::mem::take(&mut self.bit_edges)
    }

    /// When the filter took the channels (true) or gave them back (false) since the last
    /// call: `(stream time s, engaged)`, for [`crate::pipeline::ReceiverEvent::VectorTracking`].
    pub fn take_switches(&mut self) -> Vec<(f64, bool)> {
        std::mem::take(&mut self.switches)
    }

    /// The predicted SV time (TOW, s) of report `e`'s satellite at its first sample, for a
    /// report at a bit edge of a channel the filter checks (its measurements admitted, or its
    /// code vouched for: `super::vouch`); `crate::pipeline::timing::predicted` takes it.
    pub fn predicted_sv_tow_s(&self, e: &ChannelEpoch) -> Option<f64> {
        if self.time_doubt_s.is_some() {
            return None;
        }
        let snap = self.prediction()?;
        let vouched = self
            .vouchers
            .vouched_s()
            .get(&e.prn)
            .is_some_and(|t| e.t_rx_s - t <= CHECKED_S);
        (e.bit_edge && (vouched || snap.checked(e.prn, e.t_rx_s)))
            .then(|| snap.sv_tow_s(e.prn, e.t_rx_s))
            .flatten()
    }

    /// Takes what the navigation processor emitted in a round, in order, with its decoded
    /// ephemerides and ionosphere.
    pub fn take(&mut self, captured: Vec<Captured>, nav: &NavigationProcessor) {
        let mut it = captured.into_iter().peekable();
        while let Some(c) = it.next() {
            let Captured::Observables(epoch) = c else {
                continue;
            };
            let fix = match it.peek() {
                Some(Captured::Fix { .. }) => match it.next() {
                    Some(Captured::Fix {
                        t_stream_s,
                        solution,
                        valid,
                    }) => Some((t_stream_s, solution, valid)),
                    _ => None,
                },
                _ => None,
            };
            if let Some((t, sol, valid)) = &fix {
                self.pair = Some((epoch.time, *t));
                match (valid, sol.vel_ecef_mps) {
                    (true, Some(v)) => {
                        let sigma = sol
                            .vel_covariance
                            .map_or(0.0, |c| (c[(0, 0)] + c[(1, 1)] + c[(2, 2)]).max(0.0).sqrt());
                        self.dynamics.push(*t, v, sigma)
                    }
                    _ => self.dynamics.reset(),
                }
            }
            let Some((rx0, t0)) = self.pair else {
                continue;
            };
            let t_stream_s = t0 + epoch.time.diff_s(rx0);
            if self.filter.is_some() && self.ins.is_none() && self.dynamics.too_high() {
                let a = self.dynamics.accel_mps2().unwrap_or(f64::NAN);
                self.disengage(
                    t_stream_s,
                    &format!("the receiver accelerates at {a:.1} m/s^2, more than its feed-forward can follow"),
                );
            }
            self.on_epoch(&epoch, t_stream_s, nav);
            let valid = fix.as_ref().is_some_and(|f| f.2);
            match (self.time_doubt_s, self.doubt_ends_s) {
                (Some(t), None) if valid && t_stream_s > t => {
                    self.doubt_ends_s = Some(t_stream_s + DOUBT_SETTLE_S);
                }
                (Some(_), Some(end)) if t_stream_s >= end => {
                    self.time_doubt_s = None;
                    self.doubt_ends_s = None;
                }
                _ => {}
            }
            if let (None, Some((_, sol, true))) = (&self.filter, &fix) {
                let x = *NavFilter::from_solution(sol, self.params).state();
                self.fix_prediction = Some(self.snapshot(&epoch, t_stream_s, x, nav));
                if starts_the_filter(sol) && self.dynamics.calm_at(t_stream_s) {
                    self.engage(&epoch, t_stream_s, sol, nav);
                }
            }
        }
    }

    /// Starts the filter from a valid fix.
    fn engage(
        &mut self,
        epoch: &ObsEpoch,
        t_stream_s: f64,
        sol: &PvtSolution,
        nav: &NavigationProcessor,
    ) {
        let filter = NavFilter::from_solution(sol, self.params);
        tracing::info!(
            "{t_stream_s:.2} s: vector tracking on: the navigation filter drives the channels (started from a fix of {} satellites)",
            sol.n_sv
        );
        self.filter = Some(filter);
        self.last = Some((epoch.time, t_stream_s));
        self.last_admitted_s = t_stream_s;
        self.admitted_s.clear();
        self.vouchers.clear();
        self.take_in.clear();
        self.unhealthy_in_row = 0;
        self.summary.engagements += 1;
        self.switches.push((t_stream_s, true));
        self.publish(epoch, t_stream_s, nav);
    }

    /// Hands the channels back to their scalar loops.
    fn disengage(&mut self, t_stream_s: f64, why: &str) {
        if self.filter.take().is_some() {
            tracing::info!("{t_stream_s:.2} s: vector tracking off ({why}): the channels track alone until the next valid fix");
            self.summary.disengagements += 1;
            self.switches.push((t_stream_s, false));
        }
        self.port.snapshot = None;
        self.last = None;
        self.history.clear();
        self.unhealthy_in_row = 0;
        // A prediction that failed its health test may have failed on its time (samples lost
        // that no detector saw): no bit edges or SV times from the fixes' either until a
        // valid fix of a later epoch.
        self.doubt_time(t_stream_s);
    }

    /// The ephemeris of `prn` at `t`: decoded, else from the navigation file (as the fixes).
    fn ephemeris(&self, nav: &NavigationProcessor, prn: u8, t: GpsTime) -> Option<Ephemeris> {
        let policy = if self.allow_unhealthy {
            HealthPolicy::PreferHealthy
        } else {
            HealthPolicy::HealthyOnly
        };
        nav.decoded_ephemeris(prn).cloned().or_else(|| {
            self.assist
                .as_ref()
                .and_then(|n| n.select_with(prn, t, policy).cloned())
        })
    }

    /// The ionosphere of the model: decoded, assisted, else the typical set (as the fixes).
    fn iono(&self, nav: &NavigationProcessor) -> Option<KlobucharParams> {
        (self.iono_model == IonoModel::Klobuchar).then(|| {
            nav.decoded_iono()
                .or_else(|| self.assist.as_ref().and_then(|n| n.iono))
                .unwrap_or(KlobucharParams::FALLBACK)
        })
    }

    /// One epoch: predict, update, health, and the new snapshot for the channels.
    fn on_epoch(&mut self, epoch: &ObsEpoch, t_stream_s: f64, nav: &NavigationProcessor) {
        let (Some(filter), Some((rx_last, t_last))) = (self.filter.as_mut(), self.last) else {
            return;
        };
        let dt = epoch.time.diff_s(rx_last);
        if !(dt.is_finite() && dt > 0.0) {
            return;
        }
        if t_stream_s - self.last_admitted_s > self.max_coast_s {
            self.disengage(t_stream_s, "no measurement admitted for too long");
            return;
        }
        // With an INS, the velocity change it measured over the interval.
        let dv = self.ins.as_ref().and_then(|ins| {
            let (_, v1) = ins.motion_at(t_stream_s)?;
            let (_, v0) = ins.motion_at(t_last)?;
            Some(v1 - v0)
        });
        match dv {
            Some(dv) => filter.predict_driven(dt, &dv, self.ins_accel_psd_m2_s3),
            None => filter.predict(dt),
        }
        let x = *filter.state();
        let opts = PvtOptions {
            iono: self.iono(nav),
            ..self.opts
        };
        let (track, weak) = (self.track, self.weak);
        let loops = move |cn0: f64| match weak {
            Some((w, enter)) if cn0 < enter => w,
            _ => track,
        };
        let model = RowModel {
            opts: &opts,
            loops: &loops,
            dt_s: dt,
            allow_unhealthy: self.allow_unhealthy,
        };
        let eph = |prn: u8| self.ephemeris(nav, prn, epoch.time);
        let rows = if t_stream_s <= self.quarantine_until_s {
            Vec::new()
        } else {
            epoch_rows(epoch, &eph, &x, &model)
        };
        let Some(filter) = self.filter.as_mut() else {
            return;
        };
        let out = filter.update(&rows);
        self.summary.updates += 1;
        self.summary.admitted_rows += out.admitted;
        self.summary.rejected_rows += out.rejected.len();
        self.summary.vector_s += t_stream_s - t_last;
        self.last = Some((epoch.time, t_stream_s));
        for (prn, kind, nis) in &out.rejected {
            let what = match kind {
                RowKind::Code => "pseudorange",
                RowKind::Doppler => "Doppler",
            };
            tracing::debug!(
                "{t_stream_s:.2} s: vector filter excluded the {what} of G{prn:02} (NIS {nis:.1})"
            );
            self.vouchers.note_excluded(*prn, t_stream_s);
        }
        if out.admitted > 0 {
            self.last_admitted_s = t_stream_s;
        }
        for row in &rows {
            let excluded = out
                .rejected
                .iter()
                .any(|(prn, kind, _)| *prn == row.prn && *kind == row.kind);
            if !excluded {
                self.admitted_s.insert(row.prn, t_stream_s);
            }
        }
        let v = filter.velocity_mps();
        tracing::debug!(
            "{t_stream_s:.2} s: vector filter: {} rows admitted ({} pseudoranges), {} excluded; velocity {:.3} {:.3} {:.3} m/s, drift {:.3} m/s, position sigma {:.2} m",
            out.admitted,
            out.admitted_code,
            out.rejected.len(),
            v.x,
            v.y,
            v.z,
            filter.state()[super::ekf::DRIFT],
            filter.position_sigma_m()
        );
        // Per kind: a filter whose velocity went wrong (an INS whose motion is late or
        // scaled) keeps admitting the pseudoranges while it excludes most Dopplers.
        let rejected = |kind| out.rejected.iter().filter(|r| r.1 == kind).count();
        let admitted_doppler = out.admitted - out.admitted_code;
        // Several satellites' Dopplers 10 sigma off at once: the prediction broke for all of
        // them (samples lost in a manoeuvre with an INS, whose motion is then looked up at the
        // wrong time: 3 m/s in a 10 g turn for 31 ms; an INS fault). The lost-sample detectors
        // can miss it in a turn; the scalar loops, handed back, lose and re-acquire the
        // channels and time them again from their data bits.
        let broken = out
            .rejected
            .iter()
            .filter(|r| r.1 == RowKind::Doppler && r.2 > BREAK_NIS)
            .count();
        if broken >= BREAK_SATELLITES {
            let why = format!(
                "the Dopplers of {broken} satellites are more than 10 sigma off its prediction at once (samples lost, or the INS wrong)"
            );
            self.disengage(t_stream_s, &why);
            return;
        }
        let healthy = (rows.is_empty() || out.admitted > 0)
            && rejected(RowKind::Code) <= out.admitted_code
            && rejected(RowKind::Doppler) <= admitted_doppler
            && filter.position_sigma_m() <= MAX_POSITION_SIGMA_M;
        self.unhealthy_in_row = if healthy {
            0
        } else {
            self.unhealthy_in_row + 1
        };
        if self.unhealthy_in_row >= UNHEALTHY_EPOCHS {
            let why = format!(
                "health test failed {UNHEALTHY_EPOCHS} epochs in a row: {} pseudoranges and {} Dopplers admitted, {} and {} excluded, position sigma {:.1} m",
                out.admitted_code,
                admitted_doppler,
                rejected(RowKind::Code),
                rejected(RowKind::Doppler),
                filter.position_sigma_m()
            );
            self.disengage(t_stream_s, &why);
            return;
        }
        self.history.push_back(Saved {
            t_stream_s,
            filter: filter.clone(),
            last: self.last,
        });
        while self
            .history
            .front()
            .is_some_and(|h| t_stream_s - h.t_stream_s > HISTORY_S)
        {
            self.history.pop_front();
        }
        self.publish(epoch, t_stream_s, nav);
    }

    /// The prompt power of several satellites collapsed at once at stream time `t_s` (module
    /// docs): back to the filter's state at the last epoch before it, and no measurement for
    /// `QUARANTINE_S`; the channels are aided from that state meanwhile.
    pub fn collapse(&mut self, t_s: f64) {
        if self.filter.is_none() {
            return;
        }
        while self.history.back().is_some_and(|h| h.t_stream_s > t_s) {
            self.history.pop_back();
        }
        self.quarantine_until_s = t_s + QUARANTINE_S;
        let Some(Saved {
            t_stream_s: t_epoch,
            filter,
            last: Some((rx, t_last)),
        }) = self.history.back().cloned()
        else {
            return;
        };
        tracing::debug!(
            "{t_s:.3} s: collapse: the vector filter goes back to its epoch at {t_epoch:.2} s and takes no measurement for {QUARANTINE_S} s"
        );
        let x = *filter.state();
        self.filter = Some(filter);
        self.last = Some((rx, t_last));
        if let Some(snap) = self.port.snapshot.as_mut() {
            snap.t_stream_s = t_last;
            snap.gps_time = rx.add_seconds(-x[BIAS] / SPEED_OF_LIGHT_MPS);
            snap.x = x;
            snap.ins = self.ins.as_ref().and_then(|i| InsAnchor::at(i, t_last));
        }
    }

    /// The snapshot the channels are aided from until the next epoch.
    fn publish(&mut self, epoch: &ObsEpoch, t_stream_s: f64, nav: &NavigationProcessor) {
        let Some(filter) = self.filter.as_ref() else {
            return;
        };
        let x = *filter.state();
        self.port.snapshot = Some(self.snapshot(epoch, t_stream_s, x, nav));
    }

    /// A prediction from state `x` at `epoch` (stream time `t_stream_s`).
    fn snapshot(
        &self,
        epoch: &ObsEpoch,
        t_stream_s: f64,
        x: super::ekf::State,
        nav: &NavigationProcessor,
    ) -> Snapshot {
        let ephemerides: BTreeMap<u8, Ephemeris> = (1..=32u8)
            .filter_map(|prn| Some((prn, self.ephemeris(nav, prn, epoch.time)?)))
            .collect();
        Snapshot {
            t_stream_s,
            gps_time: epoch.time.add_seconds(-x[BIAS] / SPEED_OF_LIGHT_MPS),
            x,
            ephemerides: Arc::new(ephemerides),
            admitted_s: Arc::new(self.admitted_s.clone()),
            vouched_s: Arc::new(self.vouchers.vouched_s().clone()),
            max_coast_s: self.max_coast_s,
            ins: self.ins.as_ref().and_then(|i| InsAnchor::at(i, t_stream_s)),
        }
    }

    /// The prediction of the satellites' code and SV time: the filter's while it drives the
    /// channels, else that of the last valid fix (module docs, "Before the filter").
    fn prediction(&self) -> Option<&Snapshot> {
        self.port.snapshot.as_ref().or(self.fix_prediction.as_ref())
    }
}
