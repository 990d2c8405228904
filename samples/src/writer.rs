//! Writing IF samples: raw files in any [`SampleFormat`], and 16-bit WAV.
//!
//! Samples are given **in the format's units** (`ci8`: full scale is about ±127; `ci2`: the map
//! values ±1, ±3; `ci1`: the sign; real formats take the real part). Integer formats round to the
//! nearest value (halves away from zero) and saturate; 2-bit formats pick the nearest map value
//! (thresholds halfway between values, ties to the larger value); `ci1` writes bit 1 for
//! positive values and bit 0 (= -1) otherwise. Non-finite values are written as 0 (floats: as
//! they are) and counted.
//!
//! A value counts as clipped when it lies more than half a step beyond the outermost level:
//! outside -128.5..127.5 for 8-bit, outside -4..4 for the default 2-bit map, |v| > 2 for `ci1`.
//!
//! Packed formats write a final partial byte padded with zero bits (see [`crate::format`]).
//! Always call [`SampleWriter::finish`]: it writes that byte and flushes; dropping a writer
//! without it may lose the end of the data.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use num_complex::Complex32;

use crate::codec::Encoder;
use crate::error::SampleError;
use crate::format::SampleFormat;

pub use crate::wav::create_wav_writer;

/// Output buffer size (1 MiB).
const WRITE_BUFFER_BYTES: usize = 1 << 20;

/// Samples encoded per pass, bounding the scratch buffer.
const ENCODE_BLOCK: usize = 1 << 16;

/// What a writer did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct WriteStats {
    /// Samples passed to `write`.
    pub samples_written: u64,
    /// Components (I or Q, or real values) that were saturated.
    pub clipped: u64,
    /// Bytes in the file (for WAV including the header).
    pub bytes_written: u64,
    /// Non-finite components met.
    pub non_finite: u64,
}

/// A sink for IF samples.
pub trait SampleWriter: Send {
    /// Writes samples given in the format's units (see the module documentation): rounds to
    /// nearest, saturates, counts clipped values.
    fn write(&mut self, samples: &[Complex32]) -> Result<(), SampleError>;

    /// Writes any pending partial byte, flushes, and reports what was written.
    fn finish(self: Box<Self>) -> Result<WriteStats, SampleError>;
}

/// A buffered writer of raw samples in one format.
#[derive(Debug)]
struct RawWriter {
    out: BufWriter<File>,
    path: PathBuf,
    encoder: Encoder,
    scratch: Vec<u8>,
    samples: u64,
    bytes: u64,
}

impl SampleWriter for RawWriter {
    fn write(&mut self, samples: &[Complex32]) -> Result<(), SampleError> {
        for block in samples.chunks(ENCODE_BLOCK) {
            self.scratch.clear();
            self.encoder.encode(block, &mut self.scratch);
            self.out
                .write_all(&self.scratch)
                .map_err(|e| SampleError::io("write", &self.path, e))?;
            self.bytes += self.scratch.len() as u64;
            self.samples += block.len() as u64;
        }
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> Result<WriteStats, SampleError> {
        self.scratch.clear();
        self.encoder.finish(&mut self.scratch);
        self.out
            .write_all(&self.scratch)
            .and_then(|()| self.out.flush())
            .map_err(|e| SampleError::io("write", &self.path, e))?;
        self.bytes += self.scratch.len() as u64;
        Ok(WriteStats {
            samples_written: self.samples,
            clipped: self.encoder.counts.clipped,
            bytes_written: self.bytes,
            non_finite: self.encoder.counts.non_finite,
        })
    }
}

/// Creates (or truncates) `path` and returns a buffered writer of `format` samples.
pub fn create_writer(
    path: &Path,
    format: &SampleFormat,
) -> Result<Box<dyn SampleWriter>, SampleError> {
    format.validate()?;
    let file = File::create(path).map_err(|e| SampleError::io("create", path, e))?;
    Ok(Box::new(RawWriter {
        out: BufWriter::with_capacity(WRITE_BUFFER_BYTES, file),
        path: path.to_path_buf(),
        encoder: Encoder::new(format),
        scratch: Vec::with_capacity(ENCODE_BLOCK * 16),
        samples: 0,
        bytes: 0,
    }))
}
