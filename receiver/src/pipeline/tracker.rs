//! Drives tracking channels over a stream of samples.
//!
//! Samples are read in blocks into a [`SampleWindow`]; every channel then processes all the code
//! periods the window holds (channels in parallel with rayon, each on its own state, the
//! window shared read-only); samples no channel needs any more are dropped, so memory stays
//! bounded for any file length.

use crate::pipeline::ring::SampleWindow;
use gpsrx_samples::{SampleError, SampleSource};
use gpsrx_tracking::{Channel, ChannelEpoch, ChannelState, DopplerAid};
use rayon::prelude::*;

/// Samples read per block, as a fraction of a second (10 ms).
const BLOCK_S: f64 = 0.01;

/// An external Doppler source for the aiding port: `(prn, receive time s) -> aid`.
pub type AidSource<'a> = &'a (dyn Fn(u8, f64) -> Option<DopplerAid> + Sync);

/// Runs `channels` over `src` until the source ends or every channel is lost. `on_epoch` gets
/// `(channel index, report)` for every integration interval, in time order per channel
/// (channels interleaved block by block). With `aid`, each channel's carrier and code NCOs get
/// the fed-forward Doppler of its satellite at the start of every code period.
/// Returns the channels in their final state.
pub fn track(
    src: &mut dyn SampleSource,
    mut channels: Vec<Channel>,
    aid: Option<AidSource<'_>>,
    mut on_epoch: impl FnMut(usize, &ChannelEpoch),
) -> Result<Vec<Channel>, SampleError> {
    let fs = src.fs_hz();
    let block = ((fs * BLOCK_S).ceil() as usize).max(1);
    let mut window = SampleWindow::new();
    loop {
        let got = window.fill(src, block)?;
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
        window.discard_before(oldest_needed);
        if got == 0 || channels.iter().all(|c| c.state() == ChannelState::Lost) {
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
