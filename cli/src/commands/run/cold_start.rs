//! The cold start of `gpsrx run`: the first acquisition, with a more sensitive second search
//! when too few satellites are found, and the channels it starts.

use super::settings::Settings;
use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine, SearchTarget};
use gpsrx_samples::{open_source, SourceConfig};
use gpsrx_tracking::{Channel, ChannelConfig, ChannelStart};
use num_complex::Complex32;

/// The weak-signal acquisition: coherent ms and non-coherent blocks.
const WEAK_ACQ_COHERENT_MS: u32 = 10;
const WEAK_ACQ_NONCOHERENT: u32 = 10;

/// Searches the first samples of the recording for every PRN. When fewer than 4 are found and
/// the search is less sensitive than 10 ms x 10, the rest are searched again with 10 ms x 10
/// (about 8 dB more sensitive than 1 ms x 10), and that engine is kept for re-acquisition.
/// Returns the engine for re-acquisition and a channel per satellite found.
pub(super) fn cold_start(
    fs: f64,
    set: &Settings,
    src_cfg: &SourceConfig,
    cfg: &ChannelConfig,
) -> anyhow::Result<(AcquisitionEngine, Vec<Channel>)> {
    let acq_cfg = AcqConfig {
        coherent_ms: set.acq_coherent_ms,
        noncoherent: set.acq_noncoherent,
        doppler_center_hz: set.doppler_center,
        doppler_max_hz: set.doppler_max,
        ..AcqConfig::default()
    };
    let engine = AcquisitionEngine::new(fs, acq_cfg.clone())?;
    let less_sensitive = set.acq_coherent_ms < WEAK_ACQ_COHERENT_MS
        || set.acq_coherent_ms * set.acq_noncoherent < WEAK_ACQ_COHERENT_MS * WEAK_ACQ_NONCOHERENT;
    let weak_engine = if less_sensitive {
        Some(AcquisitionEngine::new(
            fs,
            AcqConfig {
                coherent_ms: WEAK_ACQ_COHERENT_MS,
                noncoherent: WEAK_ACQ_NONCOHERENT,
                ..acq_cfg.clone()
            },
        )?)
    } else {
        None
    };
    let wanted = weak_engine
        .as_ref()
        .map_or(0, AcquisitionEngine::samples_wanted)
        .max(engine.samples_wanted());
    let mut first = vec![Complex32::new(0.0, 0.0); wanted];
    let (first_index, n) = {
        let mut acq_src = open_source(src_cfg)?;
        let mut filled = 0usize;
        let mut first_index = None;
        while filled < first.len() {
            let (idx, got) = acq_src.read(&mut first[filled..])?;
            if got == 0 {
                break;
            }
            first_index.get_or_insert(idx);
            filled += got;
        }
        (first_index.unwrap_or(0), filled)
    };
    if n < engine.samples_needed() {
        anyhow::bail!(
            "the recording is too short for acquisition ({n} samples; at least {} needed)",
            engine.samples_needed()
        );
    }
    let mut found = engine.search_all(&first[..n.min(engine.samples_wanted())])?;
    let detected = found.iter().filter(|d| d.detected).count();
    let engine = match weak_engine {
        Some(weak) if detected < 4 && n >= weak.samples_needed() => {
            tracing::warn!(
                "{detected} satellite(s) found with {} ms x {}: searching again with {WEAK_ACQ_COHERENT_MS} ms x {WEAK_ACQ_NONCOHERENT} for weak signals (--acq-coherent-ms chooses)",
                acq_cfg.coherent_ms,
                acq_cfg.noncoherent
            );
            let missing: Vec<SearchTarget> = found
                .iter()
                .filter(|d| !d.detected)
                .map(|d| SearchTarget::full(d.prn))
                .collect();
            let again = weak.search(&first[..n.min(weak.samples_wanted())], &missing)?;
            for r in again {
                if let Some(slot) = found.iter_mut().find(|d| d.prn == r.prn) {
                    *slot = r;
                }
            }
            weak
        }
        _ => engine,
    };
    let mut channels = Vec::new();
    for d in found.iter().filter(|d| d.detected) {
        let start = ChannelStart::from_acquisition(d, first_index);
        channels.push(Channel::new(&start, fs, cfg)?);
        tracing::info!(
            "{}: acquired, Doppler {:.0} Hz, C/N0 {:.1} dB-Hz",
            d.prn,
            d.doppler_hz,
            d.cn0_dbhz.unwrap_or(f64::NAN)
        );
    }
    Ok((engine, channels))
}
