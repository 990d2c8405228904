//! The navigation processor: from channel reports to observables and fixes.
//!
//! Per satellite an LNAV decoder (frame sync, subframes, ephemeris); across satellites the
//! observable builder (pseudoranges, carrier phase, Doppler at common receiver epochs); per
//! epoch the WLS PVT with RAIM (`gpsrx_nav::pvt::solve`) with the decoded or assisted
//! ephemerides, the receiver clock kept within 0.5 ms of GPS time by whole-millisecond steps,
//! and the aiding feedback (ephemerides, fixes and the time origin to the INS feed-forward).

pub(crate) mod fix_output;
pub(crate) mod navdata;
pub(crate) mod observables;
pub(crate) mod smoothing;

pub use navdata::{NavDecoder, NavEvent};

use crate::config::{IonoModel, RunSettings, TropoModel};
use crate::landmarks::LandmarkObservation;
use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::channels::channel_manager::Realigned;
use crate::pipeline::channels::search_schedule::Visibility;
pub use crate::pipeline::navigation::fix_output::FixStats;
use crate::pipeline::navigation::fix_output::{fix_of, obs_epoch, passes_integrity};
use crate::pipeline::navigation::observables::{ObservableBuilder, ObservableEpoch};
use crate::pipeline::sink::{ChannelRow, FixQuality};
use crate::pipeline::sink::{
    FixReport, NavigationEnd, ObservablesReport, Progress, ReceiverEvent, Sink, SinkError,
};
use crate::pipeline::timing::coarse_fix::{CoarseFixer, CoarseRefusal};
use crate::pipeline::timing::code_jump::{Collapse, CollapseMonitor};
use crate::pipeline::timing::discontinuity::{Discontinuity, DiscontinuityMonitor};
use crate::pipeline::timing::long_gap::LongGapRecovery;
use crate::pipeline::timing::quick_sync::{QuickSync, TowCandidate};
use crate::pipeline::timing::sv_time::{CarryNote, GapRecovery, SvTimeKeeper};
use gpsrx_nav::atmosphere::KlobucharParams;
use gpsrx_nav::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::ephemeris::{Ephemeris, HealthPolicy};
use gpsrx_nav::lnav::AlmanacCollector;
use gpsrx_nav::pvt::{solve, Landmark, PvtOptions, PvtSolution, RaimStatus, SatMeasurement};
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
    /// The satellites' SV times kept over losses and gaps.
    sv_time: SvTimeKeeper,
    /// Watches for lost samples: carrier-phase jumps.
    monitor: DiscontinuityMonitor,
    /// Watches for lost samples: prompt power collapsing on several satellites at once.
    collapse: CollapseMonitor,
    /// After a code realignment: the jump's sample, the satellites moved and the sample from
    /// which their carrier phase is locked again, for the phase steps over the jump.
    pending_steps: Option<(u64, Vec<u8>, u64)>,
    /// The last valid fix: stream time (s), clock bias after any clock step (m), clock drift
    /// (m/s).
    last_clock: Option<(f64, f64, f64)>,
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
    /// The receiver time re-established after samples of unknown length were lost.
    long_gap: LongGapRecovery,
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

