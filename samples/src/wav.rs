//! WAV files as IF recordings (read and write), through `hound`.
//!
//! Reading: 16-bit PCM or 32-bit float, 1 channel = real samples (`ri16_le`, `rf32_le`),
//! 2 channels = I and Q (`ci16_le`, `cf32_le`); 8-bit PCM with 2 channels is unsigned I/Q (`cu8`
//! with zero 128). The sampling rate is the header's. Samples are streamed from the `data` chunk
//! like any raw file.
//!
//! Writing: 16-bit PCM, 1 channel (real part) or 2 channels (I, Q), samples in `i16` units.

use std::fs::File;
use std::io::{BufReader, BufWriter, Seek};
use std::path::{Path, PathBuf};

use num_complex::Complex32;

use crate::codec::Encoder;
use crate::error::SampleError;
use crate::format::SampleFormat;
use crate::writer::{SampleWriter, WriteStats};

/// Where the samples of a WAV file are and how they are stored.
#[derive(Debug, Clone, PartialEq)]
pub struct WavLayout {
    /// The samples' format.
    pub format: SampleFormat,
    /// Sampling rate from the header.
    pub fs_hz: f64,
    /// Byte offset of the first sample.
    pub data_offset: u64,
    /// Bytes of sample data.
    pub data_bytes: u64,
}

/// True when the file starts with a RIFF/WAVE header.
pub fn looks_like_wav(path: &Path) -> bool {
    let mut head = [0u8; 12];
    File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .is_ok()
        && &head[0..4] == b"RIFF"
        && &head[8..12] == b"WAVE"
}

/// Reads a WAV header and locates its sample data.
pub fn read_wav_layout(path: &Path) -> Result<WavLayout, SampleError> {
    let file = File::open(path).map_err(|e| SampleError::io("open", path, e))?;
    let reader =
        hound::WavReader::new(BufReader::new(file)).map_err(|source| SampleError::Wav {
            path: path.to_path_buf(),
            source,
        })?;
    let spec = reader.spec();
    let values = u64::from(reader.len());
    let unsupported = |reason: String| SampleError::UnsupportedWav {
        path: path.to_path_buf(),
        reason,
    };
    let format = match (spec.sample_format, spec.bits_per_sample, spec.channels) {
        (hound::SampleFormat::Int, 16, 1) => SampleFormat::Ri16Le,
        (hound::SampleFormat::Int, 16, 2) => SampleFormat::Ci16Le,
        (hound::SampleFormat::Int, 8, 2) => SampleFormat::Cu8 { zero: 128.0 },
        (hound::SampleFormat::Float, 32, 1) => SampleFormat::Rf32Le,
        (hound::SampleFormat::Float, 32, 2) => SampleFormat::Cf32Le,
        (kind, bits, channels) => {
            let kind = match kind {
                hound::SampleFormat::Int => "PCM",
                hound::SampleFormat::Float => "float",
            };
            return Err(unsupported(format!(
                "{bits}-bit {kind} samples in {channels} channel(s)"
            )));
        }
    };
    let data_bytes = values * u64::from(spec.bits_per_sample / 8);
    let mut inner = reader.into_inner();
    let data_offset = inner
        .stream_position()
        .map_err(|e| SampleError::io("seek in", path, e))?;
    Ok(WavLayout {
        format,
        fs_hz: f64::from(spec.sample_rate),
        data_offset,
        data_bytes,
    })
}

/// A 16-bit WAV writer.
struct WavWriter {
    writer: hound::WavWriter<BufWriter<File>>,
    path: PathBuf,
    encoder: Encoder,
    scratch: Vec<u8>,
    samples: u64,
}

impl std::fmt::Debug for WavWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WavWriter")
            .field("path", &self.path)
            .field("samples", &self.samples)
            .finish_non_exhaustive()
    }
}

impl SampleWriter for WavWriter {
    fn write(&mut self, samples: &[Complex32]) -> Result<(), SampleError> {
        for block in samples.chunks(1 << 16) {
            self.scratch.clear();
            self.encoder.encode(block, &mut self.scratch);
            for b in self.scratch.chunks_exact(2) {
                self.writer
                    .write_sample(i16::from_le_bytes([b[0], b[1]]))
                    .map_err(|source| SampleError::Wav {
                        path: self.path.clone(),
                        source,
                    })?;
            }
            self.samples += block.len() as u64;
        }
        Ok(())
    }

    fn finish(self: Box<Self>) -> Result<WriteStats, SampleError> {
        let WavWriter {
            writer,
            path,
            encoder,
            samples,
            ..
        } = *self;
        writer.finalize().map_err(|source| SampleError::Wav {
            path: path.clone(),
            source,
        })?;
        let bytes_written = std::fs::metadata(&path)
            .map_err(|e| SampleError::io("read the size of", &path, e))?
            .len();
        Ok(WriteStats {
            samples_written: samples,
            clipped: encoder.counts.clipped,
            bytes_written,
            non_finite: encoder.counts.non_finite,
        })
    }
}

/// Creates a 16-bit PCM WAV file at `fs_hz`: 2 channels (I, Q) when `complex`, else 1 (the real
/// part). Values are in `i16` units, rounded and saturated like `ci16_le`.
pub fn create_wav_writer(
    path: &Path,
    fs_hz: u32,
    complex: bool,
) -> Result<Box<dyn SampleWriter>, SampleError> {
    let spec = hound::WavSpec {
        channels: if complex { 2 } else { 1 },
        sample_rate: fs_hz,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let writer = hound::WavWriter::create(path, spec).map_err(|source| SampleError::Wav {
        path: path.to_path_buf(),
        source,
    })?;
    let format = if complex {
        SampleFormat::Ci16Le
    } else {
        SampleFormat::Ri16Le
    };
    Ok(Box::new(WavWriter {
        writer,
        path: path.to_path_buf(),
        encoder: Encoder::new(&format),
        scratch: Vec::new(),
        samples: 0,
    }))
}
