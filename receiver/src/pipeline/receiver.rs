//! [`Receiver`]: the whole pipeline, driven by a source or by pushed sample blocks.
//!
//! Samples go into a [`SampleWindow`]; the first ones feed the cold-start search of the
//! [`ChannelManager`]; from then on, block by block (40 ms of signal), every channel processes
//! the code periods the window holds while a due re-acquisition search runs beside them, and
//! each report goes to the [`NavigationProcessor`], which hands observables, fixes and events to
//! the [`Sink`]. The processing is cut into the same 40 ms blocks whatever the caller's block
//! size, so [`Receiver::push`] in any chunking gives what [`Receiver::run`] gives on a stream
//! the signal never leaves (`receiver/tests/pipeline.rs`). Through an outage they can differ
//! slightly: `run` hands the navigation's end of block the end of the samples read (one block
//! ahead of the channels), `push` the end of the block processed, so a collapse may be acted
//! on one block apart (measured: a fix 4 cm apart after 2 s of zeroed samples in that test's
//! simulated sky).
//! (`run`, without an INS or vector tracking, also works a round of the channels while the
//! navigation takes the reports of the round before, and works it again when the
//! navigation's end of block asks for something else: `receiver::overlap`.)

use crate::config::ReceiverConfig;
use crate::landmarks::LandmarkObservation;
use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::aiding::{AidMonitor, AidingStats, GatedAid, OutageBridge};
use crate::pipeline::channels::channel_manager::{
    drain_in_stream_order, ChannelManager, ColdStartError, SearchSettings,
};
use crate::pipeline::channels::ring::{block_samples, SampleWindow};
use crate::pipeline::channels::search_schedule::SearchBudget;
use crate::pipeline::navigation::NavigationProcessor;
use crate::pipeline::profile::{add_timed, StageTimes};
use crate::pipeline::sink::{ReceiverEvent, Sink, SinkError};
use crate::pipeline::timing::code_jump::plan_realignment;
use crate::pipeline::timing::dating::WeekReference;
use crate::pipeline::timing::BlockEvent;
use crate::pipeline::vector::{Captured, Tap, VectorSummary, VectorTracking};
use gpsrx_dsp::acquisition::{AcqConfig, AcqResult};
use gpsrx_dsp::Prn;
use gpsrx_ins_aiding::InsTrack;
use gpsrx_nav::rinex_nav::NavData;
use gpsrx_samples::sigmf::RecordingStart;
use gpsrx_samples::{SampleError, SampleSource};
use gpsrx_tracking::{AidingPort, ChannelEpoch, TrackingMode};
use num_complex::Complex32;
use std::path::Path;
use std::sync::Arc;

mod overlap;

