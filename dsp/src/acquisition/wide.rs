//! The element-wise loops of a search compiled a second time for AVX2, taken when the CPU has
//! it: the build targets baseline x86-64 (SSE2), where these loops ran four lanes wide or,
//! for the rounding of [`super::spectra::quantize`], one value at a time through `roundf`.
//!
//! Each AVX2 version is the very same Rust body (`#[inline(always)]` into a
//! `#[target_feature(enable = "avx2")]` function): the same operations on each element in the
//! same order, without FMA (Rust never contracts a multiply and an add), so the results are
//! bit for bit those of the portable loop (the tests compare them exactly): only the width of
//! the vectors changes. Measured on 60 s of 4 MHz ci8 with the defaults (AVX-512 Xeon): the
//! power accumulation of the grid, the quantization of the block spectra, the conversion of
//! the samples and the grid's maximum took about 5 % of the process CPU time at SSE2 width.

use crate::correlator::SampleSlice;
use num_complex::Complex32;

/// Whether the AVX2 versions run (checked once per call: a cached atomic load).
#[inline(always)]
fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Defines `pub(super) fn $name` that runs `$body` compiled for AVX2 when the CPU has it,
/// else as built.
macro_rules! multiversion {
    ($(#[$doc:meta])* fn $name:ident$(<$lt:lifetime>)?($($arg:ident: $ty:ty),*) $(-> $ret:ty)? $body:block) => {
        $(#[$doc])*
        pub(super) fn $name$(<$lt>)?($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn body$(<$lt>)?($($arg: $ty),*) $(-> $ret)? $body
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            unsafe fn wide$(<$lt>)?($($arg: $ty),*) $(-> $ret)? {
                body($($arg),*)
            }
            #[cfg(target_arch = "x86_64")]
            if avx2() {
                // SAFETY: the CPU supports AVX2 (checked).
                return unsafe { wide($($arg),*) };
            }
            body($($arg),*)
        }
    };
}

multiversion! {
    /// `dst[t] += scale |src[t]|^2` for the common length: one block's power added to a grid
    /// row.
    fn add_power(dst: &mut [f32], src: &[Complex32], scale: f32) {
        for (g, y) in dst.iter_mut().zip(src) {
            *g += scale * y.norm_sqr();
        }
    }
}

multiversion! {
    /// The largest `|re|`, `|im|` of `src` (NaN ignored; 0 for an empty slice): `f32::max`
    /// returns one of its operands, so the running maxima of 8 lanes, then their maximum,
    /// are the maximum of the sequential fold exactly.
    fn peak_component(src: &[Complex32]) -> f32 {
        let mut lanes = [0.0f32; 8];
        let mut chunks = src.chunks_exact(4);
        for c in chunks.by_ref() {
            for (k, x) in c.iter().enumerate() {
                lanes[2 * k] = lanes[2 * k].max(x.re.abs());
                lanes[2 * k + 1] = lanes[2 * k + 1].max(x.im.abs());
            }
        }
        let tail = chunks
            .remainder()
            .iter()
            .fold(0.0f32, |m, x| m.max(x.re.abs()).max(x.im.abs()));
        lanes.iter().fold(tail, |m, &v| m.max(v))
    }
}

multiversion! {
    /// `dst[t] = round(src[t] inv)` per component (half away from zero, saturating to i16).
    fn round_scaled(src: &[Complex32], inv: f32, dst: &mut [[i16; 2]]) {
        for (d, x) in dst.iter_mut().zip(src) {
            *d = [(x.re * inv).round() as i16, (x.im * inv).round() as i16];
        }
    }
}

multiversion! {
    /// Samples `from..from + out.len()` of `src` as complex f32 (integers are exact in f32).
    /// Panics if the range is outside `src`.
    fn copy_cf32<'a>(src: SampleSlice<'a>, from: usize, out: &mut [Complex32]) {
        let to = from + out.len();
        match src {
            SampleSlice::Cf32(x) => out.copy_from_slice(&x[from..to]),
            SampleSlice::Ci8(x) => {
                for (o, &[i, q]) in out.iter_mut().zip(&x[from..to]) {
                    *o = Complex32::new(f32::from(i), f32::from(q));
                }
            }
            SampleSlice::Ci16(x) => {
                for (o, &[i, q]) in out.iter_mut().zip(&x[from..to]) {
                    *o = Complex32::new(f32::from(i), f32::from(q));
                }
            }
        }
    }
}

multiversion! {
    /// The largest value of `cells` and the index of its first occurrence, `(-inf, 0)` when
    /// no value exceeds -inf (empty, or only NaN and -inf): the fold `if v > best` of
    /// [`super::detect`] in two vector passes (the maximum, then the first cell equal to it).
    fn first_max(cells: &[f32]) -> (f32, usize) {
        let mut lanes = [f32::NEG_INFINITY; 8];
        let mut chunks = cells.chunks_exact(8);
        for c in chunks.by_ref() {
            for (l, &v) in lanes.iter_mut().zip(c) {
                *l = if v > *l { v } else { *l };
            }
        }
        let mut best = chunks
            .remainder()
            .iter()
            .fold(f32::NEG_INFINITY, |m, &v| if v > m { v } else { m });
        for &v in &lanes {
            best = if v > best { v } else { best };
        }
        if best == f32::NEG_INFINITY {
            return (best, 0);
        }
        let at = cells.iter().position(|&v| v == best).unwrap_or(0);
        (best, at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values with every kind of rounding case: halves, large and tiny magnitudes, signs.
    fn values(n: usize) -> Vec<Complex32> {
        (0..n)
            .map(|k| {
                let t = k as f32;
                let re = match k % 5 {
                    0 => t + 0.5,
                    1 => -(t + 0.5),
                    2 => (0.37 * t).sin() * 3.0e4,
                    3 => 1e-3 * t,
                    _ => -(t * 977.0 % 32767.0),
                };
                Complex32::new(re, (1.7 * t).cos() * -2.5e3)
            })
            .collect()
    }

    #[test]
    fn every_wide_loop_gives_the_sequential_results_exactly() {
        for n in [0, 1, 3, 4, 7, 8, 9, 31, 4001] {
            let src = values(n);
            // Power: the plain loop, exactly.
            let mut got = vec![1.25f32; n];
            add_power(&mut got, &src, 0.75);
            let want: Vec<f32> = src.iter().map(|y| 1.25 + 0.75 * y.norm_sqr()).collect();
            assert_eq!(got, want, "add_power, {n} values");
            // Peak: the sequential fold.
            let want = src
                .iter()
                .fold(0.0f32, |m, x| m.max(x.re.abs()).max(x.im.abs()));
            assert_eq!(peak_component(&src), want, "peak, {n} values");
            // Rounding: f32::round (half away from zero) of each component.
            let inv = 1.0 / 0.5;
            let mut got = vec![[7i16, 7]; n];
            round_scaled(&src, inv, &mut got);
            for (x, g) in src.iter().zip(&got) {
                let w = [(x.re * inv).round() as i16, (x.im * inv).round() as i16];
                assert_eq!(*g, w, "round of {x}");
            }
            // First maximum: the fold `if v > best`.
            let cells: Vec<f32> = src.iter().map(|x| x.re.abs().min(1e3)).collect();
            let want = cells
                .iter()
                .enumerate()
                .fold((f32::NEG_INFINITY, 0usize), |b, (i, &v)| {
                    if v > b.0 {
                        (v, i)
                    } else {
                        b
                    }
                });
            assert_eq!(first_max(&cells), want, "first_max, {n} values");
        }
    }

    #[test]
    fn the_first_of_equal_maxima_is_found_and_nan_is_skipped() {
        let mut cells = vec![0.5f32; 40];
        cells[3] = f32::NAN;
        cells[17] = 2.0;
        cells[33] = 2.0;
        assert_eq!(first_max(&cells), (2.0, 17));
        assert_eq!(first_max(&[f32::NAN, f32::NAN]), (f32::NEG_INFINITY, 0));
        assert_eq!(first_max(&[]), (f32::NEG_INFINITY, 0));
        // A peak with NaN beside it, and the halves round away from zero.
        let src = [Complex32::new(f32::NAN, -3.0), Complex32::new(2.5, -0.5)];
        assert_eq!(peak_component(&src), 3.0);
        let mut d = [[0i16; 2]; 2];
        round_scaled(&src[1..], 1.0, &mut d[..1]);
        assert_eq!(d[0], [3, -1]);
    }

    #[test]
    fn integers_convert_exactly() {
        let ci8 = [[1i8, -2], [127, -128], [0, 5]];
        let mut out = [Complex32::new(9.0, 9.0); 2];
        copy_cf32(SampleSlice::Ci8(&ci8), 1, &mut out);
        assert_eq!(
            out,
            [Complex32::new(127.0, -128.0), Complex32::new(0.0, 5.0)]
        );
        let ci16 = [[7i16, 7], [-32768, 32767], [3, 4]];
        let mut out = [Complex32::new(0.0, 0.0); 3];
        copy_cf32(SampleSlice::Ci16(&ci16), 0, &mut out);
        assert_eq!(out[1], Complex32::new(-32768.0, 32767.0));
    }
}
