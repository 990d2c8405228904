//! Tracking channels driven over a stream, without acquisition or navigation: for loop
//! studies and tests that start their own channels.
//!
//! Samples are read in blocks into a [`SampleWindow`]; every channel then processes all the
//! code periods the window holds (channels in parallel, see
//! [`crate::pipeline::channels::channel_manager::ChannelManager::work`]) while the next block is read
//! behind them; samples no channel needs any more are dropped, so memory stays bounded for any
//! file length. The whole receiver is [`crate::pipeline::Receiver`].

use crate::pipeline::channels::channel_manager::ChannelManager;
use crate::pipeline::channels::ring::{block_samples, SampleWindow};
use gpsrx_samples::{SampleError, SampleSource};
use gpsrx_tracking::{AidingPort, Channel, ChannelEpoch};

/// An external Doppler source for the aiding port.
pub type AidSource<'a> = &'a dyn AidingPort;

/// Runs `channels` over `src` until the source ends or every channel is lost. `on_epoch` gets
/// `(channel index, report)` for every integration interval, in time order per channel
/// (channels interleaved block by block). With `aid`, each channel's carrier and code NCOs get
/// the fed-forward Doppler of its satellite at the start of every code period.
/// Returns the channels in their final state.
pub fn track(
    src: &mut dyn SampleSource,
    channels: Vec<Channel>,
    aid: Option<AidSource<'_>>,
    mut on_epoch: impl FnMut(usize, &ChannelEpoch),
) -> Result<Vec<Channel>, SampleError> {
    let fs = src.fs_hz();
    let block = block_samples(fs);
    let mut manager = ChannelManager::with_channels(fs, channels);
    let mut window = SampleWindow::new();
    loop {
        let (got, _) = window.fill_during(src, block, |view| manager.work(view, None, aid))?;
        manager
            .drain_reports(|i, e| {
                on_epoch(i, e);
                Ok::<(), std::convert::Infallible>(())
            })
            .unwrap_or(());
        window.discard_before(manager.oldest_needed(window.end()));
        if got == 0 || manager.finished() {
            break;
        }
    }
    Ok(manager.into_channels())
}
