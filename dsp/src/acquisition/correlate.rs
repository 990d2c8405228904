//! The FFT correlation itself: block spectra shared by all PRNs, and one PRN's non-coherent
//! power grid from them.

use super::engine::{AcquisitionEngine, Scratch};
use super::input::copy_cf32;
use super::spectra::{quantize, Spectra};
use super::wide::add_power;
use crate::constants::F_L1_HZ;
use crate::correlator::SampleSlice;
use crate::Prn;
use num_complex::Complex32;
use rayon::prelude::*;

impl AcquisitionEngine {
    /// Forward FFTs of every block of `pass` at every fractional Doppler offset, into
    /// `spectra`, stored polyphase (`X[D j + r]`, j signed, at `r * spec_len + (j mod
    /// spec_len)`, see [`super::config::Layout::decimated_bin`]) so that the decimated reads are
    /// contiguous.
    pub(super) fn block_spectra(
        &self,
        samples: SampleSlice<'_>,
        pass: usize,
        spectra: &mut Spectra,
    ) {
        let l = &self.layout;
        let n = l.block_len;
        let q_total = l.subdivision;
        let starts: Vec<usize> = l.block_start_ms[pass]
            .iter()
            .map(|&ms| l.block_start_sample(ms))
            .collect();
        let (d, m) = (l.decimation, l.spec_len);
        spectra.resize(starts.len() * q_total * d, m);
        let slices: Vec<_> = spectra.slices_mut().collect();
        let mut groups: Vec<Vec<_>> = Vec::with_capacity(starts.len() * q_total);
        let mut it = slices.into_iter();
        for _ in 0..starts.len() * q_total {
            groups.push(it.by_ref().take(d).collect());
        }
        groups.into_par_iter().enumerate().for_each(|(i, out)| {
            let (blk, q) = (i / q_total, i % q_total);
            let mut s = self.take_scratch();
            let tmp = &mut s.buf[..n];
            copy_cf32(samples, starts[blk], tmp);
            if q > 0 {
                for (t, w) in tmp.iter_mut().zip(&self.wipeoffs[q - 1]) {
                    *t *= w;
                }
            }
            self.fwd.process_with_scratch(tmp, &mut s.fft);
            s.slice.resize(m, Complex32::new(0.0, 0.0));
            for (r, (dst, scale)) in out.into_iter().enumerate() {
                let tmp = &s.buf[..n];
                if d * m == n {
                    for (j, o) in s.slice.iter_mut().enumerate() {
                        *o = tmp[d * j + r];
                    }
                } else {
                    for (j, o) in s.slice.iter_mut().enumerate() {
                        *o = tmp[l.decimated_bin(j, r, d, n)];
                    }
                }
                *scale = quantize(&s.slice, dst);
            }
            self.give_scratch(s);
        });
    }

    /// Non-coherent power grid of one PRN into `s.grid` from the `spectra` of `pass` (rows =
    /// Doppler bins `b0..=b1`, columns = code lags referred to the first sample).
    pub(super) fn fill_grid(
        &self,
        spectra: &Spectra,
        prn: Prn,
        b0: i64,
        b1: i64,
        pass: usize,
        s: &mut Scratch,
    ) {
        let l = &self.layout;
        let (d, sl, m, lags, q_total) =
            (l.decimation, l.spec_len, l.inv_len, l.n_lags, l.subdivision);
        let (kp, kn) = (l.keep_pos, l.keep_neg);
        let rows = (b1 - b0 + 1) as usize;
        s.grid.clear();
        s.grid.resize(rows * lags, 0.0);
        let replica = &self.replicas.spectra[prn.index()];
        let starts = &l.block_start_ms[pass];
        // Rows in the order of the spectrum slices they read (fractional offset q, residue r):
        // the rows of one slice set (every Q D-th bin: 10 of 201 with 10 ms blocks) follow
        // each other while its blocks' slices (1.6 MB at 4 MHz x 50 blocks) are in cache,
        // instead of every row streaming them from memory (the spectra of a 10 ms x 50 search
        // take 32 MB at 4 MHz).
        s.rows.clear();
        s.rows.extend((b0..=b1).enumerate().map(|(row, bin)| {
            let q = bin.rem_euclid(q_total as i64) as usize;
            let (r, _) = l.residue_rotation((bin - q as i64) / q_total as i64);
            (q * l.decimation + r, row, bin)
        }));
        s.rows.sort_unstable();
        for i in 0..s.rows.len() {
            let (_, row, bin) = s.rows[i];
            let q = bin.rem_euclid(q_total as i64) as usize;
            let k = (bin - q as i64) / q_total as i64;
            let (r, a) = l.residue_rotation(k);
            let f_hz = bin as f64 * l.doppler_step_hz;
            let grid_row = &mut s.grid[row * lags..(row + 1) * lags];
            for (b, &ms) in starts.iter().enumerate() {
                let (src, scale) = spectra.slice((b * q_total + q) * d + r);
                let power_scale = scale * scale;
                // Y[j] = X[D (j + a) + r] conj(C[j]) / len: the Doppler shift is a rotation;
                // the lowest kp non-negative and kn negative frequencies j (relative to the
                // Doppler) are kept, zeros between them when the inverse FFT is longer.
                let buf = &mut s.buf[..m];
                let (pos, rest) = buf.split_at_mut(kp);
                let (mid, neg) = rest.split_at_mut(m - kp - kn);
                mul_rotated(pos, src, a, &replica[..kp]);
                mul_rotated(neg, src, (sl - kn + a) % sl, &replica[m - kn..]);
                mid.fill(Complex32::new(0.0, 0.0));
                self.inv.process_with_scratch(buf, &mut s.fft);
                // Where the code period that started at lag tau of block 0 starts in this block:
                // the block start rounding plus the code Doppler (code runs f/f_L1 faster).
                let ideal = f64::from(ms) * l.period_samples;
                let shift = (ideal - l.block_start_sample(ms) as f64) - ideal * f_hz / F_L1_HZ;
                let rs = ((shift / l.lag_samples).round() as i64).rem_euclid(m as i64) as usize;
                let first = lags.min(m - rs);
                add_power(&mut grid_row[..first], &buf[rs..rs + first], power_scale);
                add_power(&mut grid_row[first..], &buf[..lags - first], power_scale);
            }
        }
    }

