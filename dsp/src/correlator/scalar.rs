//! Portable scalar kernels (and the reference): one sample at a time, fixed-point NCOs.
//!
//! Carrier: a 2^-48-cycle phase accumulator with a second-order step (for the rate) and a
//! 4096-entry table (phase error <= 1/8192 cycle). Code: the 2^-32-chip NCO of
//! [`super::plan`]. The f32 kernel accumulates `x * exp(-j 2 pi phi) * code` in f32; the int16
//! kernel multiplies integer samples by the table carrier rounded to Q14 (`round(2^14 cos)`) and
//! accumulates exactly in i64, scaled by 2^-14 on output.

use super::plan::{code_phase_fix, code_step_fix, CODE_LEN_FIX};
use super::{ReplicaState, MAX_TAPS};
use crate::constants::CA_CODE_LENGTH;
use crate::nco::SinCosTable;
use num_complex::Complex32;
use std::sync::OnceLock;

/// A complex sample format the scalar kernels read.
pub(crate) trait Sample: Copy {
    fn to_c32(self) -> Complex32;
}

/// An integer complex sample format.
pub(crate) trait IntSample: Copy {
    fn to_i32(self) -> (i32, i32);
}

impl Sample for Complex32 {
    #[inline(always)]
    fn to_c32(self) -> Complex32 {
        self
    }
}

impl Sample for [i16; 2] {
    #[inline(always)]
    fn to_c32(self) -> Complex32 {
        Complex32::new(f32::from(self[0]), f32::from(self[1]))
    }
}

impl Sample for [i8; 2] {
    #[inline(always)]
    fn to_c32(self) -> Complex32 {
        Complex32::new(f32::from(self[0]), f32::from(self[1]))
    }
}

impl IntSample for [i16; 2] {
    #[inline(always)]
    fn to_i32(self) -> (i32, i32) {
        (i32::from(self[0]), i32::from(self[1]))
    }
}

impl IntSample for [i8; 2] {
    #[inline(always)]
    fn to_i32(self) -> (i32, i32) {
        (i32::from(self[0]), i32::from(self[1]))
    }
}

fn table() -> &'static SinCosTable {
    static TABLE: OnceLock<SinCosTable> = OnceLock::new();
    TABLE.get_or_init(|| SinCosTable::new(12))
}

/// The table carrier: `exp(-j 2 pi phi(k))` sample by sample.
///
/// Phase, step and step increment in 2^-48 cycle (the table reads the top 12 bits): a rate of
/// a few kHz/s is only ~1 unit of 2^-32 cycle per sample^2 at 4 MHz, too coarse for 2^-32.
struct TableCarrier {
    phase: u64,
    step: i64,
    dstep: i64,
}

/// One cycle in the table carrier's units.
const FIX48: f64 = 281_474_976_710_656.0;

impl TableCarrier {
    fn new(state: &ReplicaState, fs_hz: f64) -> Self {
        let step0 = state.carrier_freq_hz / fs_hz;
        let dstep = state.carrier_rate_hz_s / (fs_hz * fs_hz);
        let phase = -state.carrier_phase_cycles;
        // Wipe-off multiplies by exp(-j 2 pi phi): run the accumulator at the negated
        // frequency. The phase increment between samples k and k+1 is step0 + dstep (k + 1/2).
        Self {
            phase: ((phase - phase.floor()) * FIX48) as u64,
            step: (-(step0 + 0.5 * dstep) * FIX48).round() as i64,
            dstep: (-dstep * FIX48).round() as i64,
        }
    }

    /// The phase (2^-32 cycle) for the current sample; advances to the next.
    #[inline(always)]
    fn next(&mut self) -> u32 {
        let p = (self.phase >> 16) as u32;
        self.phase = self.phase.wrapping_add(self.step as u64) & ((1 << 48) - 1);
        self.step = self.step.wrapping_add(self.dstep);
        p
    }
}

/// The scalar f32 kernel; `taps.len() <= MAX_TAPS` and `out.len() == taps.len()`.
pub(crate) fn correlate_f32<T: Sample>(
    samples: &[T],
    fs_hz: f64,
    code: &[i8; CA_CODE_LENGTH],
    state: &ReplicaState,
    taps: &[f64],
    out: &mut [Complex32],
) {
    let nt = taps.len().min(MAX_TAPS);
    let table = table();
    let mut carrier = TableCarrier::new(state, fs_hz);
    let code_step = code_step_fix(state.code_rate_chips_s, fs_hz);
    let mut phases = [0u64; MAX_TAPS];
    for (p, d) in phases.iter_mut().zip(taps) {
        *p = code_phase_fix(state.code_phase_chips + d);
    }
    let mut acc = [Complex32::new(0.0, 0.0); MAX_TAPS];
    for &x in samples {
        let w = x.to_c32() * table.lookup(carrier.next());
        for (p, a) in phases[..nt].iter_mut().zip(acc.iter_mut()) {
            let chip = f32::from(code[(*p >> 32) as usize]);
            *a += w * chip;
            *p += code_step;
            if *p >= CODE_LEN_FIX {
                *p -= CODE_LEN_FIX;
            }
        }
    }
    out[..nt].copy_from_slice(&acc[..nt]);
}

/// Q14: the carrier replica of the integer kernels is `round(2^14 exp(-j 2 pi phi))`.
pub(crate) const Q14: f32 = 16384.0;

/// The scalar int16 kernel (exact integer accumulation); same contract as [`correlate_f32`].
pub(crate) fn correlate_i16<T: IntSample>(
    samples: &[T],
    fs_hz: f64,
    code: &[i8; CA_CODE_LENGTH],
    state: &ReplicaState,
    taps: &[f64],
    out: &mut [Complex32],
) {
    let nt = taps.len().min(MAX_TAPS);
    let table = table();
    let mut carrier = TableCarrier::new(state, fs_hz);
    let code_step = code_step_fix(state.code_rate_chips_s, fs_hz);
    let mut phases = [0u64; MAX_TAPS];
    for (p, d) in phases.iter_mut().zip(taps) {
        *p = code_phase_fix(state.code_phase_chips + d);
    }
    let mut acc = [(0i64, 0i64); MAX_TAPS];
    for &x in samples {
        let c = table.lookup(carrier.next());
        let (cr, ci) = ((c.re * Q14).round() as i32, (c.im * Q14).round() as i32);
        let (xr, xi) = x.to_i32();
        // |x| <= 2^15 and |c| <= 2^14: each product fits in i32, the sum in i64.
        let wr = i64::from(xr * cr) - i64::from(xi * ci);
        let wi = i64::from(xr * ci) + i64::from(xi * cr);
        for (p, a) in phases[..nt].iter_mut().zip(acc.iter_mut()) {
            if code[(*p >> 32) as usize] < 0 {
                a.0 -= wr;
                a.1 -= wi;
            } else {
                a.0 += wr;
                a.1 += wi;
            }
            *p += code_step;
            if *p >= CODE_LEN_FIX {
                *p -= CODE_LEN_FIX;
            }
        }
    }
    for (o, a) in out[..nt].iter_mut().zip(acc) {
        *o = Complex32::new(
            (a.0 as f64 / f64::from(Q14)) as f32,
            (a.1 as f64 / f64::from(Q14)) as f32,
        );
    }
}
