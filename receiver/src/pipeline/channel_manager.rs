//! The channel manager: which satellites have a tracking channel, and the searches that start
//! new ones.
//!
//! - Cold start: the first samples of the stream are searched for every PRN; when fewer than 4
//!   are found and the configured search is less sensitive than 10 ms x 10, the rest are
//!   searched again with 10 ms x 10 (about 8 dB more sensitive), and that engine is kept for
//!   re-acquisition.
//! - Re-acquisition: every `interval_s` of signal, the PRNs without a live channel are searched
//!   in the latest samples; a PRN that has been tracked (and lost) at every interval, one never
//!   found less and less often (1, 2, 4, then every 8 intervals), since most of the 32 are
//!   below the horizon.
//! - Hot re-acquisition: a satellite whose channel lost the signal in the last
//!   [`HOT_FOR_S`] s is also searched every [`HOT_INTERVAL_S`] s between those searches, in a
//!   narrow Doppler window around its last Doppler, so that it is found again within a
//!   fraction of a second of the signal's return (after a blockage or a dropout); its SV time
//!   is carried over by the navigation processor, so fixes resume at its first bit edge.
//! - Code realignment: when the prompt power of several satellites collapsed at once
//!   ([`crate::pipeline::code_jump`]: samples lost by a fraction of a code period), those
//!   satellites are searched at once in a narrow window around the Doppler they held, and
//!   the channels whose code moved together are moved onto it ([`Channel::realign_code`]).
//! - Work: every channel processes the code periods the sample window holds, in parallel
//!   (rayon), concurrently with a due search (rayon `join`), so a search never stalls tracking.

