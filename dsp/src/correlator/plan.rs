//! Per-call setup shared by the kernels: the fixed-point code NCO of every tap and the exact
//! (f64) seeding of the vectorised carrier rotator.
//!
//! Code: phase in units of 2^-32 chip (u64), `p_i(k) = p_i(0) + k S mod 1023 * 2^32` with
//! `S = round(rc / fs * 2^32)`, exactly as the scalar reference, so every kernel picks the same
//! chip for every sample. A vector of `L` lanes covers samples `k0 + o_j` (lane order `o`, a
//! permutation of `0..L` that matches how a format's loads deinterleave samples); lane `j`'s chip
//! is `(B + o_j S) >> 32` with `B` the tap's phase at `k0`, i.e. `B_hi + (o_j S >> 32) + carry`
//! with `carry = [(B_lo + (o_j S mod 2^32)) >= 2^32]` -- exact 32-bit lane arithmetic.
//!
//! Carrier: lane `j` holds `P_j = exp(-j 2 pi phi(k0 + o_j))` and the step phasor
//! `D_j = exp(-j 2 pi (phi(k + L) - phi(k)))` at `k = k0 + o_j`; each vector step does
//! `P *= D`, and with a rate `D *= Q`, `Q = exp(-j 2 pi 2 b L^2)` (`phi(k) = phi0 + a k + b k^2`,
//! so `phi(k + L) - phi(k) = L a + L^2 b + 2 L b k`). Seeds are computed in f64 and rounded once.

// Only the SIMD kernels use the lane and rotator helpers.
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]

use super::{ReplicaState, MAX_TAPS};
use crate::constants::CA_CODE_LENGTH;
use num_complex::Complex64;

/// One chip (or cycle) in fixed-point units.
pub(crate) const FIX: f64 = 4_294_967_296.0;
/// The code period in 2^-32 chip.
pub(crate) const CODE_LEN_FIX: u64 = (CA_CODE_LENGTH as u64) << 32;
/// Vector steps between exact re-seeds of the rotator (and flushes of integer accumulators).
pub(crate) const RESEED_STEPS: usize = 256;

/// Code NCO step, 2^-32 chip per sample. Meaningless inputs (negative or NaN rate, `fs <= 0`)
/// give 0 (the code stands still) and steps are capped below one code period, so the phase
/// arithmetic never overflows.
pub(crate) fn code_step_fix(code_rate_chips_s: f64, fs_hz: f64) -> u64 {
    ((code_rate_chips_s / fs_hz * FIX).round() as u64).min(CODE_LEN_FIX - 1)
}

/// A code phase in 2^-32 chip, reduced modulo 1023 chips.
pub(crate) fn code_phase_fix(chips: f64) -> u64 {
    let p = (chips.rem_euclid(CA_CODE_LENGTH as f64) * FIX) as u64;
    // rem_euclid of a tiny negative number can round to exactly 1023.0.
    if p >= CODE_LEN_FIX {
        p - CODE_LEN_FIX
    } else {
        p
    }
}

/// The code NCO of up to [`MAX_TAPS`] taps.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CodeNco {
    /// Step per sample, 2^-32 chip.
    pub step: u64,
    /// Each tap's phase at the first sample, 2^-32 chip in [0, 1023 * 2^32).
    pub phases: [u64; MAX_TAPS],
}

impl CodeNco {
    pub fn new(state: &ReplicaState, fs_hz: f64, taps: &[f64]) -> Self {
        let mut phases = [0u64; MAX_TAPS];
        for (p, d) in phases.iter_mut().zip(taps) {
            *p = code_phase_fix(state.code_phase_chips + d);
        }
        Self {
            step: code_step_fix(state.code_rate_chips_s, fs_hz),
            phases,
        }
    }

    /// Per-lane constants for `L` lanes in `order`: `(o_j S) mod 2^32` and `o_j S >> 32`.
    /// `None` if a vector would span more than 30 chips (step > 30/(L-1) chip per sample, i.e.
    /// `fs` far below the chip rate): the 32-bit code window cannot cover it.
    pub fn lanes<const L: usize>(&self, order: &[usize; L]) -> Option<([u32; L], [u32; L])> {
        let mut lo = [0u32; L];
        let mut hi = [0u32; L];
        for j in 0..L {
            let v = (order[j] as u64).checked_mul(self.step)?;
            lo[j] = v as u32;
            hi[j] = u32::try_from(v >> 32).ok().filter(|&h| h <= 30)?;
        }
        Some((lo, hi))
    }
}

/// Reads the 32 code bits starting at chip `chip` (< 1023) from the periodically extended
/// bit-packed code (bit set = chip -1).
///
/// # Safety
/// `bits` must point to at least `(1022 >> 3) + 8` readable bytes.
#[inline(always)]
pub(crate) unsafe fn code_window(bits: *const u8, chip: usize) -> u32 {
    // SAFETY: chip < 1023, so the 8 bytes at chip >> 3 lie within the caller's guarantee.
    let w = unsafe { std::ptr::read_unaligned(bits.add(chip >> 3) as *const u64) };
    (u64::from_le(w) >> (chip & 7)) as u32
}

/// The carrier NCO `phi(k) = phi0 + a k + b k^2` in cycles.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CarrierNco {
    phi0: f64,
    a: f64,
    b: f64,
}

/// Rotator seeds for `L` lanes: phasors `P` (times a scale) and step phasors `D`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Seed<const L: usize> {
    pub p_re: [f32; L],
    pub p_im: [f32; L],
    pub d_re: [f32; L],
    pub d_im: [f32; L],
}

