//! AVX-512 (F+BW) kernels: 16 samples per vector step; the structure of [`super::avx2`].
//!
//! Differences: the code-phase carry is an unsigned compare into a mask register and a masked
//! subtract; the f32 sign flip and the XOR fuse into one `vpternlogd`; the int16 kernel selects
//! `w` or `-w` per lane with the chip mask instead of the XOR/count correction.

//!
//! The AVX-512 intrinsics are stable since Rust 1.89 (the workspace's `rust-version`).

use super::avx2::Avx2Kernel;
use super::kernel::{Arithmetic, SampleSlice};
use super::packed::PackedCode;
use super::plan::{code_window, CarrierNco, CodeNco, CODE_LEN_FIX, RESEED_STEPS};
use super::scalar::Q14;
use super::simd::{by_taps, bytes_per_sample, dispatch, step_ptr, tail_copy, Job, CF32, CI16, CI8};
use super::ReplicaState;
use super::{avx2_i16, avx512_i16};
use num_complex::Complex32;
use std::arch::x86_64::*;

const L: usize = 16;
/// Lane order of the cf32 deinterleave (`vshufps` within each 128-bit quarter).
const CF32_ORDER: [usize; L] = [0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15];

/// Proof that the CPU runs AVX-512 F and BW (and AVX2, FMA): only [`Avx512Kernel::new`]
/// makes one; `vnni` records whether it also runs AVX-512 VNNI (the 32-lane int16 kernel).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx512Kernel {
    vnni: bool,
    avx2: Avx2Kernel,
}

impl Avx512Kernel {
    /// The kernel if this CPU has AVX-512 F and BW, AVX2 and FMA.
    pub fn new() -> Option<Self> {
        let avx2 = Avx2Kernel::new()?;
        (is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512bw")).then_some(
            Self {
                vnni: is_x86_feature_detected!("avx512vnni"),
                avx2,
            },
        )
    }

    /// Whether the int16 arithmetic runs the 32-lane kernel ([`avx512_i16`], AVX-512 VNNI)
    /// where the sampling rate allows; without VNNI it runs the AVX2 16-lane one.
    pub fn has_vnni(self) -> bool {
        self.vnni
    }

    /// The int16 kernels on ci8 or ci16: 32 lanes (with VNNI, `fs` above about 2.2 MHz),
    /// else the AVX2 16-lane kernel (above about 1.1 MHz); `false` (nothing written) if
    /// neither applies.
    fn correlate_int16_lanes(
        self,
        samples: SampleSlice<'_>,
        fs_hz: f64,
        code: &PackedCode,
        state: &ReplicaState,
        taps: &[f64],
        out: &mut [Complex32],
    ) -> bool {
        if self.vnni {
            let nco = CodeNco::new(state, fs_hz, taps);
            let carrier = CarrierNco::new(state, fs_hz);
            let nt = taps.len();
            // SAFETY (every call): `self.vnni` is set only if the CPU has AVX-512 VNNI, and
            // `self` only exists if it has AVX-512 F, BW, AVX2 and FMA; pointer and length
            // come from one slice of the named format.
            let done = match samples {
                SampleSlice::Ci8(x) => avx512_i16::Plan32::with::<CI8, _>(&nco, nt, |plan| {
                    let (p, sh) = (x.as_ptr().cast(), avx2_i16::CI8_SHIFT);
                    unsafe {
                        avx512_i16::correlate::<CI8>(
                            p,
                            x.len(),
                            sh,
                            code,
                            &nco,
                            &carrier,
                            plan,
                            out,
                        )
                    }
                }),
                SampleSlice::Ci16(x) => avx512_i16::Plan32::with::<CI16, _>(&nco, nt, |plan| {
                    let p = x.as_ptr().cast();
                    unsafe {
                        let sh = avx2_i16::ci16_block_shift(x);
                        avx512_i16::correlate::<CI16>(
                            p,
                            x.len(),
                            sh,
                            code,
                            &nco,
                            &carrier,
                            plan,
                            out,
                        )
                    }
                }),
                SampleSlice::Cf32(_) => return false,
            };
            if done.is_some() {
                return true;
            }
        }
        self.avx2
            .correlate_16_lanes(samples, fs_hz, code, state, taps, out)
    }