use crate::pipeline::code_jump::{fit_code_gap, Collapse, CollapsedSat, POWER_REPORTS};
use crate::pipeline::ring::SampleView;
use gpsrx_dsp::acquisition::{AcqConfig, AcqResult, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_tracking::{
    AidingPort, Channel, ChannelConfig, ChannelEpoch, ChannelStart, ChannelState,
};
use num_complex::Complex32;
use rayon::prelude::*;

/// Coherent integration (ms) and non-coherent blocks of the weak-signal search that follows a
/// cold start finding fewer than [`WEAK_SEARCH_BELOW`] satellites.
const WEAK_ACQ: (u32, u32) = (10, 10);

/// A cold start finding fewer satellites than this runs the weak-signal search.
const WEAK_SEARCH_BELOW: usize = 4;

/// Longest wait between two searches of a PRN that was never found, in search intervals:
/// a PRN searched and not found waits 1, 2, 4, then 8 intervals before the next search.
const MAX_BACKOFF_INTERVALS: u32 = 8;

/// How long after a loss a satellite is searched in the narrow hot window, s.
pub const HOT_FOR_S: f64 = 60.0;
/// Seconds of signal between two hot searches.
pub const HOT_INTERVAL_S: f64 = 0.2;
/// Half width of the hot Doppler window: this much, Hz, plus [`HOT_DOPPLER_RATE_HZ_S`] per
/// second since the loss (the full search at every interval covers faster changes).
pub const HOT_DOPPLER_HZ: f64 = 250.0;
/// See [`HOT_DOPPLER_HZ`], Hz/s.
pub const HOT_DOPPLER_RATE_HZ_S: f64 = 25.0;

/// Half width of the Doppler window of a code realignment search, Hz (the Doppler held before
/// the collapse is known to a few hertz).
pub const REALIGN_DOPPLER_HZ: f64 = 100.0;
/// Coherent integration (ms), non-coherent blocks and refinement periods (ms) of a code
/// realignment search: the Doppler is known to a few hertz, so 5 ms blocks (bit edges handled
/// by the engine's half-shifted pass) reach about 31 dB-Hz in 30 ms of signal.
const REALIGN_ACQ: (u32, u32, u32) = (5, 6, 20);
/// Longest wait for the samples of a code realignment search after a collapse, s.
const REALIGN_WAIT_S: f64 = 0.3;

/// How the manager searches.
#[derive(Debug, Clone)]
pub struct SearchSettings {
    /// The acquisition engine's settings (integration, Doppler range).
    pub acq: AcqConfig,
    /// Search again with 10 ms x 10 when the first search finds fewer than 4 satellites and is
    /// less sensitive than that.
    pub weak_fallback: bool,
    /// Seconds of signal between re-acquisition searches; `None`: no re-acquisition.
    pub reacquisition_interval_s: Option<f64>,
    /// PRNs to look for (empty: all 32).
    pub prns: Vec<Prn>,
    /// The cold start's targets, when known better than "every wanted PRN, full Doppler
    /// range" (an assisted search with predicted Doppler windows).
    pub cold_targets: Option<Vec<SearchTarget>>,
}

/// A search due in this block: its first sample and its targets (and, for a code
/// realignment, the collapse it follows).
#[derive(Debug)]
pub struct DueSearch {
    first: u64,
    /// Samples read from `first`.
    len: usize,
    targets: Vec<SearchTarget>,
    realign: Option<Realign>,
}

/// What a search found: its first sample, targets and results.
#[derive(Debug)]
pub struct SearchOutcome {
    first: u64,
    targets: Vec<SearchTarget>,
    results: Vec<AcqResult>,
    realign: Option<Realign>,
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

/// A code realignment to make: the collapse, and the first sample a search may read.
#[derive(Debug, Clone)]
struct Realign {
    jump: u64,
    after: u64,
    satellites: Vec<CollapsedSat>,
}

/// Channels moved onto a code that jumped ([`ChannelManager::realign`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Realigned {
    /// Sample index of the collapse.
    pub jump_sample: u64,
    /// The shortest gap the code shifts allow, s.
    pub shortest_gap_s: f64,
    /// The forward shift of the first satellite moved, in code periods (`-g` modulo 1 ms).
    pub fraction_of_period: f64,
    /// The satellites moved.
    pub prns: Vec<u8>,
    /// The first sample after the move (the next code period of the channels).
    pub at_sample: u64,
}

/// The tracking channels and the searches that start them.
#[derive(Debug)]
pub struct ChannelManager {
    fs_hz: f64,
    channel_config: ChannelConfig,
    /// The re-acquisition engine (the cold start's, or the weak one); `None` before the cold
    /// start and when there is no search at all.
    engine: Option<AcquisitionEngine>,
    cold: Option<ColdStart>,
    settings: Option<SearchSettings>,
    channels: Vec<Channel>,
    /// Per channel, the reports of the last round (kept: no allocation per block).
    reports: Vec<Vec<ChannelEpoch>>,
    schedule: Option<SearchSchedule>,
    /// A code realignment waiting for its samples.
    realign: Option<Realign>,
    /// The engine of code realignment searches ([`REALIGN_ACQ`]); `None` without searches.
    realign_engine: Option<AcquisitionEngine>,
}

/// The engines of the cold start, made once.
#[derive(Debug)]
struct ColdStart {
    engine: AcquisitionEngine,
    weak: Option<AcquisitionEngine>,
}

impl ChannelManager {
    /// A manager that searches with `settings` and starts channels with `channel_config`.
    pub fn new(
        fs_hz: f64,
        channel_config: ChannelConfig,
        settings: SearchSettings,
    ) -> Result<Self, gpsrx_dsp::acquisition::AcqError> {
        let engine = AcquisitionEngine::new(fs_hz, settings.acq.clone())?;
        let realign_engine = Some(AcquisitionEngine::new(
            fs_hz,
            AcqConfig {
                coherent_ms: REALIGN_ACQ.0,
                noncoherent: REALIGN_ACQ.1,
                refine_ms: REALIGN_ACQ.2,
                ..settings.acq.clone()
            },
        )?);
        let (coh, nc) = WEAK_ACQ;
        let less_sensitive = settings.acq.coherent_ms < coh
            || settings.acq.coherent_ms * settings.acq.noncoherent < coh * nc;
        let weak = if settings.weak_fallback && less_sensitive {
            let cfg = AcqConfig {
                coherent_ms: coh,
                noncoherent: nc,
                ..settings.acq.clone()
            };
            Some(AcquisitionEngine::new(fs_hz, cfg)?)
        } else {
            None
        };
        Ok(Self {
            fs_hz,
            channel_config,
            engine: None,
            cold: Some(ColdStart { engine, weak }),
            settings: Some(settings),
            channels: Vec::new(),
            reports: Vec::new(),
            schedule: None,
            realign: None,
            realign_engine,
        })
    }

    /// A manager for channels started elsewhere, with no search (loop studies, tests).
    pub fn with_channels(fs_hz: f64, channels: Vec<Channel>) -> Self {
        Self {
            fs_hz,
            channel_config: ChannelConfig::default(),
            engine: None,
            cold: None,
            settings: None,
            channels,
            reports: Vec::new(),
            schedule: None,
            realign: None,
            realign_engine: None,
        }
    }

    /// Samples the cold start wants before it searches (0 when it is done or there is none).
    pub fn cold_start_samples(&self) -> usize {
        self.cold.as_ref().map_or(0, |c| {
            c.weak
                .as_ref()
                .map_or(0, AcquisitionEngine::samples_wanted)
                .max(c.engine.samples_wanted())
        })
    }

    /// Whether the cold start is still to come.
    pub fn cold_start_pending(&self) -> bool {
        self.cold.is_some()
    }

    /// Samples the cold start cannot do without.
    pub fn cold_start_minimum(&self) -> usize {
        self.cold.as_ref().map_or(0, |c| c.engine.samples_needed())
    }

    /// Searches `samples` (whose first sample has index `first_index`) for every wanted PRN,
    /// starts a channel per satellite found, and returns the detections.
    pub fn cold_start(
        &mut self,
        samples: &[Complex32],
        first_index: u64,
    ) -> Result<Vec<AcqResult>, ColdStartError> {
        let Some(cold) = self.cold.take() else {
            return Ok(Vec::new());
        };
        let n = samples.len();
        if n < cold.engine.samples_needed() {
            return Err(ColdStartError::TooShort {
                samples: n,
                needed: cold.engine.samples_needed(),
            });
        }
        let targets: Vec<SearchTarget> = match &self.settings {
            Some(SearchSettings {
                cold_targets: Some(t),
                ..
            }) => t.clone(),
            s => {
                let prns = s.as_ref().map(|s| s.prns.as_slice()).unwrap_or(&[]);
                wanted_prns(prns).map(SearchTarget::full).collect()
            }
        };
        let mut found = cold
            .engine
            .search(&samples[..n.min(cold.engine.samples_wanted())], &targets)?;
        let detected = found.iter().filter(|d| d.detected).count();
        let engine = match cold.weak {
            Some(weak) if detected < WEAK_SEARCH_BELOW && n >= weak.samples_needed() => {
                let acq = cold.engine.config();
                tracing::warn!(
                    "{detected} satellite(s) found with {} ms x {}: searching again with {} ms x {} for weak signals (--acq-coherent-ms chooses)",
                    acq.coherent_ms,
                    acq.noncoherent,
                    WEAK_ACQ.0,
                    WEAK_ACQ.1
                );
                let missing: Vec<SearchTarget> = found
                    .iter()
                    .filter(|d| !d.detected)
                    .map(|d| SearchTarget::full(d.prn))
                    .collect();
                let again = weak.search(&samples[..n.min(weak.samples_wanted())], &missing)?;
                for r in again {
                    if let Some(slot) = found.iter_mut().find(|d| d.prn == r.prn) {
                        *slot = r;
                    }
                }
                weak
            }
            _ => cold.engine,
        };
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
        if let Some(interval_s) = self
            .settings
            .as_ref()
            .and_then(|s| s.reacquisition_interval_s)
        {
            self.schedule = Some(SearchSchedule::new(interval_s, &self.channels, self.fs_hz));
        }
        self.engine = Some(engine);
        Ok(found.into_iter().filter(|d| d.detected).collect())
    }

    /// Samples a re-acquisition search reads (0 without one).
    fn search_samples(&self) -> usize {
        match (&self.engine, &self.schedule) {
            (Some(e), Some(_)) => e.samples_wanted(),
            _ => 0,
        }
    }

    /// The search due now that the window is `window`, if one is: a code realignment whose
    /// samples have come, else the schedule's.
    pub fn due_search(&mut self, window: SampleView<'_>) -> Option<DueSearch> {
        if let Some(due) = self.due_realignment(window) {
            return Some(due);
        }
        let keep = self.search_samples();
        let prns = self
            .settings
            .as_ref()
            .map(|s| s.prns.as_slice())
            .unwrap_or(&[]);
        let schedule = self.schedule.as_mut()?;
        schedule.due(prns, window, keep, &self.channels)
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
        let channels = &mut self.channels;
        let reports = &mut self.reports;
        let mut run_all = || {
            channels
                .par_iter_mut()
                .zip(reports.par_iter_mut())
                .for_each(|(ch, out)| run_channel(ch, window, aid, out));
        };
        let engine = match &search {
            Some(s) if s.realign.is_some() => self.realign_engine.as_ref(),
            _ => self.engine.as_ref(),
        };
        match (engine, search) {
            (Some(engine), Some(s)) => {
                let samples = window.get(s.first, s.len).unwrap_or(&[]);
                let (results, ()) = rayon::join(|| engine.search(samples, &s.targets), run_all);
                let results = results
                    .map_err(|e| tracing::warn!("a search failed: {e}"))
                    .ok();
                results.map(|results| SearchOutcome {
                    first: s.first,
                    targets: s.targets,
                    results,
                    realign: s.realign,
                })
            }
            _ => {
                run_all();
                None
            }
        }
    }

    /// Hands the reports of the last [`ChannelManager::work`] to `f` as `(channel index,
    /// report)`, channel by channel, each in time order.
    pub fn drain_reports<E>(
        &mut self,
        mut f: impl FnMut(usize, &ChannelEpoch) -> Result<(), E>,
    ) -> Result<(), E> {
        for (i, r) in self.reports.iter_mut().enumerate() {
            let mut result = Ok(());
            for e in r.iter() {
                result = f(i, e);
                if result.is_err() {
                    break;
                }
            }
            r.clear();
            result?;
        }
        Ok(())
    }

    /// Starts channels for what a search found; returns the detections.
    pub fn start_found(&mut self, outcome: SearchOutcome) -> Vec<AcqResult> {
        let keep = self.search_samples() as u64;
        if let Some(s) = self.schedule.as_mut() {
            s.record(&outcome.targets, &outcome.results, outcome.first + keep);
        }
        let mut started = Vec::new();
        for d in outcome.results.into_iter().filter(|d| d.detected) {
            let start = ChannelStart::from_acquisition(&d, outcome.first);
            match Channel::new(&start, self.fs_hz, &self.channel_config) {
                Ok(ch) => {
                    tracing::info!(
                        "{}: acquired at {:.2} s, Doppler {:.0} Hz",
                        d.prn,
                        outcome.first as f64 / self.fs_hz,
                        d.doppler_hz
                    );
                    self.channels.push(ch);
                    started.push(d);
                }
                Err(e) => tracing::warn!("{}: cannot start a channel: {e}", d.prn),
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
        let keep = self.search_samples() as u64;
        let search_from = self.schedule.as_ref().map_or(u64::MAX, |s| {
            s.next_tick.min(s.next_hot_tick).saturating_sub(keep)
        });
        // A code realignment waiting for its samples keeps the latest search's worth.
        let realign_from = self.realign.as_ref().map_or(u64::MAX, |_| {
            end.saturating_sub(self.realign_samples().unwrap_or(0) as u64)
        });
        oldest.min(search_from).min(realign_from)
    }

    /// Whether nothing more can happen: every channel lost and no search to start new ones.
    pub fn finished(&self) -> bool {
        self.schedule.is_none()
            && self.cold.is_none()
            && self
                .channels
                .iter()
                .all(|c| c.state() == ChannelState::Lost)
    }

    /// Asks for a code realignment of the satellites of `collapse` (samples at `fs_hz`): they
    /// are searched as soon as the window holds a search's worth of samples after it.
    pub fn request_realignment(&mut self, collapse: &Collapse) {
        if self.realign_engine.is_none() {
            return;
        }
        let after = collapse.sample + (POWER_REPORTS as f64 * 1e-3 * self.fs_hz) as u64;
        self.realign = Some(Realign {
            jump: collapse.sample,
            after,
            satellites: collapse.satellites.clone(),
        });
    }

    /// The realignment search due in `window`, if its samples have come: every satellite with
    /// a live channel in tracking, around the Doppler it held (those that collapsed) or holds
    /// (a long gap moves the code of some satellites less than a chip: they did not collapse
    /// but moved too).
    fn due_realignment(&mut self, window: SampleView<'_>) -> Option<DueSearch> {
        let r = self.realign.as_ref()?;
        let keep = self.realign_samples()? as u64;
        let now = window.end();
        if now < r.after + keep || now < window.start() + keep {
            if now > r.after + keep + (REALIGN_WAIT_S * self.fs_hz) as u64 {
                self.realign = None;
            }
            return None;
        }
        let r = self.realign.take()?;
        let t_s = now as f64 / self.fs_hz;
        let targets: Vec<SearchTarget> = self
            .channels
            .iter()
            .filter(|c| c.state() == ChannelState::Track)
            .map(|c| {
                let doppler = r
                    .satellites
                    .iter()
                    .find(|s| s.prn == c.prn().get())
                    .map_or(c.doppler_hz(), |s| s.doppler_at(t_s));
                SearchTarget::around(c.prn(), doppler, REALIGN_DOPPLER_HZ)
            })
            .collect();
        tracing::debug!(
            "code realignment search at sample {now}: {} PRN(s)",
            targets.len()
        );
        (!targets.is_empty()).then(|| DueSearch {
            first: now - keep,
            len: keep as usize,
            targets,
            realign: Some(r),
        })
    }

    /// Samples a code realignment search reads: the search itself and a few tens of code
    /// periods for the refinement of its code phase (not the whole refinement of an
    /// acquisition: the Doppler is known).
    fn realign_samples(&self) -> Option<usize> {
        self.realign_engine
            .as_ref()
            .map(AcquisitionEngine::samples_wanted)
    }

    /// Index of the live channel of `prn`.
    fn live(&self, prn: Prn) -> Option<usize> {
        self.channels
            .iter()
            .position(|c| c.prn() == prn && c.state() != ChannelState::Lost)
    }

    /// Moves the channels of a realignment search onto the code found, if one gap explains
    /// the code shifts of at least three satellites ([`fit_code_gap`]); returns what moved.
    /// The channels that collapsed restart their carrier loop at the Doppler they held before;
    /// the others keep their loops.
    pub fn realign(&mut self, outcome: SearchOutcome) -> Option<Realigned> {
        let r = outcome.realign?;
        let first = outcome.first as f64;
        let found: Vec<(usize, f64, gpsrx_tracking::CodeShift)> = outcome
            .results
            .iter()
            .filter(|d| d.detected)
            .filter_map(|d| {
                let i = self.live(d.prn)?;
                let start = first + d.code_phase_samples;
                Some((i, start, self.channels[i].code_shift_to(start)))
            })
            .collect();
        let shifts: Vec<(u8, gpsrx_tracking::CodeShift)> = found
            .iter()
            .map(|&(i, _, s)| (self.channels[i].prn().get(), s))
            .collect();
        // Two samples, or a twentieth of a chip at high rates: the search's code resolution.
        let tol = (0.05 * self.fs_hz / gpsrx_dsp::constants::CA_CHIP_RATE_HZ).max(2.0);
        let Some(gap) = fit_code_gap(&shifts, self.fs_hz, tol) else {
            tracing::debug!("code realignment: no gap explains the shifts {shifts:?}");
            return None;
        };
        let mut moved = Vec::new();
        let mut at_sample = 0;
        for (i, start, _) in found {
            let ch = &mut self.channels[i];
            let prn = ch.prn().get();
            if !gap.prns.contains(&prn) {
                continue;
            }
            let t_s = ch.next_span().0 as f64 / self.fs_hz;
            let carrier = r
                .satellites
                .iter()
                .find(|s| s.prn == prn)
                .map(|s| (s.doppler_at(t_s), s.doppler_rate_hz_s, s.cn0_dbhz));
            if ch.realign_code(start, carrier).is_some() {
                moved.push(prn);
                at_sample = at_sample.max(ch.next_span().0);
            }
        }
        (moved.len() >= crate::pipeline::code_jump::MIN_SATELLITES).then(|| {
            let shift_samples = shifts
                .iter()
                .find(|(p, _)| *p == moved[0])
                .map_or(0.0, |(_, s)| s.shift_samples / s.period_samples);
            Realigned {
                jump_sample: r.jump,
                shortest_gap_s: gap.shortest_s,
                fraction_of_period: shift_samples,
                prns: moved,
                at_sample,
            }
        })
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

/// When each PRN is searched next (see the module documentation).
#[derive(Debug)]
struct SearchSchedule {
    /// Sample index of the next search tick.
    next_tick: u64,
    /// Samples between ticks.
    interval: u64,
    /// Sample index of the next hot search tick, and the samples between them.
    next_hot_tick: u64,
    hot_interval: u64,
    fs_hz: f64,
    /// Per PRN (index 0 = PRN 1): sample index before which it is not searched again.
    not_before: [u64; 32],
    /// Per PRN: the current wait after a fruitless search, in intervals.
    backoff: [u32; 32],
    /// Per PRN: whether it has ever had a channel (then it is searched at every tick).
    tracked: [bool; 32],
}

impl SearchSchedule {
    fn new(interval_s: f64, channels: &[Channel], fs: f64) -> Self {
        let interval = ((interval_s * fs) as u64).max(1);
        let hot_interval = ((HOT_INTERVAL_S * fs) as u64).max(1);
        let mut s = Self {
            next_tick: interval,
            interval,
            next_hot_tick: hot_interval,
            hot_interval,
            fs_hz: fs,
            not_before: [0; 32],
            backoff: [1; 32],
            tracked: [false; 32],
        };
        for c in channels {
            s.tracked[c.prn().index()] = true;
        }
        s
    }

    /// The first sample and the targets of the search due in this block, if one is: at a
    /// tick, the wanted PRNs without a live channel whose back-off has run out (full Doppler
    /// range); between ticks, at a hot tick, the recently lost ones in their hot window.
    fn due(
        &mut self,
        prns: &[Prn],
        window: SampleView<'_>,
        keep: usize,
        channels: &[Channel],
    ) -> Option<DueSearch> {
        let now = window.end();
        let full = now >= self.next_tick;
        let hot = now >= self.next_hot_tick;
        if !(full || hot) || now - window.start() < keep as u64 {
            return None;
        }
        self.next_hot_tick = now + self.hot_interval;
        if full {
            self.next_tick = now + self.interval;
        }
        let live = |p: Prn| {
            channels
                .iter()
                .any(|c| c.prn() == p && c.state() != ChannelState::Lost)
        };
        let targets: Vec<SearchTarget> = wanted_prns(prns)
            .filter(|&p| !live(p))
            .filter_map(|p| {
                if full {
                    (self.tracked[p.index()] || now >= self.not_before[p.index()])
                        .then(|| SearchTarget::full(p))
                } else {
                    self.hot_target(p, now, channels)
                }
            })
            .collect();
        tracing::debug!(
            "{} search at sample {now}: {} PRN(s)",
            if full { "re-acquisition" } else { "hot" },
            targets.len()
        );
        (!targets.is_empty()).then(|| DueSearch {
            first: now - keep as u64,
            len: keep,
            targets,
            realign: None,
        })
    }

    /// The narrow search of `p` at sample `now` if its latest channel lost the signal less
    /// than [`HOT_FOR_S`] ago: around that channel's last Doppler.
    fn hot_target(&self, p: Prn, now: u64, channels: &[Channel]) -> Option<SearchTarget> {
        let last = channels.iter().rev().find(|c| c.prn() == p)?;
        let since_s = now.saturating_sub(last.next_span().0) as f64 / self.fs_hz;
        (since_s < HOT_FOR_S).then(|| {
            SearchTarget::around(
                p,
                last.doppler_hz(),
                HOT_DOPPLER_HZ + HOT_DOPPLER_RATE_HZ_S * since_s,
            )
        })
    }

    /// Updates the back-off of the PRNs just searched at sample `now`.
    fn record(&mut self, targets: &[SearchTarget], results: &[AcqResult], now: u64) {
        for (t, d) in targets.iter().zip(results) {
            let i = t.prn.index();
            if d.detected {
                self.tracked[i] = true;
                self.backoff[i] = 1;
            } else if !self.tracked[i] {
                // Due again `backoff` intervals after this tick (slightly early, so that it
                // falls on a tick).
                self.not_before[i] = now + (u64::from(self.backoff[i]) - 1) * self.interval + 1;
                self.backoff[i] = (self.backoff[i] * 2).min(MAX_BACKOFF_INTERVALS);
            }
        }
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
                if let Some(aid) = aid {
                    let t = start as f64 / ch.fs_hz();
                    ch.set_aid(aid.doppler_aid(ch.prn(), t), t);
                }
                if let Some(e) = ch.process_code_period(x) {
                    out.push(e);
                }
            }
            None => break,
        }
    }
}
