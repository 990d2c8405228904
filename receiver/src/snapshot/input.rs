//! Snapshot inputs: a raw recording holding one snapshot, or a SnapperGPS JSON file holding
//! many ([`super::snappergps`]). Every reader gives [`Snapshot`]s of complex baseband samples
//! (real formats read with Q = 0, the IF mixed away) with the approximate GPS time of their
//! first sample when the input carries one.

use super::SnapshotError;
use gpsrx_nav::time::GpsTime;
use gpsrx_samples::{open_source, SampleFormat, SampleSource, SourceConfig};
use num_complex::Complex32;
use std::path::Path;

/// Longest raw snapshot read, s: a snapshot receiver records milliseconds; the rest of a longer
/// file is left unread (one snapshot per file).
pub const MAX_SNAPSHOT_S: f64 = 1.0;

/// One snapshot: samples and what is known about when they were taken.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Position in the input, 0-based.
    pub index: usize,
    /// Complex baseband samples (Q = 0 for real formats), first sample = reception instant.
    pub samples: Vec<Complex32>,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Whether the recording is real with an IF that is a whole multiple of fs: the spectrum
    /// is folded around 0 Hz and a carrier offset is seen with either sign.
    pub folded: bool,
    /// Approximate GPS time of the first sample (device clock), if the input says.
    pub approx_time: Option<GpsTime>,
    /// The input's own time text (SnapperGPS timestamp), for the output.
    pub label: String,
}

/// How to read a raw recording: what `--format`, `--fs` and `--if` say.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleSpec {
    /// Sample format (`None`: from SigMF/WAV metadata).
    pub format: Option<SampleFormat>,
    /// Sampling rate, Hz (`None`: from metadata).
    pub fs_hz: Option<f64>,
    /// Intermediate frequency, Hz.
    pub if_hz: f64,
    /// Read I - jQ.
    pub invert_q: bool,
}

/// Reads one snapshot (at most [`MAX_SNAPSHOT_S`]) from a raw, WAV or SigMF recording.
pub fn read_raw_snapshot(
    path: &Path,
    spec: &SampleSpec,
    approx_time: Option<GpsTime>,
) -> Result<Snapshot, SnapshotError> {
    let cfg = SourceConfig {
        path: path.to_path_buf(),
        format: spec.format.clone(),
        fs_hz: spec.fs_hz,
        if_hz: spec.if_hz,
        invert_q: spec.invert_q,
        skip_s: 0.0,
        duration_s: Some(MAX_SNAPSHOT_S),
    };
    let mut source = open_source(&cfg).map_err(|e| SnapshotError::Input {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    let fs_hz = source.fs_hz();
    let samples = read_all(source.as_mut(), (MAX_SNAPSHOT_S * fs_hz) as usize).map_err(|e| {
        SnapshotError::Input {
            path: path.to_path_buf(),
            reason: e.to_string(),
        }
    })?;
    let folded = spec.format.as_ref().is_some_and(|f| {
        !f.is_complex() && gpsrx_samples::resolve::is_folded_if(spec.if_hz, fs_hz)
    });
    Ok(Snapshot {
        index: 0,
        samples,
        fs_hz,
        folded,
        approx_time,
        label: path.display().to_string(),
    })
}

/// The metadata file of a SigMF recording named by its data file or its `.sigmf-meta`.
fn sigmf_meta_of(path: &Path) -> Option<std::path::PathBuf> {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("sigmf-meta"))
    {
        return Some(path.to_path_buf());
    }
    let meta = gpsrx_samples::sigmf::meta_path_for(path);
    meta.is_file().then_some(meta)
}

/// The captures of a SigMF metadata file, in sample order.
fn captures(meta: &Path) -> Result<Vec<gpsrx_samples::sigmf::Capture>, SnapshotError> {
    gpsrx_samples::sigmf::read_captures(meta).map_err(|e| SnapshotError::Input {
        path: meta.to_path_buf(),
        reason: e.to_string(),
    })
}

/// The snapshots of a SigMF recording with more than one capture: capture `k` holds the
/// samples from its `core:sample_start` to the next capture's (at most [`MAX_SNAPSHOT_S`]),
/// its `core:datetime` (UTC) is the snapshot's approximate time (a capture without one, or
/// with one that cannot be read, has none: its row says so). `Ok(None)` when `path` is no
/// SigMF recording or has a single capture (one snapshot: [`read_raw_snapshot`]).
pub fn read_sigmf_set(path: &Path) -> Result<Option<Vec<Snapshot>>, SnapshotError> {
    let Some(meta) = sigmf_meta_of(path) else {
        return Ok(None);
    };
    let caps = captures(&meta)?;
    if caps.len() < 2 {
        return Ok(None);
    }
    let input_error = |e: gpsrx_samples::SampleError| SnapshotError::Input {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let if_hz = gpsrx_samples::sigmf::read_sigmf_meta(&meta)
        .map_err(input_error)?
        .described_if_hz()
        .0;
    let mut out = Vec::with_capacity(caps.len());
    for (index, c) in caps.iter().enumerate() {
        let first = SourceConfig {
            path: meta.clone(),
            format: None,
            fs_hz: None,
            if_hz: 0.0,
            invert_q: false,
            skip_s: 0.0,
            duration_s: Some(1e-3),
        };
        let fs_hz = open_source(&first).map_err(input_error)?.fs_hz();
        let end = caps.get(index + 1).map(|n| n.sample_start);
        let len = end.map_or(u64::MAX, |e| e.saturating_sub(c.sample_start));
        let wanted = (len as f64).min(MAX_SNAPSHOT_S * fs_hz) as usize;
        let cfg = SourceConfig {
            skip_s: c.sample_start as f64 / fs_hz,
            duration_s: Some(wanted as f64 / fs_hz),
            ..first
        };
        let mut source = open_source(&cfg).map_err(input_error)?;
        let samples = read_all(source.as_mut(), wanted).map_err(input_error)?;
        out.push(Snapshot {
            index,
            samples,
            fs_hz,
            folded: !source.format().is_complex()
                && gpsrx_samples::resolve::is_folded_if(if_hz, fs_hz),
            approx_time: c
                .datetime
                .as_deref()
                .and_then(|t| gpsrx_samples::sigmf::parse_datetime_utc(t).ok()),
            label: c.datetime.clone().unwrap_or_default(),
        });
    }
    Ok(Some(out))
}

/// Reads up to `wanted` samples from the start of `source`.
pub(crate) fn read_all(
    source: &mut dyn SampleSource,
    wanted: usize,
) -> Result<Vec<Complex32>, gpsrx_samples::SampleError> {
    let mut samples = vec![Complex32::new(0.0, 0.0); wanted];
    let mut filled = 0;
    while filled < wanted {
        let (_, n) = source.read(&mut samples[filled..])?;
        if n == 0 {
            break;
        }
        filled += n;
    }
    samples.truncate(filled);
    Ok(samples)
}
