//! Bytes ⇄ samples for every [`SampleFormat`], in the format's own units (see [`crate::format`]).
//!
//! Decoding turns non-finite floats into 0 and counts them. Encoding rounds to the nearest
//! representable value (2-bit: nearest map value, ties to the larger value; 1-bit: +1 when
//! the value is > 0, else -1, as GPS-SDR-SIM does), saturates, and counts what it clipped.
//! `ri1` stores the sign bit (1 = negative), `ci1` the opposite (1 = positive).

use num_complex::Complex32;

use crate::format::SampleFormat;

/// Decodes `out.len()` samples from `bytes`, starting `first` samples into `bytes` (non-zero only
/// for packed formats, whose samples do not start on byte boundaries). Returns how many
/// non-finite components were replaced by 0.
///
/// The caller guarantees that `bytes` holds `first + out.len()` samples.
pub(crate) fn decode(
    format: &SampleFormat,
    bytes: &[u8],
    first: usize,
    out: &mut [Complex32],
) -> u64 {
    fn finite(v: f32, bad: &mut u64) -> f32 {
        if v.is_finite() {
            v
        } else {
            *bad += 1;
            0.0
        }
    }
    let mut bad = 0u64;
    match format {
        SampleFormat::Ci8 => {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(2)) {
                *o = Complex32::new(f32::from(b[0] as i8), f32::from(b[1] as i8));
            }
        }
        SampleFormat::Cu8 { zero } => {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(2)) {
                *o = Complex32::new(f32::from(b[0]) - zero, f32::from(b[1]) - zero);
            }
        }
        SampleFormat::Ci16Le => {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(4)) {
                let i = i16::from_le_bytes([b[0], b[1]]);
                let q = i16::from_le_bytes([b[2], b[3]]);
                *o = Complex32::new(f32::from(i), f32::from(q));
            }
        }
        SampleFormat::Cf32Le => {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(8)) {
                let i = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                let q = f32::from_le_bytes([b[4], b[5], b[6], b[7]]);
                *o = Complex32::new(finite(i, &mut bad), finite(q, &mut bad));
            }
        }
        SampleFormat::Cf64Le => {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(16)) {
                let mut i = [0u8; 8];
                let mut q = [0u8; 8];
                i.copy_from_slice(&b[..8]);
                q.copy_from_slice(&b[8..]);
                let i = f64::from_le_bytes(i) as f32;
                let q = f64::from_le_bytes(q) as f32;
                *o = Complex32::new(finite(i, &mut bad), finite(q, &mut bad));
            }
        }
        SampleFormat::Ri8 => {
            for (o, &b) in out.iter_mut().zip(bytes) {
                *o = Complex32::new(f32::from(b as i8), 0.0);
            }
        }
        SampleFormat::Ri16Le => {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(2)) {
                *o = Complex32::new(f32::from(i16::from_le_bytes([b[0], b[1]])), 0.0);
            }
        }
        SampleFormat::Rf32Le => {
            for (o, b) in out.iter_mut().zip(bytes.chunks_exact(4)) {
                let v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                *o = Complex32::new(finite(v, &mut bad), 0.0);
            }
        }
        SampleFormat::Packed2 {
            complex,
            map,
            msb_first,
        } => {
            // Component j (I and Q count separately for complex) sits in byte j / 4, slot j % 4.
            let code = |j: usize| {
                let slot = (j % 4) as u32;
                let shift = if *msb_first { 6 - 2 * slot } else { 2 * slot };
                usize::from((bytes[j / 4] >> shift) & 0b11)
            };
            if *complex {
                for (k, o) in out.iter_mut().enumerate() {
                    let j = 2 * (first + k);
                    *o = Complex32::new(map[code(j)], map[code(j + 1)]);
                }
            } else {
                for (k, o) in out.iter_mut().enumerate() {
                    *o = Complex32::new(map[code(first + k)], 0.0);
                }
            }
        }
        SampleFormat::Packed1Complex => {
            let bit = |j: usize| {
                if (bytes[j / 8] >> (7 - (j % 8) as u32)) & 1 == 1 {
                    1.0
                } else {
                    -1.0
                }
            };
            for (k, o) in out.iter_mut().enumerate() {
                let j = 2 * (first + k);
                *o = Complex32::new(bit(j), bit(j + 1));
            }
        }
        SampleFormat::Packed1Real { lsb_first } => {
            for (k, o) in out.iter_mut().enumerate() {
                let j = first + k;
                let shift = if *lsb_first { j % 8 } else { 7 - j % 8 } as u32;
                let v = if (bytes[j / 8] >> shift) & 1 == 1 {
                    -1.0
                } else {
                    1.0
                };
                *o = Complex32::new(v, 0.0);
            }
        }
    }
    bad
}