/// Why the receiver stopped.
#[derive(Debug, thiserror::Error)]
pub enum ReceiverError {
    /// The configuration is not usable.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    /// Reading the samples failed.
    #[error(transparent)]
    Source(#[from] SampleError),
    /// The acquisition engine could not be made for this rate and search.
    #[error("acquisition: {0}")]
    Acquisition(#[from] gpsrx_dsp::acquisition::AcqError),
    /// The cold start failed (too few samples, a channel that cannot start).
    #[error(transparent)]
    ColdStart(#[from] ColdStartError),
    /// The sink failed (an output file, a closed pipe).
    #[error("{0}")]
    Sink(SinkError),
    /// A source at another sampling rate than the receiver was made for.
    #[error("the source samples at {source_hz} Hz but the receiver was made for {receiver_hz} Hz")]
    RateMismatch {
        /// The source's rate.
        source_hz: f64,
        /// The receiver's rate.
        receiver_hz: f64,
    },
    /// The INS input cannot be used.
    #[error("INS: {0}")]
    Ins(String),
    /// Samples after the end of the stream.
    #[error("the stream has ended (finish was called): make a new Receiver for another stream")]
    Finished,
}

/// Inputs beside the samples: assistance data, the INS, landmark ranges.
#[derive(Debug, Default)]
pub struct Assistance {
    /// Broadcast ephemerides (a RINEX navigation file) used until decoded ones arrive.
    pub nav: Option<NavData>,
    /// An INS whose velocity is fed forward into every carrier and code loop (seed 004).
    pub ins: Option<InsAiding>,
    /// Landmark range observations (seed 001).
    pub landmarks: Vec<LandmarkObservation>,
    /// When the recording started, from its metadata (SigMF `core:datetime`): dates the
    /// outputs until subframe 1 gives the week ([`WeekReference`]).
    pub recording_start: Option<RecordingStart>,
}

/// The files [`Assistance::read`] takes: each is optional.
#[derive(Debug, Clone, Default)]
pub struct AssistanceFiles<'a> {
    /// A RINEX 2/3 navigation file.
    pub nav: Option<&'a Path>,
    /// An INS CSV (`t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps[,gps_tow_s]`, ECEF).
    pub ins: Option<&'a Path>,
    /// Longest gap allowed between INS rows, s.
    pub ins_max_gap_s: f64,
    /// Band limit of the INS feed-forward, rad/s (seed 004 eq. 8).
    pub ins_band_limit_rad_s: Option<f64>,
    /// Read the INS but do not aid the loops (to compare aided and unaided runs).
    pub no_aiding: bool,
    /// A landmark CSV (`tow_s,x_m,y_m,z_m,range_m,sigma_m`, seed 001).
    pub landmarks: Option<&'a Path>,
}

/// An assistance file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum AssistanceError {
    /// The navigation file cannot be read (the error names the file and line).
    #[error("cannot read the navigation file: {source}")]
    Nav {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: gpsrx_nav::rinex_nav::RinexError,
    },
    /// The navigation file holds no GPS ephemeris.
    #[error("the navigation file {path} holds no GPS ephemeris (a header only, or no GPS records): give a broadcast navigation file with ephemeris records (e.g. brdcDDD0.YYn for the day of the recording), or give no navigation file, to decode the ephemerides from the signal")]
    NavWithoutEphemeris {
        /// The file.
        path: String,
    },
    /// The INS file.
    #[error(transparent)]
    Ins(#[from] gpsrx_ins_aiding::InsError),
    /// The landmark file.
    #[error(transparent)]
    Landmarks(#[from] crate::landmarks::LandmarkError),
}

impl Assistance {
    /// Reads the assistance files (each optional), checking each; the INS span is logged.
    pub fn read(files: &AssistanceFiles<'_>) -> Result<Self, AssistanceError> {
        let nav = match files.nav {
            Some(p) => {
                let path = p.display().to_string();
                let nav = gpsrx_nav::rinex_nav::read_rinex_nav(p).map_err(|source| {
                    AssistanceError::Nav {
                        path: path.clone(),
                        source,
                    }
                })?;
                if nav.ephemerides.is_empty() {
                    return Err(AssistanceError::NavWithoutEphemeris { path });
                }
                Some(nav)
            }
            None => None,
        };
        let landmarks = match files.landmarks {
            Some(p) => crate::landmarks::read_landmarks(p)?,
            None => Vec::new(),
        };
        let ins = match files.ins {
            Some(path) => {
                let track = gpsrx_ins_aiding::read_ins_csv(path, files.ins_max_gap_s)?;
                let (a, b) = track.span_s();
                let off = if files.no_aiding {
                    " (aiding switched off)"
                } else {
                    ""
                };
                tracing::info!(
                    "INS {}: {} rows from {a:.2} to {b:.2} s{off}",
                    path.display(),
                    track.samples().len()
                );
                (!files.no_aiding).then_some(InsAiding {
                    track,
                    band_limit_rad_s: files.ins_band_limit_rad_s,
                })
            }
            None => None,
        };
        Ok(Self {
            nav,
            ins,
            landmarks,
            recording_start: None,
        })
    }
}

/// The INS input of [`Assistance`].
#[derive(Debug)]
pub struct InsAiding {
    /// The INS output (ECEF position and velocity over time).
    pub track: InsTrack,
    /// First-order band limiter alpha/(s+alpha) on the feed-forward, rad/s (seed 004 eq. 8).
    pub band_limit_rad_s: Option<f64>,
}

/// What a run produced.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct RunSummary {
    /// Seconds of signal processed.
    pub duration_s: f64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Satellites tracked at some point (bit sync, or carrier lock in the tracking loops).
    pub tracked_prns: Vec<u8>,
    /// Satellites that had a channel but were never tracked (pull-in on noise, or a signal
    /// too weak to hold), ascending.
    pub dropped_prns: Vec<u8>,
    /// Stream time (s from the first sample) of the first fix.
    pub first_fix_s: Option<f64>,
    /// Number of valid fixes.
    pub fixes: usize,
    /// Solutions that failed the integrity test (RAIM fault not excluded): written flagged
    /// (quality `none`, GGA quality 0), never as fixes.
    pub invalid_fixes: usize,
    /// Mean position of the fixes, LLH degrees/m.
    pub mean_llh: Option<(f64, f64, f64)>,
    /// Mean PDOP.
    pub mean_pdop: Option<f64>,
    /// With `--ins`: how much of the recording was aided, and how often the INS was rejected
    /// for disagreeing with the tracked Doppler ([`crate::pipeline::aiding::AidMonitor`]).
    pub ins_aiding: Option<InsAidingSummary>,
    /// With `--tracking vector`: how long the navigation filter drove the channels, its
    /// handovers and its innovation test ([`crate::pipeline::vector`]).
    pub vector: Option<VectorSummary>,
    /// Where the wall time went, stage by stage ([`crate::pipeline::StageTimes`]).
    pub profile: StageTimes,
}

/// The INS aiding over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct InsAidingSummary {
    /// Seconds of signal with the INS aid applied.
    pub aided_s: f64,
    /// Their share of the recording, 0 to 1.
    pub aided_fraction: f64,
    /// Times the INS was rejected (feed-forward against tracked Doppler).
    pub rejections: usize,
    /// Times it was admitted (the first admission included).
    pub admissions: usize,
}

impl InsAidingSummary {
    fn new(stats: AidingStats, duration_s: f64) -> Self {
        Self {
            aided_s: stats.aided_s,
            aided_fraction: if duration_s > 0.0 {
                (stats.aided_s / duration_s).clamp(0.0, 1.0)
            } else {
                0.0
            },
            rejections: stats.rejections,
            admissions: stats.admissions,
        }
    }
}

/// The GPS receiver: configuration, channel manager, navigation processor and aiding.
#[derive(Debug)]
pub struct Receiver {
    fs_hz: f64,
    block: usize,
    window: SampleWindow,
    manager: ChannelManager,
    nav: NavigationProcessor,
    aiding: Option<Arc<InsFeedForward>>,
    /// The integrity monitor of the aiding (with `aiding`).
    monitor: AidMonitor,
    /// Vector tracking (`[tracking] mode = "vector"`).
    vector: Option<VectorTracking>,
    /// Without an INS: the bridge over the outage under way, and the signal lost before it
    /// was armed, s ([`OutageBridge`]).
    bridge: Option<(OutageBridge, f64)>,
    /// `[run] outage_bridge`.
    outage_bridge: bool,
    /// Samples up to this index have been processed by the channels.
    processed_to: Option<u64>,
    /// Index of the first sample of the stream.
    first_sample: Option<u64>,
    started: std::time::Instant,
    /// The serial stages' wall time so far (the rounds' parts come from the window and the
    /// channel manager).
    stages: StageTimes,
    /// Per channel, the reports of a round the navigation processor takes while the channels
    /// work on the next (`receiver::overlap`).
    spare_reports: Vec<Vec<ChannelEpoch>>,
    /// [`Receiver::run`] may work a round beside the navigation of the round before.
    overlap: bool,
    finished: bool,
    non_finite_said: bool,
}

impl Receiver {
    /// A receiver for samples at `fs_hz` (complex baseband, IF removed).
    pub fn new(
        config: &ReceiverConfig,
        fs_hz: f64,
        assistance: Assistance,
    ) -> Result<Self, ReceiverError> {
        Self::with_search(config, fs_hz, assistance, Self::configured_search(config))
    }

