//! The [`SampleSource`] over any byte stream: standard input, a named pipe, a device, a socket.
//!
//! A stream has no metadata beside it and cannot seek or report its length, so:
//! - the format and sampling rate must be given ([`SourceConfig::format`], [`SourceConfig::fs_hz`]);
//!   a SigMF file or WAV header is never looked for;
//! - the skip is read and discarded; the duration stops reading after that many samples;
//! - the length is known only when a duration is given ([`SampleSource::total_samples`]);
//! - an empty stream, or one that ends inside the skip, is an error from the first `read`
//!   (a file source reports these when it is opened).
//!
//! Everything else is as for [`crate::file_source::FileSource`]: the same decoding, Q
//! inversion, IF mixing by absolute sample index, non-finite counting and warnings, so the same
//! bytes read through the same sequence of `read` calls give bit-identical samples and indices.
//!
//! Reads from the stream may return any number of bytes (a pipe returns what is there); bytes
//! that do not yet make a whole sample (or, for packed formats, the shared byte) are kept until
//! the next read. Reads go into a buffer of 1 MiB and are retried on
//! [`std::io::ErrorKind::Interrupted`].

use std::fmt;
use std::io::{ErrorKind, Read};
use std::path::{Path, PathBuf};

use num_complex::Complex32;

use crate::chunk::CHUNK_BYTES;
use crate::codec::decode;
use crate::error::SampleError;
use crate::format::SampleFormat;
use crate::mixer::Mixer;
use crate::resolve::validate_format_and_rates;
use crate::source::{
    non_finite_warning, to_baseband, trailing_bytes_warning, SampleSource, SourceConfig,
};
use crate::span::{
    bytes_for_samples, sample_position, samples_in_bytes, seconds_to_samples, validate_times,
};

/// The path that means standard input.
pub const STDIN_PATH: &str = "-";

/// True when `path` is `-`, i.e. standard input (a file really named `-` can be given as `./-`).
pub fn is_stdin_path(path: &Path) -> bool {
    path.as_os_str() == STDIN_PATH
}

/// How a stream is named in messages: "standard input" for `-`, else the path.
fn stream_name(path: &Path) -> PathBuf {
    if is_stdin_path(path) {
        PathBuf::from("standard input")
    } else {
        path.to_path_buf()
    }
}

/// What a stream is read as: `cfg` checked, before anything is opened (opening a named pipe
/// blocks until a writer appears, so configuration errors come first).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StreamPlan {
    /// Name used in messages.
    name: PathBuf,
    format: SampleFormat,
    fs_hz: f64,
    if_hz: f64,
    invert_q: bool,
    /// The skip as given, for messages.
    skip_s: f64,
    /// First sample delivered (the skip).
    first_sample: u64,
    /// Samples to deliver (the duration); `None` = to the end of the stream.
    n_samples: Option<u64>,
}

impl StreamPlan {
    /// Checks `cfg` for streaming: format and rate given, rate and IF usable, times valid.
    pub(crate) fn new(cfg: &SourceConfig) -> Result<Self, SampleError> {
        let name = stream_name(&cfg.path);
        let (Some(format), Some(fs_hz)) = (&cfg.format, cfg.fs_hz) else {
            return Err(SampleError::StreamNeedsFormatAndRate {
                stream: name.display().to_string(),
                format_missing: cfg.format.is_none(),
                rate_missing: cfg.fs_hz.is_none(),
            });
        };
        validate_format_and_rates(&name, format, fs_hz, cfg.if_hz)?;
        validate_times(&name, cfg.skip_s, cfg.duration_s)?;
        Ok(StreamPlan {
            name,
            format: format.clone(),
            fs_hz,
            if_hz: cfg.if_hz,
            invert_q: cfg.invert_q,
            skip_s: cfg.skip_s,
            first_sample: seconds_to_samples(cfg.skip_s, fs_hz),
            n_samples: cfg.duration_s.map(|d| seconds_to_samples(d, fs_hz)),
        })
    }
}

