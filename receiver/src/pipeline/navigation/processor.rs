//! The navigation processor: from channel reports to observables and fixes.
//!
//! Per satellite an LNAV decoder (frame sync, subframes, ephemeris); across satellites the
//! observable builder (pseudoranges, carrier phase, Doppler at common receiver epochs); per
//! epoch the WLS PVT with RAIM (`gpsrx_nav::pvt::solve`) with the decoded or assisted
//! ephemerides, the receiver clock kept within 0.5 ms of GPS time by whole-millisecond steps,
//! and the aiding feedback (ephemerides, fixes and the time origin to the INS feed-forward).

mod decode;
mod predict;
mod settle;
mod solve;
mod time_recovery;

use crate::config::RunSettings;
use crate::landmarks::LandmarkObservation;
use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::navigation::fix_output::FixStats;
use crate::pipeline::navigation::navdata::NavDecoder;
use crate::pipeline::navigation::observables::ObservableBuilder;
use crate::pipeline::sink::ChannelRow;
use crate::pipeline::sink::{NavigationEnd, Progress, ReceiverEvent, Sink, SinkError};
use crate::pipeline::timing::coarse_fix::CoarseFixer;
use crate::pipeline::timing::predicted;
use crate::pipeline::timing::quick_sync::QuickSync;
use crate::pipeline::timing::sv_time::CarryNote;
use crate::pipeline::timing::{BlockEvent, FoundBy, TimeKeeper};
use gpsrx_nav::lnav::AlmanacCollector;
use gpsrx_nav::pvt::{PvtSolution, RaimStatus};
use gpsrx_nav::rinex_nav::NavData;
use gpsrx_tracking::{ChannelEpoch, ChannelState};
use std::collections::{BTreeMap, BTreeSet};

/// Decoders, observables and PVT.
#[derive(Debug)]
pub struct NavigationProcessor {
    fs_hz: f64,
    settings: RunSettings,
    /// See [`NavigationProcessor::with_aided_offset`].
    aided_offset_cycles: Option<f64>,
    reference_week: u32,
    /// Whether `reference_week` may date outputs (it is not from the system clock).
    reference_week_known: bool,
    nav_assist: Option<NavData>,
    landmarks: Vec<LandmarkObservation>,
    decoders: BTreeMap<u8, NavDecoder>,
    /// The almanac from every satellite's subframes 4 and 5.
    almanac: AlmanacCollector,
    builder: ObservableBuilder,
    prior: Option<PvtSolution>,
    /// The last valid fix for the acquisition scheduler's predictions (kept across gaps).
    anchor: Option<predict::PredictionAnchor>,
    /// The valid fixes with a velocity of the last `predict::RECENT_FIXES_S`, for the outage
    /// bridge.
    recent_fixes: std::collections::VecDeque<crate::pipeline::aiding::FixPoint>,
    /// Signal lost in all the gaps measured so far, s.
    lost_total_s: f64,
    /// The first fixes after an outage ([`settle`]).
    settle: settle::OutageSettle,
    iono_fallback_said: bool,
    /// The RAIM outcome last logged (transitions are logged).
    last_raim: Option<RaimStatus>,
    /// A too-poor geometry has been logged and has not improved since.
    poor_geometry_logged: bool,
    /// Per channel: receive time of its last channel row.
    last_row_t: BTreeMap<usize, f64>,
    /// Latest sample index a progress report was made for.
    progress_at: u64,
    stats: FixStats,
    /// C/N0 below which a report gives no observables and does not count as tracked, dB-Hz.
    cn0_lost_dbhz: f64,
    /// PRNs that had a channel.
    searched: BTreeSet<u8>,
    /// PRNs whose channel reached bit sync or carrier lock in tracking.
    locked: BTreeSet<u8>,
    /// Receiver and SV time across gaps and outages: the SV times, the gap detectors, the
    /// clock of the last fix and the recovery from long gaps.
    time: TimeKeeper,
    /// Consecutive solutions that failed the integrity test.
    failed_in_row: u32,
    /// A valid fix came since the receiver time was last forgotten.
    time_trusted: bool,
    /// The coarse-time first fix (approximate time and position given).
    coarse: Option<CoarseFixer>,
    /// A refused coarse-time attempt was logged at WARN.
    coarse_warned: bool,
    /// No fix from epochs before this sample: the channels reported before the coarse-time
    /// fix handed out the SV times give nothing to them.
    fixes_from_sample: f64,
    /// Frame sync from one TLM and HOW confirmed across satellites (with ephemerides from a
    /// navigation file, a fix can follow at once).
    quick: Option<QuickSync>,
    /// Signal lost in gaps measured since the INS feed-forward was last told, ms.
    lost_for_aid_ms: f64,
}