    /// Runs the kernel for `taps.len()` (1..=8) taps; `false` (nothing written) if the code
    /// step is too large for the 32-bit code window, and the caller must fall back.
    #[allow(clippy::too_many_arguments)]
    pub fn correlate(
        self,
        arithmetic: Arithmetic,
        samples: SampleSlice<'_>,
        fs_hz: f64,
        code: &PackedCode,
        state: &ReplicaState,
        taps: &[f64],
        out: &mut [Complex32],
    ) -> bool {
        let nt = taps.len();
        if nt == 0 {
            return true;
        }
        if arithmetic == Arithmetic::I16
            && self.correlate_int16_lanes(samples, fs_hz, code, state, taps, out)
        {
            return true;
        }
        let Some(job) = Job::<L>::new(&samples, fs_hz, code, state, taps, CF32_ORDER) else {
            return false;
        };
        // SAFETY (every kernel call): `self` exists only if the CPU check of `new` passed; the
        // pointer and length come from one slice of the named format.
        unsafe { dispatch!(arithmetic, samples, nt, &job, out) };
        true
    }
}

/// Sign-extends the low and high i16 halves of each 32-bit lane (ci16 I/Q) to f32.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
fn ci16_to_f32(v: __m512i) -> (__m512, __m512) {
    let re = _mm512_srai_epi32::<16>(_mm512_slli_epi32::<16>(v));
    let im = _mm512_srai_epi32::<16>(v);
    (_mm512_cvtepi32_ps(re), _mm512_cvtepi32_ps(im))
}

/// Loads 16 samples as f32 re and im vectors (lane order of the format).
///
/// # Safety
/// `p` must point to 16 readable samples of format `F`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
unsafe fn load_f32<const F: u8>(p: *const u8) -> (__m512, __m512) {
    // SAFETY: the caller guarantees 16 samples (128, 64 or 32 bytes) at p; loads are unaligned.
    unsafe {
        match F {
            CF32 => {
                let a = _mm512_loadu_ps(p.cast());
                let b = _mm512_loadu_ps(p.cast::<f32>().add(16));
                (
                    _mm512_shuffle_ps::<0x88>(a, b),
                    _mm512_shuffle_ps::<0xDD>(a, b),
                )
            }
            CI16 => ci16_to_f32(_mm512_loadu_si512(p.cast())),
            _ => ci16_to_f32(_mm512_cvtepi8_epi16(_mm256_loadu_si256(p.cast()))),
        }
    }
}

/// Loads 16 samples as 32 interleaved i16 (sample order).
///
/// # Safety
/// `p` must point to 16 readable samples of format `F` (ci16 or ci8).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
unsafe fn load_i16<const F: u8>(p: *const u8) -> __m512i {
    // SAFETY: as for `load_f32`.
    unsafe {
        if F == CI16 {
            _mm512_loadu_si512(p.cast())
        } else {
            _mm512_cvtepi8_epi16(_mm256_loadu_si256(p.cast()))
        }
    }
}

/// The rotator state: phasors `p` and step phasors `d` (re, im vectors).
struct Rotator {
    pr: __m512,
    pi: __m512,
    dr: __m512,
    di: __m512,
}

impl Rotator {
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
    fn seed(c: &CarrierNco, k0: usize, order: &[usize; L], scale: f64) -> Self {
        let s = c.seed::<L>(k0, order, scale);
        // SAFETY: each array holds exactly 16 f32.
        unsafe {
            Self {
                pr: _mm512_loadu_ps(s.p_re.as_ptr()),
                pi: _mm512_loadu_ps(s.p_im.as_ptr()),
                dr: _mm512_loadu_ps(s.d_re.as_ptr()),
                di: _mm512_loadu_ps(s.d_im.as_ptr()),
            }
        }
    }
}

