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
    held_gain, non_finite_warning, quantize_to_ci16, to_baseband, trailing_bytes_warning,
    IntegerFormat, IntegerSamplesMut, SampleSource, SourceConfig,
};
use crate::span::{bytes_for_samples, sample_position, Span};

/// Samples converted to ci16 per step of [`FileSource::read_converted`] (a 256 KiB f32 copy).
const CONVERT_SAMPLES: usize = 32 * 1024;

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
    /// The f32 samples of a read converted to ci16 ([`FileSource::read_converted`]), kept
    /// between reads.
    converted: Vec<Complex32>,
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
            converted: Vec::new(),
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
        let mut non_finite = 0;
        let read = self.for_each_chunk(out.len(), |format, bytes, phase, range| {
            non_finite += decode(format, bytes, phase, &mut out[range]);
        });
        self.non_finite += non_finite;
        read
    }

    /// Hands the bytes of the next `wanted` samples (fewer at the end of the span) to `take`
    /// chunk by chunk, with the sample offset into the chunk's first byte and the samples'
    /// range in the request; returns (index of the first sample, samples handed over).
    fn for_each_chunk(
        &mut self,
        wanted: usize,
        mut take: impl FnMut(&SampleFormat, &[u8], usize, std::ops::Range<usize>),
    ) -> Result<(u64, usize), SampleError> {
        let first = self.pos;
        let mut done = 0;
        while done < wanted && self.pos < self.span.end_sample() {
            let left = self.span.end_sample() - self.pos;
            let n = (wanted - done)
                .min(self.max_block)
                .min(usize::try_from(left).unwrap_or(usize::MAX));
            let format: &SampleFormat = &self.resolved.format;
            let (byte, phase) = sample_position(format, self.pos);
            let end_byte = bytes_for_samples(format, self.pos + n as u64);
            let len = (end_byte - byte) as usize;
            let bytes = self.chunks.get(self.resolved.data_offset + byte, len)?;
            take(format, bytes, phase, done..done + n);
            self.pos += n as u64;
            done += n;
        }
        Ok((first, done))
    }

    /// Whether the samples are complex integers the int16 correlators read as stored: ci8 or
    /// ci16 at IF 0 with Q as stored.
    fn as_stored(&self) -> bool {
        let r = &self.resolved;
        r.if_hz == 0.0
            && !r.invert_q
            && matches!(r.format, SampleFormat::Ci8 | SampleFormat::Ci16Le)
    }

    /// `2 zero` for cu8 at IF 0 with Q as stored, `gain` 2 and a zero that is a multiple of
    /// 1/2 within 0..=255 (127.5: 255): the held value `2 code - 2 zero` is then exact integer
    /// arithmetic.
    fn cu8_offset(&self, gain: f32) -> Option<i16> {
        let r = &self.resolved;
        match r.format {
            SampleFormat::Cu8 { zero } if r.if_hz == 0.0 && !r.invert_q && gain == 2.0 => {
                let twice = 2.0 * zero;
                (twice.fract() == 0.0 && (0.0..=510.0).contains(&twice)).then_some(twice as i16)
            }
            _ => None,
        }
    }

    /// For a real recording on an IF of exactly +-fs/4 (16.368 MHz sampling with a 4.092 MHz
    /// IF, say): the oscillator `exp(-j 2 pi IF n / fs)` is `(-j)^n` (+fs/4, `Some(-1)`) or
    /// `j^n` (-fs/4, `Some(1)`), so the mixing is exact in integers.
    fn quarter_rate_turn(&self) -> Option<i32> {
        let r = &self.resolved;
        if !matches!(r.format, SampleFormat::Ri8 | SampleFormat::Ri16Le) {
            return None;
        }
        // As the mixer reduces it (crate::mixer::Mixer::new).
        let c = (r.if_hz / r.fs_hz).rem_euclid(1.0);
        if c == 0.25 {
            Some(-1)
        } else if c == 0.75 {
            Some(1)
        } else {
            None
        }
    }

    /// [`FileSource::read_converted`] of a real recording on an IF of +-fs/4 ([`FileSource::quarter_rate_turn`]):
    /// sample `n` (absolute) times `gain` times `turn^n j^n`, straight from the bytes (the
    /// values the f32 mixer gives, rounded, without it: 4 cases of a sign and a swap).
    fn read_quarter_rate(
        &mut self,
        out: &mut [[i16; 2]],
        gain: f32,
        turn: i32,
    ) -> Result<(u64, usize), SampleError> {
        let first = self.pos;
        let gain = gain as i32;
        let sat = |v: i32| v.clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16;
        self.for_each_chunk(out.len(), |format, bytes, _, range| {
            let start = first + range.start as u64;
            let values: Box<dyn Iterator<Item = i32> + '_> = match format {
                SampleFormat::Ri8 => Box::new(bytes.iter().map(|&b| i32::from(b as i8))),
                _ => Box::new(
                    bytes
                        .chunks_exact(2)
                        .map(|b| i32::from(i16::from_le_bytes([b[0], b[1]]))),
                ),
            };
            for (k, (o, x)) in out[range].iter_mut().zip(values).enumerate() {
                let v = x * gain;
                // (turn j)^n: 1, turn j, -1, -turn j.
                *o = match (start + k as u64) % 4 {
                    0 => [sat(v), 0],
                    1 => [0, sat(turn * v)],
                    2 => [sat(-v), 0],
                    _ => [0, sat(-turn * v)],
                };
            }
        })
    }

    /// Samples left to deliver.
    pub fn remaining(&self) -> u64 {
        self.span.end_sample() - self.pos
    }

    /// [`SampleSource::read`] into `out` as ci16: the complex baseband values (decoded, Q
    /// inverted, mixed from the IF) times [`SampleSource::integer_gain`], rounded
    /// ([`quantize_to_ci16`]), in pieces of at most [`CONVERT_SAMPLES`] so that the f32 copy
    /// stays small.
    fn read_converted(&mut self, out: &mut [[i16; 2]]) -> Result<(u64, usize), SampleError> {
        let gain = self.integer_gain();
        if let Some(offset) = self.cu8_offset(gain) {
            // cu8 at IF 0, Q as stored, its zero a multiple of 1/2: gain x code - gain x zero,
            // exact, straight from the bytes.
            return self.for_each_chunk(out.len(), |_, bytes, _, range| {
                for (o, b) in out[range].iter_mut().zip(bytes.chunks_exact(2)) {
                    *o = [2 * i16::from(b[0]) - offset, 2 * i16::from(b[1]) - offset];
                }
            });
        }
        if let Some(turn) = self.quarter_rate_turn() {
            return self.read_quarter_rate(out, gain, turn);
        }
        let mut buf = std::mem::take(&mut self.converted);
        let first = self.pos;
        let mut done = 0;
        let result = loop {
            let want = (out.len() - done).min(CONVERT_SAMPLES);
            if want == 0 {
                break Ok((first, done));
            }
            buf.resize(want, Complex32::new(0.0, 0.0));
            match self.read(&mut buf) {
                Ok((_, 0)) => break Ok((first, done)),
                Ok((_, n)) => {
                    quantize_to_ci16(&buf[..n], gain, &mut out[done..done + n]);
                    done += n;
                }
                Err(e) => break Err(e),
            }
        };
        self.converted = buf;
        result
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

    /// ci8 and ci16 at IF 0 with Q as stored: handed over as stored; every other integer
    /// format (cu8, ri8, ri16, and ci8/ci16 mixed from an IF or with Q inverted): ci16, the
    /// values [`SampleSource::read`] gives times [`held_gain`], rounded
    /// (converted per 32 Ki samples as they are read).
    fn integer_format(&self) -> Option<IntegerFormat> {
        match self.resolved.format {
            SampleFormat::Ci8 if self.as_stored() => Some(IntegerFormat::Ci8),
            SampleFormat::Ci16Le if self.as_stored() => Some(IntegerFormat::Ci16),
            ref f => held_gain(f).map(|_| IntegerFormat::Ci16),
        }
    }

    fn integer_gain(&self) -> f32 {
        if self.as_stored() {
            1.0
        } else {
            held_gain(&self.resolved.format).unwrap_or(1.0)
        }
    }

    fn read_integer(&mut self, out: IntegerSamplesMut<'_>) -> Result<(u64, usize), SampleError> {
        let asked = out.format();
        if self.integer_format() != Some(asked) {
            return Err(SampleError::NoIntegerRead { asked });
        }
        let as_stored = self.as_stored();
        match out {
            IntegerSamplesMut::Ci8(out) => {
                // Stored as wanted: read straight into `out`.
                let first = self.pos;
                let left = self.span.end_sample() - self.pos;
                let n = out.len().min(usize::try_from(left).unwrap_or(usize::MAX));
                let dst: &mut [u8] = bytemuck::cast_slice_mut(&mut out[..n]);
                let (byte, _) = sample_position(&self.resolved.format, self.pos);
                self.chunks
                    .read_into(self.resolved.data_offset + byte, dst)?;
                self.pos += n as u64;
                Ok((first, n))
            }
            IntegerSamplesMut::Ci16(out) if as_stored => {
                self.for_each_chunk(out.len(), |_, bytes, _, range| {
                    for (o, b) in out[range].iter_mut().zip(bytes.chunks_exact(4)) {
                        *o = [
                            i16::from_le_bytes([b[0], b[1]]),
                            i16::from_le_bytes([b[2], b[3]]),
                        ];
                    }
                })
            }
            IntegerSamplesMut::Ci16(out) => self.read_converted(out),
        }
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
