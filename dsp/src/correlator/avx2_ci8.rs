//! The AVX2 int16 kernel for ci8 samples: 16 samples per vector step, in 16-bit lanes.
//!
//! Per step of 16 samples (one 32-byte load):
//! - **Carrier** `c + j s ~ 2^14 exp(-j 2 pi phi)` in i16 lanes (Q14), sample order. The f32
//!   rotator of [`super::plan`] (16 lanes as two vectors of 8, re-seeded exactly every 256
//!   steps) gives it, converted and packed to i16 with `vpackssdw`, every step when the
//!   frequency ramps; at a constant frequency it steps [`GROUP`] = 4 vector steps at a time
//!   and the 3 steps in between rotate the previous carrier by `E = exp(-j 2 pi 16 a)` in
//!   Q15 with `vpmulhrsw` (6 ops instead of 14). Error of the i16 carrier, in units of
//!   2^-14 (modulus): the Q14 rounding `<= 0.71`, then per rotation the two product roundings
//!   per component (`<= sqrt 2`) and the Q15 rounding of `E` (`|P| |dE| <= 2^14 * 1.12 *
//!   2^-15 = 0.56`, a component of 1 saturating to 32767): `<= 0.71 + 3 * 1.98 = 6.7`, i.e.
//!   `4.1e-4` of the carrier's modulus (against `4.3e-5` for the rounding alone; still
//!   -68 dB, nothing next to a sample's noise).
//! - **Wipe-off** in i16 lanes. Each 16-bit lane of the load holds one sample,
//!   `Q << 8 | I as u8`, so `I << 8` (`vpsllw`) and `Q << 8` (`vpand 0xFF00`) are the samples
//!   times 2^8 with no shuffle, and `vpmulhrsw` (`(a b + 2^14) >> 15`) gives
//!   `round(I c / 2^7)` etc.: `wr = I c - Q s`, `wi = I s + Q c` in units of 2^-7 sample
//!   (Q7), each of the two products rounded to the nearest unit, so the wiped sample is off
//!   by at most `2^-7` per component (`2^-7 sqrt 2` in modulus) besides the Q14 carrier.
//!   `|w| <= 181 * 2^7 < 2^15`: no lane saturates.
//! - **Code**, exactly as the 2^-32-chip NCO of [`super::plan`] picks the chips. Tap `t`'s
//!   phase is the first tap's `B` plus a constant `Delta_t = W_t 2^32 + f_t` (both advance by
//!   the same step, modulo the same period), so lane `j` of tap `t` reads chip
//!   `floor(B / 2^32) + W_t + h_tj + carry_tj` with `l_tj = f_t + o_j S`, `h_tj = l_tj >> 32`
//!   and `carry_tj = [B_lo + (l_tj mod 2^32) >= 2^32] = [B_lo >u !l_tj]`: one broadcast of
//!   `B_lo` serves every tap, and the carry is one signed compare per 8 lanes after flipping
//!   the sign bits. `vpackssdw` of the two compare masks lands in sample order, and a byte
//!   subtract adds the carry to both bytes of the duplicated offset `h_tj * 0x0101`. A
//!   `vpshufb` into the 16 code bytes at chip `floor(B / 2^32) + W_t` (`0x00` / `0xFF`,
//!   [`PackedCode::chip_bytes`], broadcast to both 128-bit halves) then `| 1` gives the +-1
//!   replica in i16 lanes; `vpmaddwd` with `wr` and `wi` multiplies and sums sample pairs
//!   into 8 i32 lanes each.
//! - Lane sums grow by at most `2 * 2^15` per step: flushed to i64 every 256 steps (with the
//!   rotator's re-seed), far below 2^31.
//!
//! Needs every `h_tj <= 14` (16 chips cover the 16 lanes: `f_t + 15 S < 15 * 2^32`, a code
//! step below 14/15 chip per sample, `fs` above about 1.1 MHz); otherwise [`Ci8Plan::new`]
//! says no and the caller runs the 8-lane kernel.

use super::packed::PackedCode;
use super::plan::{CarrierNco, CodeNco, CODE_LEN_FIX, RESEED_STEPS};
use super::scalar::Q14;
use super::simd::{step_ptr, tail_copy};
use super::MAX_TAPS;
use num_complex::Complex32;
use std::arch::x86_64::*;

const L: usize = 16;
/// Sample of each rotator / compare lane: vector A is lanes 0..8, vector B lanes 8..16;
/// `vpackssdw(A, B)` interleaves their 128-bit halves, so the packed i16 lanes come out in
/// sample order 0..16.
const ORDER: [usize; L] = [0, 1, 2, 3, 8, 9, 10, 11, 4, 5, 6, 7, 12, 13, 14, 15];
/// The largest chip offset `h_tj` a 16-byte code window allows (the carry adds one).
const MAX_OFFSET: u64 = 14;
/// Vector steps per f32 rotator step at a constant frequency (module doc).
const GROUP: usize = 4;
/// Wiped samples are in units of 2^-7 sample.
const W_UNIT: f64 = 1.0 / 128.0;

