//! The samples a search reads, in the format they are held in (complex f32, or the 8- and
//! 16-bit integers of the recording): converted to f32 one block at a time, so a search
//! never holds an f32 copy of all its samples (10 ms x 50 at 4 MHz: 16 MB).

use crate::correlator::SampleSlice;
use num_complex::Complex32;

/// Writes samples `from..from + out.len()` of `src` into `out` as complex f32 (integers are
/// exact in f32). Panics if the range is outside `src` (the engine checks lengths first).
/// (AVX2-wide where the CPU has it: [`super::wide`].)
pub(super) fn copy_cf32(src: SampleSlice<'_>, from: usize, out: &mut [Complex32]) {
    super::wide::copy_cf32(src, from, out);
}

/// Samples `from..to` of `src` as complex f32: borrowed when held so, else converted into
/// `buf` (one code period at a time in the refinement, so a search never holds an f32 copy
/// of its refinement's samples either: 102 ms at 4 MHz would be 3.3 MB). Panics if the range
/// is outside `src` (callers check lengths first).
pub(super) fn span_cf32<'a>(
    src: SampleSlice<'a>,
    from: usize,
    to: usize,
    buf: &'a mut Vec<Complex32>,
) -> &'a [Complex32] {
    match src {
        SampleSlice::Cf32(x) => &x[from..to],
        _ => {
            buf.clear();
            buf.resize(to - from, Complex32::new(0.0, 0.0));
            copy_cf32(src, from, buf);
            buf
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_convert_exactly_and_f32_is_borrowed() {
        let ci8 = [[1i8, -2], [127, -128], [0, 5]];
        let mut out = [Complex32::new(9.0, 9.0); 2];
        copy_cf32(SampleSlice::Ci8(&ci8), 1, &mut out);
        assert_eq!(
            out,
            [Complex32::new(127.0, -128.0), Complex32::new(0.0, 5.0)]
        );
        let ci16 = [[7i16, 7], [-32768, 32767], [3, 4]];
        let mut buf = Vec::new();
        let h = span_cf32(SampleSlice::Ci16(&ci16), 1, 3, &mut buf);
        assert_eq!(
            h,
            &[Complex32::new(-32768.0, 32767.0), Complex32::new(3.0, 4.0)]
        );
        let f = [Complex32::new(0.5, -0.25); 3];
        let mut unused = Vec::new();
        let b = span_cf32(SampleSlice::Cf32(&f), 1, 3, &mut unused);
        assert_eq!(b.as_ptr(), f[1..].as_ptr());
        assert!(unused.is_empty());
    }
}