    /// The search [`ReceiverConfig`] describes: its integration, Doppler range and false-alarm
    /// probability, and the background search with its budget.
    fn configured_search(config: &ReceiverConfig) -> SearchSettings {
        let run = &config.run;
        SearchSettings {
            acq: AcqConfig {
                coherent_ms: run.acq_coherent_ms,
                noncoherent: run.acq_noncoherent,
                doppler_center_hz: run.doppler_center_hz,
                doppler_max_hz: run.doppler_max_hz,
                pfa: run.acq_pfa,
                ..AcqConfig::default()
            },
            weak_fallback: true,
            background: Some(SearchBudget {
                defer_deep_from_tracked: run.defer_deep_search_from,
                ..SearchBudget::per_signal(run.search_budget_s)
            }),
            prns: run.prns.iter().filter_map(|&p| Prn::new(p).ok()).collect(),
            cold_targets: None,
        }
    }

    /// A receiver that searches with `search` instead of the configured search: another
    /// acquisition engine, an assisted cold start, no weak-signal fallback (`gpsrx track`).
    pub fn with_search(
        config: &ReceiverConfig,
        fs_hz: f64,
        assistance: Assistance,
        search: SearchSettings,
    ) -> Result<Self, ReceiverError> {
        config.validate()?;
        let vector_nav = assistance.nav.clone();
        let run = &config.run;
        let manager = ChannelManager::new(fs_hz, config.tracking, search)?;
        // The week that labels receiver time until subframe 1 is decoded, and resolves the
        // broadcast 10-bit week: configured, else the recording's, else the navigation
        // file's; else unknown (today's, which resolves the 10-bit week but dates no output).
        let reference = WeekReference::resolve(
            run.week,
            run.approx_time,
            assistance.recording_start.as_ref(),
            assistance.nav.as_ref(),
        );
        reference.log(assistance.recording_start.as_ref());
        let reference_week = reference.week;
        let aided_offset = assistance.ins.as_ref().and_then(|_| {
            log_aided_static_offset(&config.tracking);
            gpsrx_tracking::aiding::nominal_aided_offset_cycles(&config.tracking)
        });
        let aiding = match assistance.ins {
            Some(ins) => Some(Self::feedforward(
                ins,
                &assistance.nav,
                reference.known().then_some(reference_week),
                run,
                config
                    .tracking
                    .aided_track
                    .unwrap_or(config.tracking.track)
                    .pll_order,
            )?),
            None => None,
        }
        .map(Arc::new);
        // With an INS, its motion drives the filter's prediction (`crate::pipeline::vector`).
        let vector = (config.tracking.mode == TrackingMode::Vector)
            .then(|| VectorTracking::new(config, vector_nav).with_ins(aiding.clone()));
        let nav = NavigationProcessor::new(
            fs_hz,
            run.clone(),
            config.tracking.cn0_lost_dbhz,
            reference_week,
            assistance.nav,
            assistance.landmarks,
        )
        .with_reference_week_known(reference.known())
        .with_aided_offset(aided_offset)
        .with_coarse_time(
            run.approx_time
                .or(assistance.recording_start.as_ref().map(|r| r.time)),
        );
        Ok(Self {
            fs_hz,
            block: block_samples(fs_hz),
            window: SampleWindow::new(),
            manager,
            nav,
            aiding,
            monitor: AidMonitor::new(),
            vector,
            bridge: None,
            outage_bridge: config.run.outage_bridge,
            processed_to: None,
            first_sample: None,
            started: std::time::Instant::now(),
            stages: StageTimes::default(),
            spare_reports: Vec::new(),
            overlap: true,
            finished: false,
            non_finite_said: false,
        })
    }

