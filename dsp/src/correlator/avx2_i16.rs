//! The AVX2 int16 kernel for ci8 and ci16 samples: 16 samples per vector step, in 16-bit
//! lanes (positions, code plan and scale: [`super::int16_lanes`]).
//!
//! Per step of 16 samples (ci8: one 32-byte load; ci16: two, gathered into I and Q vectors
//! with two `vpshufb` and two `vpunpck{l,h}qdq`, then shifted left by the block's headroom):
//! - **Carrier** `c + j s ~ 2^14 exp(-j 2 pi phi)` in i16 lanes (Q14), in position order. The
//!   f32 rotator of [`super::plan`] (16 lanes as two vectors of 8, re-seeded exactly every
//!   256 steps) gives it, converted and packed to i16 with `vpackssdw`, every step when the
//!   frequency ramps; at a constant frequency it steps [`GROUP`] = 4 vector steps at a time
//!   and the 3 steps in between rotate the previous carrier by `E = exp(-j 2 pi 16 a)` in
//!   Q15 with `vpmulhrsw` (6 ops instead of 14). Error of the i16 carrier, in units of
//!   2^-14 (modulus): the Q14 rounding `<= 0.71`, then per rotation the two product roundings
//!   per component (`<= sqrt 2`) and the Q15 rounding of `E` (`|P| |dE| <= 2^14 * 1.12 *
//!   2^-15 = 0.56`, a component of 1 saturating to 32767): `<= 0.71 + 3 * 1.98 = 6.7`, i.e.
//!   `4.1e-4` of the carrier's modulus (against `4.3e-5` for the rounding alone; still
//!   -68 dB, nothing next to a sample's noise).
//! - **Wipe-off** in i16 lanes. ci8: each 16-bit lane of the load holds one sample,
//!   `Q << 8 | I as u8`, so `I << 8` (`vpsllw`) and `Q << 8` (`vpand 0xFF00`) are the samples
//!   times 2^8 with no shuffle. `vpmulhrsw` (`(a b + 2^14) >> 15`) gives `round(I c 2^(sh-1))`
//!   etc.: `wr = I c - Q s`, `wi = I s + Q c` in units of `2^(1 - sh)` sample (2^-7 for ci8),
//!   each of the two products rounded to the nearest unit.
//! - **Code**: the 16 code bytes at the tap's chip, `vpshufb` by each lane's offset plus its
//!   carry (two signed compares of 8 i32 lanes against the plan's thresholds, packed with
//!   `vpackssdw`: they land where the carrier lanes do), `| 1`: the +-1 replica in i16 lanes;
//!   `vpmaddwd` with `wr` and `wi` multiplies and sums sample pairs into 8 i32 lanes each.
//! - Lane sums grow by at most `2 * 2^15` per step: flushed to i64 every 256 steps (with the
//!   rotator's re-seed), far below 2^31.
//!
//! Needs 16 samples within 15 chips (`fs` above about 1.1 MHz); otherwise [`Plan16::with`]
//! says no and the caller runs the 8-lane kernel.

use super::int16_lanes::{abs_shift, pack_position, w_unit, KernelPlan};
use super::packed::PackedCode;
use super::plan::{CarrierNco, CodeNco, CODE_LEN_FIX, RESEED_STEPS};
use super::scalar::Q14;
use super::simd::{step_ptr, tail_copy, CI16, CI8};
use num_complex::Complex32;
use std::arch::x86_64::*;

const L: usize = 16;
/// Vector steps per f32 rotator step at a constant frequency (module doc).
const GROUP: usize = 4;

/// The code plan of the 16-lane kernel and the lane order of its samples.
pub(super) type Plan16 = KernelPlan<L>;

impl Plan16 {
    /// Runs `f` with the plan for the taps of `nco` (`n_taps`) on samples of format `F` (ci8
    /// or ci16), or returns `None` if some lane lies 16 or more chips past its tap's window.
    /// The plan is written in place into one kept per thread ([`KernelPlan::fill`]).
    pub(super) fn with<const F: u8, R>(
        nco: &CodeNco,
        n_taps: usize,
        f: impl FnOnce(&Self) -> R,
    ) -> Option<R> {
        thread_local! {
            static PLAN: std::cell::RefCell<Plan16> = const { std::cell::RefCell::new(Plan16::ZERO) };
        }
        PLAN.with(|plan| {
            let mut plan = plan.try_borrow_mut().ok()?;
            // Compare lane j (vectors A, B) lands on the position vpackssdw puts it.
            plan.fill::<F>(nco, n_taps, pack_position::<L>, 0x8000_0000)
                .then(|| f(&plan))
        })
    }
}

