//! The channel manager: which satellites have a tracking channel, and the searches that start
//! new ones.
//!
//! - Cold start: the first samples of the stream are searched for every wanted PRN with the
//!   configured search (or the assisted targets).
//! - Background search ([`crate::pipeline::channels::search_schedule`]): every PRN without a live channel
//!   is searched again and again within a CPU budget per second of signal, escalating the
//!   integration while it is not found (to 10 ms x 40, about 28 dB-Hz), satellites just lost
//!   (around their last Doppler, every 0.2 s) and predicted visible ones (around their
//!   predicted Doppler) first, predicted hidden ones never. A detection at the Doppler of a
//!   much stronger tracked satellite (modulo 1 kHz) is that satellite's cross-correlation, not
//!   a satellite.
//! - Code realignment ([`realign`]): after a common collapse of the prompt power, the channels
//!   are moved onto the code that jumped.
//! - Work: every channel processes the code periods the sample window holds, in parallel
//!   (rayon), concurrently with a due search (rayon `join`).

mod overlap;
pub mod realign;

pub use realign::{RealignSearch, Realigned};

use crate::pipeline::channels::dynamics::DynamicsWatch;
use crate::pipeline::channels::ring::SampleView;
use crate::pipeline::channels::search_schedule::{
    level_config, search_pfa, Batch, Liveness, Scheduler, SearchBudget, Visibility, LEVELS,
};
use crate::pipeline::profile::timed;
use gpsrx_dsp::acquisition::{AcqConfig, AcqResult, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_tracking::{
    AidingPort, Channel, ChannelConfig, ChannelEpoch, ChannelStart, ChannelState,
};
use num_complex::Complex32;
use rayon::prelude::*;

/// A detection this many dB or more below a tracked satellite, at its Doppler modulo 1 kHz
/// (within [`XCORR_DOPPLER_HZ`]), is taken for its cross-correlation: C/A codes
/// cross-correlate at -17 to -24 dB (measured: a 28 dB-Hz one of a 45 dB-Hz satellite), at
/// Doppler differences that are whole kHz. The narrow Doppler band keeps a real satellite
/// near such a line (a 31 dB-Hz one 54 Hz off was refused with a 60 Hz band); one within it
/// is found once the Dopplers drift apart.
pub const XCORR_MARGIN_DB: f64 = 12.0;
/// See [`XCORR_MARGIN_DB`], Hz (the refined Doppler of a detection is good to a few hertz).
pub const XCORR_DOPPLER_HZ: f64 = 25.0;
/// A detection or unconfirmed channel this many dB or more below a tracked satellite is taken
/// for its cross-correlation within the wider [`XCORR_WIDE_DOPPLER_HZ`] of a kHz line: no
/// real satellite is that much weaker near a line by chance often, and cross-correlations
/// of 48-52 dB-Hz satellites were measured 21-29 dB below them, 26-39 Hz off the line (the
/// codes slide against each other at the difference of their code Dopplers, which moves the
/// phase of the cross-correlation).
pub const XCORR_WIDE_MARGIN_DB: f64 = 18.0;
/// See [`XCORR_WIDE_MARGIN_DB`], Hz.
pub const XCORR_WIDE_DOPPLER_HZ: f64 = 60.0;

/// Whether a signal `margin_db` below another, `apart_hz` from it in Doppler, may be that
/// one's cross-correlation ([`XCORR_MARGIN_DB`], [`XCORR_WIDE_MARGIN_DB`]).
pub fn may_be_cross_correlation(apart_hz: f64, margin_db: f64) -> bool {
    let off_line_hz = off_line_hz(apart_hz);
    (off_line_hz <= XCORR_DOPPLER_HZ && margin_db >= XCORR_MARGIN_DB)
        || (off_line_hz <= XCORR_WIDE_DOPPLER_HZ && margin_db >= XCORR_WIDE_MARGIN_DB)
}

/// How far a Doppler difference is from the nearest whole kHz, Hz.
fn off_line_hz(apart_hz: f64) -> f64 {
    (apart_hz - (apart_hz / 1000.0).round() * 1000.0).abs()
}

/// A detection whose C/N0 estimate (from the prompts after it) is below this starts no
/// channel, dB-Hz: no loop tracks it.
pub const MIN_START_CN0_DBHZ: f64 = 22.0;

/// How the manager searches.
#[derive(Debug, Clone)]
pub struct SearchSettings {
    /// The acquisition engine's settings (integration, Doppler range, false-alarm
    /// probability): the cold start's search and the first level of the background search.
    pub acq: AcqConfig,
    /// Escalate the background search to the weak-signal levels
    /// ([`crate::pipeline::channels::search_schedule::LEVELS`]) for PRNs not found.
    pub weak_fallback: bool,
    /// The background search's CPU budget; `None`: no search after the cold start.
    pub background: Option<SearchBudget>,
    /// PRNs to look for (empty: all 32).
    pub prns: Vec<Prn>,
    /// The cold start's targets, when known better than "every wanted PRN, full Doppler
    /// range" (an assisted search with predicted Doppler windows).
    pub cold_targets: Option<Vec<SearchTarget>>,
}

/// A search due in this block: its first sample and its targets, and what it is for (a
/// scheduled batch, or a code realignment).
#[derive(Debug, Clone)]
pub struct DueSearch {
    first: u64,
    /// Samples read from `first`.
    len: usize,
    targets: Vec<SearchTarget>,
    batch: Option<Batch>,
    realign: Option<realign::Realign>,
}

/// What a search found: its first sample, targets and results.
#[derive(Debug)]
pub struct SearchOutcome {
    first: u64,
    results: Vec<AcqResult>,
    batch: Option<Batch>,
    realign: Option<realign::Realign>,
}

impl SearchOutcome {
    /// Index of the first sample searched.
    pub fn first(&self) -> u64 {
        self.first
    }

    /// Whether this is the search of a code realignment ([`ChannelManager::realign`]).
    pub fn is_realignment(&self) -> bool {
        self.realign.is_some()
    }
}

/// The tracking channels and the searches that start them.
#[derive(Debug)]
pub struct ChannelManager {
    fs_hz: f64,
    channel_config: ChannelConfig,
    /// The search engines: the configured one, then the weak-signal levels.
    engines: Vec<AcquisitionEngine>,
    /// The cold start is still to come.
    cold_pending: bool,
    settings: Option<SearchSettings>,
    channels: Vec<Channel>,
    /// Per channel, the reports of the last round (kept: no allocation per block).
    reports: Vec<Vec<ChannelEpoch>>,
    schedule: Option<Scheduler>,
    /// A code realignment waiting for its samples.
    realign: Option<realign::Realign>,
    /// The engine of code realignment searches; `None` without searches.
    realign_engine: Option<AcquisitionEngine>,
    /// Time spent in [`ChannelManager::work`] so far.
    times: WorkTimes,
    /// Whether the receiver is under dynamics (the weak channels' loops widen).
    dynamics: DynamicsWatch,
}

/// Wall time of the channels' work and of the searches beside it, summed over
/// [`ChannelManager::work`] calls (see [`crate::pipeline::profile`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WorkTimes {
    /// The channels, s.
    pub tracking_s: f64,
    /// The searches, s.
    pub search_s: f64,
    /// Searches run.
    pub searches: usize,
}