/// The per-call code constants of every tap (module doc): compare thresholds
/// `!l_tj ^ 2^31` (vectors A and B), duplicated offsets `h_tj * 0x0101` in sample order, and
/// the whole-chip offset `W_t`.
pub(super) struct Ci8Plan {
    thr: [[i32; L]; MAX_TAPS],
    hi_dup: [[i16; L]; MAX_TAPS],
    whole: [usize; MAX_TAPS],
}

impl Ci8Plan {
    /// The plan for the taps of `nco` (`n_taps` of them), or `None` if some lane lies 16 or
    /// more chips past its tap's window.
    pub(super) fn new(nco: &CodeNco, n_taps: usize) -> Option<Self> {
        let mut plan = Self {
            thr: [[0; L]; MAX_TAPS],
            hi_dup: [[0; L]; MAX_TAPS],
            whole: [0; MAX_TAPS],
        };
        let b0 = nco.phases[0];
        for t in 0..n_taps.min(MAX_TAPS) {
            let delta = (nco.phases[t] + CODE_LEN_FIX - b0) % CODE_LEN_FIX;
            plan.whole[t] = (delta >> 32) as usize;
            let frac = delta & 0xFFFF_FFFF;
            for (j, &o) in ORDER.iter().enumerate() {
                let l = frac.checked_add((o as u64).checked_mul(nco.step)?)?;
                let h = l >> 32;
                if h > MAX_OFFSET {
                    return None;
                }
                plan.thr[t][j] = (!(l as u32) ^ 0x8000_0000) as i32;
                plan.hi_dup[t][o] = (h as u16 * 0x0101) as i16;
            }
        }
        Some(plan)
    }
}

/// Runs the kernel for `out.len()` (1..=8) taps with the plan from [`Ci8Plan::new`].
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn correlate(
    x: &[[i8; 2]],
    code: &PackedCode,
    nco: &CodeNco,
    carrier: &CarrierNco,
    plan: &Ci8Plan,
    out: &mut [Complex32],
) {
    let job = Ci8Job {
        code,
        nco,
        carrier,
        plan,
    };
    let (p, n) = (x.as_ptr().cast::<u8>(), x.len());
    // SAFETY: p holds n ci8 samples; the CPU check is the caller's.
    unsafe {
        match (out.len(), carrier.chirps()) {
            (1, false) => run::<1, false>(p, n, &job, out),
            (2, false) => run::<2, false>(p, n, &job, out),
            (3, false) => run::<3, false>(p, n, &job, out),
            (4, false) => run::<4, false>(p, n, &job, out),
            (5, false) => run::<5, false>(p, n, &job, out),
            (6, false) => run::<6, false>(p, n, &job, out),
            (7, false) => run::<7, false>(p, n, &job, out),
            (_, false) => run::<8, false>(p, n, &job, out),
            (1, true) => run::<1, true>(p, n, &job, out),
            (2, true) => run::<2, true>(p, n, &job, out),
            (3, true) => run::<3, true>(p, n, &job, out),
            (4, true) => run::<4, true>(p, n, &job, out),
            (5, true) => run::<5, true>(p, n, &job, out),
            (6, true) => run::<6, true>(p, n, &job, out),
            (7, true) => run::<7, true>(p, n, &job, out),
            (_, true) => run::<8, true>(p, n, &job, out),
        }
    }
}

struct Ci8Job<'a> {
    code: &'a PackedCode,
    nco: &'a CodeNco,
    carrier: &'a CarrierNco,
    plan: &'a Ci8Plan,
}

/// The f32 rotator of 16 lanes (vectors A and B), seeded in [`ORDER`] and scaled by 2^14.
struct Rotator16 {
    p: [__m256; 4],
    d: [__m256; 4],
}

impl Rotator16 {
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn seed(c: &CarrierNco, k0: usize, stride: usize) -> Self {
        let s = c.seed_stride::<L>(k0, &ORDER, f64::from(Q14), stride);
        // SAFETY: each array holds 16 f32: two vectors of 8.
        unsafe {
            let v = |a: &[f32; L], h: usize| _mm256_loadu_ps(a.as_ptr().add(8 * h));
            Self {
                p: [v(&s.p_re, 0), v(&s.p_im, 0), v(&s.p_re, 1), v(&s.p_im, 1)],
                d: [v(&s.d_re, 0), v(&s.d_im, 0), v(&s.d_re, 1), v(&s.d_im, 1)],
            }
        }
    }