/// Runs the kernel for `out.len()` (1..=8) taps on the `n` samples of format `F` at `data`
/// with the plan from [`Plan16::with`] (of the same format).
///
/// # Safety
/// The CPU must support AVX2 and FMA; `data` must hold `n` samples of format `F`.
#[target_feature(enable = "avx2,fma")]
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn correlate<const F: u8>(
    data: *const u8,
    n: usize,
    sh: u32,
    code: &PackedCode,
    nco: &CodeNco,
    carrier: &CarrierNco,
    plan: &Plan16,
    out: &mut [Complex32],
) {
    let job = Job16 {
        code,
        nco,
        carrier,
        plan,
        sh,
    };
    let (p, n) = (data, n);
    // SAFETY: p holds n samples of format F; the CPU check is the caller's.
    unsafe {
        match (out.len(), carrier.chirps()) {
            (1, false) => run::<F, 1, false>(p, n, &job, out),
            (2, false) => run::<F, 2, false>(p, n, &job, out),
            (3, false) => run::<F, 3, false>(p, n, &job, out),
            (4, false) => run::<F, 4, false>(p, n, &job, out),
            (5, false) => run::<F, 5, false>(p, n, &job, out),
            (6, false) => run::<F, 6, false>(p, n, &job, out),
            (7, false) => run::<F, 7, false>(p, n, &job, out),
            (_, false) => run::<F, 8, false>(p, n, &job, out),
            (1, true) => run::<F, 1, true>(p, n, &job, out),
            (2, true) => run::<F, 2, true>(p, n, &job, out),
            (3, true) => run::<F, 3, true>(p, n, &job, out),
            (4, true) => run::<F, 4, true>(p, n, &job, out),
            (5, true) => run::<F, 5, true>(p, n, &job, out),
            (6, true) => run::<F, 6, true>(p, n, &job, out),
            (7, true) => run::<F, 7, true>(p, n, &job, out),
            (_, true) => run::<F, 8, true>(p, n, &job, out),
        }
    }
}

/// The headroom shift of a ci16 block ([`super::int16_lanes`]), vectorised with AVX2.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn ci16_block_shift(x: &[[i16; 2]]) -> u32 {
    // 4 vectors of 8 samples per iteration, 4 independent OR chains.
    let full = x.len() / 32;
    let p = x.as_ptr().cast::<__m256i>();
    let mut acc = [_mm256_setzero_si256(); 4];
    for i in 0..full {
        for (j, a) in acc.iter_mut().enumerate() {
            // SAFETY: vector 4i + j (samples 32i + 8j..+8) lies inside the slice: 32 (i + 1)
            // <= len.
            *a = _mm256_or_si256(
                *a,
                _mm256_abs_epi16(unsafe { _mm256_loadu_si256(p.add(4 * i + j)) }),
            );
        }
    }
    let mut lanes = [0u16; 16];
    let all = _mm256_or_si256(
        _mm256_or_si256(acc[0], acc[1]),
        _mm256_or_si256(acc[2], acc[3]),
    );
    // SAFETY: `lanes` holds 16 u16.
    unsafe { _mm256_storeu_si256(lanes.as_mut_ptr().cast(), all) };
    let m = lanes.iter().fold(0u16, |m, &v| m | v);
    abs_shift(
        x[32 * full..]
            .iter()
            .flatten()
            .fold(m, |m, &v| m | v.unsigned_abs()),
    )
}

/// The shift of format `F`'s samples: 8 for ci8 (module doc of [`super::int16_lanes`]).
pub(super) const CI8_SHIFT: u32 = 8;

struct Job16<'a> {
    code: &'a PackedCode,
    nco: &'a CodeNco,
    carrier: &'a CarrierNco,
    plan: &'a Plan16,
    sh: u32,
}

/// The f32 rotator of 16 lanes (vectors A and B), seeded in the plan's order, scaled by 2^14.
struct Rotator16 {
    p: [__m256; 4],
    d: [__m256; 4],
}

impl Rotator16 {
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn seed(c: &CarrierNco, k0: usize, order: &[usize; L], stride: usize) -> Self {
        let s = c.seed_stride::<L>(k0, order, f64::from(Q14), stride);
        // SAFETY: each array holds 16 f32: two vectors of 8.
        unsafe {
            let v = |a: &[f32; L], h: usize| _mm256_loadu_ps(a.as_ptr().add(8 * h));
            Self {
                p: [v(&s.p_re, 0), v(&s.p_im, 0), v(&s.p_re, 1), v(&s.p_im, 1)],
                d: [v(&s.d_re, 0), v(&s.d_im, 0), v(&s.d_re, 1), v(&s.d_im, 1)],
            }
        }
    }