impl ChannelManager {
    /// A manager that searches with `settings` and starts channels with `channel_config`.
    pub fn new(
        fs_hz: f64,
        channel_config: ChannelConfig,
        settings: SearchSettings,
    ) -> Result<Self, gpsrx_dsp::acquisition::AcqError> {
        // The levels and the realignment hold one copy of the replica spectra where their
        // layouts give the same ones (1 MB each at 4 MHz).
        let first = AcquisitionEngine::new(fs_hz, settings.acq.clone())?;
        let mut engines = Vec::new();
        if settings.weak_fallback {
            for level in 1..=LEVELS.len() {
                let cfg = level_config(&settings.acq, level, fs_hz);
                engines.push(AcquisitionEngine::new(fs_hz, cfg)?.sharing_replicas_with(&first));
            }
        }
        engines.insert(0, first);
        let realign_engine =
            Some(realign::realign_engine(fs_hz, &settings.acq)?.sharing_replicas_with(&engines[0]));
        Ok(Self {
            fs_hz,
            channel_config,
            engines,
            cold_pending: true,
            settings: Some(settings),
            channels: Vec::new(),
            reports: Vec::new(),
            schedule: None,
            realign: None,
            realign_engine,
            times: WorkTimes::default(),
            dynamics: DynamicsWatch::default(),
        })
    }

