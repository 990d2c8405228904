//! Batches of recordings and snapshot sets processed one after another on this machine:
//! `gpsrx batch` and the Python package's tasks (`gpsrx.batch`, one per recording or set on a
//! Dask cluster) share this code.
//!
//! A [`Manifest`] (TOML or CSV, [`manifest`]) lists the recordings with their format, rate,
//! navigation file and receiver options ([`options`]), and the snapshot sets
//! ([`crate::snapshot::SnapshotSetSpec`]); [`process`] runs a recording into its own output
//! directory, [`process_snapshots`] a set, and either turns any failure into a row of the
//! summary ([`summary`]), so a bad entry does not stop the batch; [`run_batch`] runs them in
//! turn. Memory stays bounded by one receiver: a recording's outputs are streamed to its files
//! and dropped before the next.

pub mod manifest;
pub mod options;
pub mod recording;
pub mod summary;

pub use manifest::{Manifest, ManifestError, RecordingSpec, StudySpec};
pub use recording::{run_recording, run_recording_to, RecordingError};
pub use summary::{BatchRow, Status};

use crate::snapshot::{run_set, write_set, SnapshotSetSpec};
use std::path::Path;

/// Runs one recording with its files in `out_root/NAME/`; every failure becomes a row with
/// status [`Status::Error`] and the message `gpsrx run` would print.
pub fn process(spec: &RecordingSpec, out_root: &Path) -> BatchRow {
    let path = spec.path.display().to_string();
    let out = out_root.join(&spec.name);
    match run_recording_to(spec, &out) {
        Ok((summary, warnings)) => BatchRow::done(&spec.name, &path, &summary, &warnings),
        Err(e) => {
            let message = crate::error_message(&e);
            tracing::warn!("{}: {message}", spec.name);
            BatchRow::failed(&spec.name, &path, message)
        }
    }
}

/// Positions one snapshot set with its files (`snapshots.csv`, the tracks, `errors.png` when
/// scored) in `out_root/NAME/`; every failure becomes a row with status [`Status::Error`].
pub fn process_snapshots(spec: &SnapshotSetSpec, out_root: &Path) -> BatchRow {
    let path = spec.path.display().to_string();
    let out = out_root.join(&spec.name);
    let result = run_set(spec, |_| {}).and_then(|r| write_set(&out, &r).map(|()| r));
    match result {
        Ok(r) => BatchRow::snapshot_set(&spec.name, &path, &r),
        Err(e) => {
            let message = crate::error_message(&e);
            tracing::warn!("{}: {message}", spec.name);
            BatchRow::failed_set(&spec.name, &path, message)
        }
    }
}

/// Runs every recording, then every snapshot set of `manifest` in turn (`progress` is told
/// each row as it is done).
pub fn run_batch(
    manifest: &Manifest,
    out_root: &Path,
    progress: &mut dyn FnMut(&BatchRow),
) -> Vec<BatchRow> {
    let recordings = manifest
        .recordings
        .iter()
        .map(|spec| process(spec, out_root));
    let sets = manifest
        .snapshots
        .iter()
        .map(|spec| process_snapshots(spec, out_root));
    recordings
        .chain(sets)
        .inspect(|row| progress(row))
        .collect()
}
