//! Snapshot positioning: one position per snapshot of a few milliseconds of signal, from code
//! phases alone (coarse-time navigation), as snapshot receivers (SnapperGPS, PocketSDR's
//! `pocket_snap`) are positioned after the fact.
//!
//! - [`input`]: a raw recording holding one snapshot; [`snappergps`]: SnapperGPS JSON files
//!   (many snapshots, device timestamps) and their truth files;
//! - [`measure`]: assisted acquisition of one snapshot (sub-sample code phase, common
//!   front-end offset, narrow second search, false-peak rejection);
//! - [`coherent`]: detection at a predicted code phase, coherent over the snapshot with the
//!   data-bit edge hypothesised;
//! - [`fine_phase`]: the sub-sample code phase from a band-limited matched replica;
//! - [`crlb`]: the Cramer-Rao bound of that code phase (what any estimator can reach);
//! - [`solve`]: the coarse-time fix ([`gpsrx_nav::pvt::coarse_time`]) and its checks;
//! - [`smooth`]: optional smoothing of the track across consecutive snapshots;
//! - [`driver`]: a sequence of snapshots, each good fix seeding the next;
//! - [`clock`]: the device clock's error from the sequence's fixes (a second pass);
//! - [`output`]: `snapshots.csv`, the GeoJSON track, errors against a truth;
//! - [`set`]: a whole set as one job (input, navigation data, options, outputs), as
//!   `gpsrx snapshot`, `gpsrx batch` and the Python package run it.
//!
//! # A-priori limits
//!
//! The solver reconstructs each satellite's whole milliseconds from the a-priori position and
//! time: measured limits in [`gpsrx_nav::pvt::coarse_time`] ("Limits"): about 100 km and 60 s
//! together (the defaults of [`solve::SolveOptions`]); beyond them the result is an error
//! (a row with quality `none`), not a wrong fix.

pub mod clock;
pub mod coherent;
pub mod crlb;
pub mod driver;
pub mod fine_phase;
pub mod input;
pub mod measure;
pub mod output;
pub mod set;
pub mod smooth;
pub mod snappergps;
pub mod solve;

pub use driver::{SnapshotOptions, SnapshotOutcome, SnapshotProcessor};
pub use input::{read_raw_snapshot, read_sigmf_set, SampleSpec, Snapshot};
pub use set::{run_set, write_set, SetResult, SnapshotSetSpec};
pub use solve::SnapshotQuality;

use std::path::PathBuf;

/// Errors that stop a snapshot run (a bad snapshot only gives a row with quality `none`).
#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    /// The input cannot be read.
    #[error("cannot read {path}: {reason}")]
    Input {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// The navigation file cannot be read.
    #[error("cannot read the navigation file {path}: {reason}")]
    Nav {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// No navigation data with a GPS ephemeris were given: no satellite can be predicted.
    #[error(
        "no navigation data were given (no GPS ephemeris): snapshot positioning needs the \
         broadcast ephemerides of the day, from a RINEX navigation file"
    )]
    NoEphemerides,
    /// An option out of range.
    #[error("{0}")]
    Option(String),
    /// An output file cannot be written.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// The error plot cannot be drawn.
    #[error(transparent)]
    Plot(#[from] crate::output::plots::PlotError),
}
