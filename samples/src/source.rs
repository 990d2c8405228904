//! Streaming complex baseband samples out of a recording of any length.
//!
//! [`open_source`] works out the format and sampling rate (see [`crate::resolve`]), checks them
//! against what GPS L1 C/A needs, and returns a [`SampleSource`] that reads the file in bounded
//! chunks (1 MiB) at `u64` offsets, so files beyond 4 GiB stream like small ones.

use std::fs::File;
use std::path::{Path, PathBuf};

use num_complex::Complex32;

use crate::error::SampleError;
use crate::file_source::FileSource;
use crate::format::SampleFormat;
use crate::mixer::Mixer;
use crate::stream_source::{is_stdin_path, ReaderSource, StreamPlan};

/// How to read one recording. Unset fields come from metadata beside the file.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceConfig {
    /// The data file, or its `.sigmf-meta`; `-` for standard input; or a named pipe or device
    /// (streams need `format` and `fs_hz`).
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

    /// The complex integer format this source can hand over without keeping samples in f32
    /// ([`SampleSource::read_integer`]), for the int16 correlators: complex 8- or 16-bit
    /// samples at IF 0 with Q not inverted exactly as stored (where [`SampleSource::read`]
    /// would only widen them); a source may also offer other integer formats converted to
    /// ci16 ([`SampleSource::integer_gain`]). `None` (the default) when every sample must go
    /// through [`SampleSource::read`].
    fn integer_format(&self) -> Option<IntegerFormat> {
        None
    }

    /// Like [`SampleSource::read`], in integers: the values `read` gives times
    /// [`SampleSource::integer_gain`], rounded to the nearest integer (exactly `read`'s values
    /// when they are the integers stored); only for the [`SampleSource::integer_format`] the
    /// source reports. Reading either way continues where the other stopped.
    fn read_integer(&mut self, out: IntegerSamplesMut<'_>) -> Result<(u64, usize), SampleError> {
        Err(SampleError::NoIntegerRead {
            asked: out.format(),
        })
    }

    /// The factor [`SampleSource::read_integer`] applies to [`SampleSource::read`]'s values
    /// before rounding them (see [`held_gain`]): 1 (the default) for samples handed over as
    /// stored. The receiver's loops and searches do not depend on the scale of the samples.
    fn integer_gain(&self) -> f32 {
        1.0
    }
}

/// The gain of a recording of `format` converted to ci16 for the int16 correlators (a complex
/// 16-bit sample = `round(gain x)` of the complex baseband value `x` that
/// [`SampleSource::read`] gives, after the IF mixing and Q inversion):
///
/// - `cu8` (offset binary, `x = code - zero`): 2, so that `2 code - 2 zero` is exact for the
///   usual zero of 127.5 (RTL-SDR, HackRF: codes 0..=255 give -255..=255);
/// - `ri8` and `ci8` (when mixed from an IF or with Q inverted): 128 = 2^7 (|x| <= 128 after
///   a unit-magnitude mixing: |gain x| <= 2^14), each component within 2^-8 sample units of x;
/// - `ri16` and `ci16` (when mixed or inverted): 1, each component within 1/2 unit of x (and
///   clamped to the i16 range);
/// - `None` for float formats (no integer scale to keep).
///
/// An exact integer value (every value of a real or complex recording at IF 0, or mixed at
/// IF = fs/4, where the oscillator is 1, -j, -1, j) stays exact at any of these gains.
pub fn held_gain(format: &SampleFormat) -> Option<f32> {
    match format {
        SampleFormat::Cu8 { .. } => Some(2.0),
        SampleFormat::Ci8 | SampleFormat::Ri8 => Some(128.0),
        SampleFormat::Ci16Le | SampleFormat::Ri16Le => Some(1.0),
        _ => None,
    }
}

/// Rounds complex baseband values `x` times `gain` into `out` (same length) as the ci16 the
/// int16 correlators read: `[round(gain re), round(gain im)]`, clamped to the i16 range
/// (see [`held_gain`]); to the nearest integer, ties to even.
///
/// The rounding adds and subtracts `1.5 2^23` (the f32 whose unit in the last place is 1):
/// exact for any value clamped to the i16 range, and plain SIMD adds where `round` would be a
/// library call per value (it was a third of a cu8 run's CPU time).
pub fn quantize_to_ci16(x: &[Complex32], gain: f32, out: &mut [[i16; 2]]) {
    const MAGIC: f32 = 12_582_912.0; // 1.5 * 2^23
                                     // The f32 `MAGIC + k` for an integer |k| < 2^22 has the bits of MAGIC plus k.
    const MAGIC_BITS: i32 = 0x4B40_0000;
    let q = |v: f32| {
        // max/min (not clamp): a NaN reads as the lower bound instead of passing through.
        let v = (v * gain).max(f32::from(i16::MIN)).min(f32::from(i16::MAX));
        ((v + MAGIC).to_bits() as i32 - MAGIC_BITS) as i16
    };
    for (o, c) in out.iter_mut().zip(x) {
        *o = [q(c.re), q(c.im)];
    }
}

