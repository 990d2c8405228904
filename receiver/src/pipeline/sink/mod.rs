//! What the receiver emits, and where it goes: the [`Sink`] trait.
//!
//! A [`crate::pipeline::Receiver`] hands every product to its sink as soon as it exists: channel
//! reports (every integration interval), channel rows (at the fix rate), observable epochs,
//! fixes, decoded ephemerides and events such as "satellite acquired" or "satellite lost".
//! Every method but [`Sink::fix`] has a default that ignores the product, so a sink only
//! implements what it wants. [`crate::output::FileSink`] writes the standard files;
//! [`MemorySink`] keeps everything in memory (tests, bindings, notebooks).

mod products;

pub use products::{ChannelRow, Fix, FixQuality, ObsEpoch, SatObs, SatView};

use gpsrx_nav::atmosphere::{KlobucharParams, UtcParams};
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::pvt::PvtSolution;
use gpsrx_tracking::ChannelEpoch;

/// An error a sink reports (an output file that cannot be written, a closed pipe); the
/// receiver stops and returns it.
pub type SinkError = Box<dyn std::error::Error + Send + Sync>;

/// A position fix and the solution it came from.
#[derive(Debug, Clone)]
pub struct FixReport {
    /// The fix as the outputs write it.
    pub fix: Fix,
    /// The full solution: covariance, residuals, RAIM.
    pub solution: PvtSolution,
    /// Seconds from the first sample of the stream to the epoch of the fix (receive time).
    pub t_stream_s: f64,
}

/// One epoch of observables.
#[derive(Debug, Clone)]
pub struct ObservablesReport {
    /// The observables, as RINEX writes them.
    pub epoch: ObsEpoch,
    /// The position of the fix at this epoch, if there is one (RINEX's approximate position).
    pub fix_position_m: Option<[f64; 3]>,
    /// Whether the GPS week has been decoded (else `epoch.time.week` is the reference week,
    /// which may be 1024 weeks off).
    pub week_decoded: bool,
    /// Whether `epoch.time.week` is known: decoded, or a reference week that does not come
    /// from the system clock ([`crate::pipeline::WeekReference`]).
    pub week_known: bool,
}

/// Something that happened, for logs and user interfaces.
#[derive(Debug, Clone, PartialEq)]
pub enum ReceiverEvent {
    /// A channel was started for a satellite found by a search.
    Acquired {
        /// The satellite.
        prn: u8,
        /// Stream time of the search's first sample, s.
        t_s: f64,
        /// Doppler found, Hz.
        doppler_hz: f64,
        /// C/N0 estimated by the search, dB-Hz (NaN when unknown).
        cn0_dbhz: f64,
    },
    /// A channel lost its satellite.
    Lost {
        /// The satellite.
        prn: u8,
        /// Stream time, s.
        t_s: f64,
    },
    /// Subframe synchronisation: the satellite's time of week is known.
    FrameSync {
        /// The satellite.
        prn: u8,
        /// Time of week of the next subframe, s.
        tow_s: f64,
    },
    /// A new ephemeris was decoded.
    EphemerisDecoded {
        /// The satellite.
        prn: u8,
        /// Issue of data.
        iode: u32,
    },
    /// The receiver clock was stepped by whole milliseconds to stay within 0.5 ms of GPS time.
    ClockStep {
        /// The step, ms.
        ms: i64,
    },
    /// Samples were lost at this point of the stream (a carrier-phase jump common to the
    /// satellites): the receiver time is re-established from the satellites, and no fix is
    /// made until it is.
    SampleGap {
        /// Stream time of the gap (as counted by the samples received), s.
        t_s: f64,
    },
    /// The receiver time was re-established after a [`ReceiverEvent::SampleGap`]: the length of
    /// the gap, from the jump of the receiver clock bias between the fixes before and after.
    GapMeasured {
        /// Stream time of the gap, s.
        t_s: f64,
        /// Samples lost, as time, ms.
        length_ms: f64,
    },
    /// The satellites' SV times came from their code phases, the approximate time and
    /// position (`crate::pipeline::timing::coarse_fix`), before any time of week was decoded.
    CoarseTime {
        /// Stream time of the solution, s.
        t_s: f64,
        /// Satellites given a time.
        satellites: usize,
        /// Correction to the approximate time, s.
        time_correction_s: f64,
    },
    /// Vector tracking took the channels (`engaged`: the navigation filter's prediction drives
    /// their carrier NCOs from here on) or gave them back to their own loops.
    VectorTracking {
        /// Stream time, s.
        t_s: f64,
        /// Taken (true) or given back (false).
        engaged: bool,
    },
    /// The SV times of the coarse-time fix were dropped (a bit edge or a HOW disagreed, or the
    /// fixes failed the integrity test): the time comes from frame sync.
    CoarseTimeDropped {
        /// Stream time, s.
        t_s: f64,
    },
}

/// Where the processing stands, about five times per second of signal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Samples processed (index of the latest sample a channel reached).
    pub sample_index: u64,
    /// Satellites with a decoder (tracked at some point).
    pub satellites: usize,
    /// Satellites in subframe synchronisation.
    pub frame_synced: usize,
    /// Satellites with an ephemeris.
    pub with_ephemeris: usize,
    /// Fixes so far.
    pub fixes: usize,
}