    /// A manager for channels started elsewhere, with no search (loop studies, tests).
    pub fn with_channels(fs_hz: f64, channels: Vec<Channel>) -> Self {
        Self {
            fs_hz,
            channel_config: ChannelConfig::default(),
            engines: Vec::new(),
            cold_pending: false,
            settings: None,
            channels,
            reports: Vec::new(),
            schedule: None,
            realign: None,
            realign_engine: None,
            times: WorkTimes::default(),
            dynamics: DynamicsWatch::default(),
        }
    }

    /// Samples the cold start wants before it searches (0 when it is done or there is none).
    pub fn cold_start_samples(&self) -> usize {
        match (self.cold_pending, self.engines.first()) {
            (true, Some(e)) => e.samples_wanted(),
            _ => 0,
        }
    }

    /// Whether the cold start is still to come.
    pub fn cold_start_pending(&self) -> bool {
        self.cold_pending && !self.engines.is_empty()
    }

    /// Samples the cold start cannot do without.
    pub fn cold_start_minimum(&self) -> usize {
        match (self.cold_pending, self.engines.first()) {
            (true, Some(e)) => e.samples_needed(),
            _ => 0,
        }
    }

    /// Searches `samples` (whose first sample has index `first_index`) for every wanted PRN,
    /// starts a channel per satellite found, and returns the detections. The background search
    /// (when configured) starts from here.
    pub fn cold_start(
        &mut self,
        samples: &[Complex32],
        first_index: u64,
    ) -> Result<Vec<AcqResult>, ColdStartError> {
        if !self.cold_start_pending() {
            return Ok(Vec::new());
        }
        self.cold_pending = false;
        let engine = &self.engines[0];
        let n = samples.len();
        if n < engine.samples_needed() {
            return Err(ColdStartError::TooShort {
                samples: n,
                needed: engine.samples_needed(),
            });
        }
        let prns: Vec<Prn> = self
            .settings
            .as_ref()
            .map(|s| s.prns.clone())
            .unwrap_or_default();
        let mut targets: Vec<SearchTarget> =
            match self.settings.as_ref().and_then(|s| s.cold_targets.clone()) {
                Some(t) => t,
                None => wanted_prns(&prns).map(SearchTarget::full).collect(),
            };
        let background = self
            .settings
            .as_ref()
            .and_then(|s| s.background.map(|b| (b, s.acq.pfa)));
        if let Some((_, pfa)) = background {
            // The first of the run's searches of each PRN: its share of the run's pfa.
            for t in &mut targets {
                *t = t.with_pfa(search_pfa(t.pfa.unwrap_or(pfa), 1));
            }
        }
        let found = engine.search(&samples[..n.min(engine.samples_wanted())], &targets)?;
        for d in found.iter().filter(|d| d.detected) {
            let start = ChannelStart::from_acquisition(d, first_index);
            self.channels
                .push(Channel::new(&start, self.fs_hz, &self.channel_config)?);
            tracing::info!(
                "{}: acquired, Doppler {:.0} Hz, C/N0 {:.1} dB-Hz",
                d.prn,
                d.doppler_hz,
                d.cn0_dbhz.unwrap_or(f64::NAN)
            );
        }
        if let Some((budget, pfa)) = background {
            let end = first_index + engine.samples_wanted().min(n) as u64;
            let searched: Vec<Prn> = targets.iter().map(|t| t.prn).collect();
            self.schedule =
                Some(Scheduler::new(self.fs_hz, budget, pfa, &prns, end).with_searched(&searched));
        }
        Ok(found.into_iter().filter(|d| d.detected).collect())
    }

    /// Samples the background search reads at most (0 without one).
    fn search_samples(&self) -> usize {
        match self.schedule {
            Some(_) => self
                .engines
                .iter()
                .map(AcquisitionEngine::samples_wanted)
                .max()
                .unwrap_or(0),
            None => 0,
        }
    }