    /// The carrier of this step as i16 lanes in position order: `(c, s)`.
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

/// 16 samples of format `F` at `p` as `(I 2^sh, Q 2^sh)` in i16 lanes, position order.
///
/// # Safety
/// `p` points to 16 readable samples of format `F`.
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn load<const F: u8>(p: *const u8, sh: __m128i) -> (__m256i, __m256i) {
    // SAFETY: 32 (ci8) or 64 (ci16) readable bytes at p.
    unsafe {
        if F == CI16 {
            // Word 2m of a 128-bit lane: I (then Q) of the first vector's sample m, word
            // 2m + 1: of the second's.
            let a = _mm256_sll_epi16(_mm256_loadu_si256(p.cast()), sh);
            let b = _mm256_sll_epi16(_mm256_loadu_si256(p.add(32).cast()), sh);
            (
                _mm256_blend_epi16::<0xAA>(a, _mm256_slli_epi32::<16>(b)),
                _mm256_blend_epi16::<0xAA>(_mm256_srli_epi32::<16>(a), b),
            )
        } else {
            let x = _mm256_loadu_si256(p.cast());
            (
                _mm256_slli_epi16::<8>(x),
                _mm256_and_si256(x, _mm256_set1_epi16(0xFF00_u16 as i16)),
            )
        }
    }
}

/// Wipes the carrier `(c, s)` off `(xi, xq)`: `(wr, wi)` in units of `2^(1 - sh)` sample.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn wipe(xi: __m256i, xq: __m256i, c: __m256i, s: __m256i) -> (__m256i, __m256i) {
    (
        _mm256_sub_epi16(_mm256_mulhrs_epi16(xi, c), _mm256_mulhrs_epi16(xq, s)),
        _mm256_add_epi16(_mm256_mulhrs_epi16(xi, s), _mm256_mulhrs_epi16(xq, c)),
    )
}

/// The +-1 replica (i16 lanes, position order) of tap `t` when the first tap's phase has low
/// half `bx ^ 2^31` (broadcast) and chip `chip`.
///
/// # Safety
/// `chip < 1023`.
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn replica(job: &Job16<'_>, t: usize, chip: usize, bx: __m256i) -> __m256i {
    let plan = &job.plan.code;
    // SAFETY: thr[t] holds 16 u32 (two vectors), hi_dup[t] 16 i16; chip + W_t < 2046 and the
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
/// `p` points to 16 readable samples of format `F`.
#[inline]
#[target_feature(enable = "avx2,fma")]
#[allow(clippy::too_many_arguments)]
unsafe fn step<const F: u8, const NT: usize>(
    p: *const u8,
    sh: __m128i,
    c: __m256i,
    s: __m256i,
    job: &Job16<'_>,
    phase: &CodePhase,
    acc: &mut [[__m256i; NT]; 2],
) {
    // SAFETY: the caller guarantees 16 samples at p.
    let (xi, xq) = unsafe { load::<F>(p, sh) };
    let (wr, wi) = wipe(xi, xq, c, s);
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

/// The kernel body for format `F` and `NT` taps, the rotator's rate compiled in or out.
///
/// Without a rate the f32 rotator steps [`GROUP`] vector steps at a time and the carrier of
/// the steps in between is rotated in i16 ([`rotate_i16`]); with a rate every step takes the
/// f32 rotator's carrier.
///
/// # Safety
/// `data` must hold `n` samples of format `F`; `out.len() >= NT`; the CPU supports AVX2 and
/// FMA.
#[inline]
#[target_feature(enable = "avx2,fma")]
unsafe fn run<const F: u8, const NT: usize, const CHIRP: bool>(
    data: *const u8,
    n: usize,
    job: &Job16<'_>,
    out: &mut [Complex32],
) {
    let bps = if F == CI8 { 2 } else { 4 };
    let (full, total) = (n / L, n.div_ceil(L));
    // SAFETY: forwarded from the caller.
    let tail = unsafe { tail_copy::<L>(data, n, bps) };
    let (q_re, q_im) = job.carrier.chirp::<L>();
    let (qr, qi) = (_mm256_set1_ps(q_re), _mm256_set1_ps(q_im));
    let (ec, es) = step_rotation(job.carrier);
    let sh = _mm_cvtsi32_si128(job.sh as i32);
    let mut phase = CodePhase::new(job.nco.phases[0], job.nco.step * L as u64);
    let zero = _mm256_setzero_si256();
    let mut acc = [[zero; NT]; 2];
    let mut sums = [(0i64, 0i64); NT];
    let mut s = 0;
    while s < total {
        let end = total.min(s + RESEED_STEPS);
        let stride = if CHIRP { L } else { GROUP * L };
        let mut rot = Rotator16::seed(job.carrier, s * L, &job.plan.rotator, stride);
        while s < end {
            let (mut c, mut sn) = rot.carrier_i16();
            rot.advance::<CHIRP>(qr, qi);
            let group_end = if CHIRP { s + 1 } else { end.min(s + GROUP) };
            loop {
                // SAFETY: step_ptr yields 16 readable samples (slice or tail buffer).
                unsafe {
                    let p = step_ptr::<L>(data, s, full, bps, &tail);
                    step::<F, NT>(p, sh, c, sn, job, &phase, &mut acc);
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
    let unit = w_unit(job.sh);
    for t in 0..NT {
        out[t] = Complex32::new(
            (sums[t].0 as f64 * unit) as f32,
            (sums[t].1 as f64 * unit) as f32,
        );
    }
}