    /// The carrier of this step as i16 lanes in sample order: `(c, s)`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn carrier_i16(&self) -> (__m256i, __m256i) {
        let [ar, ai, br, bi] = self.p;
        (
            _mm256_packs_epi32(_mm256_cvtps_epi32(ar), _mm256_cvtps_epi32(br)),
            _mm256_packs_epi32(_mm256_cvtps_epi32(ai), _mm256_cvtps_epi32(bi)),
        )
    }

    /// `P *= D`, and with a rate `D *= Q`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn advance<const CHIRP: bool>(&mut self, qr: __m256, qi: __m256) {
        for h in 0..2 {
            let (pr, pi) = (self.p[2 * h], self.p[2 * h + 1]);
            let (dr, di) = (self.d[2 * h], self.d[2 * h + 1]);
            self.p[2 * h] = _mm256_fmsub_ps(pr, dr, _mm256_mul_ps(pi, di));
            self.p[2 * h + 1] = _mm256_fmadd_ps(pr, di, _mm256_mul_ps(pi, dr));
            if CHIRP {
                self.d[2 * h] = _mm256_fmsub_ps(dr, qr, _mm256_mul_ps(di, qi));
                self.d[2 * h + 1] = _mm256_fmadd_ps(dr, qi, _mm256_mul_ps(di, qr));
            }
        }
    }
}

/// Wipes the carrier `(c, s)` off 16 ci8 samples `x`: `(wr, wi)` in Q7 (module doc).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn wipe(x: __m256i, c: __m256i, s: __m256i) -> (__m256i, __m256i) {
    let xi = _mm256_slli_epi16::<8>(x);
    let xq = _mm256_and_si256(x, _mm256_set1_epi16(0xFF00_u16 as i16));
    (
        _mm256_sub_epi16(_mm256_mulhrs_epi16(xi, c), _mm256_mulhrs_epi16(xq, s)),
        _mm256_add_epi16(_mm256_mulhrs_epi16(xi, s), _mm256_mulhrs_epi16(xq, c)),
    )
}

/// The +-1 replica (i16 lanes, sample order) of tap `t` when the first tap's phase has low
/// half `bx ^ 2^31` (broadcast) and chip `chip`.
///
/// # Safety
/// `chip < 1023`.
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn replica(job: &Ci8Job<'_>, t: usize, chip: usize, bx: __m256i) -> __m256i {
    let plan = job.plan;
    // SAFETY: thr[t] holds 16 i32 (two vectors), hi_dup[t] 16 i16; chip + W_t < 2046 and the
    // byte code holds 2064 bytes, so the 16 bytes at chip + W_t are readable.
    unsafe {
        let thr = plan.thr[t].as_ptr();
        let carry = _mm256_packs_epi32(
            _mm256_cmpgt_epi32(bx, _mm256_loadu_si256(thr.cast())),
            _mm256_cmpgt_epi32(bx, _mm256_loadu_si256(thr.add(8).cast())),
        );
        // Both bytes of a lane hold the offset; a carry lane is -1 in both bytes.
        let idx = _mm256_sub_epi8(_mm256_loadu_si256(plan.hi_dup[t].as_ptr().cast()), carry);
        let window = _mm256_broadcastsi128_si256(_mm_loadu_si128(
            job.code
                .chip_bytes()
                .as_ptr()
                .add(chip + plan.whole[t])
                .cast(),
        ));
        // `| 1` as a 32-bit pattern: rematerialised from memory, a broadcast is a plain load.
        _mm256_or_si256(
            _mm256_shuffle_epi8(window, idx),
            _mm256_set1_epi32(0x0001_0001),
        )
    }
}

/// Sum of the 8 i32 lanes.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn hsum_i(v: __m256i) -> i64 {
    let mut a = [0i32; 8];
    // SAFETY: `a` holds 8 i32.
    unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), v) };
    a.iter().map(|&x| i64::from(x)).sum()
}

/// The code phase of the first tap: `base` in 2^-32 chip and its low half `bx ^ 2^31`
/// broadcast (module doc).
struct CodePhase {
    base: u64,
    bx: __m256i,
    step: u64,
    step_lo: __m256i,
}

impl CodePhase {
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn new(base: u64, step: u64) -> Self {
        Self {
            base,
            bx: _mm256_set1_epi32((base as u32 ^ 0x8000_0000) as i32),
            step,
            step_lo: _mm256_set1_epi32(step as u32 as i32),
        }
    }

    /// Advances by one vector step (the low half wraps by itself: the period is a multiple
    /// of 2^32).
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn advance(&mut self) {
        self.bx = _mm256_add_epi32(self.bx, self.step_lo);
        self.base += self.step;
        if self.base >= CODE_LEN_FIX {
            self.base -= CODE_LEN_FIX;
        }
    }
}

