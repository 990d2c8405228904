//! The AVX-512 int16 kernel for ci8 and ci16 samples: 32 samples per vector step in 16-bit
//! lanes, `vpdpwssd` (AVX-512 VNNI) for the code products; the design of
//! [`super::avx2_i16`] twice as wide (positions, code plan and scale:
//! [`super::int16_lanes`]).
//!
//! Per step of 32 samples (ci8: one 64-byte load; ci16: two, blended into I and Q vectors
//! and shifted left by the block's headroom):
//! - **Carrier** in Q14 i16 lanes from the f32 rotator of [`super::plan`] (32 lanes as two
//!   sets of 16, packed with `vpackssdw`), every step when the frequency ramps; at a constant
//!   frequency every [`GROUP`] = 4 steps, the 3 between rotating the previous i16 carrier by
//!   `E = exp(-j 2 pi 32 a)` in Q15 (`vpmulhrsw`): the error bound of [`super::avx2_i16`],
//!   `4.1e-4` of the carrier's modulus (the same 3 rotations, whatever the rotation angle).
//! - **Wipe-off** with `vpmulhrsw` as in [`super::avx2_i16`] (units of `2^(1 - sh)` sample).
//! - **Code**: two unsigned compares of 16 i32 lanes against the plan's thresholds give the
//!   carries straight into mask registers (`kunpckwd` joins them, one bit per position), a
//!   masked `vpaddw` adds them to both bytes of each lane's offset, `vpshufb` reads the 16
//!   code bytes broadcast to the four 128-bit lanes, `| 1` makes them +-1, and `vpdpwssd`
//!   multiplies with `wr` / `wi`, sums pairs and accumulates in one instruction.
//! - Lane sums grow by at most `2 * 2^15` per step: flushed to i64 every 256 steps (with the
//!   rotator's re-seed).
//!
//! Needs 32 samples within 15 chips (a code step below 14/31 chip per sample, `fs` above
//! about 2.2 MHz); otherwise [`Plan32::with`] says no and the caller runs the 16-lane AVX2
//! kernel.

use super::int16_lanes::{w_unit, KernelPlan};
use super::packed::PackedCode;
use super::plan::{CarrierNco, CodeNco, CODE_LEN_FIX, RESEED_STEPS};
use super::scalar::Q14;
use super::simd::{step_ptr, tail_copy, CI16, CI8};
use num_complex::Complex32;
use std::arch::x86_64::*;

const L: usize = 32;
/// Vector steps per f32 rotator step at a constant frequency (module doc).
const GROUP: usize = 4;

/// The code plan of the 32-lane kernel and the lane order of its samples.
pub(super) type Plan32 = KernelPlan<L>;

impl Plan32 {
    /// Runs `f` with the plan for the taps of `nco` (`n_taps`) on samples of format `F` (ci8
    /// or ci16), or returns `None` if some lane lies 16 or more chips past its tap's window.
    /// The plan is written in place into one kept per thread ([`KernelPlan::fill`]).
    pub(super) fn with<const F: u8, R>(
        nco: &CodeNco,
        n_taps: usize,
        f: impl FnOnce(&Self) -> R,
    ) -> Option<R> {
        thread_local! {
            static PLAN: std::cell::RefCell<Plan32> = const { std::cell::RefCell::new(Plan32::ZERO) };
        }
        PLAN.with(|plan| {
            let mut plan = plan.try_borrow_mut().ok()?;
            // Compare lane j sets mask bit j: position j. Unsigned compares: no sign flip.
            plan.fill::<F>(nco, n_taps, |j| j, 0).then(|| f(&plan))
        })
    }
}

/// Runs the kernel for `out.len()` (1..=8) taps on the `n` samples of format `F` at `data`
/// with the plan from [`Plan32::with`] (of the same format) and headroom shift `sh`.
///
/// # Safety
/// The CPU must support AVX-512 F, BW and VNNI, AVX2 and FMA; `data` must hold `n` samples of
/// format `F`.
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn correlate<const F: u8>(
    data: *const u8,
    n: usize,
    sh: u32,
    code: &PackedCode,
    nco: &CodeNco,
    carrier: &CarrierNco,
    plan: &Plan32,
    out: &mut [Complex32],
) {
    let job = Job32 {
        code,
        nco,
        carrier,
        plan,
        sh,
    };
    let p = data;
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

struct Job32<'a> {
    code: &'a PackedCode,
    nco: &'a CodeNco,
    carrier: &'a CarrierNco,
    plan: &'a Plan32,
    sh: u32,
}

/// The f32 rotator of 32 lanes (A and B, 16 each), seeded in the plan's order, scaled by 2^14.
struct Rotator32 {
    p: [__m512; 4],
    d: [__m512; 4],
}

impl Rotator32 {
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
    fn seed(c: &CarrierNco, k0: usize, order: &[usize; L], stride: usize) -> Self {
        let s = c.seed_stride::<L>(k0, order, f64::from(Q14), stride);
        // SAFETY: each array holds 32 f32: two vectors of 16.
        unsafe {
            let v = |a: &[f32; L], h: usize| _mm512_loadu_ps(a.as_ptr().add(16 * h));
            Self {
                p: [v(&s.p_re, 0), v(&s.p_im, 0), v(&s.p_re, 1), v(&s.p_im, 1)],
                d: [v(&s.d_re, 0), v(&s.d_im, 0), v(&s.d_re, 1), v(&s.d_im, 1)],
            }
        }
    }