    /// Whether `prn` has a live channel, or when and at what Doppler its last one was lost.
    fn liveness(&self, prn: Prn) -> Liveness {
        if self.live(prn).is_some() {
            return Liveness::Live;
        }
        // Only a satellite its channel confirmed is searched at once in its hot window; one
        // lost in its pull-in (too weak to follow, or a false alarm) waits its turn.
        match self.channels.iter().rev().find(|c| c.prn() == prn) {
            Some(c) if c.confirmed() => {
                Liveness::LostAt(c.next_span().0, c.doppler_hz(), c.tracked_cn0_dbhz())
            }
            _ => Liveness::Never,
        }
    }

    /// The search due now that the window is `window`, if one is: a code realignment whose
    /// samples have come, else the background search's next batch, with `visibility` what is
    /// predicted of each PRN.
    pub fn due_search(
        &mut self,
        window: SampleView<'_>,
        visibility: &dyn Fn(Prn) -> Visibility,
    ) -> Option<DueSearch> {
        if let Some(due) = self.due_realignment(window) {
            return Some(due);
        }
        let mut schedule = self.schedule.take()?;
        let due = self.scheduled(
            &mut schedule,
            window.end(),
            window.end() - window.start(),
            visibility,
        );
        self.schedule = Some(schedule);
        let due = due?;
        tracing::debug!(
            "search at sample {}: level {}, {} PRN(s)",
            window.end(),
            due.batch.as_ref().map_or(0, |b| b.level),
            due.targets.len()
        );
        Some(due)
    }

    /// The background search's next batch from `schedule`, with the window ending at sample
    /// `end` and holding `span` samples.
    fn scheduled(
        &self,
        schedule: &mut Scheduler,
        end: u64,
        span: u64,
        visibility: &dyn Fn(Prn) -> Visibility,
    ) -> Option<DueSearch> {
        let batch = schedule.due(end, span, &self.engines, &|p| self.liveness(p), visibility)?;
        Some(DueSearch {
            first: batch.first,
            len: batch.len,
            targets: batch.targets.clone(),
            batch: Some(batch),
            realign: None,
        })
    }

    /// Every channel processes the code periods `window` holds (in parallel), while `search`
    /// (if any) runs beside them. With `aid`, each channel's NCOs get the fed-forward Doppler
    /// of its satellite at the start of every code period.
    pub fn work(
        &mut self,
        window: SampleView<'_>,
        search: Option<DueSearch>,
        aid: Option<&dyn AidingPort>,
    ) -> Option<SearchOutcome> {
        self.reports.resize_with(self.channels.len(), Vec::new);
        self.watch_dynamics(window.end());
        let channels = &mut self.channels;
        let reports = &mut self.reports;
        let mut run_all = || {
            timed(|| {
                channels
                    .par_iter_mut()
                    .zip(reports.par_iter_mut())
                    .for_each(|(ch, out)| run_channel(ch, window, aid, out));
            })
            .1
        };
        let engine = match &search {
            Some(s) if s.realign.is_some() => self.realign_engine.as_ref(),
            Some(s) => s.batch.as_ref().and_then(|b| self.engines.get(b.level)),
            None => None,
        };
        let outcome = match (engine, search) {
            (Some(engine), Some(s)) => {
                let search = || {
                    // Read where the window holds them (converted block by block).
                    let samples = window
                        .get(s.first, s.len)
                        .unwrap_or(gpsrx_dsp::SampleSlice::Cf32(&[]));
                    timed(|| engine.search_slice(samples, &s.targets))
                };
                let ((results, searching), tracking) = rayon::join(search, run_all);
                self.times.tracking_s += tracking.as_secs_f64();
                self.times.search_s += searching.as_secs_f64();
                self.times.searches += 1;
                let results = results
                    .map_err(|e| tracing::warn!("a search failed: {e}"))
                    .ok();
                results.map(|results| SearchOutcome {
                    first: s.first,
                    results,
                    batch: s.batch,
                    realign: s.realign,
                })
            }
            _ => {
                self.times.tracking_s += run_all().as_secs_f64();
                None
            }
        };
        self.release_cross_correlations();
        outcome
    }

    /// Whether the receiver is under dynamics, from the Doppler rates the strong channels'
    /// loops followed up to `sample` (the second largest: [`crate::pipeline::channels::dynamics`]);
    /// told to every channel (a weak one widens its loops).
    fn watch_dynamics(&mut self, sample: u64) {
        let mut rates: Vec<f64> = self
            .channels
            .iter()
            .filter_map(|c| c.los_rate_hz_s())
            .map(f64::abs)
            .collect();
        rates.sort_by(|a, b| b.total_cmp(a));
        // The second largest (one channel's noise or transient is not the receiver's motion).
        let rate = rates.get(1).or(rates.first()).copied();
        let on = self.dynamics.update(sample as f64 / self.fs_hz, rate);
        for c in &mut self.channels {
            c.set_dynamics(on);
        }
    }