/// Counters an [`Encoder`] keeps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct EncodeCounts {
    /// Components that were saturated.
    pub clipped: u64,
    /// Non-finite components (written as 0, or as is for float formats).
    pub non_finite: u64,
}

/// Nearest-level quantiser for a 2-bit map.
#[derive(Debug, Clone)]
struct Packed2Quantiser {
    /// Levels sorted ascending with their codes.
    levels: [(f32, u8); 4],
    /// Values below `lo` or above `hi` count as clipped.
    lo: f32,
    hi: f32,
}

impl Packed2Quantiser {
    fn new(map: &[f32; 4]) -> Self {
        let mut levels = [(map[0], 0u8), (map[1], 1), (map[2], 2), (map[3], 3)];
        levels.sort_by(|a, b| a.0.total_cmp(&b.0));
        let lo = levels[0].0 - 0.5 * (levels[1].0 - levels[0].0);
        let hi = levels[3].0 + 0.5 * (levels[3].0 - levels[2].0);
        Packed2Quantiser { levels, lo, hi }
    }

    /// Code of the nearest level (ties to the larger level).
    fn code(&self, v: f32, counts: &mut EncodeCounts) -> u8 {
        let v = if v.is_finite() {
            v
        } else {
            counts.non_finite += 1;
            0.0
        };
        if v < self.lo || v > self.hi {
            counts.clipped += 1;
        }
        let mut best = self.levels[0];
        for &l in &self.levels[1..] {
            if (v - l.0).abs() <= (v - best.0).abs() {
                best = l;
            }
        }
        best.1
    }
}

/// Appends `n * width` zero bytes to `out` and returns them as `n` chunks of `width`.
fn grow(out: &mut Vec<u8>, width: usize, n: usize) -> std::slice::ChunksExactMut<'_, u8> {
    let start = out.len();
    out.resize(start + width * n, 0);
    out[start..].chunks_exact_mut(width)
}

/// Turns samples into bytes for one format, keeping the partial byte of packed formats between
/// calls.
#[derive(Debug, Clone)]
pub(crate) struct Encoder {
    format: SampleFormat,
    packed2: Option<Packed2Quantiser>,
    /// Bits collected for the next packed byte, and how many bits are in it.
    acc: u8,
    acc_bits: u32,
    pub counts: EncodeCounts,
}

impl Encoder {
    pub fn new(format: &SampleFormat) -> Self {
        let packed2 = match format {
            SampleFormat::Packed2 { map, .. } => Some(Packed2Quantiser::new(map)),
            _ => None,
        };
        Encoder {
            format: format.clone(),
            packed2,
            acc: 0,
            acc_bits: 0,
            counts: EncodeCounts::default(),
        }
    }

    /// Rounds and saturates to `lo..=hi`, counting clips and non-finite values (written as 0).
    fn quantise(v: f32, lo: f32, hi: f32, counts: &mut EncodeCounts) -> f32 {
        if !v.is_finite() {
            counts.non_finite += 1;
            return 0.0_f32.clamp(lo, hi);
        }
        let r = v.round();
        if r > hi {
            counts.clipped += 1;
            hi
        } else if r < lo {
            counts.clipped += 1;
            lo
        } else {
            r
        }
    }

    fn float(v: f32, counts: &mut EncodeCounts) -> f32 {
        if !v.is_finite() {
            counts.non_finite += 1;
        }
        v
    }

    /// Appends one packed field of `bits` bits (MSB-first order of arrival; `lsb_first` places
    /// the first field in the low bits instead).
    fn push_bits(&mut self, field: u8, bits: u32, lsb_first: bool, out: &mut Vec<u8>) {
        if lsb_first {
            self.acc |= field << self.acc_bits;
        } else {
            self.acc |= field << (8 - bits - self.acc_bits);
        }
        self.acc_bits += bits;
        if self.acc_bits == 8 {
            out.push(self.acc);
            self.acc = 0;
            self.acc_bits = 0;
        }
    }

