//! Observables at common receive epochs: every satellite's transmit time, pseudorange,
//! accumulated carrier phase, Doppler and C/N0 at the same receiver-clock instants.
//!
//! Receiver time scale: the sample with index `k` is at receiver time `T0 + k / fs`. `T0` is set
//! when the first satellite's SV time becomes known, so that this satellite's pseudorange is
//! 75 ms (a typical travel time) at that instant, rounded to a whole millisecond; the PVT then
//! estimates the clock bias against GPS time. When the bias leaves +-0.5 ms the receiver clock is
//! stepped by a whole number of milliseconds (pseudoranges jump by c x 1 ms = 299,792.458 m and
//! carrier phases by 1,575,420 cycles per ms, consistently, so the carrier stays continuous with
//! the code); steps are reported so outputs can flag them.
//!
//! A channel report covers `[t_rx, t_rx + T)`; the observables at an epoch `t` inside it come
//! from the NCO state at its start advanced to `t`: SV time by `(t - t_rx) r / 1.023 MHz` for the
//! code rate `r`, carrier phase by `(t - t_rx) f_D`.

use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::navigation::navdata::NavDecoder;
use crate::pipeline::navigation::smoothing::{
    CarrierAnchor, GivenChange, Hatch, HatchEpoch, MAX_BRIDGE_S,
};
use gpsrx_dsp::constants::{CA_CHIP_RATE_HZ, F_L1_HZ, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::{ChannelEpoch, ChannelState};
use std::collections::{BTreeMap, BTreeSet, VecDeque};

/// Code periods a channel must have run before its pseudorange is used: five time constants
/// `1 / (4 Bn)` of the 2 Hz pull-in DLL, so that the acquisition's code error (up to half a
/// sample: 58 m at 2.6 MHz) has decayed below a metre (`e^-4.8`). It matters only when the
/// SV time is known at once (carried over an outage); otherwise frame sync takes longer.
pub const CODE_SETTLE_MS: u64 = 600;

/// Time after lost samples before a channel's carrier phase may anchor a bridge of its
/// smoothing, s: the gap is found 40-100 ms late and the restarted 1 ms loops (18 Hz) settle
/// within about `3 / Bn` (0.17 s); the phase-lock indicator need not drop meanwhile.
pub const ANCHOR_SETTLE_S: f64 = 0.3;
/// Spacing of the kept points of a channel's locked carrier, s, and how long they are kept.
const RUN_POINT_S: f64 = 0.05;
const RUN_KEPT_S: f64 = 10.0;
/// A data bit, s.
const BIT_S: f64 = 0.020;

/// One satellite's observables at an epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatObservable {
    /// PRN.
    pub prn: u8,
    /// SV transmit time (TOW, s, SV clock).
    pub sv_tow_s: f64,
    /// Pseudorange, m (receiver clock).
    pub pseudorange_m: f64,
    /// Carrier-smoothed pseudorange (Hatch filter), m.
    pub smoothed_pseudorange_m: f64,
    /// Accumulated carrier phase, cycles (RINEX sign: grows as the range grows).
    pub carrier_cycles: f64,
    /// Doppler, Hz (positive when approaching): the carrier phase change from the previous to
    /// the next epoch over twice the epoch interval (a central difference, so that the Doppler
    /// belongs to the epoch itself and not half an interval earlier: at 10 Hz under a 5 g
    /// turn a backward difference lags the velocity by 2.5 m/s), or the backward difference
    /// when the next epoch is not in lock, else the NCO frequency.
    pub doppler_hz: f64,
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
    /// The phase lock indicator was off at some point since the previous epoch (or the channel
    /// restarted): a cycle slip may have happened.
    pub loss_of_lock: bool,
    /// The Costas half-cycle ambiguity is not resolved.
    pub half_cycle_ambiguous: bool,
}

