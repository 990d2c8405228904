//! The [`SampleSource`] over a file of raw samples (plain, SigMF data, or a WAV data chunk).

use std::fs::File;

use num_complex::Complex32;

use crate::chunk::{ChunkReader, CHUNK_BYTES};
use crate::codec::decode;
use crate::error::SampleError;
use crate::format::SampleFormat;
use crate::mixer::Mixer;
use crate::resolve::{resolve, Resolved};
use crate::source::{
    non_finite_warning, to_baseband, trailing_bytes_warning, SampleSource, SourceConfig,
};
use crate::span::{bytes_for_samples, sample_position, Span};

/// Streams samples from a file in chunks of at most 1 MiB.
#[derive(Debug)]
pub struct FileSource {
    resolved: Resolved,
    span: Span,
    chunks: ChunkReader,
    /// Next sample to deliver, counted from the start of the data.
    pos: u64,
    /// Most samples decoded per chunk.
    max_block: usize,
    mixer: Option<Mixer>,
    non_finite: u64,
}

impl FileSource {
    /// Resolves and validates `cfg` and opens the data file.
    pub fn open(cfg: &SourceConfig) -> Result<Self, SampleError> {
        let resolved = resolve(cfg)?;
        let span = Span::plan(
            &cfg.path,
            &resolved.format,
            resolved.data_bytes,
            resolved.fs_hz,
            cfg.skip_s,
            cfg.duration_s,
        )?;
        let file = File::open(&resolved.data_path)
            .map_err(|e| SampleError::io("open", &resolved.data_path, e))?;
        let limit = resolved.data_offset + resolved.data_bytes;
        let chunks = ChunkReader::new(file, resolved.data_path.clone(), limit);
        let bits = resolved.format.bits_per_sample() as usize;
        let max_block = (CHUNK_BYTES - 1) * 8 / bits;
        let mixer = (resolved.if_hz != 0.0).then(|| Mixer::new(resolved.if_hz, resolved.fs_hz));
        Ok(FileSource {
            pos: span.first_sample,
            resolved,
            span,
            chunks,
            max_block,
            mixer,
            non_finite: 0,
        })
    }

    /// What was resolved: data file, format, rate, IF, Q sign.
    pub fn resolved(&self) -> &Resolved {
        &self.resolved
    }

    /// Which samples this source delivers.
    pub fn span(&self) -> &Span {
        &self.span
    }

    /// Like [`SampleSource::read`] but without Q inversion or IF mixing: the values as stored
    /// (real formats give Q = 0). Non-finite values still read as 0.
    pub fn read_raw(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let first = self.pos;
        let mut done = 0;
        while done < out.len() && self.pos < self.span.end_sample() {
            let left = self.span.end_sample() - self.pos;
            let n = (out.len() - done)
                .min(self.max_block)
                .min(usize::try_from(left).unwrap_or(usize::MAX));
            let format: &SampleFormat = &self.resolved.format;
            let (byte, phase) = sample_position(format, self.pos);
            let end_byte = bytes_for_samples(format, self.pos + n as u64);
            let len = (end_byte - byte) as usize;
            let bytes = self.chunks.get(self.resolved.data_offset + byte, len)?;
            self.non_finite += decode(format, bytes, phase, &mut out[done..done + n]);
            self.pos += n as u64;
            done += n;
        }
        Ok((first, done))
    }

    /// Samples left to deliver.
    pub fn remaining(&self) -> u64 {
        self.span.end_sample() - self.pos
    }
}

impl SampleSource for FileSource {
    fn fs_hz(&self) -> f64 {
        self.resolved.fs_hz
    }

    fn format(&self) -> &SampleFormat {
        &self.resolved.format
    }

    fn total_samples(&self) -> Option<u64> {
        Some(self.span.n_samples)
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let (first, n) = self.read_raw(out)?;
        to_baseband(
            &mut out[..n],
            first,
            self.resolved.invert_q,
            self.mixer.as_ref(),
        );
        Ok((first, n))
    }

    fn warnings(&self) -> Vec<String> {
        let mut w = self.resolved.warnings.clone();
        let data_path = &self.resolved.data_path;
        let path = data_path.display();
        if self.span.trailing_bytes > 0 {
            w.push(trailing_bytes_warning(
                data_path,
                self.span.trailing_bytes,
                &self.resolved.format,
            ));
        }
        if self.span.duration_truncated {
            w.push(format!(
                "{path}: the asked-for duration runs past the end of the file; reading {} samples ({:.6} s) instead",
                self.span.n_samples,
                self.span.n_samples as f64 / self.resolved.fs_hz
            ));
        }
        if self.non_finite > 0 {
            w.push(non_finite_warning(data_path, self.non_finite));
        }
        w
    }
}