    /// Noise power of a full-band correlation over that of the search's band-limited one at
    /// Doppler bin `bin`: `sum_j P[j] W[j] / sum_{j kept} P[j] W[j]`, with `P` the power
    /// spectrum of the pass's blocks (relative to the bin's Doppler) and `W` the mean
    /// replica power spectrum. 1 when the search keeps the whole spectrum. The grid floor times
    /// this is the noise of the prompts of the refinement, which correlate at the input rate,
    /// whatever the front-end filter (white noise gives 1/(fraction of the replica's power in
    /// the band), about 1.05 at +-2.048 MHz).
    pub(super) fn band_noise_ratio(&self, spectra: &Spectra, bin: i64) -> f64 {
        let l = &self.layout;
        if l.inv_len >= l.spec_len {
            return 1.0;
        }
        let (d, sl, q_total) = (l.decimation, l.spec_len, l.subdivision);
        let q = bin.rem_euclid(q_total as i64) as usize;
        let k = (bin - q as i64) / q_total as i64;
        let (r, a) = l.residue_rotation(k);
        let (mut all, mut kept) = (0.0f64, 0.0f64);
        for b in 0..l.block_start_ms.first().map_or(0, Vec::len) {
            let (src, scale) = spectra.slice((b * q_total + q) * d + r);
            for (j, w) in self.replicas.power.iter().enumerate() {
                let [re, im] = src[(j + a) % sl].map(f32::from);
                let p = f64::from((re * re + im * im) * scale * scale * w);
                all += p;
                if j < l.keep_pos || j >= sl - l.keep_neg {
                    kept += p;
                }
            }
        }
        if kept > 0.0 && all.is_finite() {
            (all / kept).max(1.0)
        } else {
            1.0
        }
    }
}

/// `dst[t] = src[(start + t) mod src.len()] * rep[t]` (`start < src.len()`,
/// `dst.len() <= src.len()`), the stored integers `src` read as complex f32, in at most two
/// contiguous runs. The loops are compiled a second time for AVX2 + FMA and that version is
/// taken when the CPU has them (the build targets baseline x86-64, whose SSE2 complex
/// products ran at half the speed: 14 % of a weak-signal run's time was here).
fn mul_rotated(dst: &mut [Complex32], src: &[[i16; 2]], start: usize, rep: &[Complex32]) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports AVX2 and FMA (checked above).
        unsafe { mul_rotated_avx2(dst, src, start, rep) };
        return;
    }
    mul_rotated_portable(dst, src, start, rep);
}

/// [`mul_rotated`] with AVX2 and FMA.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn mul_rotated_avx2(
    dst: &mut [Complex32],
    src: &[[i16; 2]],
    start: usize,
    rep: &[Complex32],
) {
    let first = dst.len().min(src.len() - start);
    let (d0, d1) = dst.split_at_mut(first);
    let (r0, r1) = rep.split_at(first);
    let rest = d1.len();
    // SAFETY: the caller guarantees AVX2 and FMA.
    unsafe {
        mul_avx2(d0, &src[start..start + first], r0);
        mul_avx2(d1, &src[..rest], &r1[..rest]);
    }
}

