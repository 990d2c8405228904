//! AVX2+FMA kernels: 8 samples per vector step, lanes split into re/im vectors.
//!
//! Per step: load and convert 8 samples (cf32 deinterleaved with one shuffle each for re and im,
//! which leaves the lanes in sample order [0,1,4,5,2,3,6,7]; ci16 by shifts; ci8 widened to ci16
//! first), wipe off the carrier with the rotator (module doc of [`super::plan`]), then per tap
//! read a 32-bit code window at the tap's chip and shift each lane's chip bit into the sign bit
//! (`vpsllvd`), flip the wiped sample's sign by XOR and accumulate. No gathers, no per-sample
//! branches. The int16 kernel packs the rotator to Q14 int16 pairs and wipes off with `vpmaddwd`.

use super::avx2_i16;
use super::kernel::{Arithmetic, SampleSlice};
use super::packed::PackedCode;
use super::plan::{code_window, CarrierNco, CodeNco, CODE_LEN_FIX, RESEED_STEPS};
use super::scalar::Q14;
use super::simd::{by_taps, bytes_per_sample, dispatch, step_ptr, tail_copy, Job, CF32, CI16, CI8};
use super::ReplicaState;
use num_complex::Complex32;
use std::arch::x86_64::*;

const L: usize = 8;
/// Lane order of the cf32 deinterleave.
const CF32_ORDER: [usize; L] = [0, 1, 4, 5, 2, 3, 6, 7];

/// Proof that the CPU runs AVX2 and FMA: only [`Avx2Kernel::new`] makes one.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx2Kernel(());

impl Avx2Kernel {
    /// The kernel if this CPU has AVX2 and FMA.
    pub fn new() -> Option<Self> {
        (is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")).then_some(Self(()))
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
            && self.correlate_16_lanes(samples, fs_hz, code, state, taps, out)
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

impl Avx2Kernel {
    /// The 16-lane int16 kernel ([`avx2_i16`]) on ci8 or ci16 samples; `false` (nothing
    /// written) for cf32 or a code step too large for its code window.
    pub(super) fn correlate_16_lanes(
        self,
        samples: SampleSlice<'_>,
        fs_hz: f64,
        code: &PackedCode,
        state: &ReplicaState,
        taps: &[f64],
        out: &mut [Complex32],
    ) -> bool {
        let nco = CodeNco::new(state, fs_hz, taps);
        let carrier = CarrierNco::new(state, fs_hz);
        // SAFETY (both calls): `self` exists only if the CPU check of `new` passed; pointer
        // and length come from one slice of the named format.
        let done = match samples {
            SampleSlice::Ci8(x) => avx2_i16::Plan16::with::<CI8, _>(&nco, taps.len(), |plan| {
                let sh = avx2_i16::CI8_SHIFT;
                let p = x.as_ptr().cast();
                unsafe {
                    avx2_i16::correlate::<CI8>(p, x.len(), sh, code, &nco, &carrier, plan, out)
                }
            }),
            SampleSlice::Ci16(x) => avx2_i16::Plan16::with::<CI16, _>(&nco, taps.len(), |plan| {
                let p = x.as_ptr().cast();
                unsafe {
                    let sh = avx2_i16::ci16_block_shift(x);
                    avx2_i16::correlate::<CI16>(p, x.len(), sh, code, &nco, &carrier, plan, out)
                }
            }),
            SampleSlice::Cf32(_) => None,
        };
        done.is_some()
    }
}

/// Sign-extends the low and high i16 halves of each 32-bit lane (ci16 I/Q) to f32.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn ci16_to_f32(v: __m256i) -> (__m256, __m256) {
    let re = _mm256_srai_epi32::<16>(_mm256_slli_epi32::<16>(v));
    let im = _mm256_srai_epi32::<16>(v);
    (_mm256_cvtepi32_ps(re), _mm256_cvtepi32_ps(im))
}

/// Loads 8 samples as f32 re and im vectors (lane order of the format).
///
/// # Safety
/// `p` must point to 8 readable samples of format `F`.
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn load_f32<const F: u8>(p: *const u8) -> (__m256, __m256) {
    // SAFETY: the caller guarantees 8 samples (64, 32 or 16 bytes) at p; loads are unaligned.
    unsafe {
        match F {
            CF32 => {
                let a = _mm256_loadu_ps(p.cast());
                let b = _mm256_loadu_ps(p.cast::<f32>().add(8));
                (
                    _mm256_shuffle_ps::<0x88>(a, b),
                    _mm256_shuffle_ps::<0xDD>(a, b),
                )
            }
            CI16 => ci16_to_f32(_mm256_loadu_si256(p.cast())),
            _ => ci16_to_f32(_mm256_cvtepi8_epi16(_mm_loadu_si128(p.cast()))),
        }
    }
}

/// Loads 8 samples as 16 interleaved i16 (sample order).
///
/// # Safety
/// `p` must point to 8 readable samples of format `F` (ci16 or ci8).
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn load_i16<const F: u8>(p: *const u8) -> __m256i {
    // SAFETY: as for `load_f32`.
    unsafe {
        if F == CI16 {
            _mm256_loadu_si256(p.cast())
        } else {
            _mm256_cvtepi8_epi16(_mm_loadu_si128(p.cast()))
        }
    }
}

/// The rotator state: phasors `p` and step phasors `d` (re, im vectors).
struct Rotator {
    pr: __m256,
    pi: __m256,
    dr: __m256,
    di: __m256,
}

impl Rotator {
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn seed(c: &CarrierNco, k0: usize, order: &[usize; L], scale: f64) -> Self {
        let s = c.seed::<L>(k0, order, scale);
        // SAFETY: each array holds exactly 8 f32.
        unsafe {
            Self {
                pr: _mm256_loadu_ps(s.p_re.as_ptr()),
                pi: _mm256_loadu_ps(s.p_im.as_ptr()),
                dr: _mm256_loadu_ps(s.d_re.as_ptr()),
                di: _mm256_loadu_ps(s.d_im.as_ptr()),
            }
        }
    }
}

/// The complex product `(ar + j ai)(br + j bi)`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn cmul(ar: __m256, ai: __m256, br: __m256, bi: __m256) -> (__m256, __m256) {
    (
        _mm256_fmsub_ps(ar, br, _mm256_mul_ps(ai, bi)),
        _mm256_fmadd_ps(ar, bi, _mm256_mul_ps(ai, br)),
    )
}

/// Per-lane code constants: `(o_j S) mod 2^32` and the shift base `30 - (o_j S >> 32)`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn code_lanes(job: &Job<'_, L>) -> (__m256i, __m256i) {
    let mut base = [0i32; L];
    for (b, &h) in base.iter_mut().zip(&job.lane_hi) {
        *b = 30 - h as i32;
    }
    // SAFETY: both arrays hold exactly 8 i32/u32.
    unsafe {
        (
            _mm256_loadu_si256(job.lane_lo.as_ptr().cast()),
            _mm256_loadu_si256(base.as_ptr().cast()),
        )
    }
}

