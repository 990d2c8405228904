//! Drives tracking channels over a stream of samples.
//!
//! Samples are read in blocks into a [`SampleWindow`]; every channel then processes all the code
//! periods the window holds (channels in parallel with rayon, each on its own state, the
//! window shared read-only); samples no channel needs any more are dropped, so memory stays
//! bounded for any file length.

use crate::pipeline::ring::SampleWindow;
use gpsrx_dsp::acquisition::{AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_samples::{SampleError, SampleSource};
use gpsrx_tracking::{
    Channel, ChannelConfig, ChannelEpoch, ChannelStart, ChannelState, DopplerAid,
};
use rayon::prelude::*;

/// Samples read per block, as a fraction of a second (10 ms).
const BLOCK_S: f64 = 0.01;

/// An external Doppler source for the aiding port: `(prn, receive time s) -> aid`.
pub type AidSource<'a> = &'a (dyn Fn(u8, f64) -> Option<DopplerAid> + Sync);

/// Periodic acquisition of the satellites that are not being tracked (never found, or lost):
/// every `interval_s` of recording the engine searches the latest samples, and each detection
/// starts a new channel with `channel_config`.
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
    let mut next_search: Option<u64> = reacq.map(|r| (r.interval_s * fs) as u64);
    loop {
        let got = window.fill(src, block)?;
        if let (Some(r), Some(at)) = (reacq, next_search) {
            if window.end() >= at && window.end() - window.start() >= keep as u64 {
                search_again(r, &window, keep, &mut channels);
                next_search = Some(window.end() + (r.interval_s * fs) as u64);
            }
        }
        let reports: Vec<Vec<ChannelEpoch>> = channels
            .par_iter_mut()
            .map(|ch| run_channel(ch, &window, aid))
            .collect();
        for (i, r) in reports.iter().enumerate() {
            for e in r {
                on_epoch(i, e);
            }
        }
        let live = channels.iter().filter(|c| c.state() != ChannelState::Lost);
        let oldest_needed = live.map(|c| c.next_span().0).min().unwrap_or(window.end());
        // Keep enough recent samples for a search.
        window.discard_before(oldest_needed.min(window.end().saturating_sub(keep as u64)));
        if got == 0 || (reacq.is_none() && channels.iter().all(|c| c.state() == ChannelState::Lost))
        {
            break;
        }
    }
    Ok(channels)
}

/// Processes every code period of `ch` that `window` holds.
fn run_channel(
    ch: &mut Channel,
    window: &SampleWindow,
    aid: Option<AidSource<'_>>,
) -> Vec<ChannelEpoch> {
    let mut out = Vec::new();
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
    out
}

/// Searches the latest samples for the satellites without a live channel and starts channels
/// for those found.
fn search_again(
    r: &Reacquisition<'_>,
    window: &SampleWindow,
    keep: usize,
    channels: &mut Vec<Channel>,
) {
    let live: Vec<Prn> = channels
        .iter()
        .filter(|c| c.state() != ChannelState::Lost)
        .map(|c| c.prn())
        .collect();
    let wanted: Vec<Prn> = if r.prns.is_empty() {
        Prn::all().collect()
    } else {
        r.prns.clone()
    };
    let targets: Vec<SearchTarget> = wanted
        .into_iter()
        .filter(|p| !live.contains(p))
        .map(SearchTarget::full)
        .collect();
    if targets.is_empty() {
        return;
    }
    let first = window.end() - keep as u64;
    let Some(samples) = window.get(first, keep) else {
        return;
    };
    let Ok(results) = r.engine.search(samples, &targets) else {
        return;
    };
    for d in results.iter().filter(|d| d.detected) {
        let start = ChannelStart {
            prn: d.prn,
            code_start_sample: first + d.code_phase_samples.round().max(0.0) as u64,
            doppler_hz: d.doppler_hz,
            cn0_dbhz: d.cn0_dbhz.unwrap_or(f64::NAN),
        };
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