/// Time the code loops of channels that kept their satellites over lost samples need before
/// their offsets measure the gap, s (four time constants of a 1 Hz DLL).
const CODE_SETTLE_AFTER_GAP_S: f64 = 1.0;

/// Time the code loops of channels moved onto a code that jumped need before their offsets
/// measure the gap, s (the search placed them within a few hundredths of a chip).
const CODE_SETTLE_AFTER_REALIGN_S: f64 = 0.5;

/// Time the phase loops of channels moved onto a code that jumped need to lock again before
/// the carrier-phase step over the jump is measured, s.
const PHASE_SETTLE_AFTER_REALIGN_S: f64 = 0.25;

/// Doppler uncertainty of a satellite predicted from a fix and an ephemeris, Hz (the fix's
/// velocity and clock drift are good to a few cm/s: a few hertz; the rest is margin), and its
/// growth with the age of the fix, Hz/s (a receiver accelerating at 1 g changes the Doppler by
/// up to 50 Hz/s).
pub const PREDICTED_DOPPLER_HZ: f64 = 60.0;
/// See [`PREDICTED_DOPPLER_HZ`].
pub const PREDICTED_DOPPLER_RATE_HZ_S: f64 = 50.0;
/// Doppler uncertainty of a satellite predicted from `--approx-llh` and `--time` alone, Hz:
/// the receiver clock's frequency error is unknown (a TCXO within 2 ppm: 3.2 kHz).
pub const APPROX_DOPPLER_HZ: f64 = 3500.0;
/// How long the first fix is awaited with `--nav` before the background search's most
/// sensitive level runs without a prediction, s of signal.
pub const PENDING_FOR_S: f64 = 30.0;
/// Elevation below which a satellite predicted hidden is not searched, deg (margin for an
/// approximate position or time).
pub const BELOW_HORIZON_DEG: f64 = -2.0;

/// Solutions failing the integrity test in a row, after a valid one, that make the receiver
/// time suspect.
const FAILURES_TO_DISTRUST_TIME: u32 = 5;

impl NavigationProcessor {
    /// A processor for samples at `fs_hz`. `cn0_lost_dbhz`: reports below it give no
    /// observables. `reference_week` resolves the broadcast 10-bit week.
    pub fn new(
        fs_hz: f64,
        settings: RunSettings,
        cn0_lost_dbhz: f64,
        reference_week: u32,
        nav_assist: Option<NavData>,
        landmarks: Vec<LandmarkObservation>,
    ) -> Self {
        let builder =
            ObservableBuilder::new(fs_hz, settings.rate_hz).with_min_cn0_dbhz(cn0_lost_dbhz);
        let nav_assist_given = nav_assist.is_some();
        Self {
            fs_hz,
            settings,
            reference_week,
            reference_week_known: true,
            nav_assist,
            landmarks,
            decoders: BTreeMap::new(),
            almanac: AlmanacCollector::new(reference_week),
            builder,
            prior: None,
            anchor: None,
            recent_fixes: std::collections::VecDeque::new(),
            lost_total_s: 0.0,
            settle: settle::OutageSettle::default(),
            iono_fallback_said: false,
            last_raim: None,
            poor_geometry_logged: false,
            last_row_t: BTreeMap::new(),
            progress_at: 0,
            stats: FixStats::default(),
            cn0_lost_dbhz,
            searched: BTreeSet::new(),
            locked: BTreeSet::new(),
            time: TimeKeeper::new(fs_hz),
            failed_in_row: 0,
            time_trusted: false,
            coarse: None,
            coarse_warned: false,
            fixes_from_sample: 0.0,
            quick: nav_assist_given.then(QuickSync::default),
            aided_offset_cycles: None,
            lost_for_aid_ms: 0.0,
        }
    }

    /// The static phase offset the aided loops keep under a nominal INS bias
    /// (`gpsrx_tracking::aiding::nominal_aided_offset_cycles`), written in `channels.csv` for
    /// the channels fed forward (`None`: no column value).
    pub fn with_aided_offset(mut self, cycles: Option<f64>) -> Self {
        self.aided_offset_cycles = cycles;
        self
    }