    /// Hands the reports of the last [`ChannelManager::work`] to `f` as `(channel index,
    /// report)` in stream order: by the first sample of their interval, then by channel (a
    /// channel's own reports keep their order). A block holds 40 ms of every channel's reports;
    /// handed over channel by channel, a fix and the clock step it makes, decided on the
    /// reports of the channels before, came after the later reports of the channels after
    /// (a satellite missing from the next fix). Every report is dropped afterwards, also
    /// when `f` fails (its error is returned).
    pub fn drain_reports<E>(
        &mut self,
        f: impl FnMut(usize, &ChannelEpoch) -> Result<(), E>,
    ) -> Result<(), E> {
        drain_in_stream_order(&mut self.reports, f)
    }

    /// Whether detection `d` sits at the Doppler of a much stronger live channel modulo 1 kHz
    /// ([`XCORR_MARGIN_DB`]): its cross-correlation, not a satellite.
    fn cross_correlation(&self, d: &AcqResult) -> Option<Prn> {
        let cn0 = d.cn0_dbhz?;
        self.channels
            .iter()
            .filter(|c| c.state() != ChannelState::Lost && c.prn() != d.prn)
            .find(|c| may_be_cross_correlation(d.doppler_hz - c.doppler_hz(), c.cn0_dbhz() - cn0))
            .map(Channel::prn)
    }

    /// Releases the channels still in their pull-in that follow a cross-correlation of a
    /// confirmed channel: within [`XCORR_WIDE_DOPPLER_HZ`] of its kHz lines and
    /// [`XCORR_WIDE_MARGIN_DB`] below it (the highest C/N0 the pull-in measured: a failing
    /// pull-in's last estimate is no measure, and its Doppler wanders, so the tight rule for
    /// detections is not used). A false channel locks on the strong satellite's carrier and
    /// data and must never be confirmed (measured: one 29 dB below a 52 dB-Hz satellite
    /// reached tracking). Not a channel its aid checks ([`Channel::checked_aid`]: vector
    /// tracking's prediction puts its own satellite's code where the channel's is, which a
    /// cross-correlation, at the strong satellite's code alignment, matches by chance only:
    /// a 24 dB-Hz satellite 1 kHz from a 43 dB-Hz one was released again and again).
    fn release_cross_correlations(&mut self) {
        let sources: Vec<(Prn, f64, f64)> = self
            .channels
            .iter()
            .filter(|c| c.confirmed() && c.state() != ChannelState::Lost)
            .map(|c| (c.prn(), c.doppler_hz(), c.cn0_dbhz()))
            .collect();
        for c in self
            .channels
            .iter_mut()
            .filter(|c| !c.confirmed() && c.state() != ChannelState::Lost && !c.checked_aid())
        {
            let own_cn0 = match c.tracked_cn0_dbhz() {
                x if x.is_finite() => x.max(c.cn0_dbhz()),
                _ => c.cn0_dbhz(),
            };
            let of = sources.iter().find(|&&(prn, doppler_hz, cn0)| {
                prn != c.prn()
                    && off_line_hz(c.doppler_hz() - doppler_hz) <= XCORR_WIDE_DOPPLER_HZ
                    && cn0 - own_cn0 >= XCORR_WIDE_MARGIN_DB
            });
            if let Some(&(prn, _, cn0)) = of {
                tracing::info!(
                    "{}: released: its channel ({:.0} Hz, at most {own_cn0:.1} dB-Hz) follows a cross-correlation of {prn} ({cn0:.1} dB-Hz)",
                    c.prn(),
                    c.doppler_hz(),
                );
                c.release();
            }
        }
    }