/// `dst[t] = a[t] b[t]` for equal lengths, `a` integers, AVX2 + FMA: four complex products
/// per instruction group, `a b = (a_re b_re - a_im b_im, a_im b_re + a_re b_im)` as
/// `fmaddsub(a, dup(b_re), swap(a) dup(b_im))`, `a` widened from i16 first.
///
/// # Safety
/// The CPU must support AVX2 and FMA; `a` and `b` at least as long as `dst`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn mul_avx2(dst: &mut [Complex32], a: &[[i16; 2]], b: &[Complex32]) {
    use std::arch::x86_64::{
        __m128i, _mm256_cvtepi16_epi32, _mm256_cvtepi32_ps, _mm256_fmaddsub_ps, _mm256_loadu_ps,
        _mm256_movehdup_ps, _mm256_moveldup_ps, _mm256_mul_ps, _mm256_permute_ps, _mm256_storeu_ps,
        _mm_loadu_si128,
    };
    let n = dst.len().min(a.len()).min(b.len());
    let lanes = n / 4 * 4;
    let (pd, pa, pb) = (
        dst.as_mut_ptr().cast::<f32>(),
        a.as_ptr().cast::<i16>(),
        b.as_ptr().cast::<f32>(),
    );
    let mut k = 0;
    while k < lanes {
        // SAFETY: k + 4 <= n complex values in each slice (8 i16 of `a`: 16 bytes; 8 floats
        // of `b` and `dst`); Complex32 is two f32 (repr(C)), [i16; 2] two i16; unaligned
        // loads and stores.
        unsafe {
            let ai = _mm_loadu_si128(pa.add(2 * k).cast::<__m128i>());
            let va = _mm256_cvtepi32_ps(_mm256_cvtepi16_epi32(ai));
            let vb = _mm256_loadu_ps(pb.add(2 * k));
            let b_re = _mm256_moveldup_ps(vb);
            let b_im = _mm256_movehdup_ps(vb);
            let a_swapped = _mm256_permute_ps(va, 0b1011_0001);
            let t = _mm256_mul_ps(a_swapped, b_im);
            _mm256_storeu_ps(pd.add(2 * k), _mm256_fmaddsub_ps(va, b_re, t));
        }
        k += 4;
    }
    for t in lanes..n {
        dst[t] = widen(a[t]) * b[t];
    }
}

/// A stored integer pair as complex f32.
#[inline(always)]
fn widen([re, im]: [i16; 2]) -> Complex32 {
    Complex32::new(f32::from(re), f32::from(im))
}

/// The body of [`mul_rotated`], inlined into each compiled version.
#[inline(always)]
fn mul_rotated_portable(dst: &mut [Complex32], src: &[[i16; 2]], start: usize, rep: &[Complex32]) {
    let first = dst.len().min(src.len() - start);
    let (d0, d1) = dst.split_at_mut(first);
    let (r0, r1) = rep.split_at(first);
    for ((y, x), c) in d0.iter_mut().zip(&src[start..]).zip(r0) {
        *y = widen(*x) * c;
    }
    for ((y, x), c) in d1.iter_mut().zip(src).zip(r1) {
        *y = widen(*x) * c;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotated_products_of_stored_integers_match_the_portable_loop() {
        // Every length up to two vector steps and every start: the AVX2 path (when the CPU
        // has it) against the scalar body, exactly (the same f32 products).
        let src: Vec<[i16; 2]> = (0..13i32)
            .map(|k| {
                [
                    (k * 9377 % 65535 - 32767) as i16,
                    (k * 25391 % 65535 - 32767) as i16,
                ]
            })
            .collect();
        let rep: Vec<Complex32> = (0..13)
            .map(|k| Complex32::new(0.5 + k as f32, -0.25 * k as f32))
            .collect();
        for len in 0..=src.len() {
            for start in 0..src.len() {
                let mut fast = vec![Complex32::new(0.0, 0.0); len];
                let mut slow = fast.clone();
                mul_rotated(&mut fast, &src, start, &rep[..len]);
                mul_rotated_portable(&mut slow, &src, start, &rep[..len]);
                assert_eq!(fast, slow, "len {len} start {start}");
                for (t, y) in slow.iter().enumerate() {
                    let want = widen(src[(start + t) % src.len()]) * rep[t];
                    assert!((y - want).norm() <= 1e-4 * want.norm().max(1.0));
                }
            }
        }
    }
}