/// Streams samples from any reader (standard input, a pipe), which is never sought.
///
/// Delivers the same samples with the same indices as [`crate::file_source::FileSource`] would
/// from a file holding the same bytes (see the module documentation).
pub struct ReaderSource<R: Read + Send> {
    reader: R,
    plan: StreamPlan,
    mixer: Option<Mixer>,
    /// Bytes read and not yet consumed: `buf[..buf_len]` starts at stream byte `buf_start`.
    buf: Vec<u8>,
    buf_start: u64,
    buf_len: usize,
    /// The reader returned 0 (end of stream).
    eof: bool,
    /// Next sample to deliver, counted from the first byte of the stream.
    pos: u64,
    /// Most samples decoded per pass (their bytes fit in `buf`).
    max_block: usize,
    /// Once the stream has ended: whole samples in it, and bytes after the last one.
    ended: Option<(u64, u64)>,
    non_finite: u64,
}

impl<R: Read + Send> fmt::Debug for ReaderSource<R> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ReaderSource")
            .field("plan", &self.plan)
            .field("buf_start", &self.buf_start)
            .field("buf_len", &self.buf_len)
            .field("eof", &self.eof)
            .field("pos", &self.pos)
            .field("ended", &self.ended)
            .field("non_finite", &self.non_finite)
            .finish_non_exhaustive()
    }
}

impl<R: Read + Send> ReaderSource<R> {
    /// Checks `cfg` and wraps `reader`. `cfg.format` and `cfg.fs_hz` must be set (else
    /// [`SampleError::StreamNeedsFormatAndRate`]); rate, IF, skip and duration are checked as
    /// for a file. `cfg.path` only names the stream in messages (`-` reads as "standard input").
    /// Nothing is read until the first [`SampleSource::read`].
    pub fn new(reader: R, cfg: &SourceConfig) -> Result<Self, SampleError> {
        Ok(Self::with_plan(reader, StreamPlan::new(cfg)?))
    }

    pub(crate) fn with_plan(reader: R, plan: StreamPlan) -> Self {
        let bits = plan.format.bits_per_sample() as usize;
        let max_block = (CHUNK_BYTES - 1) * 8 / bits;
        let mixer = (plan.if_hz != 0.0).then(|| Mixer::new(plan.if_hz, plan.fs_hz));
        ReaderSource {
            reader,
            mixer,
            buf: vec![0; CHUNK_BYTES],
            buf_start: 0,
            buf_len: 0,
            eof: false,
            pos: plan.first_sample,
            max_block,
            ended: None,
            non_finite: 0,
            plan,
        }
    }

    /// Gives the reader back (positioned wherever reading stopped; buffered bytes are lost).
    pub fn into_inner(self) -> R {
        self.reader
    }

    /// Like [`SampleSource::read`] but without Q inversion or IF mixing: the values as stored
    /// (real formats give Q = 0). Non-finite values still read as 0.
    pub fn read_raw(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let first = self.pos;
        let mut done = 0;
        while done < out.len() {
            let left = self.end_sample().map_or(u64::MAX, |end| end - self.pos);
            if left == 0 {
                break;
            }
            let want = (out.len() - done)
                .min(self.max_block)
                .min(usize::try_from(left).unwrap_or(usize::MAX));
            let (byte, phase) = sample_position(&self.plan.format, self.pos);
            let want_end = bytes_for_samples(&self.plan.format, self.pos + want as u64);
            self.make_available(byte, byte_count(want_end - byte))?;
            let (have, _) = samples_in_bytes(&self.plan.format, self.buf_end());
            let n = want.min(usize::try_from(have.saturating_sub(self.pos)).unwrap_or(usize::MAX));
            if n == 0 {
                self.finish_stream()?;
                break;
            }
            // n > 0: the stream reached `byte`, so `buf` starts there.
            let end = bytes_for_samples(&self.plan.format, self.pos + n as u64);
            let len = byte_count(end - byte);
            let off = byte_count(byte - self.buf_start);
            self.non_finite += decode(
                &self.plan.format,
                &self.buf[off..off + len],
                phase,
                &mut out[done..done + n],
            );
            self.pos += n as u64;
            done += n;
        }
        Ok((first, done))
    }

    /// One past the last sample to deliver, when a duration was given.
    fn end_sample(&self) -> Option<u64> {
        self.plan
            .n_samples
            .map(|n| self.plan.first_sample.saturating_add(n))
    }

    /// Stream offset one past the last buffered byte.
    fn buf_end(&self) -> u64 {
        self.buf_start + self.buf_len as u64
    }