    /// Appends the encoding of `samples` to `out`.
    pub fn encode(&mut self, samples: &[Complex32], out: &mut Vec<u8>) {
        let c = &mut self.counts;
        let q8 = |v: f32, c: &mut EncodeCounts| Self::quantise(v, -128.0, 127.0, c) as i8 as u8;
        let q16 = |v: f32, c: &mut EncodeCounts| Self::quantise(v, -32768.0, 32767.0, c) as i16;
        match &self.format {
            SampleFormat::Ci8 => {
                for (o, s) in grow(out, 2, samples.len()).zip(samples) {
                    o[0] = q8(s.re, c);
                    o[1] = q8(s.im, c);
                }
            }
            SampleFormat::Cu8 { zero } => {
                let zero = *zero;
                out.reserve(2 * samples.len());
                for s in samples {
                    out.push(Self::quantise(s.re + zero, 0.0, 255.0, c) as u8);
                    out.push(Self::quantise(s.im + zero, 0.0, 255.0, c) as u8);
                }
            }
            SampleFormat::Ci16Le => {
                for (o, s) in grow(out, 4, samples.len()).zip(samples) {
                    o[..2].copy_from_slice(&q16(s.re, c).to_le_bytes());
                    o[2..].copy_from_slice(&q16(s.im, c).to_le_bytes());
                }
            }
            SampleFormat::Cf32Le => {
                for (o, s) in grow(out, 8, samples.len()).zip(samples) {
                    o[..4].copy_from_slice(&Self::float(s.re, c).to_le_bytes());
                    o[4..].copy_from_slice(&Self::float(s.im, c).to_le_bytes());
                }
            }
            SampleFormat::Cf64Le => {
                out.reserve(16 * samples.len());
                for s in samples {
                    out.extend_from_slice(&f64::from(Self::float(s.re, c)).to_le_bytes());
                    out.extend_from_slice(&f64::from(Self::float(s.im, c)).to_le_bytes());
                }
            }
            SampleFormat::Ri8 => {
                out.extend(samples.iter().map(|s| q8(s.re, c)));
            }
            SampleFormat::Ri16Le => {
                out.reserve(2 * samples.len());
                for s in samples {
                    out.extend_from_slice(&q16(s.re, c).to_le_bytes());
                }
            }
            SampleFormat::Rf32Le => {
                out.reserve(4 * samples.len());
                for s in samples {
                    out.extend_from_slice(&Self::float(s.re, c).to_le_bytes());
                }
            }
            SampleFormat::Packed2 {
                complex, msb_first, ..
            } => {
                let (complex, lsb_first) = (*complex, !*msb_first);
                let Some(quant) = self.packed2.clone() else {
                    return;
                };
                out.reserve(samples.len() / 2 + 1);
                for s in samples {
                    let code = quant.code(s.re, &mut self.counts);
                    self.push_bits(code, 2, lsb_first, out);
                    if complex {
                        let code = quant.code(s.im, &mut self.counts);
                        self.push_bits(code, 2, lsb_first, out);
                    }
                }
            }
            SampleFormat::Packed1Complex => {
                out.reserve(samples.len() / 4 + 1);
                for s in samples {
                    for v in [s.re, s.im] {
                        let v = if v.is_finite() {
                            v
                        } else {
                            self.counts.non_finite += 1;
                            0.0
                        };
                        if v.abs() > 2.0 {
                            self.counts.clipped += 1;
                        }
                        self.push_bits(u8::from(v > 0.0), 1, false, out);
                    }
                }
            }
            SampleFormat::Packed1Real { lsb_first } => {
                let lsb_first = *lsb_first;
                out.reserve(samples.len() / 8 + 1);
                for s in samples {
                    let v = if s.re.is_finite() {
                        s.re
                    } else {
                        self.counts.non_finite += 1;
                        0.0
                    };
                    if v.abs() > 2.0 {
                        self.counts.clipped += 1;
                    }
                    self.push_bits(u8::from(v <= 0.0), 1, lsb_first, out);
                }
            }
        }
    }