    fn feedforward(
        ins: InsAiding,
        nav: &Option<NavData>,
        reference_week: Option<u32>,
        run: &crate::config::RunSettings,
        aided_order: u8,
    ) -> Result<InsFeedForward, ReceiverError> {
        if let Some(a) = ins.band_limit_rad_s {
            if !(a.is_finite() && a > 0.0) {
                return Err(ReceiverError::Ins(format!(
                    "band limit {a}: give a corner frequency > 0 rad/s"
                )));
            }
        }
        Ok(
            InsFeedForward::new(ins.track, nav.clone(), reference_week, ins.band_limit_rad_s)
                .allow_unhealthy(run.allow_unhealthy)
                .with_velocity_calibration(aided_order <= 2),
        )
    }

    /// The sampling rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The integrity monitor of the INS aiding (idle without an INS).
    pub fn aid_monitor(&self) -> &AidMonitor {
        &self.monitor
    }

    /// Whether [`Receiver::run`] may work a round of the channels while the navigation
    /// processor takes the reports of the round before (default: yes; the outputs are the
    /// same either way, only the wall time differs: see `receiver::overlap`).
    pub fn set_overlap(&mut self, overlap: bool) {
        self.overlap = overlap;
    }

    /// The INS feed-forward, when the receiver is aided.
    pub fn aiding(&self) -> Option<&InsFeedForward> {
        self.aiding.as_deref()
    }

    /// Vector tracking, with `[tracking] mode = "vector"`.
    pub fn vector(&self) -> Option<&VectorTracking> {
        self.vector.as_ref()
    }

    /// Reads `source` to its end, front to back, once; returns the summary.
    pub fn run(
        &mut self,
        source: &mut dyn SampleSource,
        sink: &mut dyn Sink,
    ) -> Result<RunSummary, ReceiverError> {
        if self.finished {
            return Err(ReceiverError::Finished);
        }
        if (source.fs_hz() - self.fs_hz).abs() > 1e-6 * self.fs_hz {
            return Err(ReceiverError::RateMismatch {
                source_hz: source.fs_hz(),
                receiver_hz: self.fs_hz,
            });
        }
        // Samples held as integers where the source can (ci8, ci16 as stored; cu8, ri8, ri16
        // converted to ci16): the int16 correlators read them in place.
        if let Some(f) = self.window.hold_as_stored(source) {
            let gain = self.window.gain();
            if gain == 1.0 {
                tracing::debug!("samples held as {f}, read by the correlators in place");
            } else {
                tracing::debug!(
                    "{} samples held as {f} (times {gain}, rounded), read by the correlators in place",
                    source.format()
                );
            }
        }
        // Until the cold start: gather its samples.
        while self.manager.cold_start_pending() {
            let got = self.window.fill(source, self.block)?;
            self.first_sample.get_or_insert(self.window.start());
            if got == 0 || self.window.end() - self.window.start() >= self.cold_samples() {
                self.cold_start(sink)?;
                // The blocks read so far but the last, as if they had come one by one; the
                // last is processed while the next is read.
                let end = self.window.end();
                self.catch_up(end.saturating_sub(1), sink)?;
            }
        }
        // Without an INS or vector tracking nothing of a round waits for the navigation of
        // the round before, unless that asks for something: the two run side by side.
        if self.overlap && self.aiding.is_none() && self.vector.is_none() {
            self.run_rounds_overlapped(source, sink)?;
            return self.finish(sink);
        }
        // Every block: the channels (and a due search) work on the samples held, on the pool;
        // then their reports go to the navigation processor while the next block is read
        // behind them (the channels have two threads; the read hides behind the navigation,
        // which runs on this thread alone).
        loop {
            let found = self.work_until(self.window.end());
            if self.deliver_while_reading(found, source, sink)? == 0 {
                break;
            }
        }
        self.finish(sink)
    }