    /// Makes stream bytes `start..start + len` (`len <= CHUNK_BYTES`) available in `buf` from
    /// offset `start - buf_start`, fewer only at the end of the stream. `start` never moves
    /// backwards. Bytes before `start` are dropped (read and discarded when not yet read).
    fn make_available(&mut self, start: u64, len: usize) -> Result<(), SampleError> {
        let buf_end = self.buf_end();
        if start + len as u64 <= buf_end {
            return Ok(());
        }
        if start <= buf_end {
            // Keep the tail from `start` (a partial sample, or a shared packed byte).
            let off = byte_count(start.saturating_sub(self.buf_start));
            self.buf.copy_within(off..self.buf_len, 0);
            self.buf_len -= off;
            self.buf_start = start;
        } else {
            // Skip: read and discard up to `start`.
            self.buf_start = buf_end;
            self.buf_len = 0;
            while self.buf_start < start {
                let chunk = byte_count((start - self.buf_start).min(CHUNK_BYTES as u64));
                let n = self.read_into(0, chunk)?;
                if n == 0 {
                    return Ok(());
                }
                self.buf_start += n as u64;
            }
        }
        while self.buf_len < len {
            let n = self.read_into(self.buf_len, CHUNK_BYTES)?;
            if n == 0 {
                break;
            }
            self.buf_len += n;
        }
        Ok(())
    }

    /// One read into `buf[from..to]` (non-empty), retried when interrupted; 0 = end of stream.
    fn read_into(&mut self, from: usize, to: usize) -> Result<usize, SampleError> {
        if self.eof {
            return Ok(0);
        }
        loop {
            match self.reader.read(&mut self.buf[from..to]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(0);
                }
                Ok(n) => return Ok(n),
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(SampleError::io("read", &self.plan.name, e)),
            }
        }
    }

    /// Records the end of the stream; an error when it held no sample at all or ended inside
    /// the skip (as a file source reports when it is opened).
    fn finish_stream(&mut self) -> Result<(), SampleError> {
        let size_bytes = self.buf_end();
        let (samples, trailing) = samples_in_bytes(&self.plan.format, size_bytes);
        self.ended = Some((samples, trailing));
        let path = self.plan.name.clone();
        if samples == 0 {
            return Err(SampleError::EmptyFile {
                path,
                size_bytes,
                format: self.plan.format.name(),
            });
        }
        if self.plan.first_sample >= samples {
            return Err(SampleError::SkipBeyondEnd {
                path,
                skip_s: self.plan.skip_s,
                file_duration_s: samples as f64 / self.plan.fs_hz,
                file_samples: samples,
            });
        }
        Ok(())
    }

    /// Samples delivered in all, once the stream has ended.
    fn delivered_at_end(&self) -> Option<u64> {
        self.ended
            .map(|(samples, _)| samples.saturating_sub(self.plan.first_sample))
    }
}

/// A byte count within the 1 MiB buffer as `usize`.
fn byte_count(n: u64) -> usize {
    usize::try_from(n).unwrap_or(usize::MAX)
}

impl<R: Read + Send> SampleSource for ReaderSource<R> {
    fn fs_hz(&self) -> f64 {
        self.plan.fs_hz
    }

    fn format(&self) -> &SampleFormat {
        &self.plan.format
    }

    /// `Some` only when a duration was given: that many samples, or fewer once the stream has
    /// ended short of it. `None` without a duration (a stream's length is unknown).
    fn total_samples(&self) -> Option<u64> {
        let n = self.plan.n_samples?;
        Some(self.delivered_at_end().map_or(n, |d| d.min(n)))
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let (first, n) = self.read_raw(out)?;
        to_baseband(
            &mut out[..n],
            first,
            self.plan.invert_q,
            self.mixer.as_ref(),
        );
        Ok((first, n))
    }

    /// As for a file; the trailing partial sample and a short stream are known only once the
    /// stream has ended.
    fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        let name = &self.plan.name;
        if let Some((_, trailing)) = self.ended {
            if trailing > 0 {
                w.push(trailing_bytes_warning(name, trailing, &self.plan.format));
            }
        }
        if let (Some(want), Some(got)) = (self.plan.n_samples, self.delivered_at_end()) {
            if got < want {
                w.push(format!(
                    "{}: the stream ended before the asked-for duration; read {got} samples ({:.6} s) instead",
                    name.display(),
                    got as f64 / self.plan.fs_hz
                ));
            }
        }
        if self.non_finite > 0 {
            w.push(non_finite_warning(name, self.non_finite));
        }
        w
    }
}