    /// The carrier of this step as i16 lanes in position order: `(c, s)`.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
    fn carrier_i16(&self) -> (__m512i, __m512i) {
        let [ar, ai, br, bi] = self.p;
        (
            _mm512_packs_epi32(_mm512_cvtps_epi32(ar), _mm512_cvtps_epi32(br)),
            _mm512_packs_epi32(_mm512_cvtps_epi32(ai), _mm512_cvtps_epi32(bi)),
        )
    }

    /// `P *= D`, and with a rate `D *= Q`.
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
    fn advance<const CHIRP: bool>(&mut self, qr: __m512, qi: __m512) {
        for h in 0..2 {
            let (pr, pi) = (self.p[2 * h], self.p[2 * h + 1]);
            let (dr, di) = (self.d[2 * h], self.d[2 * h + 1]);
            self.p[2 * h] = _mm512_fmsub_ps(pr, dr, _mm512_mul_ps(pi, di));
            self.p[2 * h + 1] = _mm512_fmadd_ps(pr, di, _mm512_mul_ps(pi, dr));
            if CHIRP {
                self.d[2 * h] = _mm512_fmsub_ps(dr, qr, _mm512_mul_ps(di, qi));
                self.d[2 * h + 1] = _mm512_fmadd_ps(dr, qi, _mm512_mul_ps(di, qr));
            }
        }
    }
}

/// 32 samples of format `F` at `p` as `(I 2^sh, Q 2^sh)` in i16 lanes, position order.
///
/// # Safety
/// `p` points to 32 readable samples of format `F`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
unsafe fn load<const F: u8>(p: *const u8, sh: __m128i) -> (__m512i, __m512i) {
    // SAFETY: 64 (ci8) or 128 (ci16) readable bytes at p.
    unsafe {
        if F == CI16 {
            let a = _mm512_sll_epi16(_mm512_loadu_si512(p.cast()), sh);
            let b = _mm512_sll_epi16(_mm512_loadu_si512(p.add(64).cast()), sh);
            let odd = 0xAAAA_AAAA;
            (
                _mm512_mask_blend_epi16(odd, a, _mm512_slli_epi32::<16>(b)),
                _mm512_mask_blend_epi16(odd, _mm512_srli_epi32::<16>(a), b),
            )
        } else {
            let x = _mm512_loadu_si512(p.cast());
            (
                _mm512_slli_epi16::<8>(x),
                _mm512_and_si512(x, _mm512_set1_epi16(0xFF00_u16 as i16)),
            )
        }
    }
}

/// Wipes the carrier `(c, s)` off `(xi, xq)`: `(wr, wi)` in units of `2^(1 - sh)` sample.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
fn wipe(xi: __m512i, xq: __m512i, c: __m512i, s: __m512i) -> (__m512i, __m512i) {
    (
        _mm512_sub_epi16(_mm512_mulhrs_epi16(xi, c), _mm512_mulhrs_epi16(xq, s)),
        _mm512_add_epi16(_mm512_mulhrs_epi16(xi, s), _mm512_mulhrs_epi16(xq, c)),
    )
}

/// The +-1 replica (i16 lanes, position order) of tap `t` when the first tap's phase has low
/// half `bx` (broadcast) and chip `chip`.
///
/// # Safety
/// `chip < 1023`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
unsafe fn replica(job: &Job32<'_>, t: usize, chip: usize, bx: __m512i) -> __m512i {
    let plan = &job.plan.code;
    // SAFETY: thr[t] holds 32 u32 (two vectors), hi_dup[t] 32 i16; chip + W_t < 2046 and the
    // byte code holds 2064 bytes, so the 16 bytes at chip + W_t are readable.
    unsafe {
        let thr = plan.thr[t].as_ptr();
        let lo = _mm512_cmpgt_epu32_mask(bx, _mm512_loadu_si512(thr.cast()));
        let hi = _mm512_cmpgt_epu32_mask(bx, _mm512_loadu_si512(thr.add(16).cast()));
        let carry = _mm512_kunpackw(u32::from(hi), u32::from(lo));
        let off = _mm512_loadu_si512(plan.hi_dup[t].as_ptr().cast());
        let idx = _mm512_mask_add_epi16(off, carry, off, _mm512_set1_epi16(0x0101));
        let window = _mm512_broadcast_i32x4(_mm_loadu_si128(
            job.code
                .chip_bytes()
                .as_ptr()
                .add(chip + plan.whole[t])
                .cast(),
        ));
        _mm512_or_si512(
            _mm512_shuffle_epi8(window, idx),
            _mm512_set1_epi32(0x0001_0001),
        )
    }
}

/// The code phase of the first tap: `base` in 2^-32 chip and its low half `bx` broadcast.
struct CodePhase {
    base: u64,
    bx: __m512i,
    step: u64,
    step_lo: __m512i,
}