    /// Takes the next samples of the stream (any number: the processing is cut into 40 ms
    /// blocks of the stream, whatever the chunking). The first sample pushed has index 0.
    ///
    /// Non-finite values (NaN, infinity) are read as 0, with a warning, as sources do.
    pub fn push(
        &mut self,
        samples: &[Complex32],
        sink: &mut dyn Sink,
    ) -> Result<(), ReceiverError> {
        if self.finished {
            return Err(ReceiverError::Finished);
        }
        let finite = |c: &Complex32| c.re.is_finite() && c.im.is_finite();
        if samples.iter().all(finite) {
            self.window.push(samples);
        } else {
            let clean: Vec<Complex32> = samples
                .iter()
                .map(|c| {
                    if finite(c) {
                        *c
                    } else {
                        Complex32::new(0.0, 0.0)
                    }
                })
                .collect();
            if !self.non_finite_said {
                tracing::warn!("non-finite samples (NaN or infinity) pushed: read as 0");
                self.non_finite_said = true;
            }
            self.window.push(&clean);
        }
        self.first_sample.get_or_insert(self.window.start());
        if self.manager.cold_start_pending() {
            if self.window.end() - self.window.start() < self.cold_samples() {
                return Ok(());
            }
            self.cold_start(sink)?;
        }
        self.catch_up(self.window.end(), sink)
    }

    /// Ends the stream: processes what is left, completes the sink's files and returns the
    /// summary. (Called by [`Receiver::run`]; call it after the last [`Receiver::push`].)
    pub fn finish(&mut self, sink: &mut dyn Sink) -> Result<RunSummary, ReceiverError> {
        if !self.finished {
            if self.manager.cold_start_pending() {
                self.cold_start(sink)?;
            }
            let end = self.window.end();
            self.catch_up(end, sink)?;
            // A last round on the samples after the last whole block (a run has done it
            // already, at the end of its source).
            if self.processed_to.is_some_and(|done| done < end) {
                self.step(end, sink)?;
            }
            let nav_end = self.nav.end();
            add_timed(&mut self.stages.finish_s, || sink.finish(&nav_end))
                .map_err(ReceiverError::Sink)?;
            self.finished = true;
        }
        let stats = self.nav.stats();
        let samples = self.window.end() - self.first_sample.unwrap_or(0);
        let duration_s = samples as f64 / self.fs_hz;
        Ok(RunSummary {
            duration_s,
            wall_s: self.started.elapsed().as_secs_f64(),
            tracked_prns: self.nav.tracked_prns(),
            dropped_prns: self.nav.dropped_prns(),
            first_fix_s: stats.first_fix_s,
            fixes: stats.fixes,
            invalid_fixes: stats.invalid_fixes,
            mean_llh: stats.mean_llh(),
            mean_pdop: stats.mean_pdop(),
            ins_aiding: self
                .aiding
                .as_ref()
                .map(|_| InsAidingSummary::new(self.monitor.stats(), duration_s)),
            vector: self.vector.as_ref().map(VectorTracking::summary),
            profile: self.profile(),
        })
    }

    /// Where the wall time went so far ([`crate::pipeline::StageTimes`]).
    pub fn profile(&self) -> StageTimes {
        let work = self.manager.work_times();
        StageTimes {
            tracking_s: work.tracking_s,
            search_s: work.search_s,
            searches: work.searches,
            read_s: self.window.read_s(),
            ..self.stages
        }
    }

    /// Samples the cold start wants.
    fn cold_samples(&self) -> u64 {
        self.manager.cold_start_samples() as u64
    }

    /// Searches the first samples and starts the channels.
    fn cold_start(&mut self, sink: &mut dyn Sink) -> Result<(), ReceiverError> {
        let first = self.window.start();
        let n = (self.window.end() - first).min(self.cold_samples()) as usize;
        let samples = self.window.get_cf32(first, n).unwrap_or_default();
        let manager = &mut self.manager;
        let found = add_timed(&mut self.stages.cold_start_s, || {
            manager.cold_start(&samples, first)
        })?;
        self.processed_to = Some(first);
        self.announce(&found, first, sink)
    }

    /// Processes the blocks that end at or before `upto`, one by one.
    fn catch_up(&mut self, upto: u64, sink: &mut dyn Sink) -> Result<(), ReceiverError> {
        let start = self.first_sample.unwrap_or(0);
        loop {
            let done = self.processed_to.unwrap_or(start);
            // The next block boundary after `done`, counted from the first sample.
            let k = (done - start) / self.block as u64 + 1;
            let limit = start + k * self.block as u64;
            if limit > upto {
                return Ok(());
            }
            self.step(limit, sink)?;
        }
    }

    /// One block: the channels process the samples before `limit`, with a due search beside.
    fn step(&mut self, limit: u64, sink: &mut dyn Sink) -> Result<(), ReceiverError> {
        let found = self.work_until(limit);
        self.timed_deliver(found, limit, sink)
    }