    /// Starts channels for what a search found (`visibility` as in
    /// [`ChannelManager::due_search`]); returns the detections.
    pub fn start_found(
        &mut self,
        mut outcome: SearchOutcome,
        visibility: &dyn Fn(Prn) -> Visibility,
    ) -> Vec<AcqResult> {
        for d in outcome.results.iter_mut().filter(|d| d.detected) {
            if d.cn0_dbhz.is_some_and(|c| c < MIN_START_CN0_DBHZ) {
                // A peak over the threshold whose prompts after it are mostly noise (the signal
                // returning at the end of the search's samples): searched again next time.
                tracing::debug!(
                    "{}: detection at {:.0} Hz with C/N0 {:.1} dB-Hz not started",
                    d.prn,
                    d.doppler_hz,
                    d.cn0_dbhz.unwrap_or(f64::NAN)
                );
                d.detected = false;
                continue;
            }
            if let Some(strong) = self.cross_correlation(d) {
                tracing::debug!(
                    "{}: detection at {:.0} Hz, {:.1} dB-Hz taken for a cross-correlation of {strong}",
                    d.prn,
                    d.doppler_hz,
                    d.cn0_dbhz.unwrap_or(f64::NAN)
                );
                d.detected = false;
                d.cross_correlation_of = Some(strong);
            }
        }
        let end = outcome.first + outcome.batch.as_ref().map_or(0, |b| b.len as u64);
        let tracked = Prn::all().filter(|&p| self.live(p).is_some()).count()
            + outcome.results.iter().filter(|d| d.detected).count();
        if let (Some(s), Some(b)) = (self.schedule.as_mut(), outcome.batch.as_ref()) {
            for (t, r) in b.targets.iter().zip(&outcome.results) {
                tracing::trace!(
                    "search at sample {end}, level {}: {} in {:?} Hz: detected {} (metric {:.2}, threshold {:.2})",
                    b.level,
                    t.prn,
                    t.doppler_window_hz,
                    r.detected,
                    r.metric,
                    r.threshold
                );
            }
            s.record(b, &outcome.results, end, tracked, visibility);
        }
        let mut started = Vec::new();
        for d in outcome.results.into_iter().filter(|d| d.detected) {
            let start = ChannelStart::from_acquisition(&d, outcome.first);
            match Channel::new(&start, self.fs_hz, &self.channel_config) {
                Ok(ch) => {
                    tracing::info!(
                        "{}: acquired at {:.2} s, Doppler {:.0} Hz, C/N0 {:.1} dB-Hz",
                        d.prn,
                        outcome.first as f64 / self.fs_hz,
                        d.doppler_hz,
                        d.cn0_dbhz.unwrap_or(f64::NAN)
                    );
                    self.channels.push(ch);
                    started.push(d);
                }
                Err(e) => tracing::warn!("{}: cannot start a channel: {e}", d.prn),
            }
        }
        started
    }

    /// Whether a live channel tracks `prn`.
    pub fn tracks(&self, prn: Prn) -> bool {
        self.live(prn).is_some()
    }

    /// Channels started from predictions of their signals, without a search
    /// ([`Channel::predicted`]: vector tracking takes in a satellite it predicts above the
    /// horizon but no channel tracks); a satellite already tracked is skipped. Returns the
    /// satellites started.
    pub fn start_predicted(&mut self, starts: &[ChannelStart]) -> Vec<Prn> {
        let mut started = Vec::new();
        for start in starts {
            if self.live(start.prn).is_some() {
                continue;
            }
            match Channel::predicted(start, self.fs_hz, &self.channel_config) {
                Ok(ch) => {
                    tracing::info!(
                        "{}: taken in from vector tracking's prediction at {:.2} s, Doppler {:.0} Hz (no search)",
                        start.prn,
                        start.code_start_sample as f64 / self.fs_hz,
                        start.doppler_hz
                    );
                    self.channels.push(ch);
                    started.push(start.prn);
                }
                Err(e) => tracing::warn!("{}: cannot start a channel: {e}", start.prn),
            }
        }
        started
    }

    /// The oldest sample still needed: the slowest live channel's next code period, and the
    /// samples the next search will read. `end` is the window's end.
    pub fn oldest_needed(&self, end: u64) -> u64 {
        let live = self
            .channels
            .iter()
            .filter(|c| c.state() != ChannelState::Lost);
        let oldest = live.map(|c| c.next_span().0).min().unwrap_or(end);
        let search_from = end.saturating_sub(self.search_samples() as u64);
        // A code realignment waiting for its samples keeps the latest search's worth.
        let realign_from = self.realign.as_ref().map_or(u64::MAX, |_| {
            end.saturating_sub(self.realign_samples().unwrap_or(0) as u64)
        });
        oldest.min(search_from).min(realign_from)
    }