impl CodePhase {
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
    fn new(base: u64, step: u64) -> Self {
        Self {
            base,
            bx: _mm512_set1_epi32(base as u32 as i32),
            step,
            step_lo: _mm512_set1_epi32(step as u32 as i32),
        }
    }

    /// Advances by one vector step (the low half wraps by itself: the period is a multiple
    /// of 2^32).
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
    fn advance(&mut self) {
        self.bx = _mm512_add_epi32(self.bx, self.step_lo);
        self.base += self.step;
        if self.base >= CODE_LEN_FIX {
            self.base -= CODE_LEN_FIX;
        }
    }
}

/// One vector step: wipes the carrier `(c, s)` off the 32 samples at `p` and adds every
/// tap's sums.
///
/// # Safety
/// `p` points to 32 readable samples of format `F`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
#[allow(clippy::too_many_arguments)]
unsafe fn step<const F: u8, const NT: usize>(
    p: *const u8,
    sh: __m128i,
    c: __m512i,
    s: __m512i,
    job: &Job32<'_>,
    phase: &CodePhase,
    acc: &mut [[__m512i; NT]; 2],
) {
    // SAFETY: the caller guarantees 32 samples at p.
    let (xi, xq) = unsafe { load::<F>(p, sh) };
    let (wr, wi) = wipe(xi, xq, c, s);
    let chip = (phase.base >> 32) as usize;
    let [acc_re, acc_im] = acc;
    for (t, (re, im)) in acc_re.iter_mut().zip(acc_im.iter_mut()).enumerate() {
        // SAFETY: base < 1023 * 2^32, so chip < 1023.
        let code = unsafe { replica(job, t, chip, phase.bx) };
        *re = _mm512_dpwssd_epi32(*re, wr, code);
        *im = _mm512_dpwssd_epi32(*im, wi, code);
    }
}

/// `(c + j s) (ec + j es)` in i16 lanes: `(c, s)` in Q14, `(ec, es)` in Q15, each product
/// rounded (`vpmulhrsw`).
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
fn rotate_i16(c: __m512i, s: __m512i, ec: __m512i, es: __m512i) -> (__m512i, __m512i) {
    (
        _mm512_sub_epi16(_mm512_mulhrs_epi16(c, ec), _mm512_mulhrs_epi16(s, es)),
        _mm512_add_epi16(_mm512_mulhrs_epi16(c, es), _mm512_mulhrs_epi16(s, ec)),
    )
}

/// The step rotation `E = exp(-j 2 pi 32 a)` in Q15 lanes `(ec, es)`.
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
fn step_rotation(carrier: &CarrierNco) -> (__m512i, __m512i) {
    let (re, im) = carrier.step_phasor(L);
    let q15 = |v: f64| (v * 32768.0).round().clamp(-32768.0, 32767.0) as i16;
    (_mm512_set1_epi16(q15(re)), _mm512_set1_epi16(q15(im)))
}

/// The kernel body for format `F` and `NT` taps, the rotator's rate compiled in or out (as
/// [`super::avx2_i16`]'s).
///
/// # Safety
/// `data` must hold `n` samples of format `F`; `out.len() >= NT`; the CPU supports the
/// features of [`correlate`].
#[inline]
#[target_feature(enable = "avx512f,avx512bw,avx512vnni,avx2,fma")]
unsafe fn run<const F: u8, const NT: usize, const CHIRP: bool>(
    data: *const u8,
    n: usize,
    job: &Job32<'_>,
    out: &mut [Complex32],
) {
    let bps = if F == CI8 { 2 } else { 4 };
    let (full, total) = (n / L, n.div_ceil(L));
    // SAFETY: forwarded from the caller.
    let tail = unsafe { tail_copy::<L>(data, n, bps) };
    let (q_re, q_im) = job.carrier.chirp::<L>();
    let (qr, qi) = (_mm512_set1_ps(q_re), _mm512_set1_ps(q_im));
    let (ec, es) = step_rotation(job.carrier);
    let sh = _mm_cvtsi32_si128(job.sh as i32);
    let mut phase = CodePhase::new(job.nco.phases[0], job.nco.step * L as u64);
    let zero = _mm512_setzero_si512();
    let mut acc = [[zero; NT]; 2];
    let mut sums = [(0i64, 0i64); NT];
    let mut s = 0;
    while s < total {
        let end = total.min(s + RESEED_STEPS);
        let stride = if CHIRP { L } else { GROUP * L };
        let mut rot = Rotator32::seed(job.carrier, s * L, &job.plan.rotator, stride);
        while s < end {
            let (mut c, mut sn) = rot.carrier_i16();
            rot.advance::<CHIRP>(qr, qi);
            let group_end = if CHIRP { s + 1 } else { end.min(s + GROUP) };
            loop {
                // SAFETY: step_ptr yields 32 readable samples (slice or tail buffer).
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
            // 16 lanes below 2^24 each: the i32 sum cannot overflow.
            sums[t].0 += i64::from(_mm512_reduce_add_epi32(acc[0][t]));
            sums[t].1 += i64::from(_mm512_reduce_add_epi32(acc[1][t]));
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