    /// The channels (and the search due now) on the samples held before `limit`, with the
    /// aid of this round; returns what the search found.
    fn work_until(
        &mut self,
        limit: u64,
    ) -> Option<crate::pipeline::channels::channel_manager::SearchOutcome> {
        let view = self.window.view().until(limit);
        let (nav, t_s) = (&self.nav, limit as f64 / self.fs_hz);
        let due = self
            .manager
            .due_search(view, &|p| nav.visibility(p.get(), t_s));
        let gated = gated_aid(self.aiding.as_deref(), &self.monitor);
        let bridge = self.bridge.as_ref().map(|(b, _)| b);
        let aid = round_aid(gated.as_ref(), self.vector.as_ref(), bridge);
        let manager = &mut self.manager;
        let found = add_timed(&mut self.stages.rounds_s, || manager.work(view, due, aid));
        self.processed_to = Some(limit);
        found
    }

    /// [`Receiver::deliver`], its wall time added to the navigation stage.
    fn timed_deliver(
        &mut self,
        found: Option<crate::pipeline::channels::channel_manager::SearchOutcome>,
        end: u64,
        sink: &mut dyn Sink,
    ) -> Result<(), ReceiverError> {
        let t0 = std::time::Instant::now();
        let r = self.deliver(found, end, sink);
        self.stages.navigation_s += t0.elapsed().as_secs_f64();
        r
    }

    /// After a round: the reports to the navigation processor, new channels for what a search
    /// found, and the samples no one needs any more dropped (`end`: the end of the samples
    /// read so far, or of the block processed).
    fn deliver(
        &mut self,
        found: Option<crate::pipeline::channels::channel_manager::SearchOutcome>,
        end: u64,
        sink: &mut dyn Sink,
    ) -> Result<(), ReceiverError> {
        self.reports_out().pass(sink)?;
        self.end_round(found, end, sink)
    }

    /// [`Receiver::deliver`] while the next block is read: the reports go to the navigation
    /// processor on this thread while the pool reads (they need no sample), then the rest of
    /// the round's end with the end of the samples read. Returns the samples read (0 at the
    /// end of the source).
    fn deliver_while_reading(
        &mut self,
        found: Option<crate::pipeline::channels::channel_manager::SearchOutcome>,
        source: &mut dyn SampleSource,
        sink: &mut dyn Sink,
    ) -> Result<usize, ReceiverError> {
        let t0 = std::time::Instant::now();
        let reports = ReportsOut {
            nav: &mut self.nav,
            reports: self.manager.reports_mut(),
            aiding: self.aiding.as_deref(),
            monitor: &mut self.monitor,
            vector: self.vector.as_mut(),
            span: done_span(self.first_sample, self.processed_to, self.fs_hz),
        };
        let (got, passed) = self
            .window
            .read_during(source, self.block, || reports.pass(sink))?;
        passed?;
        let end = self.window.end();
        self.end_round(found, end, sink)?;
        self.stages.navigation_s += t0.elapsed().as_secs_f64();
        Ok(got)
    }

    /// The parts of the receiver that take the channels' reports.
    fn reports_out(&mut self) -> ReportsOut<'_> {
        ReportsOut {
            nav: &mut self.nav,
            reports: self.manager.reports_mut(),
            aiding: self.aiding.as_deref(),
            monitor: &mut self.monitor,
            vector: self.vector.as_mut(),
            span: done_span(self.first_sample, self.processed_to, self.fs_hz),
        }
    }

    /// The end of a round after its reports ([`ReportsOut::pass`]): the navigation
    /// processor's end of block at `end` and what it asks of the channels, new channels for
    /// what a search found, and the samples no one needs any more dropped.
    fn end_round(
        &mut self,
        found: Option<crate::pipeline::channels::channel_manager::SearchOutcome>,
        end: u64,
        sink: &mut dyn Sink,
    ) -> Result<(), ReceiverError> {
        let event = self.nav.end_block(end, sink).map_err(ReceiverError::Sink)?;
        self.after_end_block(event, found, end, sink)
    }