/// The complex product `(ar + j ai)(br + j bi)`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
fn cmul(ar: __m512, ai: __m512, br: __m512, bi: __m512) -> (__m512, __m512) {
    (
        _mm512_fmsub_ps(ar, br, _mm512_mul_ps(ai, bi)),
        _mm512_fmadd_ps(ar, bi, _mm512_mul_ps(ai, br)),
    )
}

/// Per-lane code constants: `(o_j S) mod 2^32` and the shift base `31 - (o_j S >> 32)`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
fn code_lanes(job: &Job<'_, L>) -> (__m512i, __m512i) {
    let mut base = [0i32; L];
    for (b, &h) in base.iter_mut().zip(&job.lane_hi) {
        *b = 31 - h as i32;
    }
    // SAFETY: both arrays hold exactly 16 i32/u32.
    unsafe {
        (
            _mm512_loadu_si512(job.lane_lo.as_ptr().cast()),
            _mm512_loadu_si512(base.as_ptr().cast()),
        )
    }
}

/// Each lane's chip bit of the tap at phase `b` (2^-32 chip), shifted into bit 31 (lower bits
/// are other chips).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
fn chip_bits(bits: &PackedCode, b: u64, lane_lo: __m512i, sh_base: __m512i) -> __m512i {
    // SAFETY: b < 1023 * 2^32, so the chip index is < 1023 and the packed code is long enough.
    let w = unsafe { code_window(bits.bits().as_ptr(), (b >> 32) as usize) };
    let sum = _mm512_add_epi32(_mm512_set1_epi32(b as u32 as i32), lane_lo);
    let carry = _mm512_cmplt_epu32_mask(sum, lane_lo);
    let shift = _mm512_mask_sub_epi32(sh_base, carry, sh_base, _mm512_set1_epi32(1));
    _mm512_sllv_epi32(_mm512_set1_epi32(w as i32), shift)
}

/// The f32 kernel for format `F` and `NT` taps.
///
/// # Safety
/// `data` must hold `n` samples of format `F`; `out.len() >= NT`.
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
unsafe fn f32_kernel<const F: u8, const NT: usize>(
    data: *const u8,
    n: usize,
    job: &Job<'_, L>,
    out: &mut [Complex32],
) {
    // SAFETY: forwarded from the caller.
    unsafe {
        if job.carrier.chirps() {
            f32_run::<F, NT, true>(data, n, job, out)
        } else {
            f32_run::<F, NT, false>(data, n, job, out)
        }
    }
}