    /// Enables the coarse-time first fix (`crate::pipeline::timing::coarse_fix`) when the settings
    /// hold an approximate position, `start` (the approximate GPS time of sample 0: `--time`,
    /// else the recording's date) is known and a navigation file gives the ephemerides;
    /// says why not when the position is given without the rest.
    pub fn with_coarse_time(mut self, start: Option<gpsrx_nav::time::GpsTime>) -> Self {
        let Some([lat, lon, h]) = self.settings.approx_llh else {
            return self;
        };
        match (start, &self.nav_assist) {
            (Some(t), Some(_)) => {
                tracing::info!(
                    "coarse time: approximate start {}:{:.1}, position {lat:.4} {lon:.4} {h:.0} m: the first fix comes from the code phases once 5-6 satellites are tracked",
                    t.week,
                    t.tow_s
                );
                self.coarse = Some(CoarseFixer::new(
                    self.fs_hz,
                    t,
                    gpsrx_nav::frames::Llh::from_degrees(lat, lon, h),
                ));
            }
            (None, _) => tracing::warn!(
                "an approximate position was given without an approximate time (none given, none in the recording's metadata): no coarse-time fix; the first fix waits for frame sync"
            ),
            (_, None) => tracing::warn!(
                "an approximate position was given, but no navigation data (ephemerides), which a coarse-time fix needs: the first fix waits for frame sync"
            ),
        }
        self
    }

    /// After every channel has reported up to sample `end`: looks for lost samples. On a
    /// carrier-phase jump the SV times are kept aside until the gap's length is resolved
    /// (frame sync gives the time when it is not), carrier smoothing restarts, and no fix is
    /// made until then; the channels must then find their bit edges again. On a common
    /// collapse of the prompt power their code must be searched again.
    pub fn end_block(
        &mut self,
        end: u64,
        sink: &mut dyn Sink,
    ) -> Result<Option<BlockEvent>, SinkError> {
        let d = match self.time.end_block(end) {
            None => return Ok(None),
            Some(BlockEvent::Collapse(c)) => {
                self.settle.collapse(c.sample as f64 / self.fs_hz);
                tracing::info!(
                "{:.3} s: the prompt power of {} of {} satellites collapsed at once (samples lost, or a blockage): searching their code again",
                c.sample as f64 / self.fs_hz,
                c.satellites.len(),
                c.watched
                );
                return Ok(Some(BlockEvent::Collapse(c)));
            }
            Some(BlockEvent::PhaseJump(d)) => d,
        };
        let t_s = d.sample as f64 / self.fs_hz;
        match d.found_by {
            FoundBy::CarrierPhase => tracing::warn!(
                "{t_s:.3} s: samples lost (the carrier phase of {} of {} satellites jumped at once): no fix until the receiver time is re-established",
                d.jumped,
                d.watched
            ),
            FoundBy::BitEdges {
                offset_ms,
                after_sample,
            } => tracing::warn!(
                "{t_s:.3}-{:.3} s: samples lost (the data-bit edges of {} of {} satellites moved by {offset_ms} ms at once): no fix until the receiver time is re-established",
                after_sample as f64 / self.fs_hz,
                d.jumped,
                d.watched
            ),
        }
        let steps = d.steps.clone();
        tracing::debug!("carrier-phase steps over the jump: {steps:?}");
        // The code loops of the channels that kept their satellites take a second to follow
        // the code's step over the gap before their offsets measure it.
        self.forget_time(t_s, steps, Some(t_s + CODE_SETTLE_AFTER_GAP_S));
        sink.event(&ReceiverEvent::SampleGap { t_s })?;
        Ok(Some(BlockEvent::PhaseJump(d)))
    }

    /// Says whether the reference week may date the outputs (true unless set here): when
    /// not, times before subframe 1 is decoded carry [`crate::output::Fix::week_known`] and
    /// [`crate::pipeline::ObservablesReport::week_known`] false ([`crate::pipeline::WeekReference`]).
    pub fn with_reference_week_known(mut self, known: bool) -> Self {
        self.reference_week_known = known;
        self
    }

    /// Whether the week of the times is known: decoded from a subframe 1, or a reference
    /// week that does not come from the system clock.
    fn week_known(&self) -> bool {
        self.reference_week_known || self.decoders.values().any(|d| d.decoded_week().is_some())
    }