/// What the navigation processor knows at the end of a stream.
#[derive(Debug, Clone, Default)]
pub struct NavigationEnd {
    /// The decoded ephemerides, one per satellite (the latest).
    pub ephemerides: Vec<Ephemeris>,
    /// When each of `ephemerides` was sent (its subframe 1's HOW time, s of the week of its
    /// toe), by PRN: RINEX's "transmission time of message".
    pub transmission_tow_s: std::collections::BTreeMap<u8, f64>,
    /// Broadcast ionosphere (subframe 4 page 18), if decoded.
    pub iono: Option<KlobucharParams>,
    /// Broadcast UTC parameters, if decoded.
    pub utc: Option<UtcParams>,
    /// The almanac decoded from subframes 4 and 5 (complete pages dated by a page 25), if any.
    pub almanac: Option<gpsrx_nav::almanac::AlmanacSet>,
}

/// The receiver's outputs go to a sink.
pub trait Sink {
    /// A position fix.
    fn fix(&mut self, report: &FixReport) -> Result<(), SinkError>;

    /// An epoch of observables (emitted before the fix of the same epoch).
    fn observables(&mut self, _report: &ObservablesReport) -> Result<(), SinkError> {
        Ok(())
    }

    /// A channel's state, at most once per fix interval per channel.
    fn channel(&mut self, _row: &ChannelRow) -> Result<(), SinkError> {
        Ok(())
    }

    /// A channel's report of one integration interval (every 1-20 ms per channel: for loop
    /// studies; most sinks ignore it).
    fn channel_epoch(&mut self, _channel: usize, _epoch: &ChannelEpoch) -> Result<(), SinkError> {
        Ok(())
    }

    /// Something happened.
    fn event(&mut self, _event: &ReceiverEvent) -> Result<(), SinkError> {
        Ok(())
    }

    /// Where the processing stands.
    fn progress(&mut self, _progress: &Progress) -> Result<(), SinkError> {
        Ok(())
    }

    /// The stream ended; what was decoded. Files are completed and closed here.
    fn finish(&mut self, _end: &NavigationEnd) -> Result<(), SinkError> {
        Ok(())
    }
}

/// Keeps everything the receiver emits, except the per-interval channel reports (unless
/// [`MemorySink::with_channel_epochs`]).
#[derive(Debug, Default)]
pub struct MemorySink {
    /// The fixes, in time order.
    pub fixes: Vec<FixReport>,
    /// The observable epochs.
    pub observables: Vec<ObservablesReport>,
    /// Channel rows.
    pub channels: Vec<ChannelRow>,
    /// Per-interval channel reports `(channel index, report)`, when asked for.
    pub channel_epochs: Vec<(usize, ChannelEpoch)>,
    /// Events.
    pub events: Vec<ReceiverEvent>,
    /// What was decoded, once the stream ended.
    pub end: Option<NavigationEnd>,
    keep_channel_epochs: bool,
}

impl MemorySink {
    /// An empty sink.
    pub fn new() -> Self {
        Self::default()
    }

    /// Also keeps every channel report (a lot of memory for long streams).
    pub fn with_channel_epochs(mut self) -> Self {
        self.keep_channel_epochs = true;
        self
    }
}

impl Sink for MemorySink {
    fn fix(&mut self, report: &FixReport) -> Result<(), SinkError> {
        self.fixes.push(report.clone());
        Ok(())
    }

    fn observables(&mut self, report: &ObservablesReport) -> Result<(), SinkError> {
        self.observables.push(report.clone());
        Ok(())
    }

    fn channel(&mut self, row: &ChannelRow) -> Result<(), SinkError> {
        self.channels.push(row.clone());
        Ok(())
    }

    fn channel_epoch(&mut self, channel: usize, epoch: &ChannelEpoch) -> Result<(), SinkError> {
        if self.keep_channel_epochs {
            self.channel_epochs.push((channel, *epoch));
        }
        Ok(())
    }

    fn event(&mut self, event: &ReceiverEvent) -> Result<(), SinkError> {
        self.events.push(event.clone());
        Ok(())
    }

    fn finish(&mut self, end: &NavigationEnd) -> Result<(), SinkError> {
        self.end = Some(end.clone());
        Ok(())
    }
}

/// Sends everything to two sinks in turn (e.g. files and a progress display).
#[derive(Debug)]
pub struct Tee<A, B>(pub A, pub B);

impl<A: Sink, B: Sink> Sink for Tee<A, B> {
    fn fix(&mut self, report: &FixReport) -> Result<(), SinkError> {
        self.0.fix(report)?;
        self.1.fix(report)
    }
    fn observables(&mut self, report: &ObservablesReport) -> Result<(), SinkError> {
        self.0.observables(report)?;
        self.1.observables(report)
    }
    fn channel(&mut self, row: &ChannelRow) -> Result<(), SinkError> {
        self.0.channel(row)?;
        self.1.channel(row)
    }
    fn channel_epoch(&mut self, channel: usize, epoch: &ChannelEpoch) -> Result<(), SinkError> {
        self.0.channel_epoch(channel, epoch)?;
        self.1.channel_epoch(channel, epoch)
    }
    fn event(&mut self, event: &ReceiverEvent) -> Result<(), SinkError> {
        self.0.event(event)?;
        self.1.event(event)
    }
    fn progress(&mut self, progress: &Progress) -> Result<(), SinkError> {
        self.0.progress(progress)?;
        self.1.progress(progress)
    }
    fn finish(&mut self, end: &NavigationEnd) -> Result<(), SinkError> {
        self.0.finish(end)?;
        self.1.finish(end)
    }
}
