//! Streaming complex baseband samples out of a recording of any length.
//!
//! [`open_source`] works out the format and sampling rate (see [`crate::resolve`]), checks them
//! against what GPS L1 C/A needs, and returns a [`SampleSource`] that reads the file in bounded
//! chunks (1 MiB) at `u64` offsets, so files beyond 4 GiB stream like small ones.

use std::path::PathBuf;

use num_complex::Complex32;

use crate::error::SampleError;
use crate::file_source::FileSource;
use crate::format::SampleFormat;

/// How to read one recording. Unset fields come from metadata beside the file.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceConfig {
    /// The data file, or its `.sigmf-meta`.
    pub path: PathBuf,
    /// Sample format; `None` = from SigMF metadata or a WAV header.
    pub format: Option<SampleFormat>,
    /// Sampling rate in Hz; `None` = from SigMF metadata or a WAV header.
    pub fs_hz: Option<f64>,
    /// Intermediate frequency in Hz, mixed down to 0 (0 = baseband, or `gpsrx:if_hz` from SigMF).
    pub if_hz: f64,
    /// Read samples as I - jQ (some front ends swap the sign of Q).
    pub invert_q: bool,
    /// Seconds to skip at the start.
    pub skip_s: f64,
    /// Seconds to read after the skip; `None` = to the end.
    pub duration_s: Option<f64>,
}

impl SourceConfig {
    /// Reads all of `path` with everything else from metadata.
    pub fn new(path: impl Into<PathBuf>) -> Self {
        SourceConfig {
            path: path.into(),
            format: None,
            fs_hz: None,
            if_hz: 0.0,
            invert_q: false,
            skip_s: 0.0,
            duration_s: None,
        }
    }

    /// Sets the sample format.
    pub fn with_format(mut self, format: SampleFormat) -> Self {
        self.format = Some(format);
        self
    }

    /// Sets the sampling rate in Hz.
    pub fn with_fs_hz(mut self, fs_hz: f64) -> Self {
        self.fs_hz = Some(fs_hz);
        self
    }
}

/// A stream of complex baseband samples.
pub trait SampleSource: Send {
    /// Sampling rate in Hz.
    fn fs_hz(&self) -> f64;

    /// How the samples are stored.
    fn format(&self) -> &SampleFormat;

    /// Samples this source delivers in all (after skip and duration), if known.
    fn total_samples(&self) -> Option<u64>;

    /// Fills `out` with the next complex baseband samples, in the format's units (see
    /// [`crate::format`]): real input is mixed down by exp(-j 2π IF t), complex input with a
    /// non-zero IF likewise; Q is negated first if asked; NaN/inf read as 0 and are counted.
    ///
    /// Returns (index of `out[0]` counted from the first sample of the file, number written).
    /// Writes fewer than `out.len()` only at the end of the stream; 0 means the end.
    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError>;

    /// Things the user should know: a trailing partial sample dropped, non-finite values zeroed,
    /// a duration cut at the end of the file, `--format` or `--fs` overriding metadata.
    fn warnings(&self) -> Vec<String>;
}

/// Opens a recording described by `cfg` (see [`crate::resolve`] for where the format and rate
/// come from when `cfg` does not give them).
///
/// Errors: missing or unreadable file, empty file, unknown format or rate, a sampling rate below
/// 1.023 MHz (complex) / 2.046 MHz (real), an IF beyond fs/2 (or not in (0, fs/2) for real
/// samples), a skip beyond the end, SigMF metadata without its data file.
pub fn open_source(cfg: &SourceConfig) -> Result<Box<dyn SampleSource>, SampleError> {
    Ok(Box::new(FileSource::open(cfg)?))
}