    /// The fixes so far, summarised.
    pub fn stats(&self) -> &FixStats {
        &self.stats
    }

    /// The satellites really tracked at some point: their channel reached bit sync, or carrier
    /// lock after the hand-over to the tracking loops, with a C/N0 estimate at or above the
    /// loss threshold. (A channel on noise can declare a bit edge or flicker into lock, but
    /// below that threshold: measured on a simulated recording, noise channels gave bits at
    /// 23-25 dB-Hz.)
    pub fn tracked_prns(&self) -> Vec<u8> {
        self.locked.iter().copied().collect()
    }

    /// The satellites that had a channel but were never tracked (pull-in on noise, or a
    /// signal too weak to hold).
    pub fn dropped_prns(&self) -> Vec<u8> {
        self.searched.difference(&self.locked).copied().collect()
    }

    /// The ephemeris decoded from satellite `prn`'s signal, if any (vector tracking's model).
    pub fn decoded_ephemeris(&self, prn: u8) -> Option<&gpsrx_nav::ephemeris::Ephemeris> {
        self.decoders.get(&prn)?.ephemeris.as_ref()
    }

    /// The decoded Klobuchar parameters, if any (vector tracking's model).
    pub fn decoded_iono(&self) -> Option<gpsrx_nav::atmosphere::KlobucharParams> {
        self.decoders.values().find_map(|d| d.iono)
    }

    /// What was decoded: ephemerides, ionosphere and UTC parameters.
    pub fn end(&self) -> NavigationEnd {
        NavigationEnd {
            ephemerides: self
                .decoders
                .values()
                .filter_map(|d| d.ephemeris.clone())
                .collect(),
            transmission_tow_s: self
                .decoders
                .values()
                .filter_map(|d| Some((d.ephemeris.as_ref()?.prn, d.ephemeris_transmission_tow_s?)))
                .collect(),
            iono: self.decoders.values().find_map(|d| d.iono),
            utc: self.decoders.values().find_map(|d| d.utc),
            almanac: self.almanac.almanac_set(),
        }
    }

    /// Takes one channel report: decodes its bit, writes the channel row, builds observables
    /// and solves every epoch that is complete. `predicted_sv_tow_s`: vector tracking's
    /// prediction of the satellite's SV time at the report's first sample, which a channel
    /// without frame sync takes at a bit edge (`crate::pipeline::timing::predicted`).
    pub fn on_report(
        &mut self,
        channel: usize,
        e: &ChannelEpoch,
        aiding: Option<&InsFeedForward>,
        predicted_sv_tow_s: Option<f64>,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        sink.channel_epoch(channel, e)?;
        self.time.push(e);
        self.searched.insert(e.prn);
        let locked = e.bit.is_some() || (e.pll_lock && e.state == ChannelState::Track);
        // The channel's own threshold where vector tracking checks it (lower), else ours.
        let cn0_lost_dbhz = self.cn0_lost_dbhz.min(e.cn0_lost_dbhz);
        if locked && e.cn0_dbhz >= cn0_lost_dbhz {
            self.locked.insert(e.prn);
        }
        self.decode(e, aiding, sink)?;
        let usable = e.pll_lock && e.state != ChannelState::Lost && e.cn0_dbhz >= cn0_lost_dbhz;
        let note = match self.decoders.get_mut(&e.prn) {
            Some(dec) => self.time.observe(e, dec, usable),
            None => None,
        };
        match note {
            Some(CarryNote::Refused(off_ms)) => self.on_refused(e.t_rx_s, e.prn, off_ms, sink)?,
            Some(CarryNote::GapResolved {
                t_s,
                length_ms,
                from_bits,
            }) => {
                let from = if from_bits {
                    "the data bits, matched in the frames before"
                } else {
                    "the carrier-phase steps and the code at the new bit edges"
                };
                tracing::warn!(
                    "{:.3} s: the samples lost at {t_s:.3} s were {length_ms:.3} ms of signal (from {from}): SV times carried over the gap",
                    e.t_rx_s
                );
                sink.event(&ReceiverEvent::GapMeasured { t_s, length_ms })?;
                self.lost_for_aid_ms += length_ms;
                self.step_clock_over_gap(t_s, length_ms, sink)?;
            }
            None => {}
        }
        if let (Some(sv), true) = (predicted_sv_tow_s, usable) {
            self.take_predicted_sv_time(e, sv);
        }
        self.start_long_gap();
        self.coarse_step(e, sink)?;
        self.channel_row(channel, e, sink)?;
        self.realign_clock(e, sink)?;
        let ready = match self.decoders.get(&e.prn) {
            Some(d) => self.builder.push(e, d, aiding),
            None => Vec::new(),
        };
        if let (Some(ff), Some(t0)) = (aiding, self.builder.rx_time_origin()) {
            ff.set_time_origin(t0);
        }
        for epoch in ready {
            self.solve_epoch(epoch, aiding, sink)?;
        }
        if self.lost_for_aid_ms > 0.0 {
            if let Some(ff) = aiding {
                ff.note_samples_lost(self.lost_for_aid_ms * 1e-3);
            }
            self.lost_total_s += self.lost_for_aid_ms * 1e-3;
            self.lost_for_aid_ms = 0.0;
        }
        let s = e.sample_index;
        if s > self.progress_at + (self.fs_hz * 0.2) as u64 {
            self.progress_at = s;
            sink.progress(&Progress {
                sample_index: s,
                satellites: self.decoders.len(),
                frame_synced: self.decoders.values().filter(|d| d.synced()).count(),
                with_ephemeris: self
                    .decoders
                    .values()
                    .filter(|d| d.ephemeris.is_some())
                    .count(),
                fixes: self.stats.fixes,
            })?;
        }
        Ok(())
    }

