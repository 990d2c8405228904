//! The one error type of the sample layer.
//!
//! Every variant names the problem, the file involved (when there is one) and what to do next, so
//! the binary can print it as is.

use std::path::PathBuf;

/// What went wrong while opening, reading, writing or inspecting a recording.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SampleError {
    /// A source was asked for samples as stored in a format it does not hand over (a
    /// programming error: ask `integer_format()` first).
    #[error("this source cannot hand over {asked} samples as stored; read them with read()")]
    NoIntegerRead {
        /// The format asked for.
        asked: crate::source::IntegerFormat,
    },

    /// The recording does not exist.
    #[error("recording {path} does not exist: check the path")]
    NotFound {
        /// The path that was asked for.
        path: PathBuf,
    },

    /// The path exists but is not a regular file (e.g. a directory).
    #[error("{path} is not a regular file (a directory?): give the recording's data file or its .sigmf-meta")]
    NotAFile {
        /// The path that was asked for.
        path: PathBuf,
    },

    /// An I/O error while reading, seeking or writing a file.
    #[error("cannot {action} {path}: {source}")]
    Io {
        /// What was being done ("open", "read", "write", ...).
        action: &'static str,
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },

    /// The recording holds no bytes at all (or no whole sample).
    #[error("recording {path} is empty ({size_bytes} bytes, no whole {format} sample): was the capture interrupted?")]
    EmptyFile {
        /// The file.
        path: PathBuf,
        /// Its size.
        size_bytes: u64,
        /// The sample format it was read as.
        format: String,
    },

    /// A sample-format name that is not one we know.
    #[error("unknown sample format {name:?}: use one of {}", crate::format::SampleFormat::SUPPORTED.join(", "))]
    UnknownFormat {
        /// The name as given.
        name: String,
    },

    /// A sample format whose parameters make no sense (e.g. a non-finite 2-bit value map).
    #[error("invalid sample format {format}: {reason}")]
    InvalidFormat {
        /// The format's name.
        format: String,
        /// What is wrong with it.
        reason: String,
    },

    /// Neither the configuration nor any metadata beside the file says how samples are stored.
    #[error("no sample format known for {path} (none given, no .sigmf-meta beside it, not a WAV file): give the sample format, one of {}", crate::format::SampleFormat::SUPPORTED.join(", "))]
    FormatUnknown {
        /// The recording.
        path: PathBuf,
    },

    /// Neither the configuration nor any metadata beside the file gives the sampling rate.
    #[error("no sampling rate known for {path} (none given, no core:sample_rate in SigMF, not a WAV file): give the sampling rate in Hz")]
    SampleRateUnknown {
        /// The recording.
        path: PathBuf,
    },

    /// Samples streamed from standard input, a pipe or a device, without an explicit format or
    /// sampling rate (a stream has no metadata beside it to take them from).
    #[error("reading from {stream} needs the sample format and the sampling rate (a stream has no metadata to take them from): give {}", match (format_missing, rate_missing) {
        (true, true) => "both",
        (true, false) => "the sample format",
        _ => "the sampling rate",
    })]
    StreamNeedsFormatAndRate {
        /// What is being read: "standard input" or the pipe's path.
        stream: String,
        /// The sample format was not given.
        format_missing: bool,
        /// The sampling rate was not given.
        rate_missing: bool,
    },

    /// A pipe or device path that names a metadata-bearing file (`.sigmf-meta`, `.wav`):
    /// metadata is read only from regular files.
    #[error("{path} is a pipe or device, not a regular file: {reason}")]
    NotStreamable {
        /// The path that was asked for.
        path: PathBuf,
        /// Why it cannot be streamed, and what to do.
        reason: String,
    },

    /// The sampling rate is not positive and finite, or too low to hold the C/A signal.
    #[error("sampling rate {fs_hz} Hz for {path} is {reason}: give the sampling rate in Hz (at least {min_hz} Hz for {kind} samples)")]
    BadSampleRate {
        /// The recording.
        path: PathBuf,
        /// The rate that was given.
        fs_hz: f64,
        /// The lowest usable rate for this kind of sample.
        min_hz: f64,
        /// "complex" or "real".
        kind: &'static str,
        /// Why it is rejected ("not a positive finite number", "too low for GPS L1 C/A").
        reason: &'static str,
    },

    /// The intermediate frequency does not fit the sampling rate.
    #[error(
        "IF {if_hz} Hz for {path} is outside {allowed} at fs = {fs_hz} Hz: check the intermediate frequency (and the sampling rate)"
    )]
    IfOutOfRange {
        /// The recording.
        path: PathBuf,
        /// The IF that was given.
        if_hz: f64,
        /// The sampling rate.
        fs_hz: f64,
        /// The allowed range in words.
        allowed: String,
    },

    /// `--if` disagrees with the IF the SigMF metadata describes.
    #[error(
        "the IF given, {given_hz} Hz, for {path} disagrees with the SigMF metadata's IF of {described_hz} Hz (from {field}): give none to use the metadata, or correct the .sigmf-meta"
    )]
    IfConflict {
        /// The recording.
        path: PathBuf,
        /// The IF given on the command line, Hz.
        given_hz: f64,
        /// The IF the metadata describes, Hz.
        described_hz: f64,
        /// The metadata field it comes from (`gpsrx:if_hz` or `core:frequency`).
        field: &'static str,
    },

    /// A skip or duration that is negative or not finite.
    #[error("{what} = {value} s for {path} is not a finite, non-negative number of seconds")]
    BadTimeSpan {
        /// The recording.
        path: PathBuf,
        /// "skip" or "duration".
        what: &'static str,
        /// The value that was given.
        value: f64,
    },

    /// The skip lands at or beyond the end of the recording.
    #[error("skip of {skip_s} s is at or beyond the end of {path}, which holds only {file_duration_s:.6} s ({file_samples} samples): skip less")]
    SkipBeyondEnd {
        /// The recording.
        path: PathBuf,
        /// The skip that was asked for.
        skip_s: f64,
        /// The recording's length in seconds.
        file_duration_s: f64,
        /// The recording's length in samples.
        file_samples: u64,
    },

    /// A SigMF metadata file whose dataset file is missing.
    #[error("SigMF metadata {meta} has no data file beside it (looked for {data}): put the .sigmf-data next to the .sigmf-meta")]
    SigmfMissingData {
        /// The metadata file.
        meta: PathBuf,
        /// The data file that was looked for.
        data: PathBuf,
    },

    /// A SigMF metadata file that cannot be understood.
    #[error("SigMF metadata {path} is not usable: {reason}")]
    SigmfInvalid {
        /// The metadata file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },

    /// A WAV file that hound cannot parse or write.
    #[error("WAV file {path}: {source}")]
    Wav {
        /// The file.
        path: PathBuf,
        /// hound's error.
        #[source]
        source: hound::Error,
    },

    /// A WAV file in a layout we cannot read as IF samples.
    #[error("WAV file {path} has {reason}: convert it to 16-bit PCM or 32-bit float with 1 (real) or 2 (I/Q) channels")]
    UnsupportedWav {
        /// The file.
        path: PathBuf,
        /// The offending property.
        reason: String,
    },
}

impl SampleError {
    /// Wraps an I/O error with the action and the file.
    pub(crate) fn io(
        action: &'static str,
        path: impl Into<PathBuf>,
        source: std::io::Error,
    ) -> Self {
        SampleError::Io {
            action,
            path: path.into(),
            source,
        }
    }
}
