//! Drives tracking channels over a stream of samples.
//!
//! Samples are read in blocks into a [`SampleWindow`]; every channel then processes all the code
//! periods the window holds (channels in parallel with rayon, each on its own state, the
//! window shared read-only) while the next block is read behind them; samples no channel needs
//! any more are dropped, so memory stays bounded for any file length. Re-acquisition searches
//! run concurrently with the channels too, so a search never stalls tracking.

use crate::pipeline::ring::{SampleView, SampleWindow};
use gpsrx_dsp::acquisition::{AcqResult, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_samples::{SampleError, SampleSource};
use gpsrx_tracking::{
    Channel, ChannelConfig, ChannelEpoch, ChannelStart, ChannelState, DopplerAid,
};
use rayon::prelude::*;

/// Samples read per block, as a fraction of a second (10 ms). 40 ms blocks (a quarter of the
/// rayon rounds) measured no faster on 2 cores, with more memory.
const BLOCK_S: f64 = 0.01;

/// Longest wait between two searches of a PRN that was never found, in search intervals:
/// a PRN searched and not found waits 1, 2, 4, then 8 intervals before the next search.
const MAX_BACKOFF_INTERVALS: u32 = 8;

/// An external Doppler source for the aiding port: `(prn, receive time s) -> aid`.
pub type AidSource<'a> = &'a (dyn Fn(u8, f64) -> Option<DopplerAid> + Sync);

/// Periodic acquisition of the satellites that are not being tracked (never found, or lost):
/// every `interval_s` of recording the engine searches the latest samples, and each detection
/// starts a new channel with `channel_config`.
///
/// A PRN that has been tracked (and lost) is searched at every interval, as blocked signals
/// come back; a PRN that has never been found is searched less and less often (1, 2, 4, then
/// every 8 intervals), since most of the 32 are below the horizon.
#[derive(Debug)]
pub struct Reacquisition<'a> {
    /// The search engine (plans made once).
    pub engine: &'a AcquisitionEngine,
    /// Seconds of recording between searches.
    pub interval_s: f64,
    /// Configuration of the channels it starts.
    pub channel_config: ChannelConfig,
    /// PRNs to look for (empty: all 32).
    pub prns: Vec<Prn>,
}

/// Runs `channels` over `src` until the source ends or every channel is lost. `on_epoch` gets
/// `(channel index, report)` for every integration interval, in time order per channel
/// (channels interleaved block by block). With `aid`, each channel's carrier and code NCOs get
/// the fed-forward Doppler of its satellite at the start of every code period.
/// Returns the channels in their final state.
pub fn track(
    src: &mut dyn SampleSource,
    channels: Vec<Channel>,
    aid: Option<AidSource<'_>>,
    on_epoch: impl FnMut(usize, &ChannelEpoch),
) -> Result<Vec<Channel>, SampleError> {
    track_with_reacquisition(src, channels, aid, None, on_epoch)
}

/// [`track`], plus periodic re-acquisition: a satellite whose channel was lost (or that was
/// never found) is searched for again, and tracked again when it returns. New channels get
/// the next indices after the existing ones.
///
/// The search runs concurrently with the channels' processing of the same block (rayon
/// `join`), on the latest samples of the window; the channels it starts process from the next
/// block on. Nothing is allocated per block in the steady state: the per-channel report
/// buffers are kept and reused.
pub fn track_with_reacquisition(
    src: &mut dyn SampleSource,
    mut channels: Vec<Channel>,
    aid: Option<AidSource<'_>>,
    reacq: Option<&Reacquisition<'_>>,
    mut on_epoch: impl FnMut(usize, &ChannelEpoch),
) -> Result<Vec<Channel>, SampleError> {
    let fs = src.fs_hz();
    let block = ((fs * BLOCK_S).ceil() as usize).max(1);
    let keep = reacq.map(|r| r.engine.samples_wanted()).unwrap_or(0);
    let mut window = SampleWindow::new();
    let mut schedule = reacq.map(|r| SearchSchedule::new(r, &channels, fs));
    let mut reports: Vec<Vec<ChannelEpoch>> = Vec::new();
    loop {
        reports.resize_with(channels.len(), Vec::new);
        let search = match (reacq, schedule.as_mut()) {
            (Some(r), Some(s)) => s.due(r, window.view(), keep, &channels),
            _ => None,
        };
        // The channels (and the search, if one is due) work on the samples held while the
        // next block is read behind them.
        let (got, found) = window.fill_during(src, block, |view| {
            let run_all = |channels: &mut Vec<Channel>, reports: &mut Vec<Vec<ChannelEpoch>>| {
                channels
                    .par_iter_mut()
                    .zip(reports.par_iter_mut())
                    .for_each(|(ch, out)| run_channel(ch, view, aid, out));
            };
            match (reacq, search) {
                (Some(r), Some((first, targets))) => {
                    let samples = view.get(first, keep).unwrap_or(&[]);
                    let (results, ()) = rayon::join(
                        || r.engine.search(samples, &targets),
                        || run_all(&mut channels, &mut reports),
                    );
                    results.ok().map(|res| (first, targets, res))
                }
                _ => {
                    run_all(&mut channels, &mut reports);
                    None
                }
            }
        })?;
        for (i, r) in reports.iter_mut().enumerate() {
            for e in r.iter() {
                on_epoch(i, e);
            }
            r.clear();
        }
        if let (Some(r), Some(s), Some((first, targets, results))) =
            (reacq, schedule.as_mut(), found)
        {
            s.record(&targets, &results, first + keep as u64);
            start_channels(r, first, &results, &mut channels);
        }
        let live = channels.iter().filter(|c| c.state() != ChannelState::Lost);
        let oldest_needed = live.map(|c| c.next_span().0).min().unwrap_or(window.end());
        // Keep the samples the next search will read: the `keep` before its tick.
        let search_from = schedule
            .as_ref()
            .map_or(u64::MAX, |s| s.next_tick.saturating_sub(keep as u64));
        window.discard_before(oldest_needed.min(search_from));
        if got == 0 || (reacq.is_none() && channels.iter().all(|c| c.state() == ChannelState::Lost))
        {
            break;
        }
    }
    Ok(channels)
}