/// Observables of all satellites at one receiver-clock instant.
#[derive(Debug, Clone, PartialEq)]
pub struct ObservableEpoch {
    /// Receiver time of the epoch (GPS time scale + the receiver clock bias).
    pub rx_time: GpsTime,
    /// Sample index (fractional) of the epoch.
    pub sample: f64,
    /// Whether the receiver clock was stepped just before this epoch.
    pub clock_step_ms: i64,
    /// One entry per satellite with a known SV time.
    pub sats: Vec<SatObservable>,
}

/// Longest stretch without a feed-forward in a break that a channel's own carrier still
/// bridges, s: an outage bridge comes on a round or two after the collapse
/// (`crate::pipeline::aiding::OutageBridge`); until then the loops coast on their memories.
const MAX_UNAIDED_COAST_S: f64 = 0.2;

/// How a satellite's channel coasted over its last break in lock.
#[derive(Debug, Clone, Copy, Default)]
struct Coast {
    /// `ms_count` of its latest report.
    last_ms: Option<u64>,
    /// In a break (its latest report was not usable).
    in_break: bool,
    /// Stream time of the break's first report, s.
    start_s: f64,
    /// The loop's share of the NCO frequency (`doppler - feed-forward`) at the break's first
    /// report with a feed-forward, Hz (None: none had one).
    loop_share_hz: Option<f64>,
    /// Integration time of the break's reports without one, s (infinite: another channel).
    unaided_s: f64,
    /// Stream time of the break's first report coasted on a predicting aid
    /// ([`ChannelEpoch::coasting`]: vector tracking), s.
    coast_start_s: Option<f64>,
    /// Phase the loop added to the NCO over the break, `sum |doppler - feed-forward| T`,
    /// cycles: on noise before the coast started (and pulling in after it), what the aid's own
    /// range change does not carry.
    loop_cycles: f64,
    /// The last break was coasted with a feed-forward that held the signal (decided at its
    /// end).
    coasted: bool,
    /// ... and some of it on a predicting aid ([`Coast::coast_start_s`]).
    predicted: bool,
}

impl Coast {
    /// How long a break the channel's own carrier may bridge, s (None: it may not): an aid
    /// that only steadies the loops holds as long as the carrier's own quadratic
    /// ([`MAX_BRIDGE_S`]); a predicting one (vector tracking) for as long as it predicts the
    /// signal (its miss at the re-lock was checked, whatever the length).
    fn bridge_s(&self) -> Option<f64> {
        match (self.coasted, self.predicted) {
            (false, _) => None,
            (true, false) => Some(MAX_BRIDGE_S),
            (true, true) => Some(f64::INFINITY),
        }
    }
}

/// Largest error of the range change a coasted channel's carrier may carry into the carrier
/// smoothing, m (as the extrapolations of `crate::pipeline::navigation::smoothing`).
const MAX_COAST_ERROR_M: f64 = 1.5;

/// Builds observable epochs from channel reports.
#[derive(Debug)]
pub struct ObservableBuilder {
    fs_hz: f64,
    rate_hz: f64,
    /// Receiver time of sample 0 (None until the first SV time is known).
    t0: Option<GpsTime>,
    pending_step_ms: i64,
    total_step_ms: i64,
    /// Epoch index -> observables collected so far.
    pending: BTreeMap<i64, Vec<SatObservable>>,
    /// Per PRN: lock lost since the last epoch, and the carrier-phase origin (cycles) used to
    /// keep the accumulated phase small.
    lli: BTreeMap<u8, bool>,
    /// PRNs whose loss of lock fell on an epoch not collected, to flag at the next one.
    lli_carried: BTreeSet<u8>,
    /// Highest epoch index any channel has reached.
    newest: i64,
    /// Receiver time (TOW, s) of the end of the newest usable report (with or without its SV
    /// time).
    reached_rx_s: f64,
    /// Epochs below this index are not collected: channels reported across them before the
    /// receiver time changed (a clock step, the time carried over lost samples), so they would
    /// hold only the satellites reported after the change.
    first_epoch: i64,
    /// Per PRN: the Hatch filter ([`crate::pipeline::navigation::smoothing`]), kept over losses of lock to
    /// bridge them.
    smoothing: BTreeMap<u8, Hatch>,
    /// Samples lost: `(stream time s, length s if known)`; a filter is bridged over a gap only
    /// once its length is known.
    gaps: Vec<(f64, Option<f64>)>,
    /// Backward carrier-phase Doppler `-(L(n) - L(n-1)) / dt` per (epoch, PRN), for the central
    /// difference at emission.
    phase_rate: BTreeMap<(i64, u8), f64>,
    /// Per PRN: `(stream time s, carrier cycles)` of the channel's reports since its lock
    /// last broke (every [`RUN_POINT_S`], the last [`RUN_KEPT_S`]): anchors for a bridge.
    runs: BTreeMap<u8, VecDeque<(f64, f64)>>,
    /// Per PRN, since its last usable report: how its channel coasted
    /// ([`ObservableBuilder::note_coast`]).
    coasts: BTreeMap<u8, Coast>,
    /// Hatch filter length, epochs.
    hatch_epochs: u32,
    /// Reports with a lower C/N0 estimate give no observables (see
    /// [`ObservableBuilder::with_min_cn0_dbhz`]).
    min_cn0_dbhz: f64,
}