    /// [`Receiver::end_round`] after the navigation processor's end of block, which gave
    /// `event`.
    fn after_end_block(
        &mut self,
        event: Option<BlockEvent>,
        found: Option<crate::pipeline::channels::channel_manager::SearchOutcome>,
        end: u64,
        sink: &mut dyn Sink,
    ) -> Result<(), ReceiverError> {
        match event {
            Some(BlockEvent::PhaseJump(_)) => {
                self.manager.restart_bit_sync();
                if let Some(v) = self.vector.as_mut() {
                    v.doubt_time(end as f64 / self.fs_hz);
                }
            }
            Some(BlockEvent::Collapse(c)) => {
                self.manager.request_realignment(&c);
                self.arm_bridge(c.sample as f64 / self.fs_hz);
                if let Some(v) = self.vector.as_mut() {
                    v.collapse(c.sample as f64 / self.fs_hz);
                    v.doubt_time(c.sample as f64 / self.fs_hz);
                }
            }
            None => {}
        }
        if let Some(v) = self.vector.as_mut() {
            for (channel, prn, edge) in v.take_bit_edges() {
                self.manager.assume_bit_edge(channel, prn, edge);
            }
            for (t_s, engaged) in v.take_switches() {
                sink.event(&ReceiverEvent::VectorTracking { t_s, engaged })
                    .map_err(ReceiverError::Sink)?;
            }
        }
        self.follow_bridge(end as f64 / self.fs_hz);
        match found {
            Some(outcome) if outcome.is_realignment() => {
                // The channels report the code shifts; timing decides what they show.
                let planned = self.manager.realignment_found(outcome).and_then(|s| {
                    let plan = plan_realignment(s.shifts(), self.fs_hz)?;
                    Some((s, plan))
                });
                let realigned = planned.and_then(|(s, plan)| self.manager.realign(s, &plan));
                if let Some(r) = realigned {
                    // The bit edges of every channel moved with the code.
                    self.manager.restart_bit_sync();
                    if let Some(v) = self.vector.as_mut() {
                        v.doubt_time(end as f64 / self.fs_hz);
                    }
                    self.nav
                        .on_code_realigned(&r, sink)
                        .map_err(ReceiverError::Sink)?;
                }
            }
            Some(outcome) => {
                let first = outcome.first();
                let (nav, t_s) = (&self.nav, end as f64 / self.fs_hz);
                let started = self
                    .manager
                    .start_found(outcome, &|p| nav.visibility(p.get(), t_s));
                self.announce(&started, first, sink)?;
            }
            None => {}
        }
        if let Some(v) = self.vector.as_mut() {
            let manager = &self.manager;
            let tracked = |prn: u8| Prn::new(prn).is_ok_and(|p| manager.tracks(p));
            let starts = v.take_in(end, self.fs_hz, &tracked);
            self.manager.start_predicted(&starts);
        }
        let keep_from = self.manager.oldest_needed(end);
        self.window.discard_before(keep_from);
        Ok(())
    }

    /// Without an INS: arms the bridge over the outage whose collapse was at stream time
    /// `collapse_s`, unless one is under way ([`NavigationProcessor::outage_bridge`]).
    fn arm_bridge(&mut self, collapse_s: f64) {
        if self.outage_bridge && self.aiding.is_none() && self.bridge.is_none() {
            let lost_s = self.nav.lost_total_s();
            self.bridge = self.nav.outage_bridge(collapse_s).map(|b| (b, lost_s));
        }
    }

    /// The bridge under way after the round ending at stream time `t_s`: the signal lost
    /// since it was armed (measured gaps), its end at the first valid fix more than
    /// [`BRIDGE_RETURN_S`] after the collapse, and gone once over.
    fn follow_bridge(&mut self, t_s: f64) {
        let Some((bridge, lost_before_s)) = self.bridge.as_mut() else {
            return;
        };
        bridge.set_lost_s(self.nav.lost_total_s() - *lost_before_s);
        if let Some(t_fix) = self.nav.last_valid_fix_s() {
            if t_fix > bridge.from_s() + BRIDGE_RETURN_S {
                bridge.end_at(t_fix);
            }
        }
        if bridge.over_at(t_s) {
            tracing::info!(
                "{t_s:.3} s: the outage bridge from {:.3} s ends (a valid fix after the return, or its longest)",
                bridge.from_s()
            );
            self.bridge = None;
        }
    }

    /// Tells the sink about the channels just started.
    fn announce(
        &self,
        found: &[AcqResult],
        first: u64,
        sink: &mut dyn Sink,
    ) -> Result<(), ReceiverError> {
        for d in found {
            sink.event(&ReceiverEvent::Acquired {
                prn: d.prn.get(),
                t_s: first as f64 / self.fs_hz,
                doppler_hz: d.doppler_hz,
                cn0_dbhz: d.cn0_dbhz.unwrap_or(f64::NAN),
            })
            .map_err(ReceiverError::Sink)?;
        }
        Ok(())
    }
}

/// Stream times (s) of the first sample and of the end of the samples processed, when
/// both are known.
fn done_span(
    first_sample: Option<u64>,
    processed_to: Option<u64>,
    fs_hz: f64,
) -> Option<(f64, f64)> {
    processed_to.map(|done| {
        (
            first_sample.unwrap_or(0) as f64 / fs_hz,
            done as f64 / fs_hz,
        )
    })
}

/// What takes the reports of a round: the navigation processor, the INS integrity monitor
/// (with an INS) and the channel manager that holds them.
struct ReportsOut<'a> {
    nav: &'a mut NavigationProcessor,
    /// The round's reports, per channel (cleared once passed).
    reports: &'a mut [Vec<ChannelEpoch>],
    aiding: Option<&'a InsFeedForward>,
    monitor: &'a mut AidMonitor,
    /// Vector tracking, which takes the round's observables and fixes.
    vector: Option<&'a mut VectorTracking>,
    /// [`done_span`] of the round.
    span: Option<(f64, f64)>,
}