    /// A channel in phase lock at a bit edge, its decoder without an SV time, takes the one
    /// vector tracking predicts (`crate::pipeline::timing::predicted`); not while the length
    /// of lost samples is unknown.
    fn take_predicted_sv_time(&mut self, e: &ChannelEpoch, predicted_sv_tow_s: f64) {
        if !e.bit_edge || self.time.gap().is_some() {
            return;
        }
        let Some(dec) = self.decoders.get_mut(&e.prn).filter(|d| !d.synced()) else {
            return;
        };
        match predicted::edge_sv_tow_s(e, predicted_sv_tow_s) {
            Ok(sv_tow_s) => {
                dec.carry_time(e.ms_count, sv_tow_s);
                tracing::info!(
                    "G{:02}: SV time {sv_tow_s:.3} s from vector tracking's prediction at its bit edge (before frame sync)",
                    e.prn
                );
            }
            Err(off_ms) => tracing::debug!(
                "G{:02}: vector tracking's predicted SV time falls {off_ms:+.3} ms off its bit edge: not taken",
                e.prn
            ),
        }
    }

    /// Whether the receiver ever knew the SV time of `prn` in this run (a satellite timed
    /// before keeps its own checks of a new bit edge against that time: the data-bit edges
    /// of vector tracking's prediction are not imposed on it).
    pub fn sv_time_ever_known(&self, prn: u8) -> bool {
        self.time.ever_known(prn)
    }

    /// The channel's row, at most once per fix interval.
    fn channel_row(
        &mut self,
        channel: usize,
        e: &ChannelEpoch,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let due = self
            .last_row_t
            .get(&channel)
            .is_none_or(|&t| e.t_rx_s - t >= 1.0 / self.settings.rate_hz - 1e-9);
        if !due {
            return Ok(());
        }
        self.last_row_t.insert(channel, e.t_rx_s);
        let synced = self.decoders.get(&e.prn).is_some_and(NavDecoder::synced);
        let row = ChannelRow {
            time: self
                .builder
                .rx_time_origin()
                .map(|t0| t0.add_seconds(e.t_rx_s)),
            week_known: self.week_known(),
            t_stream_s: e.t_rx_s,
            channel: channel as u32,
            prn: e.prn,
            state: format!("{:?}", e.state).to_lowercase(),
            cn0_dbhz: e.cn0_dbhz.is_finite().then_some(e.cn0_dbhz),
            doppler_hz: Some(e.doppler_hz),
            code_phase_chips: Some(e.code_phase_chips),
            pll_lock_indicator: Some(e.pll_lock_metric),
            code_lock: e.code_lock,
            carrier_lock: e.pll_lock,
            bit_sync: e.bit_edge || synced,
            frame_sync: synced,
            predicted_offset_cycles: self.aided_offset_cycles.filter(|_| {
                e.state == ChannelState::Track && e.feedforward_hz.is_some_and(f64::is_finite)
            }),
        };
        sink.channel(&row)
    }
}