impl ObservableBuilder {
    /// Epochs at `rate_hz` (1-50 Hz) of receiver time, for samples at `fs_hz`.
    pub fn new(fs_hz: f64, rate_hz: f64) -> Self {
        Self {
            fs_hz,
            rate_hz,
            t0: None,
            pending_step_ms: 0,
            total_step_ms: 0,
            pending: BTreeMap::new(),
            lli: BTreeMap::new(),
            coasts: BTreeMap::new(),
            lli_carried: BTreeSet::new(),
            newest: i64::MIN,
            first_epoch: i64::MIN,
            reached_rx_s: f64::NEG_INFINITY,
            smoothing: BTreeMap::new(),
            gaps: Vec::new(),
            phase_rate: BTreeMap::new(),
            runs: BTreeMap::new(),
            hatch_epochs: (rate_hz * 10.0).round().max(1.0) as u32,
            min_cn0_dbhz: f64::NEG_INFINITY,
        }
    }

    /// Takes observables only from reports whose C/N0 estimate is at least `dbhz` (and
    /// flags a loss of lock when it falls below). A blocked signal's C/N0 estimate falls within
    /// a few hundred ms, while a wide PLL running on noise keeps the PLL lock indicator high for
    /// about a second (it steers the noise into the in-phase arm): without this gate a tunnel
    /// entry gives a second of fixes from noise.
    pub fn with_min_cn0_dbhz(mut self, dbhz: f64) -> Self {
        self.min_cn0_dbhz = dbhz;
        self
    }

    /// Receiver time of sample 0, once known.
    pub fn rx_time_origin(&self) -> Option<GpsTime> {
        self.t0
    }

    /// Steps the receiver clock by `ms` milliseconds (receiver time of every sample moves by
    /// `+ms`): used to keep the clock bias within +-0.5 ms.
    pub fn step_clock_ms(&mut self, ms: i64) {
        if let Some(t0) = self.t0 {
            self.t0 = Some(t0.add_seconds(ms as f64 * 1e-3));
            self.pending_step_ms += ms;
            self.total_step_ms += ms;
            // Epochs not yet emitted were measured on the old scale: drop them, and those some
            // channels have already reported across (moved onto the new scale).
            self.pending.clear();
            self.reached_rx_s += ms as f64 * 1e-3;
            self.skip_epochs_through(self.reached_rx_s);
        }
    }

    /// Collects no epoch at or before receiver time `t_rx_s` (TOW, s).
    fn skip_epochs_through(&mut self, t_rx_s: f64) {
        if t_rx_s.is_finite() {
            let last = (t_rx_s * self.rate_hz).floor() as i64;
            self.first_epoch = self.first_epoch.max(last + 1);
        }
    }

    /// Restarts every satellite's carrier smoothing and flags a loss of lock (the SV times may
    /// be wrong), and drops the epochs not yet emitted.
    pub fn restart(&mut self) {
        for lost in self.lli.values_mut() {
            *lost = true;
        }
        self.smoothing.clear();
        self.phase_rate.clear();
        self.pending.clear();
    }