/// When each PRN is searched next (see [`Reacquisition`]).
#[derive(Debug)]
struct SearchSchedule {
    /// Sample index of the next search tick.
    next_tick: u64,
    /// Samples between ticks.
    interval: u64,
    /// Per PRN (index 0 = PRN 1): sample index before which it is not searched again.
    not_before: [u64; 32],
    /// Per PRN: the current wait after a fruitless search, in intervals.
    backoff: [u32; 32],
    /// Per PRN: whether it has ever had a channel (then it is searched at every tick).
    tracked: [bool; 32],
}

impl SearchSchedule {
    fn new(r: &Reacquisition<'_>, channels: &[Channel], fs: f64) -> Self {
        let interval = ((r.interval_s * fs) as u64).max(1);
        let mut s = Self {
            next_tick: interval,
            interval,
            not_before: [0; 32],
            backoff: [1; 32],
            tracked: [false; 32],
        };
        for c in channels {
            s.tracked[c.prn().index()] = true;
        }
        s
    }

    /// The first sample and the targets of the search due in this block, if one is: the wanted
    /// PRNs without a live channel whose back-off has run out.
    fn due(
        &mut self,
        r: &Reacquisition<'_>,
        window: SampleView<'_>,
        keep: usize,
        channels: &[Channel],
    ) -> Option<(u64, Vec<SearchTarget>)> {
        let now = window.end();
        if now < self.next_tick || now - window.start() < keep as u64 {
            return None;
        }
        self.next_tick = now + self.interval;
        let live = |p: Prn| {
            channels
                .iter()
                .any(|c| c.prn() == p && c.state() != ChannelState::Lost)
        };
        let wanted: Box<dyn Iterator<Item = Prn>> = if r.prns.is_empty() {
            Box::new(Prn::all())
        } else {
            Box::new(r.prns.iter().copied())
        };
        let targets: Vec<SearchTarget> = wanted
            .filter(|&p| !live(p) && (self.tracked[p.index()] || now >= self.not_before[p.index()]))
            .map(SearchTarget::full)
            .collect();
        tracing::debug!(
            "re-acquisition at sample {now}: {} PRN(s) searched",
            targets.len()
        );
        (!targets.is_empty()).then(|| (now - keep as u64, targets))
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
    aid: Option<AidSource<'_>>,
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
                    ch.set_aid(aid(ch.prn().get(), t), t);
                }
                if let Some(e) = ch.process_code_period(x) {
                    out.push(e);
                }
            }
            None => break,
        }
    }
}

/// Starts channels for the detections of a search whose first sample was `first`.
fn start_channels(
    r: &Reacquisition<'_>,
    first: u64,
    results: &[AcqResult],
    channels: &mut Vec<Channel>,
) {
    for d in results.iter().filter(|d| d.detected) {
        let start = ChannelStart::from_acquisition(d, first);
        match Channel::new(&start, r.engine.fs_hz(), &r.channel_config) {
            Ok(ch) => {
                tracing::info!(
                    "{}: acquired at {:.2} s, Doppler {:.0} Hz",
                    d.prn,
                    first as f64 / r.engine.fs_hz(),
                    d.doppler_hz
                );
                channels.push(ch);
            }
            Err(e) => tracing::warn!("{}: cannot start a channel: {e}", d.prn),
        }
    }
}