/// A complex integer sample format handed over as stored ([`SampleSource::integer_format`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntegerFormat {
    /// Interleaved signed 8-bit I/Q (SigMF `ci8`).
    Ci8,
    /// Interleaved signed 16-bit I/Q (SigMF `ci16_le`), in host order once read.
    Ci16,
}

impl std::fmt::Display for IntegerFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            IntegerFormat::Ci8 => "ci8",
            IntegerFormat::Ci16 => "ci16",
        })
    }
}

/// Room for samples read as stored ([`SampleSource::read_integer`]), one variant per
/// [`IntegerFormat`].
#[derive(Debug)]
pub enum IntegerSamplesMut<'a> {
    /// Room for ci8 samples.
    Ci8(&'a mut [[i8; 2]]),
    /// Room for ci16 samples.
    Ci16(&'a mut [[i16; 2]]),
}

impl IntegerSamplesMut<'_> {
    /// The format this room takes.
    pub fn format(&self) -> IntegerFormat {
        match self {
            IntegerSamplesMut::Ci8(_) => IntegerFormat::Ci8,
            IntegerSamplesMut::Ci16(_) => IntegerFormat::Ci16,
        }
    }

    /// Samples of room.
    pub fn len(&self) -> usize {
        match self {
            IntegerSamplesMut::Ci8(s) => s.len(),
            IntegerSamplesMut::Ci16(s) => s.len(),
        }
    }

    /// Whether there is no room at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Turns decoded samples into complex baseband the way every source does: negates Q when
/// asked, then mixes by the oscillator at absolute index `first` (so the result does not depend
/// on which source delivered the block).
pub(crate) fn to_baseband(
    block: &mut [Complex32],
    first: u64,
    invert_q: bool,
    mixer: Option<&Mixer>,
) {
    if invert_q {
        for s in block.iter_mut() {
            s.im = -s.im;
        }
    }
    if let Some(m) = mixer {
        m.mix(first, block);
    }
}

/// The warning for bytes after the last whole sample.
pub(crate) fn trailing_bytes_warning(
    name: &Path,
    trailing_bytes: u64,
    format: &SampleFormat,
) -> String {
    format!(
        "{}: the last {trailing_bytes} byte(s) do not make a whole {format} sample and were dropped",
        name.display()
    )
}

/// The warning for NaN or infinite values read as 0.
pub(crate) fn non_finite_warning(name: &Path, non_finite: u64) -> String {
    format!(
        "{}: {non_finite} non-finite value(s) (NaN or infinity) read as 0",
        name.display()
    )
}

/// Opens a recording described by `cfg` (see [`crate::resolve`] for where the format and rate
/// come from when `cfg` does not give them).
///
/// - `cfg.path` = `-`: standard input, streamed by a [`ReaderSource`];
/// - a path that exists but is neither a regular file nor a directory (a named pipe from
///   `mkfifo`, `/dev/stdin` on a pipe, a device): opened and streamed by a [`ReaderSource`]
///   (opening a named pipe waits for its writer);
/// - a regular file: a [`FileSource`], with metadata as described in [`crate::resolve`].
///
/// Streams need `cfg.format` and `cfg.fs_hz` (there is no metadata on a pipe) and cannot be
/// named `.sigmf-meta` or `.wav` (metadata is read from regular files only); see
/// [`crate::stream_source`] for how they differ from files.
///
/// Errors: missing or unreadable file, empty file, unknown format or rate, a sampling rate below
/// 1.023 MHz (complex) / 2.046 MHz (real), an IF beyond fs/2 (or not in (0, fs/2) for real
/// samples), a skip beyond the end, SigMF metadata without its data file; for a stream, a
/// missing format or rate (an empty stream or a skip beyond its end is reported by the first
/// `read`).
pub fn open_source(cfg: &SourceConfig) -> Result<Box<dyn SampleSource>, SampleError> {
    if is_stdin_path(&cfg.path) {
        let plan = StreamPlan::new(cfg)?;
        return Ok(Box::new(ReaderSource::with_plan(std::io::stdin(), plan)));
    }
    // A missing path falls through to `FileSource`, which reports it.
    if let Ok(meta) = std::fs::metadata(&cfg.path) {
        let kind = meta.file_type();
        if !kind.is_file() && !kind.is_dir() {
            return open_stream_path(cfg);
        }
    }
    Ok(Box::new(FileSource::open(cfg)?))
}

/// Streams a pipe or device path through a [`ReaderSource`].
fn open_stream_path(cfg: &SourceConfig) -> Result<Box<dyn SampleSource>, SampleError> {
    let path = &cfg.path;
    let names_metadata = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("sigmf-meta") || e.eq_ignore_ascii_case("wav"));
    if names_metadata {
        return Err(SampleError::NotStreamable {
            path: path.clone(),
            reason: "SigMF metadata and WAV headers are read from regular files only: \
                     stream the raw samples instead and give their format and sampling rate"
                .to_string(),
        });
    }
    // Check the configuration first: opening a named pipe blocks until a writer opens it.
    let plan = StreamPlan::new(cfg)?;
    let file = File::open(path).map_err(|e| SampleError::io("open", path, e))?;
    Ok(Box::new(ReaderSource::with_plan(file, plan)))
}