    /// Samples were lost at stream time `t_s`: every satellite's lock is flagged lost and the
    /// epochs not yet emitted are dropped; the carrier smoothing is kept, to be bridged over
    /// the gap once its length is known ([`ObservableBuilder::set_gap_length`]).
    pub fn note_gap(&mut self, t_s: f64) {
        for lost in self.lli.values_mut() {
            *lost = true;
        }
        self.phase_rate.clear();
        self.pending.clear();
        // The epochs since the gap (found a few epochs late) were on a shifted time scale.
        self.smoothing.retain(|_, h| h.rewind(t_s));
        self.gaps.retain(|g| t_s - g.0 < 60.0);
        self.gaps.push((t_s, None));
    }

    /// The samples lost at stream time `t_s` (within 50 ms) were `length_s` of signal.
    pub fn set_gap_length(&mut self, t_s: f64, length_s: f64) {
        // The SV times are carried over the gap from now on, each satellite's at its next data
        // bit edge: the epochs until all have theirs would hold only some satellites.
        self.skip_epochs_through(self.reached_rx_s + BIT_S);
        if let Some(g) = self.gaps.iter_mut().find(|g| (g.0 - t_s).abs() < 0.05) {
            g.1 = Some(length_s);
        }
    }

    /// The signal time lost between stream times `from_s` and `to_s`, s: `None` when samples
    /// of unknown length were lost in between.
    fn lost_between(&self, from_s: f64, to_s: f64) -> Option<f64> {
        self.gaps
            .iter()
            .filter(|g| g.0 > from_s && g.0 <= to_s)
            .map(|g| g.1)
            .sum()
    }

    /// Records `e` in its satellite's run of locked carrier (`usable`), or ends the run.
    fn note_run(&mut self, e: &ChannelEpoch, usable: bool) {
        if !usable {
            self.runs.remove(&e.prn);
            return;
        }
        let t = e.sample_index as f64 / self.fs_hz;
        let run = self.runs.entry(e.prn).or_default();
        if run.back().is_none_or(|p| t - p.0 >= RUN_POINT_S) {
            run.push_back((t, -e.carrier_phase_cycles));
        }
        while run.front().is_some_and(|p| t - p.0 > RUN_KEPT_S) {
            run.pop_front();
        }
    }

    /// Follows whether `e`'s satellite coasted with a feed-forward over its last break in
    /// lock: every report in it was of the same channel (its `ms_count` grew), some held a
    /// feed-forward, those without one (before an outage bridge came on) span at most
    /// [`MAX_UNAIDED_COAST_S`], and the feed-forward held the signal: the loop's share of the
    /// NCO frequency (`doppler - feed-forward`) changed by `d` Hz from the break's first aided
    /// report to the re-lock, which is what the feed-forward missed; a miss growing
    /// linearly over the break of `T` s leaves `|d| T / 2` cycles in the carrier's range
    /// change, which must be within [`MAX_COAST_ERROR_M`]. A channel that coasted on a
    /// predicting aid ([`ChannelEpoch::coasting`], vector tracking) held its loop's share at
    /// zero from the coast's start `t_c`: its error is the phase its loop added over the break
    /// on noise (and pulling in again), `sum |doppler - feed-forward| T`, plus `|d| (t - t_c) / 2`
    /// with `d` the loop's share at the re-lock. Returns the longest break the channel's own
    /// carrier may bridge ([`Coast::bridge_s`]; None: it may not), from the first usable report
    /// after the break (it must hold a feed-forward too) until the next break.
    fn note_coast(&mut self, e: &ChannelEpoch, usable: bool) -> Option<f64> {
        let ff = e.feedforward_hz.filter(|f| f.is_finite());
        let t_s = e.sample_index as f64 / self.fs_hz;
        let c = self.coasts.entry(e.prn).or_default();
        let same = c.last_ms.is_none_or(|m| e.ms_count > m);
        c.last_ms = Some(e.ms_count);
        if usable {
            if c.in_break {
                let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
                let error_cycles = match (ff, c.coast_start_s, c.loop_share_hz) {
                    // Coasted on a prediction: the loop's share was zero over the coast, so
                    // what it holds at the re-lock is the aid's miss there.
                    (Some(f), Some(coast_s), _) => {
                        Some(c.loop_cycles + ((e.doppler_hz - f) * (t_s - coast_s) / 2.0).abs())
                    }
                    (Some(f), None, Some(start)) => {
                        Some(((e.doppler_hz - f) - start) * (t_s - c.start_s) / 2.0)
                    }
                    _ => None,
                };
                let held = error_cycles.is_some_and(|x| x.abs() * lambda <= MAX_COAST_ERROR_M);
                c.coasted = same && held && c.unaided_s <= MAX_UNAIDED_COAST_S;
                c.predicted = c.coasted && c.coast_start_s.is_some();
                c.in_break = false;
            }
            return c.bridge_s();
        }
        if !c.in_break {
            *c = Coast {
                last_ms: Some(e.ms_count),
                in_break: true,
                start_s: t_s,
                ..Coast::default()
            };
        }
        match ff {
            Some(f) => {
                c.loop_share_hz.get_or_insert(e.doppler_hz - f);
                c.loop_cycles += (e.doppler_hz - f).abs() * e.t_coh_s;
            }
            None => c.unaided_s += e.t_coh_s,
        }
        if e.coasting {
            c.coast_start_s.get_or_insert(t_s);
        }
        if !same {
            c.unaided_s = f64::INFINITY;
        }
        None
    }