/// `exp(-j 2 pi x)`, argument reduced first so large phases keep their precision.
fn cis_neg(cycles: f64) -> Complex64 {
    if cycles == 0.0 {
        // No rate (a constant frequency, what tracking asks for): no sin/cos to pay.
        return Complex64::new(1.0, 0.0);
    }
    let x = cycles - cycles.round();
    let (s, c) = (2.0 * std::f64::consts::PI * x).sin_cos();
    Complex64::new(c, -s)
}

impl CarrierNco {
    pub fn new(state: &ReplicaState, fs_hz: f64) -> Self {
        Self {
            phi0: state.carrier_phase_cycles.rem_euclid(1.0),
            a: state.carrier_freq_hz / fs_hz,
            b: 0.5 * state.carrier_rate_hz_s / (fs_hz * fs_hz),
        }
    }

    /// Whether the frequency ramps within the block.
    pub fn chirps(&self) -> bool {
        self.b != 0.0
    }

    /// `phi(k)` in cycles, each term reduced modulo 1.
    fn phase(&self, k: f64) -> f64 {
        let ak = self.a * k;
        let bk = self.b * k * k;
        self.phi0 + (ak - ak.floor()) + (bk - bk.floor())
    }

    /// The phasor of `n` samples at the initial frequency, `exp(-j 2 pi a n)` (re, im).
    pub fn step_phasor(&self, n: usize) -> (f64, f64) {
        let d = cis_neg(self.a * n as f64);
        (d.re, d.im)
    }

    /// The chirp phasor `Q = exp(-j 2 pi 2 b L^2)` as f32 (re, im).
    pub fn chirp<const L: usize>(&self) -> (f32, f32) {
        let l = L as f64;
        let q = cis_neg(2.0 * self.b * l * l);
        (q.re as f32, q.im as f32)
    }

    /// Seeds for the vector step starting at sample `k0`: lane `j` at sample `k0 + order[j]`,
    /// `P` scaled by `scale`. Natural-order lanes by f64 recurrences (3 sin/cos in all).
    pub fn seed<const L: usize>(&self, k0: usize, order: &[usize; L], scale: f64) -> Seed<L> {
        self.seed_stride(k0, order, scale, L)
    }

    /// [`CarrierNco::seed`] with step phasors `D` for an advance of `stride` samples (a
    /// multiple of `L` when one rotator step serves several vector steps).
    pub fn seed_stride<const L: usize>(
        &self,
        k0: usize,
        order: &[usize; L],
        scale: f64,
        stride: usize,
    ) -> Seed<L> {
        if self.b == 0.0 {
            return self.seed_constant(k0, order, scale, stride);
        }
        let k = k0 as f64;
        let l = stride as f64;
        let mut p = cis_neg(self.phase(k)) * scale;
        // phi(k+1) - phi(k) = a + (2k + 1) b, growing by 2b per sample.
        let mut e = cis_neg(self.a + (2.0 * k + 1.0) * self.b);
        let g = cis_neg(2.0 * self.b);
        let mut d = cis_neg(l * self.a + l * l * self.b + 2.0 * l * self.b * k);
        let h = cis_neg(2.0 * l * self.b);
        let mut pn = [Complex64::new(0.0, 0.0); L];
        let mut dn = [Complex64::new(0.0, 0.0); L];
        for (pj, dj) in pn.iter_mut().zip(dn.iter_mut()) {
            *pj = p;
            *dj = d;
            p *= e;
            e *= g;
            d *= h;
        }
        let mut s = Seed {
            p_re: [0.0; L],
            p_im: [0.0; L],
            d_re: [0.0; L],
            d_im: [0.0; L],
        };
        for (j, &o) in order.iter().enumerate() {
            s.p_re[j] = pn[o].re as f32;
            s.p_im[j] = pn[o].im as f32;
            s.d_re[j] = dn[o].re as f32;
            s.d_im[j] = dn[o].im as f32;
        }
        s
    }
}

impl CarrierNco {
    /// [`CarrierNco::seed_stride`] at a constant frequency: `P_j = P_0 e^j` by four
    /// interleaved recurrences (`P_{j+4} = P_j e^4`: a quarter of the serial chain of complex
    /// products, which is what the seeding time is), every `D_j` the same.
    fn seed_constant<const L: usize>(
        &self,
        k0: usize,
        order: &[usize; L],
        scale: f64,
        stride: usize,
    ) -> Seed<L> {
        let p0 = cis_neg(self.phase(k0 as f64)) * scale;
        let e = cis_neg(self.a);
        let e2 = e * e;
        let e4 = e2 * e2;
        let d = cis_neg(stride as f64 * self.a);
        let mut pn = [Complex64::new(0.0, 0.0); L];
        let mut head = [p0, p0 * e, p0 * e2, p0 * e2 * e];
        for chunk in pn.chunks_mut(4) {
            for (pj, h) in chunk.iter_mut().zip(head.iter_mut()) {
                *pj = *h;
                *h *= e4;
            }
        }
        let mut s = Seed {
            p_re: [0.0; L],
            p_im: [0.0; L],
            d_re: [d.re as f32; L],
            d_im: [d.im as f32; L],
        };
        for (j, &o) in order.iter().enumerate() {
            s.p_re[j] = pn[o].re as f32;
            s.p_im[j] = pn[o].im as f32;
        }
        s
    }
}

/// The identity lane order `0..L`.
pub(crate) const fn natural<const L: usize>() -> [usize; L] {
    let mut o = [0usize; L];
    let mut j = 0;
    while j < L {
        o[j] = j;
        j += 1;
    }
    o
}