impl ReportsOut<'_> {
    /// The reports of the last round to the navigation processor in stream order (and to the
    /// integrity monitor, which then evaluates the round, with an INS).
    fn pass(self, sink: &mut dyn Sink) -> Result<(), ReceiverError> {
        let Self {
            nav,
            reports,
            aiding,
            monitor,
            vector,
            span,
        } = self;
        let predict = |prn: u8, t: f64| aiding.and_then(|ff| ff.predicted_doppler_hz(prn, t));
        let mut captured: Vec<Captured> = Vec::new();
        let tapping = vector.is_some();
        // While the navigation filter drives the channels (vector tracking with an INS) their
        // feed-forward is the filter's, not the INS's: nothing for the INS's monitor to judge
        // (it read the filter's clock drift as 63 Hz of INS error and rejected the INS).
        let judged =
            aiding.is_some() && vector.as_ref().is_none_or(|v| v.port().snapshot.is_none());
        let mut vector = vector;
        drain_in_stream_order(reports, |i, e| {
            if judged {
                monitor.observe(i, e, &predict);
            }
            let predicted_sv_tow_s = vector.as_deref_mut().and_then(|v| {
                v.vouch(i, e, !nav.sv_time_ever_known(e.prn));
                v.predicted_sv_tow_s(e)
            });
            if tapping {
                let mut tap = Tap {
                    inner: &mut *sink,
                    captured: &mut captured,
                };
                nav.on_report(i, e, aiding, predicted_sv_tow_s, &mut tap)
            } else {
                nav.on_report(i, e, aiding, predicted_sv_tow_s, sink)
            }
        })
        .map_err(ReceiverError::Sink)?;
        if let Some(v) = vector {
            v.take(captured, nav);
        }
        if let (Some(ff), Some((t_first, t_done)), true) = (aiding, span, judged) {
            monitor.evaluate(t_first, t_done, ff.expected_common_residual_hz(), &predict);
        }
        Ok(())
    }
}

/// The aiding port for the next round: the INS feed-forward for the satellites the integrity
/// monitor admits (None without an INS).
fn gated_aid<'a>(
    aiding: Option<&'a InsFeedForward>,
    monitor: &AidMonitor,
) -> Option<GatedAid<'a, InsFeedForward>> {
    aiding.map(|port| GatedAid {
        port,
        permission: monitor.permission(),
    })
}

/// The aiding port of the next round: the navigation filter's with `--tracking vector` while
/// it drives the channels (with `--ins` the INS's motion is in its prediction), else the gated
/// INS feed-forward with `--ins`, else the bridge over an outage under way, else none.
fn round_aid<'a>(
    gated: Option<&'a GatedAid<'a, InsFeedForward>>,
    vector: Option<&'a VectorTracking>,
    bridge: Option<&'a OutageBridge>,
) -> Option<&'a dyn AidingPort> {
    let vector = vector.filter(|v| v.port().snapshot.is_some());
    match (gated, vector, bridge) {
        (_, Some(v), _) => Some(v.port() as &dyn AidingPort),
        (Some(g), None, _) => Some(g as &dyn AidingPort),
        (None, None, Some(b)) => Some(b as &dyn AidingPort),
        (None, None, None) => None,
    }
}

/// A valid fix this long after the collapse ends the outage bridge, s (the fixes of the
/// reports from before the collapse still come in for a round or two).
const BRIDGE_RETURN_S: f64 = 0.2;

/// Logs what an INS accelerometer bias of 1 mg per axis (up to sqrt 3 mg on a line of sight)
/// does to the aided carrier loops: the static phase offset of a 2nd-order loop (seed 004
/// Table 1; the lock test allows 0.2 cycle, a Costas loop slips at 0.25), none for 3rd order.
fn log_aided_static_offset(tracking: &gpsrx_tracking::ChannelConfig) {
    let loops = tracking.aided_track.unwrap_or(tracking.track);
    let bias_mps2 = gpsrx_tracking::aiding::NOMINAL_INS_BIAS_LOS_MPS2;
    match gpsrx_tracking::aiding::static_phase_offset_cycles(loops.pll_order, loops.pll_bw_hz, bias_mps2) {
        Some(c) if c > 0.0 => tracing::info!(
            "aided loops: 2nd-order PLL at {} Hz: an INS accelerometer bias of 1 mg per axis leaves up to {c:.3} cycle of static phase offset (B / (lambda w0^2); lock allows 0.2, slips at 0.25) until the INS velocity calibration from the fixes takes the drift out (about 15 s of fixes outside manoeuvres); a 3rd-order aided loop leaves none",
            loops.pll_bw_hz
        ),
        Some(_) => tracing::info!(
            "aided loops: {}-order PLL at {} Hz: no static phase offset from an INS accelerometer bias",
            if loops.pll_order == 3 { "3rd" } else { "other" },
            loops.pll_bw_hz
        ),
        None => tracing::warn!(
            "aided loops: a 1st-order PLL at {} Hz drifts with an INS accelerometer bias (its phase error grows without bound): an aided PLL of order 2 or 3 does not",
            loops.pll_bw_hz
        ),
    }
}