/// The body of [`f32_kernel`], the rotator's rate (`d *= q`) compiled in or out.
///
/// # Safety
/// As for [`f32_kernel`].
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
unsafe fn f32_run<const F: u8, const NT: usize, const CHIRP: bool>(
    data: *const u8,
    n: usize,
    job: &Job<'_, L>,
    out: &mut [Complex32],
) {
    let bps = bytes_per_sample(F);
    let (full, total) = (n / L, n.div_ceil(L));
    // SAFETY: forwarded from the caller.
    let tail = unsafe { tail_copy::<L>(data, n, bps) };
    let (lane_lo, sh_base) = code_lanes(job);
    let sign = _mm512_set1_epi32(i32::MIN);
    let (q_re, q_im) = job.carrier.chirp::<L>();
    let (qr, qi) = (_mm512_set1_ps(q_re), _mm512_set1_ps(q_im));
    let step = job.nco.step * L as u64;
    let mut base = [0u64; NT];
    base.copy_from_slice(&job.nco.phases[..NT]);
    let mut acc_re = [_mm512_setzero_ps(); NT];
    let mut acc_im = [_mm512_setzero_ps(); NT];
    let mut s = 0;
    while s < total {
        let end = total.min(s + RESEED_STEPS);
        let Rotator {
            mut pr,
            mut pi,
            mut dr,
            mut di,
        } = Rotator::seed(&job.carrier, s * L, &job.order, 1.0);
        while s < end {
            // SAFETY: step_ptr yields 16 readable samples (slice or tail buffer).
            let (xr, xi) = unsafe { load_f32::<F>(step_ptr::<L>(data, s, full, bps, &tail)) };
            let wr = _mm512_castps_si512(_mm512_fmsub_ps(xr, pr, _mm512_mul_ps(xi, pi)));
            let wi = _mm512_castps_si512(_mm512_fmadd_ps(xr, pi, _mm512_mul_ps(xi, pr)));
            (pr, pi) = cmul(pr, pi, dr, di);
            if CHIRP {
                (dr, di) = cmul(dr, di, qr, qi);
            }
            for t in 0..NT {
                let bits = chip_bits(job.code, base[t], lane_lo, sh_base);
                // w ^ (bits & sign): imm 0x78 is a ^ (b & c).
                let fr = _mm512_ternarylogic_epi32::<0x78>(wr, bits, sign);
                let fi = _mm512_ternarylogic_epi32::<0x78>(wi, bits, sign);
                acc_re[t] = _mm512_add_ps(acc_re[t], _mm512_castsi512_ps(fr));
                acc_im[t] = _mm512_add_ps(acc_im[t], _mm512_castsi512_ps(fi));
                let b = base[t] + step;
                base[t] = if b >= CODE_LEN_FIX {
                    b - CODE_LEN_FIX
                } else {
                    b
                };
            }
            s += 1;
        }
    }
    for t in 0..NT {
        out[t] = Complex32::new(hsum(acc_re[t]) as f32, hsum(acc_im[t]) as f32);
    }
}

/// Sum of the 16 lanes in f64.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
fn hsum(v: __m512) -> f64 {
    let mut a = [0f32; L];
    // SAFETY: `a` holds 16 f32.
    unsafe { _mm512_storeu_ps(a.as_mut_ptr(), v) };
    a.iter().map(|&x| f64::from(x)).sum()
}

/// Sum of the 16 i32 lanes.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
fn hsum_i(v: __m512i) -> i64 {
    let mut a = [0i32; L];
    // SAFETY: `a` holds 16 i32.
    unsafe { _mm512_storeu_si512(a.as_mut_ptr().cast(), v) };
    a.iter().map(|&x| i64::from(x)).sum()
}

/// The int16 kernel for format `F` (ci16 or ci8) and `NT` taps; the scaling of
/// [`super::avx2`]'s (|w| <= 2^22, ci16 rounded to multiples of 2^8), i32 sums flushed to i64
/// every 256 steps.
///
/// # Safety
/// `data` must hold `n` samples of format `F`; `out.len() >= NT`.
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
unsafe fn i16_kernel<const F: u8, const NT: usize>(
    data: *const u8,
    n: usize,
    job: &Job<'_, L>,
    out: &mut [Complex32],
) {
    // SAFETY: forwarded from the caller.
    unsafe {
        if job.carrier.chirps() {
            i16_run::<F, NT, true>(data, n, job, out)
        } else {
            i16_run::<F, NT, false>(data, n, job, out)
        }
    }
}

