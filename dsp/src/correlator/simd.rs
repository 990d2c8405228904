//! Pieces shared by the AVX2 and AVX-512 kernels: sample formats, the per-call job, the
//! zero-padded tail and the dispatch on format, arithmetic and tap count.

use super::kernel::SampleSlice;
use super::packed::PackedCode;
use super::plan::{natural, CarrierNco, CodeNco};
use super::ReplicaState;

/// Sample format tags (const generic parameters of the kernels).
pub(super) const CF32: u8 = 0;
pub(super) const CI16: u8 = 1;
pub(super) const CI8: u8 = 2;

/// Bytes per complex sample of a format.
pub(super) const fn bytes_per_sample(f: u8) -> usize {
    match f {
        CF32 => 8,
        CI16 => 4,
        _ => 2,
    }
}

/// Bytes of the tail buffer: 16 cf32 samples, the widest vector step.
const TAIL_BYTES: usize = 128;

/// Everything a kernel of `L` lanes needs besides the samples.
pub(super) struct Job<'a, const L: usize> {
    pub code: &'a PackedCode,
    pub nco: CodeNco,
    pub lane_lo: [u32; L],
    pub lane_hi: [u32; L],
    pub carrier: CarrierNco,
    pub order: [usize; L],
}

impl<'a, const L: usize> Job<'a, L> {
    /// The job for a block; cf32 lanes in `cf32_order`, integer formats in sample order.
    /// `None` if the code step is too large for the 32-bit code window.
    pub fn new(
        samples: &SampleSlice<'_>,
        fs_hz: f64,
        code: &'a PackedCode,
        state: &ReplicaState,
        taps: &[f64],
        cf32_order: [usize; L],
    ) -> Option<Self> {
        let order = match samples {
            SampleSlice::Cf32(_) => cf32_order,
            _ => natural::<L>(),
        };
        let nco = CodeNco::new(state, fs_hz, taps);
        let (lane_lo, lane_hi) = nco.lanes(&order)?;
        Some(Self {
            code,
            nco,
            lane_lo,
            lane_hi,
            carrier: CarrierNco::new(state, fs_hz),
            order,
        })
    }
}

/// The samples of vector step `s` (`full` whole steps in `data`, then the zero-padded tail).
///
/// # Safety
/// `data` must hold `full * L` samples of `bps` bytes.
#[inline(always)]
pub(super) unsafe fn step_ptr<const L: usize>(
    data: *const u8,
    s: usize,
    full: usize,
    bps: usize,
    tail: &[u8; TAIL_BYTES],
) -> *const u8 {
    if s < full {
        // SAFETY: step s < full lies inside the slice.
        unsafe { data.add(s * L * bps) }
    } else {
        tail.as_ptr()
    }
}

/// The zero-padded copy of the last `n % L` samples (zero samples add exactly nothing).
///
/// # Safety
/// `data` must hold `n` samples of `bps` bytes; `L * bps <= 128`.
#[inline(always)]
pub(super) unsafe fn tail_copy<const L: usize>(
    data: *const u8,
    n: usize,
    bps: usize,
) -> [u8; TAIL_BYTES] {
    let mut tail = [0u8; TAIL_BYTES];
    let full = n / L;
    // SAFETY: the last n % L samples lie inside the slice and fit the buffer.
    unsafe {
        std::ptr::copy_nonoverlapping(data.add(full * L * bps), tail.as_mut_ptr(), (n % L) * bps)
    };
    tail
}

/// Calls `$f::<$fmt, NT>(args)` with `NT` the tap count (1..=8) as a const generic.
macro_rules! by_taps {
    ($nt:expr, $f:ident::<$fmt:ident>($($arg:expr),*)) => {
        match $nt {
            1 => $f::<$fmt, 1>($($arg),*),
            2 => $f::<$fmt, 2>($($arg),*),
            3 => $f::<$fmt, 3>($($arg),*),
            4 => $f::<$fmt, 4>($($arg),*),
            5 => $f::<$fmt, 5>($($arg),*),
            6 => $f::<$fmt, 6>($($arg),*),
            7 => $f::<$fmt, 7>($($arg),*),
            _ => $f::<$fmt, 8>($($arg),*),
        }
    };
}

/// Runs the calling module's `f32_kernel` / `i16_kernel` for the arithmetic, format and tap
/// count (cf32 input always takes the f32 kernel). Must be used inside `unsafe`.
macro_rules! dispatch {
    ($arith:expr, $samples:expr, $nt:expr, $job:expr, $out:expr) => {
        match ($arith, $samples) {
            (Arithmetic::I16, SampleSlice::Ci16(x)) => {
                by_taps!(
                    $nt,
                    i16_kernel::<CI16>(x.as_ptr().cast(), x.len(), $job, $out)
                )
            }
            (Arithmetic::I16, SampleSlice::Ci8(x)) => {
                by_taps!(
                    $nt,
                    i16_kernel::<CI8>(x.as_ptr().cast(), x.len(), $job, $out)
                )
            }
            (_, SampleSlice::Cf32(x)) => {
                by_taps!(
                    $nt,
                    f32_kernel::<CF32>(x.as_ptr().cast(), x.len(), $job, $out)
                )
            }
            // F32 (and an unresolved Auto, which `Correlator` never passes).
            (_, SampleSlice::Ci16(x)) => {
                by_taps!(
                    $nt,
                    f32_kernel::<CI16>(x.as_ptr().cast(), x.len(), $job, $out)
                )
            }
            (_, SampleSlice::Ci8(x)) => {
                by_taps!(
                    $nt,
                    f32_kernel::<CI8>(x.as_ptr().cast(), x.len(), $job, $out)
                )
            }
        }
    };
}

pub(super) use {by_taps, dispatch};