    /// Appends the final partial byte of a packed format, padded with zero bits (nothing for
    /// byte-aligned formats or when the last byte is full).
    pub fn finish(&mut self, out: &mut Vec<u8>) {
        if self.acc_bits > 0 {
            out.push(self.acc);
            self.acc = 0;
            self.acc_bits = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f32, im: f32) -> Complex32 {
        Complex32::new(re, im)
    }

    #[test]
    fn ci2_layout_msb_first() {
        // I0=+1 (00), Q0=+3 (01), I1=-3 (10), Q1=-1 (11) -> 0b00_01_10_11
        let mut e = Encoder::new(&SampleFormat::ci2());
        let mut out = Vec::new();
        e.encode(&[c(1.0, 3.0), c(-3.0, -1.0)], &mut out);
        assert_eq!(out, vec![0b0001_1011]);
        let mut back = [Complex32::default(); 2];
        decode(&SampleFormat::ci2(), &out, 0, &mut back);
        assert_eq!(back, [c(1.0, 3.0), c(-3.0, -1.0)]);
    }

    #[test]
    fn ci2_lsb_layout() {
        let f = SampleFormat::Packed2 {
            complex: true,
            map: crate::format::DEFAULT_PACKED2_MAP,
            msb_first: false,
        };
        let mut e = Encoder::new(&f);
        let mut out = Vec::new();
        e.encode(&[c(1.0, 3.0), c(-3.0, -1.0)], &mut out);
        assert_eq!(out, vec![0b1110_0100]);
    }

    #[test]
    fn ci1_layout_matches_gps_sdr_sim() {
        // I0 Q0 I1 Q1 I2 Q2 I3 Q3 = + - - + + + - -  -> 1001 1100
        let mut e = Encoder::new(&SampleFormat::Packed1Complex);
        let mut out = Vec::new();
        e.encode(
            &[c(5.0, -1.0), c(-0.5, 0.1), c(1.0, 1.0), c(0.0, -9.0)],
            &mut out,
        );
        assert_eq!(out, vec![0b1001_1100]);
        assert_eq!(e.counts.clipped, 2);
    }

    #[test]
    fn ri1_lsb_layout_matches_snappergps() {
        // Samples + - - + + + - + from the least significant bit: bit 1 = negative.
        let f = SampleFormat::Packed1Real { lsb_first: true };
        let mut e = Encoder::new(&f);
        let mut out = Vec::new();
        let v = [1.0, -1.0, -0.5, 2.0, 0.1, 3.0, -3.0, 1.0];
        let samples: Vec<Complex32> = v.iter().map(|&x| c(x, 0.0)).collect();
        e.encode(&samples, &mut out);
        assert_eq!(out, vec![0b0100_0110]);
        assert_eq!(e.counts.clipped, 2);
        let mut back = [Complex32::default(); 8];
        decode(&f, &out, 0, &mut back);
        let signs: Vec<f32> = back.iter().map(|s| s.re).collect();
        assert_eq!(signs, vec![1.0, -1.0, -1.0, 1.0, 1.0, 1.0, -1.0, 1.0]);
        // The same bits MSB first read in the opposite order; a start inside the byte.
        let msb = SampleFormat::Packed1Real { lsb_first: false };
        let mut back = [Complex32::default(); 3];
        decode(&msb, &[0b0100_0110], 5, &mut back);
        assert_eq!(back.map(|s| s.re), [-1.0, -1.0, 1.0]);
    }

    #[test]
    fn packed_partial_byte_is_zero_padded() {
        let mut e = Encoder::new(&SampleFormat::ri2());
        let mut out = Vec::new();
        e.encode(&[c(-1.0, 0.0)], &mut out);
        assert!(out.is_empty());
        e.finish(&mut out);
        assert_eq!(out, vec![0b1100_0000]);
    }

    #[test]
    fn ints_round_and_saturate() {
        let mut e = Encoder::new(&SampleFormat::Ci8);
        let mut out = Vec::new();
        e.encode(&[c(127.6, -128.4), c(f32::NAN, 2.5)], &mut out);
        assert_eq!(out, vec![127, 128, 0, 3]);
        assert_eq!(e.counts.clipped, 1);
        assert_eq!(e.counts.non_finite, 1);
    }
}