/// The body of [`i16_kernel`], the rotator's rate (`d *= q`) compiled in or out.
///
/// # Safety
/// As for [`i16_kernel`].
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx2,fma")]
unsafe fn i16_run<const F: u8, const NT: usize, const CHIRP: bool>(
    data: *const u8,
    n: usize,
    job: &Job<'_, L>,
    out: &mut [Complex32],
) {
    let bps = bytes_per_sample(F);
    let (full, total) = (n / L, n.div_ceil(L));
    // SAFETY: forwarded from the caller.
    let tail = unsafe { tail_copy::<L>(data, n, bps) };
    let (lane_lo, sh_base) = code_lanes(job);
    let (q_re, q_im) = job.carrier.chirp::<L>();
    let (qr, qi) = (_mm512_set1_ps(q_re), _mm512_set1_ps(q_im));
    // packs_epi32(c, s) holds [c0 c1 c2 c3 s0 s1 s2 s3] per 128-bit quarter.
    let to_cs = _mm512_broadcast_i32x4(_mm_setr_epi8(
        0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15,
    ));
    let to_sc = _mm512_broadcast_i32x4(_mm_setr_epi8(
        8, 9, 0, 1, 10, 11, 2, 3, 12, 13, 4, 5, 14, 15, 6, 7,
    ));
    let round = _mm512_set1_epi32(128);
    let step = job.nco.step * L as u64;
    let mut base = [0u64; NT];
    base.copy_from_slice(&job.nco.phases[..NT]);
    let zero = _mm512_setzero_si512();
    let (mut acc_re, mut acc_im) = ([zero; NT], [zero; NT]);
    let mut sums = [(0i64, 0i64); NT];
    let scale = f64::from(Q14);
    let mut s = 0;
    while s < total {
        let end = total.min(s + RESEED_STEPS);
        let Rotator {
            mut pr,
            mut pi,
            mut dr,
            mut di,
        } = Rotator::seed(&job.carrier, s * L, &job.order, scale);
        if s > 0 {
            for t in 0..NT {
                sums[t].0 += hsum_i(acc_re[t]);
                sums[t].1 += hsum_i(acc_im[t]);
                (acc_re[t], acc_im[t]) = (zero, zero);
            }
        }
        while s < end {
            // SAFETY: step_ptr yields 16 readable samples (slice or tail buffer).
            let x = unsafe { load_i16::<F>(step_ptr::<L>(data, s, full, bps, &tail)) };
            let cs = _mm512_packs_epi32(_mm512_cvtps_epi32(pr), _mm512_cvtps_epi32(pi));
            let cs_pairs = _mm512_shuffle_epi8(cs, to_cs);
            // Negate the odd i16 (the sine): [c, -s] pairs.
            let pair_re = _mm512_mask_sub_epi16(cs_pairs, 0xAAAA_AAAA, zero, cs_pairs);
            let pair_im = _mm512_shuffle_epi8(cs, to_sc);
            let mut wr = _mm512_madd_epi16(x, pair_re);
            let mut wi = _mm512_madd_epi16(x, pair_im);
            if F == CI16 {
                wr = _mm512_srai_epi32::<8>(_mm512_add_epi32(wr, round));
                wi = _mm512_srai_epi32::<8>(_mm512_add_epi32(wi, round));
            }
            let (nwr, nwi) = (_mm512_sub_epi32(zero, wr), _mm512_sub_epi32(zero, wi));
            (pr, pi) = cmul(pr, pi, dr, di);
            if CHIRP {
                (dr, di) = cmul(dr, di, qr, qi);
            }
            for t in 0..NT {
                let neg =
                    _mm512_cmplt_epi32_mask(chip_bits(job.code, base[t], lane_lo, sh_base), zero);
                acc_re[t] = _mm512_add_epi32(acc_re[t], _mm512_mask_mov_epi32(wr, neg, nwr));
                acc_im[t] = _mm512_add_epi32(acc_im[t], _mm512_mask_mov_epi32(wi, neg, nwi));
                let b = base[t] + step;
                base[t] = if b >= CODE_LEN_FIX {
                    b - CODE_LEN_FIX
                } else {
                    b
                };
            }
            s += 1;
        }
    }
    let unit = if F == CI16 {
        256.0 / scale
    } else {
        1.0 / scale
    };
    for t in 0..NT {
        let re = sums[t].0 + hsum_i(acc_re[t]);
        let im = sums[t].1 + hsum_i(acc_im[t]);
        out[t] = Complex32::new((re as f64 * unit) as f32, (im as f64 * unit) as f32);
    }
}