/// Each lane's chip bit of the tap at phase `b` (2^-32 chip), shifted into bit 31 (lower bits
/// are other chips).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn chip_bits(bits: &PackedCode, b: u64, lane_lo: __m256i, sh_base: __m256i) -> __m256i {
    // SAFETY: b < 1023 * 2^32, so the chip index is < 1023 and the packed code is long enough.
    let w = unsafe { code_window(bits.bits().as_ptr(), (b >> 32) as usize) };
    let sum = _mm256_add_epi32(_mm256_set1_epi32(b as u32 as i32), lane_lo);
    // No carry out of the low 32 bits <=> sum >= lane_lo (unsigned); then the mask is -1.
    let no_carry = _mm256_cmpeq_epi32(_mm256_max_epu32(sum, lane_lo), sum);
    let shift = _mm256_sub_epi32(sh_base, no_carry);
    _mm256_sllv_epi32(_mm256_set1_epi32(w as i32), shift)
}

/// Sum of the 8 lanes in f64.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn hsum(v: __m256) -> f64 {
    let mut a = [0f32; L];
    // SAFETY: `a` holds 8 f32.
    unsafe { _mm256_storeu_ps(a.as_mut_ptr(), v) };
    a.iter().map(|&x| f64::from(x)).sum()
}

/// The f32 kernel for format `F` and `NT` taps.
///
/// # Safety
/// `data` must hold `n` samples of format `F`; `out.len() >= NT`.
#[target_feature(enable = "avx2,fma")]
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
#[target_feature(enable = "avx2,fma")]
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
    let sign = _mm256_set1_epi32(i32::MIN);
    let (q_re, q_im) = job.carrier.chirp::<L>();
    let (qr, qi) = (_mm256_set1_ps(q_re), _mm256_set1_ps(q_im));
    let step = job.nco.step * L as u64;
    let mut base = [0u64; NT];
    base.copy_from_slice(&job.nco.phases[..NT]);
    let mut acc_re = [_mm256_setzero_ps(); NT];
    let mut acc_im = [_mm256_setzero_ps(); NT];
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
            // SAFETY: step_ptr yields 8 readable samples (slice or tail buffer).
            let (xr, xi) = unsafe { load_f32::<F>(step_ptr::<L>(data, s, full, bps, &tail)) };
            let wr = _mm256_fmsub_ps(xr, pr, _mm256_mul_ps(xi, pi));
            let wi = _mm256_fmadd_ps(xr, pi, _mm256_mul_ps(xi, pr));
            (pr, pi) = cmul(pr, pi, dr, di);
            if CHIRP {
                (dr, di) = cmul(dr, di, qr, qi);
            }
            for t in 0..NT {
                let m = _mm256_castsi256_ps(_mm256_and_si256(
                    chip_bits(job.code, base[t], lane_lo, sh_base),
                    sign,
                ));
                acc_re[t] = _mm256_add_ps(acc_re[t], _mm256_xor_ps(wr, m));
                acc_im[t] = _mm256_add_ps(acc_im[t], _mm256_xor_ps(wi, m));
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

/// Sum of the 8 i32 lanes.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn hsum_i(v: __m256i) -> i64 {
    let mut a = [0i32; L];
    // SAFETY: `a` holds 8 i32.
    unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), v) };
    a.iter().map(|&x| i64::from(x)).sum()
}