/// What the end of a block found in the reports.
#[derive(Debug, Clone, PartialEq)]
pub enum BlockEvent {
    /// Samples lost by whole milliseconds: the carrier phase jumped on every satellite; the
    /// channels must find their bit edges again.
    PhaseJump(Discontinuity),
    /// The prompt power collapsed on several satellites at once: their code must be searched
    /// again (samples lost by a fraction of a millisecond, or a blockage).
    Collapse(Collapse),
}

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
            iono_fallback_said: false,
            last_raim: None,
            poor_geometry_logged: false,
            last_row_t: BTreeMap::new(),
            progress_at: 0,
            stats: FixStats::default(),
            cn0_lost_dbhz,
            searched: BTreeSet::new(),
            locked: BTreeSet::new(),
            sv_time: SvTimeKeeper::default(),
            monitor: DiscontinuityMonitor::new(fs_hz),
            collapse: CollapseMonitor::new(),
            pending_steps: None,
            last_clock: None,
            failed_in_row: 0,
            time_trusted: false,
            coarse: None,
            coarse_warned: false,
            fixes_from_sample: 0.0,
            quick: nav_assist_given.then(QuickSync::default),
            aided_offset_cycles: None,
            long_gap: LongGapRecovery::default(),
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

    /// Enables the coarse-time first fix ([`crate::pipeline::timing::coarse_fix`]) when the settings
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
                "--approx-llh without an approximate time (--time WEEK:TOW, or a SigMF core:datetime): no coarse-time fix; the first fix waits for frame sync"
            ),
            (_, None) => tracing::warn!(
                "--approx-llh needs the ephemerides of --nav for a coarse-time fix: the first fix waits for frame sync"
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
        self.measure_pending_steps(end);
        if let Some(c) = self.collapse.evaluate(end, self.fs_hz) {
            tracing::info!(
                "{:.3} s: the prompt power of {} of {} satellites collapsed at once (samples lost, or a blockage): searching their code again",
                c.sample as f64 / self.fs_hz,
                c.satellites.len(),
                c.watched
            );
            return Ok(Some(BlockEvent::Collapse(c)));
        }
        let Some(d) = self.monitor.evaluate(end) else {
            return Ok(None);
        };
        let t_s = d.sample as f64 / self.fs_hz;
        tracing::warn!(
            "{t_s:.3} s: samples lost (the carrier phase of {} of {} satellites jumped at once): no fix until the receiver time is re-established",
            d.jumped,
            d.watched
        );
        let steps = d.steps.clone();
        tracing::debug!("carrier-phase steps over the jump: {steps:?}");
        // The code loops of the channels that kept their satellites take a second to follow
        // the code's step over the gap before their offsets measure it.
        self.forget_time(t_s, steps, Some(t_s + CODE_SETTLE_AFTER_GAP_S));
        sink.event(&ReceiverEvent::SampleGap { t_s })?;
        Ok(Some(BlockEvent::PhaseJump(d)))
    }

    /// The channels of the satellites in `r` were moved onto a code that jumped as lost
    /// samples make it jump. The SV times are kept aside until the length is resolved from
    /// the new bit edges, the carrier-phase steps (measured once the phase loops hold again)
    /// and the code, as after a whole-millisecond gap.
    pub fn on_code_realigned(
        &mut self,
        r: &Realigned,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let t_s = r.jump_sample as f64 / self.fs_hz;
        if r.length_unknown {
            tracing::warn!(
                "{t_s:.3} s: samples lost (the code of {} satellites moved by more than any gap of up to {:.0} s explains): channels moved onto it; no fix until the receiver time is re-established",
                r.prns.len(),
                r.shortest_gap_s
            );
            self.forget_time(t_s, Vec::new(), None);
            let settled =
                r.at_sample as f64 + crate::pipeline::timing::long_gap::CODE_SETTLE_S * self.fs_hz;
            self.fixes_from_sample = self.fixes_from_sample.max(settled);
            return sink.event(&ReceiverEvent::SampleGap { t_s });
        }
        let frac_ms = (-r.fraction_of_period).rem_euclid(1.0);
        tracing::warn!(
            "{t_s:.3} s: samples lost (the code of {} satellites jumped: {frac_ms:.4} ms modulo 1 ms, at least {:.1} ms): channels moved onto it; no fix until the receiver time is re-established",
            r.prns.len(),
            r.shortest_gap_s * 1e3
        );
        self.forget_time(t_s, Vec::new(), Some(t_s + CODE_SETTLE_AFTER_REALIGN_S));
        let settle = (PHASE_SETTLE_AFTER_REALIGN_S * self.fs_hz) as u64;
        self.monitor.hold_until(r.at_sample + settle);
        self.pending_steps = Some((r.jump_sample, r.prns.clone(), r.at_sample + settle));
        sink.event(&ReceiverEvent::SampleGap { t_s })
    }

    /// The carrier-phase steps over a code jump, once the phase loops of the moved channels
    /// hold again (up to sample `end`): handed to the gap being recovered from.
    fn measure_pending_steps(&mut self, end: u64) {
        let Some((jump, prns, from)) = self.pending_steps.as_ref() else {
            return;
        };
        if end < from + (0.02 * self.fs_hz) as u64 {
            return;
        }
        let steps = self.monitor.phase_steps(prns, *jump, Some(*from));
        tracing::debug!("carrier-phase steps over the code jump: {steps:?}");
        if let Some(gap) = self.sv_time.gap.as_mut() {
            gap.steps = steps;
        }
        self.pending_steps = None;
    }

    /// Says whether the reference week may date the outputs (true unless set here): when
    /// not, times before subframe 1 is decoded carry [`crate::output::Fix::week_known`] and
    /// [`ObservablesReport::week_known`] false ([`crate::pipeline::timing::dating`]).
    pub fn with_reference_week_known(mut self, known: bool) -> Self {
        self.reference_week_known = known;
        self
    }

    /// Whether the week of the times is known: decoded from a subframe 1, or a reference
    /// week that does not come from the system clock.
    fn week_known(&self) -> bool {
        self.reference_week_known || self.decoders.values().any(|d| d.decoded_week().is_some())
    }

    /// What is predicted of `prn` at stream time `t_stream_s` for the acquisition scheduler:
    /// with a fix (position, velocity, clock bias and drift) and the satellite's ephemeris
    /// (decoded or from `--nav`), whether it is above the horizon and its Doppler within
    /// [`PREDICTED_DOPPLER_HZ`] plus [`PREDICTED_DOPPLER_RATE_HZ_S`] per second since the fix
    /// ([`crate::pipeline::channels::visibility`]); else nothing.
    pub fn visibility(&self, prn: u8, t_stream_s: f64) -> Visibility {
        let Some((rx, t, drift, half_width_hz)) = self.prediction_origin(t_stream_s) else {
            // With ephemerides from `--nav`, the first fix (a few seconds away) will tell.
            let soon = self.nav_assist.is_some() && t_stream_s < PENDING_FOR_S;
            return if soon {
                Visibility::Pending
            } else {
                Visibility::Unknown
            };
        };
        let decoded = self.decoders.get(&prn).and_then(|d| d.ephemeris.as_ref());
        let eph = decoded.or_else(|| {
            self.nav_assist
                .as_ref()
                .and_then(|n| n.select_with(prn, t, HealthPolicy::PreferHealthy))
        });
        // An ephemeris within 4 h, else the decoded almanac (a few hertz worse: margin enough).
        let seen = match eph.filter(|e| e.is_within_s(t, 4.0 * 3600.0)) {
            Some(e) => e.at_reception(t, &rx.pos_m, 0.075, 3),
            None => match self.almanac.almanac(prn) {
                Some(a) => a.at_reception(t, &rx.pos_m),
                None => return Visibility::Unknown,
            },
        };
        match crate::pipeline::channels::visibility::predict_seen(&seen, &rx, drift) {
            Some(p) if p.elevation_deg < BELOW_HORIZON_DEG => Visibility::Below,
            Some(p) => Visibility::Visible {
                doppler_hz: p.doppler_hz,
                half_width_hz,
            },
            None => Visibility::Unknown,
        }
    }

    /// Where, when and with which clock drift (s/s) the receiver is at stream time
    /// `t_stream_s`, and the Doppler uncertainty of a prediction from that: the last fix
    /// (position, velocity, clock bias and drift; [`PREDICTED_DOPPLER_HZ`] growing by
    /// [`PREDICTED_DOPPLER_RATE_HZ_S`] with its age), else `--approx-llh` and `--time` (the
    /// receiver clock drift unknown: [`APPROX_DOPPLER_HZ`]).
    fn prediction_origin(
        &self,
        t_stream_s: f64,
    ) -> Option<(gpsrx_core::PosVel, gpsrx_nav::time::GpsTime, f64, f64)> {
        if let (Some(fix), Some(t0)) = (self.prior.as_ref(), self.builder.rx_time_origin()) {
            // GPS time: receiver time less the clock bias of the fix.
            let t = t0.add_seconds(t_stream_s - fix.clock_bias_m / SPEED_OF_LIGHT_MPS);
            let rx = gpsrx_core::PosVel {
                pos_m: fix.pos_ecef_m,
                vel_mps: fix.vel_ecef_mps.unwrap_or_default(),
            };
            let drift = fix.clock_drift_mps.unwrap_or(0.0) / SPEED_OF_LIGHT_MPS;
            let age_s = (t.tow_s - fix.time.tow_s).abs();
            let width = PREDICTED_DOPPLER_HZ + PREDICTED_DOPPLER_RATE_HZ_S * age_s;
            return Some((rx, t, drift, width));
        }
        let ([lat, lon, h], t0) = (self.settings.approx_llh?, self.settings.approx_time?);
        let rx = gpsrx_core::PosVel {
            pos_m: gpsrx_nav::Llh::from_degrees(lat, lon, h).to_ecef(),
            vel_mps: gpsrx_nav::Vector3::zeros(),
        };
        Some((rx, t0.add_seconds(t_stream_s), 0.0, APPROX_DOPPLER_HZ))
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
    /// and solves every epoch that is complete.
    pub fn on_report(
        &mut self,
        channel: usize,
        e: &ChannelEpoch,
        aiding: Option<&InsFeedForward>,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        sink.channel_epoch(channel, e)?;
        self.monitor.push(e);
        self.collapse.push(e);
        self.searched.insert(e.prn);
        let locked = e.bit.is_some() || (e.pll_lock && e.state == ChannelState::Track);
        if locked && e.cn0_dbhz >= self.cn0_lost_dbhz {
            self.locked.insert(e.prn);
        }
        self.decode(e, aiding, sink)?;
        let usable =
            e.pll_lock && e.state != ChannelState::Lost && e.cn0_dbhz >= self.cn0_lost_dbhz;
        let note = match self.decoders.get_mut(&e.prn) {
            Some(dec) => self.sv_time.observe(e, dec, self.fs_hz, usable),
            None => None,
        };
        match note {
            Some(CarryNote::Refused(off_ms)) => self.on_refused(e.t_rx_s, e.prn, off_ms, sink)?,
            Some(CarryNote::GapResolved { t_s, length_ms }) => {
                tracing::warn!(
                    "{:.3} s: the samples lost at {t_s:.3} s were {length_ms:.3} ms of signal (from the carrier-phase steps and the new bit edges): SV times carried over the gap",
                    e.t_rx_s
                );
                sink.event(&ReceiverEvent::GapMeasured { t_s, length_ms })?;
                self.lost_for_aid_ms += length_ms;
                self.step_clock_over_gap(t_s, length_ms, sink)?;
            }
            None => {}
        }
        self.start_long_gap();
        self.coarse_step(e, sink)?;
        self.channel_row(channel, e, sink)?;
        self.realign_clock(e, sink)?;
        let ready = match self.decoders.get(&e.prn) {
            Some(d) => self.builder.push(e, d),
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

    /// Feeds the report's data bit to its satellite's decoder.
    fn decode(
        &mut self,
        e: &ChannelEpoch,
        aiding: Option<&InsFeedForward>,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let week = self.reference_week;
        let quick = self.quick.is_some();
        let dec = self.decoders.entry(e.prn).or_insert_with(|| {
            let mut d = NavDecoder::new(e.prn, week);
            d.report_tow_candidates(quick);
            d
        });
        let mut coarse_wrong = None;
        let mut candidate = None;
        if let (Some(b), Some(ms)) = (e.bit, e.bit_start_ms) {
            let coarse_given = self
                .coarse
                .as_ref()
                .is_some_and(|c| c.given.contains(&e.prn));
            let mut mismatch = false;
            for ev in dec.push_bit(b.value, ms) {
                match ev {
                    NavEvent::TowCandidate { first_ms, tow_s } => {
                        candidate = Some(TowCandidate::new(e, first_ms, tow_s));
                    }
                    NavEvent::Subframe { tow_s, .. } if coarse_given && !mismatch => {
                        tracing::info!(
                            "G{:02}: its first HOW (TOW {tow_s} s) confirms the SV time of the coarse-time fix",
                            e.prn
                        );
                        if let Some(c) = self.coarse.as_mut() {
                            c.given.remove(&e.prn);
                        }
                    }
                    NavEvent::TowMismatch { error_ms } if coarse_given => {
                        mismatch = true;
                        coarse_wrong = Some(format!(
                            "the HOW of G{:02} differs from its SV time by {error_ms:.3} ms",
                            e.prn
                        ));
                    }
                    NavEvent::BitEdgeMismatch { offset_ms } if coarse_given => {
                        coarse_wrong = Some(format!(
                            "the first bit edge of G{:02} falls {offset_ms:+.3} ms off a 20 ms boundary of its SV time",
                            e.prn
                        ));
                    }
                    NavEvent::FrameSync { tow_s } => {
                        tracing::info!("G{:02}: frame sync, TOW {tow_s} s", e.prn);
                        sink.event(&ReceiverEvent::FrameSync {
                            prn: e.prn,
                            tow_s: f64::from(tow_s),
                        })?;
                    }
                    NavEvent::Ephemeris(eph) => {
                        tracing::info!("G{:02}: ephemeris decoded (IODE {})", e.prn, eph.iode);
                        if let Some(ff) = aiding {
                            ff.set_ephemeris(&eph);
                        }
                        sink.event(&ReceiverEvent::EphemerisDecoded {
                            prn: e.prn,
                            iode: eph.iode,
                        })?;
                    }
                    NavEvent::AlmanacPage(sf) => {
                        if let Some(w) = dec.decoded_week() {
                            self.almanac.set_reference_week(w);
                        }
                        let added = self.almanac.push(&sf);
                        if !added.is_empty() {
                            tracing::debug!("almanac of {added:?} decoded (from G{:02})", e.prn);
                        }
                    }
                    NavEvent::TowMismatch { error_ms } => {
                        tracing::warn!(
                            "G{:02}: the HOW time differs from the SV time kept by {error_ms:.3} ms (a gap in the samples?): the HOW's time is taken",
                            e.prn
                        );
                    }
                    NavEvent::BitEdgeMismatch { offset_ms } => {
                        tracing::info!(
                            "G{:02}: the bit edges found disagree with the SV time carried over the outage by {offset_ms:.3} ms (samples lost?): waiting for frame sync",
                            e.prn
                        );
                        self.sv_time.make_rough(Some(e.prn));
                    }
                    _ => {}
                }
            }
        }
        if e.state == ChannelState::Lost {
            let reason = if e.cn0_dbhz.is_finite() && e.cn0_dbhz < self.cn0_lost_dbhz {
                format!(
                    "C/N0 estimate {:.1} dB-Hz, below the {:.0} dB-Hz loss threshold",
                    e.cn0_dbhz, self.cn0_lost_dbhz
                )
            } else {
                "no data-bit edges found (no usable signal)".to_string()
            };
            tracing::info!("G{:02}: signal lost at {:.2} s: {reason}", e.prn, e.t_rx_s);
            dec.reset_sync();
            sink.event(&ReceiverEvent::Lost {
                prn: e.prn,
                t_s: e.t_rx_s,
            })?;
        }
        if let Some(why) = coarse_wrong {
            self.drop_coarse_times(e.t_rx_s, &why, sink)?;
        }
        if let Some(c) = candidate {
            self.on_tow_candidate(c, sink)?;
        }
        Ok(())
    }

    /// A TLM and HOW found while unsynchronised: frame sync on it (and on the waiting
    /// candidates it agrees with) once another satellite confirms its time
    /// ([`crate::pipeline::timing::quick_sync`]).
    fn on_tow_candidate(&mut self, c: TowCandidate, sink: &mut dyn Sink) -> Result<(), SinkError> {
        let known: Vec<(u8, u64, f64)> = self
            .decoders
            .iter()
            .filter(|(_, d)| d.synced())
            .filter_map(|(&p, _)| self.sv_time.last_known(p).map(|(k, sv)| (p, k, sv)))
            .collect();
        let Some(quick) = self.quick.as_mut() else {
            return Ok(());
        };
        let confirmed = quick.offer(c, &known, self.fs_hz);
        let by: Vec<String> = confirmed.iter().map(|c| format!("G{:02}", c.prn)).collect();
        for c in &confirmed {
            let synced = self
                .decoders
                .get_mut(&c.prn)
                .is_some_and(|d| d.sync_at(c.first_ms, c.tow_s));
            if synced {
                tracing::info!(
                    "G{:02}: frame sync, TOW {} s (TLM and HOW; times agree: {})",
                    c.prn,
                    c.tow_s,
                    if by.len() > 1 {
                        by.join(" ")
                    } else {
                        "with the satellites synchronised".to_string()
                    }
                );
                sink.event(&ReceiverEvent::FrameSync {
                    prn: c.prn,
                    tow_s: f64::from(c.tow_s),
                })?;
            }
        }
        Ok(())
    }

    /// Feeds the report to the coarse-time fix while no satellite's time is known, and hands
    /// its SV times to the decoders once it succeeds.
    fn coarse_step(&mut self, e: &ChannelEpoch, sink: &mut dyn Sink) -> Result<(), SinkError> {
        if self.coarse.as_ref().is_none_or(|c| c.done) {
            return Ok(());
        }
        if self.decoders.values().any(NavDecoder::synced) {
            tracing::debug!("coarse time: a satellite's time is known already, no coarse-time fix");
            if let Some(c) = self.coarse.as_mut() {
                c.done = true;
            }
            return Ok(());
        }
        let opts = self.pvt_options();
        let (decoders, nav) = (&self.decoders, self.nav_assist.as_ref());
        let Some(cf) = self.coarse.as_mut() else {
            return Ok(());
        };
        cf.observe(e);
        let allow_unhealthy = self.settings.allow_unhealthy;
        let policy = if allow_unhealthy {
            HealthPolicy::PreferHealthy
        } else {
            HealthPolicy::HealthyOnly
        };
        // Decoded (after a long gap without a navigation file), else from the file.
        let ephemeris = |prn: u8, t| {
            decoders
                .get(&prn)
                .and_then(|d| d.ephemeris.clone())
                .filter(|eph| eph.sv_health == 0 || allow_unhealthy)
                .or_else(|| nav?.select_with(prn, t, policy).cloned())
        };
        match cf.attempt(&ephemeris, &opts) {
            Ok(out) => {
                self.step_clock_to_coarse_time(&out, sink)?;
                for t in &out.sv_times {
                    if let Some(d) = self.decoders.get_mut(&t.prn) {
                        d.carry_time(t.ms_count, t.sv_tow_s);
                    }
                }
                // A report covers up to 20 ms: later epochs have every channel's observables.
                let from = (out.t_s + 0.025) * self.fs_hz;
                self.fixes_from_sample = self.fixes_from_sample.max(from);
                tracing::info!(
                    "coarse-time fix at {:.2} s: {} satellites, time corrected by {:+.3} s, {:.1} km from the approximate position ({}): SV times set, fixes follow",
                    out.t_s,
                    out.sv_times.len(),
                    out.time_correction_s,
                    out.position_shift_m * 1e-3,
                    out.check
                );
                sink.event(&ReceiverEvent::CoarseTime {
                    t_s: out.t_s,
                    satellites: out.sv_times.len(),
                    time_correction_s: out.time_correction_s,
                })?;
            }
            Err(CoarseRefusal::Waiting) => {}
            Err(CoarseRefusal::Refused(why)) => {
                if self.coarse_warned {
                    tracing::debug!("{:.2} s: no coarse-time fix: {why}", e.t_rx_s);
                } else {
                    tracing::warn!(
                        "{:.2} s: no coarse-time fix: {why}; trying again as satellites come, else the first fix waits for frame sync",
                        e.t_rx_s
                    );
                    self.coarse_warned = true;
                }
            }
        }
        Ok(())
    }

    /// The SV times of the coarse-time fix disagree with the signal (`why`): every one not yet
    /// confirmed by a HOW is dropped (frame sync gives the time).
    fn drop_coarse_times(
        &mut self,
        t_s: f64,
        why: &str,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let Some(c) = self.coarse.as_mut() else {
            return Ok(());
        };
        let given = std::mem::take(&mut c.given);
        tracing::warn!(
            "{t_s:.2} s: {why}: the SV times of the coarse-time fix are dropped, waiting for frame sync"
        );
        for p in given {
            if let Some(d) = self.decoders.get_mut(&p) {
                if d.time_carried() {
                    d.reset_sync();
                }
            }
            self.sv_time.make_rough(Some(p));
        }
        self.builder.restart();
        self.prior = None;
        sink.event(&ReceiverEvent::CoarseTimeDropped { t_s })
    }

    /// After lost samples: every SV time is dropped (the decoders find frame sync again and the
    /// HOW gives the time), carrier smoothing restarts, and the clock of the last fix is kept
    /// to measure the gap once the time is back.
    ///
    /// With the carrier-phase steps of the gap (`steps`), the SV times are kept, to be carried
    /// over it once its length is resolved from them and the new bit edges.
    /// `code_from_s`: from when the code offsets may measure the gap (`None`: not used).
    fn forget_time(
        &mut self,
        t_s: f64,
        steps: Vec<crate::pipeline::timing::carrier_step::PhaseStep>,
        code_from_s: Option<f64>,
    ) {
        for dec in self.decoders.values_mut() {
            dec.reset_sync();
        }
        // The clocks as they were a little before the gap (its instant is known to a few
        // milliseconds).
        self.sv_time
            .rewind(((t_s - 0.003) * self.fs_hz).max(0.0) as u64);
        let gap = GapRecovery::new(t_s, self.last_clock, steps, code_from_s);
        if gap.unresolved {
            self.sv_time.make_rough(None);
        }
        self.builder.note_gap(t_s);
        self.sv_time.gap = Some(gap);
        self.prior = None;
    }

    /// A carried SV time refused at `t_s` for `prn`, `off_ms` off the bit edge: when
    /// [`crate::pipeline::timing::discontinuity::MIN_SATELLITES`] satellites are refused within 2 s by
    /// the same offset (0.1 ms), samples were lost during the outage (that offset plus a
    /// whole number of 20 ms bits): reported as a gap.
    fn on_refused(
        &mut self,
        t_s: f64,
        prn: u8,
        off_ms: f64,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        self.sv_time
            .refused
            .retain(|r| t_s - r.0 < 2.0 && r.1 != prn);
        self.sv_time.refused.push((t_s, prn, off_ms));
        let agreeing = self
            .sv_time
            .refused
            .iter()
            .filter(|r| (r.2 - off_ms).abs() < 0.1)
            .count();
        if agreeing >= crate::pipeline::timing::discontinuity::MIN_SATELLITES {
            let offsets: Vec<(u8, f64, f64)> = self
                .sv_time
                .refused
                .iter()
                .filter(|r| (r.2 - off_ms).abs() < 0.1)
                .filter_map(|r| self.sv_time.clocks.get(&r.1).map(|c| (r.1, r.2, c.rate)))
                .collect();
            self.sv_time.refused.clear();
            tracing::warn!(
                "{t_s:.3} s: samples lost during the outage: the SV times carried over it are {:.3} ms (modulo 20 ms) off the new bit edges of {agreeing} satellites",
                -off_ms
            );
            // The new channels' code has settled by their bit edges: the code offsets measure
            // the gap at once.
            self.forget_time(t_s, Vec::new(), Some(t_s));
            sink.event(&ReceiverEvent::SampleGap { t_s })?;
            let mut resolved = None;
            if let Some(gap) = self.sv_time.gap.as_mut() {
                for (p, o, r) in offsets {
                    if gap.add_edge_offset(p, o, r, t_s) {
                        resolved = gap.length_ms;
                    }
                }
            }
            if let Some(length_ms) = resolved {
                tracing::warn!(
                    "{t_s:.3} s: the samples lost were {length_ms:.3} ms of signal (from the code of the new channels): SV times carried over the gap"
                );
                self.sv_time.move_over_gap(length_ms);
                sink.event(&ReceiverEvent::GapMeasured { t_s, length_ms })?;
                self.lost_for_aid_ms += length_ms;
                self.step_clock_over_gap(t_s, length_ms, sink)?;
            }
        }
        Ok(())
    }

    /// Solutions keep failing the integrity test while SV times carried over an outage are in
    /// use: samples may have been lost during the outage by a whole number of data bits, which
    /// the bit edges cannot show. The carried times are dropped (frame sync gives the time).
    fn drop_carried_times(&mut self, t_s: f64) {
        let carried: Vec<u8> = self
            .decoders
            .iter()
            .filter(|(_, d)| d.time_carried())
            .map(|(p, _)| *p)
            .collect();
        if carried.is_empty() {
            return;
        }
        if let Some(c) = self.coarse.as_mut() {
            c.given.clear();
        }
        tracing::warn!(
            "{t_s:.2} s: the solutions fail the integrity test with the SV times carried over the outage of {} satellites (samples lost during it?): every SV time dropped (they all count the samples), re-establishing the time from the signal",
            carried.len()
        );
        for d in self.decoders.values_mut() {
            d.reset_sync();
        }
        self.sv_time.make_rough(None);
        self.builder.restart();
        self.failed_in_row = 0;
        let before = self.last_clock;
        self.sv_time
            .gap
            .get_or_insert_with(|| GapRecovery::new(t_s, before, Vec::new(), None));
    }

    /// Once the length of the gap being recovered from cannot be measured: the time comes
    /// back from the coarse-time solver or the next time of week ([`LongGapRecovery::begin`]).
    fn start_long_gap(&mut self) {
        let with_eph = self.decoders.values().filter(|d| d.ephemeris.is_some());
        let eph = self.nav_assist.is_some()
            || with_eph.count() >= crate::pipeline::timing::coarse_fix::MIN_SATELLITES;
        let origin = self.builder.rx_time_origin();
        let gap = self.sv_time.gap.as_ref();
        let Some(start) = self.long_gap.begin(gap, self.fs_hz, origin, eph) else {
            return;
        };
        self.coarse = start.coarse.or(self.coarse.take());
        if start.quick_sync {
            self.quick.get_or_insert_with(QuickSync::default);
        }
        for d in self.decoders.values_mut() {
            d.report_tow_candidates(self.quick.is_some());
        }
    }

    /// After a coarse-time fix while a long gap is recovered from: the receiver clock stepped
    /// by the whole milliseconds of the time lost ([`LongGapRecovery::clock_step_ms`]).
    fn step_clock_to_coarse_time(
        &mut self,
        out: &crate::pipeline::timing::coarse_fix::CoarseOutcome,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let origin = self.builder.rx_time_origin();
        let Some(step) = self.long_gap.clock_step_ms(out, origin) else {
            return Ok(());
        };
        self.builder.step_clock_ms(step);
        if let Some(gap) = self.sv_time.gap.as_mut() {
            gap.stepped_ms += step;
        }
        tracing::info!("receiver clock stepped by {step} ms to the coarse time");
        sink.event(&ReceiverEvent::ClockStep { ms: step })
    }

    /// Once the length of the samples lost at stream time `t_s` is known: the carrier smoothing
    /// may be bridged over them, and the receiver time (which counts samples) is late by it; it is stepped forward by the whole milliseconds (the fraction is a clock
    /// bias the solution takes up), so that the first fix after a long gap does not start
    /// from a bias of tenths of a second (pseudoranges would come out negative).
    fn step_clock_over_gap(
        &mut self,
        t_s: f64,
        length_ms: f64,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        self.builder.set_gap_length(t_s, length_ms * 1e-3);
        let step = length_ms.round() as i64;
        if step == 0 {
            return Ok(());
        }
        self.builder.step_clock_ms(step);
        if let Some(gap) = self.sv_time.gap.as_mut() {
            gap.stepped_ms += step;
        }
        if let Some((t, b, d)) = self.last_clock {
            // The clock of the last fix, on the stepped time scale.
            self.last_clock = Some((t, b + step as f64 * 1e-3 * SPEED_OF_LIGHT_MPS, d));
        }
        tracing::info!("receiver clock stepped by {step} ms over the lost samples");
        sink.event(&ReceiverEvent::ClockStep { ms: step })
    }

    /// While the receiver time is re-established after lost samples, the first satellite
    /// whose time comes from its navigation message puts the receiver clock back near GPS time
    /// by a whole-millisecond step, as at the start (its pseudorange near 75 ms): lost samples
    /// of a second leave the receiver time a second late, which the least squares cannot take
    /// up as a clock bias from a cold start.
    fn realign_clock(&mut self, e: &ChannelEpoch, sink: &mut dyn Sink) -> Result<(), SinkError> {
        let (Some(gap), Some(t0)) = (self.sv_time.gap.as_mut(), self.builder.rx_time_origin())
        else {
            return Ok(());
        };
        let Some(dec) = self.decoders.get(&e.prn) else {
            return Ok(());
        };
        if dec.time_carried() || !e.pll_lock {
            return Ok(());
        }
        let Some(sv) = dec.sv_tow_s(e.ms_count, e.code_phase_chips) else {
            return Ok(());
        };
        let tau = gpsrx_nav::time::GpsTime::fold_tow_difference_s(t0.tow_s + e.t_rx_s - sv);
        if (0.06..=0.095).contains(&tau) {
            return Ok(());
        }
        let step = -((tau - 0.075) * 1e3).round() as i64;
        gap.stepped_ms += step;
        self.builder.step_clock_ms(step);
        tracing::info!("receiver clock stepped by {step} ms to re-establish the time");
        sink.event(&ReceiverEvent::ClockStep { ms: step })
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

    /// The ionosphere parameters for the next solution: decoded, assisted, else a typical set.
    fn iono(&mut self) -> Option<KlobucharParams> {
        if self.settings.iono != IonoModel::Klobuchar {
            return None;
        }
        let known = self
            .decoders
            .values()
            .find_map(|d| d.iono)
            .or_else(|| self.nav_assist.as_ref().and_then(|n| n.iono));
        if known.is_none() && !self.iono_fallback_said {
            tracing::info!(
                "ionosphere: typical Klobuchar coefficients until subframe 4 page 18 is decoded (or give --nav)"
            );
            self.iono_fallback_said = true;
        }
        Some(known.unwrap_or(KlobucharParams::FALLBACK))
    }

    /// The PVT options of the settings, with the ionosphere parameters known now.
    fn pvt_options(&mut self) -> PvtOptions {
        PvtOptions {
            tropo: self.settings.tropo == TropoModel::Saastamoinen,
            elevation_mask_deg: self.settings.elevation_mask_deg,
            raim_pfa: self.settings.raim_pfa,
            iono: self.iono(),
            ..PvtOptions::default()
        }
    }

    /// The ephemeris for each satellite of the epoch: decoded, else from the navigation file.
    fn ephemerides(&self, epoch: &ObservableEpoch) -> Vec<(u8, Ephemeris)> {
        // With `--allow-unhealthy` an unhealthy satellite's ephemeris is taken from the file too
        // (before, only its decoded one: it waited 18-30 s for subframes 1-3).
        let policy = if self.settings.allow_unhealthy {
            HealthPolicy::PreferHealthy
        } else {
            HealthPolicy::HealthyOnly
        };
        epoch
            .sats
            .iter()
            .filter_map(|s| {
                let decoded = self.decoders.get(&s.prn).and_then(|d| d.ephemeris.clone());
                decoded
                    .or_else(|| {
                        self.nav_assist
                            .as_ref()
                            .and_then(|n| n.select_with(s.prn, epoch.rx_time, policy).cloned())
                    })
                    .map(|e| (s.prn, e))
            })
            .collect()
    }

    /// The WLS solution of one epoch, if there are enough measurements.
    fn solution(
        &mut self,
        epoch: &ObservableEpoch,
        ephs: &[(u8, Ephemeris)],
    ) -> Option<PvtSolution> {
        let meas: Vec<SatMeasurement<'_>> = epoch
            .sats
            .iter()
            .filter_map(|s| {
                let (_, eph) = ephs.iter().find(|(p, _)| *p == s.prn)?;
                (eph.sv_health == 0 || self.settings.allow_unhealthy).then_some(SatMeasurement {
                    prn: s.prn,
                    pseudorange_m: s.smoothed_pseudorange_m,
                    doppler_hz: Some(s.doppler_hz),
                    cn0_dbhz: s.cn0_dbhz,
                    tx_time: None,
                    ephemeris: eph,
                })
            })
            .collect();
        let opts = self.pvt_options();
        // Landmark observations of this epoch (receiver time within half an interval; the clock
        // bias is kept below 0.5 ms, far less than that).
        let landmarks: Vec<Landmark> = self
            .landmarks
            .iter()
            .filter(|l| (l.tow_s - epoch.rx_time.tow_s).abs() <= 0.5 / self.settings.rate_hz)
            .map(|l| l.landmark)
            .collect();
        if meas.len() + landmarks.len() < 4 || meas.is_empty() {
            tracing::trace!(
                "{} satellites with ephemeris at {:.3}",
                meas.len(),
                epoch.rx_time.tow_s
            );
            return None;
        }
        match solve(epoch.rx_time, &meas, &landmarks, &opts, self.prior.as_ref()) {
            Ok(s) => Some(s),
            Err(e) => {
                tracing::debug!("no fix at {:.3}: {e}", epoch.rx_time.tow_s);
                None
            }
        }
    }

    /// Logs the start of a stretch of solutions whose geometry is too poor to hand out
    /// ([`RunSettings::max_pdop`]).
    fn log_poor_geometry(&mut self, t_stream_s: f64, pdop: f64, n_sv: usize) {
        if !self.poor_geometry_logged {
            tracing::info!(
                "{t_stream_s:.2} s: PDOP {pdop:.1} with {n_sv} satellites is above the largest PDOP {} (--max-pdop): fixes flagged invalid until the geometry improves",
                self.settings.max_pdop
            );
            self.poor_geometry_logged = true;
        }
    }

    /// Logs a change of the RAIM outcome at INFO: an exclusion (with the residuals of the
    /// rest), a fault that could not be excluded, and the return to a clean test.
    fn log_raim(&mut self, t_stream_s: f64, sol: &PvtSolution) {
        if self.last_raim.as_ref() == Some(&sol.raim) {
            return;
        }
        let residuals = || {
            sol.residuals_m
                .iter()
                .map(|(p, r)| format!("G{p:02} {r:+.1} m"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match &sol.raim {
            RaimStatus::FaultExcluded { prn } => tracing::info!(
                "{t_stream_s:.2} s: RAIM excluded G{prn:02} (a fault in its pseudorange); residuals of the rest: {}",
                residuals()
            ),
            RaimStatus::FaultDetectedNotExcluded => tracing::info!(
                "{t_stream_s:.2} s: RAIM detected a fault it could not exclude: no valid fix (residuals {})",
                residuals()
            ),
            RaimStatus::Ok
                if matches!(
                    self.last_raim,
                    Some(RaimStatus::FaultExcluded { .. } | RaimStatus::FaultDetectedNotExcluded)
                ) =>
            {
                tracing::info!("{t_stream_s:.2} s: RAIM test passes again")
            }
            _ => {}
        }
        self.last_raim = Some(sol.raim);
    }

    /// Solves one epoch and hands its observables and fix to the sink.
    fn solve_epoch(
        &mut self,
        epoch: ObservableEpoch,
        aiding: Option<&InsFeedForward>,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        if epoch.sample < self.fixes_from_sample {
            return Ok(());
        }
        let ephs = self.ephemerides(&epoch);
        let solution = self.solution(&epoch, &ephs);
        let max_pdop = self.settings.max_pdop;
        let integrity_ok = solution.as_ref().is_some_and(passes_integrity);
        let valid = integrity_ok && solution.as_ref().is_some_and(|s| s.dop.pdop <= max_pdop);
        if let Some(s) = solution.as_ref().filter(|s| s.dop.pdop > max_pdop) {
            self.log_poor_geometry(epoch.sample / self.fs_hz, s.dop.pdop, s.n_sv);
        } else {
            self.poor_geometry_logged = false;
        }
        sink.observables(&ObservablesReport {
            epoch: obs_epoch(&epoch),
            fix_position_m: solution
                .as_ref()
                .filter(|_| valid)
                .map(|s| [s.pos_ecef_m.x, s.pos_ecef_m.y, s.pos_ecef_m.z]),
            week_decoded: self.decoders.values().any(|d| d.decoded_week().is_some()),
            week_known: self.week_known(),
        })?;
        let Some(sol) = solution else {
            return Ok(());
        };
        let t_stream_s = epoch.sample / self.fs_hz;
        self.log_raim(t_stream_s, &sol);
        // A poor geometry is no sign of a wrong time: only integrity failures count.
        self.failed_in_row = if integrity_ok {
            0
        } else {
            self.failed_in_row + 1
        };
        if self.failed_in_row >= 3 {
            self.drop_carried_times(t_stream_s);
        }
        if self.failed_in_row >= FAILURES_TO_DISTRUST_TIME && self.time_trusted {
            // Every solution fails after good ones: the receiver time itself may be wrong
            // (samples lost by whole data bits, which neither the carrier nor the bits show).
            tracing::warn!(
                "{t_stream_s:.2} s: {} solutions in a row fail the integrity test: the receiver time may be wrong (samples lost?); re-establishing it from the satellites' time of week",
                self.failed_in_row
            );
            self.time_trusted = false;
            self.forget_time(t_stream_s, Vec::new(), None);
            sink.event(&ReceiverEvent::SampleGap { t_s: t_stream_s })?;
        }
        if valid {
            self.time_trusted = true;
        }
        if !valid {
            // Written for the record, flagged: quality `none` in pvt.csv, GGA quality 0, absent
            // from the GeoJSON and KML tracks; it steers nothing.
            self.stats.invalid_fixes += 1;
            let mut fix = fix_of(&sol, &epoch, &ephs, self.week_known());
            fix.quality = FixQuality::None;
            return sink.fix(&FixReport {
                fix,
                solution: sol,
                t_stream_s,
            });
        }
        if let Some(gap) = self.sv_time.gap.take().filter(|g| g.length_ms.is_none()) {
            let length = gap.length_from_bias_ms(t_stream_s, sol.clock_bias_m);
            match length {
                Some(ms) => tracing::warn!(
                    "{t_stream_s:.2} s: receiver time re-established; the samples lost at {:.3} s were {ms:.3} ms of signal",
                    gap.t_s
                ),
                None => tracing::warn!(
                    "{t_stream_s:.2} s: receiver time re-established after the samples lost at {:.3} s",
                    gap.t_s
                ),
            }
            if let Some(length_ms) = length {
                sink.event(&ReceiverEvent::GapMeasured {
                    t_s: gap.t_s,
                    length_ms,
                })?;
                self.lost_for_aid_ms += length_ms;
            }
        }
        // Keep the receiver clock within +-0.5 ms of GPS time by whole-millisecond steps.
        let bias_ms = sol.clock_bias_m / SPEED_OF_LIGHT_MPS * 1e3;
        let mut bias_after_m = sol.clock_bias_m;
        if bias_ms.abs() > 0.5 {
            let step = -bias_ms.round() as i64;
            self.builder.step_clock_ms(step);
            bias_after_m += step as f64 * 1e-3 * SPEED_OF_LIGHT_MPS;
            tracing::debug!("receiver clock stepped by {step} ms");
            sink.event(&ReceiverEvent::ClockStep { ms: step })?;
        }
        self.last_clock = Some((t_stream_s, bias_after_m, sol.clock_drift_mps.unwrap_or(0.0)));
        self.long_gap.note_fix(sol.llh);
        if self.stats.first_fix_s.is_none() {
            tracing::info!(
                "first fix at {:.2} s: {:.7} {:.7} {:.1} m, {} satellites, PDOP {:.1}",
                t_stream_s,
                sol.llh.lat_rad.to_degrees(),
                sol.llh.lon_rad.to_degrees(),
                sol.llh.h_m,
                sol.n_sv,
                sol.dop.pdop
            );
        }
        let fix = fix_of(&sol, &epoch, &ephs, self.week_known());
        if let Some(ff) = aiding {
            ff.set_fix_from(t_stream_s, &sol);
        }
        self.stats.add(t_stream_s, &fix);
        sink.fix(&FixReport {
            fix,
            solution: sol.clone(),
            t_stream_s,
        })?;
        self.prior = Some(sol);
        Ok(())
    }
}