    /// Whether nothing more can happen: every channel lost and no search to start new ones.
    pub fn finished(&self) -> bool {
        self.schedule.is_none()
            && !self.cold_start_pending()
            && self
                .channels
                .iter()
                .all(|c| c.state() == ChannelState::Lost)
    }

    /// Channel `channel`, if it still tracks `prn`, takes data-bit edges from outside
    /// ([`Channel::assume_bit_edge`]: vector tracking's prediction).
    pub fn assume_bit_edge(&mut self, channel: usize, prn: u8, edge_phase: usize) {
        if let Some(c) = self
            .channels
            .get_mut(channel)
            .filter(|c| c.prn().get() == prn)
        {
            c.assume_bit_edge(edge_phase);
        }
    }

    /// Every live channel forgets its data-bit edges ([`Channel::restart_bit_sync`]).
    pub fn restart_bit_sync(&mut self) {
        for c in self
            .channels
            .iter_mut()
            .filter(|c| c.state() != ChannelState::Lost)
        {
            c.restart_bit_sync();
        }
    }

    /// Time spent in [`ChannelManager::work`] so far.
    pub fn work_times(&self) -> WorkTimes {
        self.times
    }

    /// The channels, in the order they were started.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// The channels, consumed.
    pub fn into_channels(self) -> Vec<Channel> {
        self.channels
    }
}

/// The cold start could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ColdStartError {
    /// Fewer samples than one search needs.
    #[error(
        "the recording is too short for acquisition ({samples} samples; at least {needed} needed)"
    )]
    TooShort {
        /// Samples available.
        samples: usize,
        /// Samples one search needs.
        needed: usize,
    },
    /// The search failed.
    #[error(transparent)]
    Acquisition(#[from] gpsrx_dsp::acquisition::AcqError),
    /// A channel could not be started.
    #[error("cannot start a tracking channel: {0}")]
    Channel(#[from] gpsrx_tracking::ConfigError),
}

/// The PRNs in `prns`, or all 32 when it is empty.
fn wanted_prns(prns: &[Prn]) -> Box<dyn Iterator<Item = Prn> + '_> {
    if prns.is_empty() {
        Box::new(Prn::all())
    } else {
        Box::new(prns.iter().copied())
    }
}

/// Processes every code period of `ch` that `window` holds, appending the reports to `out`.
fn run_channel(
    ch: &mut Channel,
    window: SampleView<'_>,
    aid: Option<&dyn AidingPort>,
    out: &mut Vec<ChannelEpoch>,
) {
    while ch.state() != ChannelState::Lost {
        let (start, n) = ch.next_span();
        if start < window.start() {
            ch.skip_to(window.start());
            continue;
        }
        match window.get(start, n) {
            Some(x) => {
                // Without a port (vector tracking off, an outage bridge over) the aid goes: a
                // channel must not extrapolate the last one for ever.
                let t = start as f64 / ch.fs_hz();
                ch.set_aid(aid.and_then(|a| a.doppler_aid(ch.prn(), t)), t);
                if let Some(e) = ch.process_period(x) {
                    out.push(e);
                }
            }
            None => break,
        }
    }
}

/// Hands `reports` (per channel, as [`ChannelManager::work`] leaves them) to `f` as `(channel
/// index, report)` in stream order (see [`ChannelManager::drain_reports`]) and clears them,
/// also when `f` fails (its error is returned).
pub fn drain_in_stream_order<E>(
    reports: &mut [Vec<ChannelEpoch>],
    mut f: impl FnMut(usize, &ChannelEpoch) -> Result<(), E>,
) -> Result<(), E> {
    let mut order: Vec<(u64, usize, usize)> = reports
        .iter()
        .enumerate()
        .flat_map(|(i, r)| {
            r.iter()
                .enumerate()
                .map(move |(j, e)| (e.sample_index, i, j))
        })
        .collect();
    order.sort_unstable();
    let result = order.iter().try_for_each(|&(_, i, j)| f(i, &reports[i][j]));
    for r in reports.iter_mut() {
        r.clear();
    }
    result
}