/// The int16 kernel for format `F` (ci16 or ci8) and `NT` taps.
///
/// Wiped samples `w = x * round(2^14 P)` are exact i32 (|w| <= 2^22 for ci8; for ci16 they are
/// rounded to multiples of 2^8 first, `(w + 128) >> 8`, to keep |w| <= 2^22). Per tap the sign
/// flip is `w ^ m` with `m = -1` for a -1 chip, corrected by `-sum m` (`(w ^ -1) + 1 = -w`);
/// the i32 sums are flushed to i64 every 256 steps (< 2^30 each), so nothing overflows.
///
/// # Safety
/// `data` must hold `n` samples of format `F`; `out.len() >= NT`.
#[target_feature(enable = "avx2,fma")]
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
#[target_feature(enable = "avx2,fma")]
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
    let (qr, qi) = (_mm256_set1_ps(q_re), _mm256_set1_ps(q_im));
    // packs_epi32(c, s) holds [c0 c1 c2 c3 s0 s1 s2 s3] per 128-bit half.
    let to_cs = _mm256_setr_epi8(
        0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15, 0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12,
        13, 6, 7, 14, 15,
    );
    let to_sc = _mm256_setr_epi8(
        8, 9, 0, 1, 10, 11, 2, 3, 12, 13, 4, 5, 14, 15, 6, 7, 8, 9, 0, 1, 10, 11, 2, 3, 12, 13, 4,
        5, 14, 15, 6, 7,
    );
    let neg_odd = _mm256_set1_epi32(0xFFFF_0001_u32 as i32);
    let round = _mm256_set1_epi32(128);
    let step = job.nco.step * L as u64;
    let mut base = [0u64; NT];
    base.copy_from_slice(&job.nco.phases[..NT]);
    let zero = _mm256_setzero_si256();
    let (mut acc_re, mut acc_im, mut cnt) = ([zero; NT], [zero; NT], [zero; NT]);
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
                let c = hsum_i(cnt[t]);
                sums[t].0 += hsum_i(acc_re[t]) - c;
                sums[t].1 += hsum_i(acc_im[t]) - c;
                (acc_re[t], acc_im[t], cnt[t]) = (zero, zero, zero);
            }
        }
        while s < end {
            // SAFETY: step_ptr yields 8 readable samples (slice or tail buffer).
            let x = unsafe { load_i16::<F>(step_ptr::<L>(data, s, full, bps, &tail)) };
            let cs = _mm256_packs_epi32(_mm256_cvtps_epi32(pr), _mm256_cvtps_epi32(pi));
            let pair_re = _mm256_sign_epi16(_mm256_shuffle_epi8(cs, to_cs), neg_odd);
            let pair_im = _mm256_shuffle_epi8(cs, to_sc);
            let mut wr = _mm256_madd_epi16(x, pair_re);
            let mut wi = _mm256_madd_epi16(x, pair_im);
            if F == CI16 {
                wr = _mm256_srai_epi32::<8>(_mm256_add_epi32(wr, round));
                wi = _mm256_srai_epi32::<8>(_mm256_add_epi32(wi, round));
            }
            (pr, pi) = cmul(pr, pi, dr, di);
            if CHIRP {
                (dr, di) = cmul(dr, di, qr, qi);
            }
            for t in 0..NT {
                let m = _mm256_srai_epi32::<31>(chip_bits(job.code, base[t], lane_lo, sh_base));
                acc_re[t] = _mm256_add_epi32(acc_re[t], _mm256_xor_si256(wr, m));
                acc_im[t] = _mm256_add_epi32(acc_im[t], _mm256_xor_si256(wi, m));
                cnt[t] = _mm256_add_epi32(cnt[t], m);
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
        let c = hsum_i(cnt[t]);
        let re = sums[t].0 + hsum_i(acc_re[t]) - c;
        let im = sums[t].1 + hsum_i(acc_im[t]) - c;
        out[t] = Complex32::new((re as f64 * unit) as f32, (im as f64 * unit) as f32);
    }
}