    /// The anchor of a bridge of `prn`'s smoothing from stream time `from_s` to `to_s`: the
    /// first point of its current locked run after `from_s` and [`ANCHOR_SETTLE_S`] after
    /// the latest samples lost in between.
    fn anchor(&self, prn: u8, from_s: f64, to_s: f64) -> Option<CarrierAnchor> {
        let settled = self
            .gaps
            .iter()
            .filter(|g| g.0 > from_s && g.0 <= to_s)
            .map(|g| g.0 + ANCHOR_SETTLE_S)
            .fold(from_s, f64::max);
        self.runs
            .get(&prn)?
            .iter()
            .find(|p| p.0 > settled && p.0 <= to_s)
            .map(|&(t, cycles)| CarrierAnchor {
                t_stream_s: t,
                signal_cycles: cycles,
            })
    }

    /// The Hatch filter's epoch `he` of `e`'s satellite (carrier smoothing, 10 s) and its
    /// carrier Doppler: a loss of lock (`lost_flag`) is bridged when it can be
    /// ([`crate::pipeline::navigation::smoothing`]; with an INS over a manoeuvre), else the
    /// filter restarts. Returns the smoothed pseudorange (m) and the Doppler (Hz).
    fn smooth(
        &mut self,
        e: &ChannelEpoch,
        he: &HatchEpoch,
        lost_flag: bool,
        aid: Option<&InsFeedForward>,
        coasted_s: Option<f64>,
    ) -> (f64, f64) {
        let (n, t_stream, steps) = (he.epoch, he.t_stream_s, he.steps_ms);
        let max_m = self.hatch_epochs;
        let lost_s = self
            .smoothing
            .get(&e.prn)
            .and_then(|h| self.lost_between(h.t_stream_s, t_stream));
        // With an INS the range change over a break follows the motion (a manoeuvre's jerk
        // defeats the quadratic); only when the INS has been told of every gap (its times are
        // then signal times).
        let total_lost: Option<f64> = self.gaps.iter().map(|g| g.1).sum();
        let anchor = self
            .smoothing
            .get(&e.prn)
            .filter(|h| h.epoch != n - 1 || lost_flag)
            .and_then(|h| self.anchor(e.prn, h.t_stream_s, t_stream));
        match self.smoothing.get_mut(&e.prn) {
            Some(h) if h.epoch == n - 1 && !lost_flag => {
                // A clock step is not a Doppler; over the elapsed sample time (an epoch after a
                // clock step is not 1/rate after the previous one).
                let dl_signal = he.carrier_cycles
                    - h.carrier_cycles
                    - (steps - h.steps_ms) as f64 * 1e-3 * F_L1_HZ;
                let rate = -dl_signal / (t_stream - h.t_stream_s);
                h.update(he, max_m);
                self.phase_rate.insert((n, e.prn), rate);
                (h.smoothed_m, rate)
            }
            Some(h) => {
                let by_ins = match (aid, lost_s, total_lost) {
                    (Some(a), Some(g), Some(total)) => a
                        .carrier_change_cycles(e.prn, t_stream, t_stream - h.t_stream_s + g)
                        .filter(|&(_, told)| (told - total).abs() < 1e-4)
                        .map(|(cycles, _)| GivenChange {
                            change_m: -cycles * SPEED_OF_LIGHT_MPS / F_L1_HZ,
                            max_s: MAX_BRIDGE_S,
                        }),
                    _ => None,
                };
                // A channel that coasted with a feed-forward (an INS, the outage bridge, vector
                // tracking's prediction) moved its NCO with the motion: its own carrier is the
                // range change (no samples lost).
                let own_s = coasted_s.filter(|_| lost_s.is_some_and(|g| g.abs() < 1e-9));
                let by_own = own_s.map(|max_s| {
                    let cycles = |c: f64, steps: i64| c - steps as f64 * 1e-3 * F_L1_HZ;
                    GivenChange {
                        change_m: SPEED_OF_LIGHT_MPS / F_L1_HZ
                            * (cycles(he.carrier_cycles, he.steps_ms)
                                - cycles(h.carrier_cycles, h.steps_ms)),
                        max_s,
                    }
                });
                let given = by_ins.or(by_own);
                let break_s = t_stream - h.t_stream_s;
                let bridged = lost_s.is_some_and(|g| h.bridge(he, g, max_m, given, anchor));
                tracing::debug!(
                    "PRN {}: carrier smoothing {} over a break of {:.3} s (lost {:?} s; coasted with a feed-forward: {:?} m)",
                    e.prn,
                    if bridged { "bridged" } else { "restarted" },
                    break_s,
                    lost_s,
                    by_own.map(|g| g.change_m)
                );
                if !bridged {
                    *h = Hatch::start(he);
                }
                (h.smoothed_m, e.doppler_hz)
            }
            None => {
                self.smoothing.insert(e.prn, Hatch::start(he));
                (he.pseudorange_m, e.doppler_hz)
            }
        }
    }