/// One vector step: wipes the carrier `(c, s)` off the 16 samples at `p` and adds every
/// tap's sums.
///
/// # Safety
/// `p` points to 16 readable ci8 samples.
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn step<const NT: usize>(
    p: *const u8,
    c: __m256i,
    s: __m256i,
    job: &Ci8Job<'_>,
    phase: &CodePhase,
    acc: &mut [[__m256i; NT]; 2],
) {
    // SAFETY: the caller guarantees 16 samples (32 bytes) at p.
    let x = unsafe { _mm256_loadu_si256(p.cast()) };
    let (wr, wi) = wipe(x, c, s);
    let chip = (phase.base >> 32) as usize;
    let [acc_re, acc_im] = acc;
    for (t, (re, im)) in acc_re.iter_mut().zip(acc_im.iter_mut()).enumerate() {
        // SAFETY: base < 1023 * 2^32, so chip < 1023.
        let code = unsafe { replica(job, t, chip, phase.bx) };
        *re = _mm256_add_epi32(*re, _mm256_madd_epi16(wr, code));
        *im = _mm256_add_epi32(*im, _mm256_madd_epi16(wi, code));
    }
}

/// `(c + j s) (ec + j es)` in i16 lanes: `(c, s)` in Q14, `(ec, es)` in Q15, each product
/// rounded (`vpmulhrsw`).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn rotate_i16(c: __m256i, s: __m256i, ec: __m256i, es: __m256i) -> (__m256i, __m256i) {
    (
        _mm256_sub_epi16(_mm256_mulhrs_epi16(c, ec), _mm256_mulhrs_epi16(s, es)),
        _mm256_add_epi16(_mm256_mulhrs_epi16(c, es), _mm256_mulhrs_epi16(s, ec)),
    )
}

/// The step rotation `E = exp(-j 2 pi 16 a)` in Q15 lanes `(ec, es)` (a component of +1
/// saturates to 32767, 3e-5 short).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn step_rotation(carrier: &CarrierNco) -> (__m256i, __m256i) {
    let (re, im) = carrier.step_phasor(L);
    let q15 = |v: f64| (v * 32768.0).round().clamp(-32768.0, 32767.0) as i16;
    (_mm256_set1_epi16(q15(re)), _mm256_set1_epi16(q15(im)))
}

/// The kernel body for `NT` taps, the rotator's rate compiled in or out.
///
/// Without a rate the f32 rotator steps [`GROUP`] vector steps at a time and the carrier of
/// the steps in between is rotated in i16 ([`rotate_i16`]); with a rate every step takes the
/// f32 rotator's carrier.
///
/// # Safety
/// `data` must hold `n` ci8 samples; `out.len() >= NT`; the CPU supports AVX2 and FMA.
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn run<const NT: usize, const CHIRP: bool>(
    data: *const u8,
    n: usize,
    job: &Ci8Job<'_>,
    out: &mut [Complex32],
) {
    let (full, total) = (n / L, n.div_ceil(L));
    // SAFETY: forwarded from the caller.
    let tail = unsafe { tail_copy::<L>(data, n, 2) };
    let (q_re, q_im) = job.carrier.chirp::<L>();
    let (qr, qi) = (_mm256_set1_ps(q_re), _mm256_set1_ps(q_im));
    let (ec, es) = step_rotation(job.carrier);
    let mut phase = CodePhase::new(job.nco.phases[0], job.nco.step * L as u64);
    let zero = _mm256_setzero_si256();
    let mut acc = [[zero; NT]; 2];
    let mut sums = [(0i64, 0i64); NT];
    let mut s = 0;
    while s < total {
        let end = total.min(s + RESEED_STEPS);
        let stride = if CHIRP { L } else { GROUP * L };
        let mut rot = Rotator16::seed(job.carrier, s * L, stride);
        while s < end {
            let (mut c, mut sn) = rot.carrier_i16();
            rot.advance::<CHIRP>(qr, qi);
            let group_end = if CHIRP { s + 1 } else { end.min(s + GROUP) };
            loop {
                // SAFETY: step_ptr yields 16 readable samples (slice or tail buffer).
                unsafe {
                    let p = step_ptr::<L>(data, s, full, 2, &tail);
                    step::<NT>(p, c, sn, job, &phase, &mut acc);
                }
                phase.advance();
                s += 1;
                if s == group_end {
                    break;
                }
                (c, sn) = rotate_i16(c, sn, ec, es);
            }
        }
        for t in 0..NT {
            sums[t].0 += hsum_i(acc[0][t]);
            sums[t].1 += hsum_i(acc[1][t]);
            (acc[0][t], acc[1][t]) = (zero, zero);
        }
    }
    for t in 0..NT {
        out[t] = Complex32::new(
            (sums[t].0 as f64 * W_UNIT) as f32,
            (sums[t].1 as f64 * W_UNIT) as f32,
        );
    }
}