    /// Takes one channel report (with the decoder of its satellite); returns the epochs that
    /// are complete (no channel can add to them any more).
    pub fn push(
        &mut self,
        e: &ChannelEpoch,
        dec: &NavDecoder,
        aid: Option<&InsFeedForward>,
    ) -> Vec<ObservableEpoch> {
        // Only phase-locked channels with signal give observables (a channel that has just
        // lost its signal still reports until its C/N0 test releases it), once their code loop
        // has settled.
        let usable = e.pll_lock
            && e.state != ChannelState::Lost
            && e.cn0_dbhz >= self.min_cn0_dbhz.min(e.cn0_lost_dbhz)
            && e.ms_count >= CODE_SETTLE_MS;
        let lost = self.lli.entry(e.prn).or_insert(true);
        *lost |= !usable;
        self.note_run(e, usable);
        let coasted = self.note_coast(e, usable);
        if !usable {
            return Vec::new();
        }
        if let Some(t0) = self.t0 {
            let end_rx = t0.tow_s + e.sample_index as f64 / self.fs_hz + e.t_coh_s;
            self.reached_rx_s = self.reached_rx_s.max(end_rx);
        }
        let Some(sv_tow0) = dec.sv_tow_s(e.ms_count, e.code_phase_chips) else {
            return Vec::new();
        };
        let t_rx = e.sample_index as f64 / self.fs_hz;
        let t0 = *self.t0.get_or_insert_with(|| {
            // Travel time 75 ms, receiver time of sample 0 on a whole millisecond.
            let t = sv_tow0 + 0.075 - t_rx;
            GpsTime::new(dec.week(), (t * 1e3).round() * 1e-3)
        });
        // The week label comes from the reference week until a subframe 1 is decoded.
        let t0 = match dec.decoded_week() {
            Some(w) if w != t0.week => {
                let fixed = GpsTime {
                    week: w,
                    tow_s: t0.tow_s,
                };
                self.t0 = Some(fixed);
                fixed
            }
            _ => t0,
        };
        // Epoch indices whose receiver time falls inside this report's interval.
        let start_rx = t0.tow_s + t_rx;
        let end_rx = start_rx + e.t_coh_s;
        let first = (start_rx * self.rate_hz).ceil() as i64;
        let mut n = first;
        while (n as f64) / self.rate_hz < end_rx {
            let t_epoch = n as f64 / self.rate_hz;
            let dt = t_epoch - start_rx;
            let sv_tow = sv_tow0 + dt * e.code_rate_chips_s / CA_CHIP_RATE_HZ;
            // Week-boundary safe difference of two TOWs.
            let tau = GpsTime::fold_tow_difference_s(t_epoch - sv_tow);
            let carrier = e.carrier_phase_cycles + dt * e.doppler_hz;
            let lost_flag = std::mem::replace(self.lli.entry(e.prn).or_insert(false), false);
            let pseudorange_m = tau * SPEED_OF_LIGHT_MPS;
            // The NCO phase grows with the Doppler (range shrinking); RINEX phase grows with the
            // range: negate. The receiver clock steps move it by f_L1 per second.
            let carrier_cycles = -carrier + self.total_step_ms as f64 * 1e-3 * F_L1_HZ;
            // Hatch filter (carrier smoothing, 10 s) and carrier Doppler; a loss of lock is
            // bridged when it can be ([`crate::pipeline::navigation::smoothing`]), else the filter restarts.
            let t_stream = t_epoch - t0.tow_s;
            let he = HatchEpoch {
                epoch: n,
                carrier_cycles,
                pseudorange_m,
                steps_ms: self.total_step_ms,
                t_stream_s: t_stream,
            };
            let (smoothed, doppler_hz) = self.smooth(e, &he, lost_flag, aid, coasted);
            if n < self.first_epoch {
                // Not collected: its loss of lock is reported with the next epoch (the
                // smoothing has taken the break here).
                if lost_flag {
                    self.lli_carried.insert(e.prn);
                }
                self.newest = self.newest.max(n);
                n += 1;
                continue;
            }
            let lost_flag = self.lli_carried.remove(&e.prn) || lost_flag;
            self.pending.entry(n).or_default().push(SatObservable {
                prn: e.prn,
                sv_tow_s: sv_tow,
                pseudorange_m,
                smoothed_pseudorange_m: smoothed,
                carrier_cycles,
                doppler_hz,
                cn0_dbhz: e.cn0_dbhz,
                loss_of_lock: lost_flag,
                half_cycle_ambiguous: false,
            });
            self.newest = self.newest.max(n);
            n += 1;
        }
        // Epochs two or more behind the newest are complete.
        let done: Vec<i64> = self
            .pending
            .keys()
            .copied()
            .filter(|&k| k + 2 <= self.newest)
            .collect();
        let mut out = Vec::new();
        for k in done {
            if let Some(mut sats) = self.pending.remove(&k) {
                sats.sort_by_key(|s| s.prn);
                sats.dedup_by_key(|s| s.prn);
                // Central difference: the mean of the backward differences into k and k+1.
                for s in &mut sats {
                    if let (Some(a), Some(b)) = (
                        self.phase_rate.get(&(k, s.prn)),
                        self.phase_rate.get(&(k + 1, s.prn)),
                    ) {
                        s.doppler_hz = 0.5 * (a + b);
                    }
                }
                self.phase_rate = self.phase_rate.split_off(&(k + 1, 0));
                let t = k as f64 / self.rate_hz;
                out.push(ObservableEpoch {
                    rx_time: GpsTime::new(t0.week, t),
                    sample: (t - t0.tow_s) * self.fs_hz,
                    clock_step_ms: std::mem::take(&mut self.pending_step_ms),
                    sats,
                });
            }
        }
        out
    }
}
