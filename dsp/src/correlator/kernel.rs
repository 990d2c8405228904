//! The run-time chosen correlator: [`Isa`] x [`Arithmetic`], sample formats read directly.
//!
//! As in RustFFT, a SIMD kernel is a distinct private type that only its CPU check constructs,
//! so every call into `#[target_feature]` code rests on a fact the type proves; a [`Correlator`]
//! holds one of them and can only be made by [`Correlator::new`], [`Correlator::best`] or
//! [`Correlator::available`].

use super::packed::PackedCode;
use super::{scalar, ReplicaState, MAX_TAPS};
use crate::constants::CA_CODE_LENGTH;
use num_complex::Complex32;

#[cfg(target_arch = "x86_64")]
use super::{avx2::Avx2Kernel, avx512::Avx512Kernel};

/// A block of complex baseband samples in one of the supported formats, read in place.
#[derive(Debug, Clone, Copy)]
pub enum SampleSlice<'a> {
    /// Complex f32 (`re`, `im`).
    Cf32(&'a [Complex32]),
    /// Interleaved 16-bit I/Q.
    Ci16(&'a [[i16; 2]]),
    /// Interleaved 8-bit I/Q.
    Ci8(&'a [[i8; 2]]),
}

impl SampleSlice<'_> {
    /// Number of complex samples.
    pub fn len(&self) -> usize {
        match self {
            Self::Cf32(s) => s.len(),
            Self::Ci16(s) => s.len(),
            Self::Ci8(s) => s.len(),
        }
    }

    /// Whether the block holds no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Instruction set of a kernel, ordered from the most portable to the widest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// Portable scalar code (the reference; every CPU).
    Scalar,
    /// x86-64 AVX2 and FMA: 8 samples per vector step.
    Avx2Fma,
    /// x86-64 AVX-512 F+BW: 16 samples per vector step.
    Avx512,
}

impl Isa {
    /// Every instruction set, scalar first.
    pub const ALL: [Isa; 3] = [Isa::Scalar, Isa::Avx2Fma, Isa::Avx512];

    /// The short name used in kernel names and options: `scalar`, `avx2+fma`, `avx512`.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Scalar => "scalar",
            Isa::Avx2Fma => "avx2+fma",
            Isa::Avx512 => "avx512",
        }
    }

    /// Whether the running CPU has this instruction set.
    pub fn is_available(self) -> bool {
        Correlator::new(self, Arithmetic::F32).is_some()
    }
}

/// The sampling rate from which the 16-lane int16 kernels surely take a block: 16 samples
/// within 14 chips at the nominal chip rate (code Doppler and the taps' fractions can move the
/// real limit by a few kHz; below it they fall back to the 8-lane kernels, as they say).
const INT16_LANES_16_FS_HZ: f64 = 1.1e6;
/// The same for the 32-lane AVX-512 int16 kernel: 32 samples within 14 chips.
const INT16_LANES_32_FS_HZ: f64 = 2.27e6;

/// Arithmetic of a kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Arithmetic {
    /// f32 wipe-off and accumulation.
    F32,
    /// Integer samples times a Q14 int16 carrier replica `round(2^14 exp(-j 2 pi phi))`
    /// (`vpmaddwd`: exact i32 products), exact integer accumulation, scaled back by 2^-14 on
    /// output. Carrier quantisation: 2^-15 per component (< 4.5e-5 relative). ci8 products
    /// (|w| <= 2^22) are summed as they are; ci16 products are first rounded to multiples of
    /// 2^8 (`(w + 128) >> 8`, at most 2^-7 sample units per sample) to stay within 2^22; the
    /// i32 lane sums are flushed to i64 every 256 vector steps, so nothing overflows. The
    /// int16-lane kernels on ci8 and ci16 (AVX2: 16 samples per step above about 1.1 MHz;
    /// AVX-512 with VNNI: 32 above about 2.27 MHz) work in 16-bit lanes instead: each product
    /// `I c`, `Q s` is rounded to `2^-sh` sample (`vpmulhrsw`), `sh = 8` for ci8 and the
    /// block's headroom for ci16 (so `2^-15` of the block's largest sample), a wiped sample
    /// off by at most `2^(1 - sh) sqrt 2`; then `vpmaddwd` / `vpdpwssd` with the +-1 code sum
    /// exactly. At a constant frequency 3 of every 4 of their carrier vectors are the previous
    /// one rotated in i16, which bounds the carrier error by `4.1e-4` (relative, instead of
    /// `4.3e-5`). These roundings are far below the noise of any real recording (-68 dB
    /// against the noise: < 1e-3 dB of loss). The scalar I16 kernel uses the table carrier in
    /// Q14 and i64 sums. Cf32 input has no integer scale to quantise to: with it, an I16
    /// correlator runs the F32 kernel of the same ISA.
    I16,
    /// The faster of the two for each block: I16 of the correlator's own ISA on ci8 and ci16
    /// where the int16-lane kernels run (AVX2 or AVX-512, `fs` above about 1.1 MHz: about
    /// twice the f32 kernels' speed; their accuracy is I16's), F32 on cf32, at lower rates and
    /// on a CPU without AVX2. Never listed by [`Correlator::available`]: it picks among those.
    Auto,
}

impl Arithmetic {
    /// The short name: `f32` or `i16`.
    pub fn name(self) -> &'static str {
        match self {
            Arithmetic::F32 => "f32",
            Arithmetic::I16 => "i16",
            Arithmetic::Auto => "auto",
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Kernel {
    Scalar,
    #[cfg(target_arch = "x86_64")]
    Avx2(Avx2Kernel),
    #[cfg(target_arch = "x86_64")]
    Avx512(Avx512Kernel),
}

/// A correlator kernel the running CPU supports; see the module doc of [`super`] for the sums.
#[derive(Clone, Copy, Debug)]
pub struct Correlator {
    kernel: Kernel,
    arithmetic: Arithmetic,
}

impl Correlator {
    /// The fastest f32 kernel this CPU runs (AVX-512, else AVX2+FMA, else scalar).
    pub fn best() -> Self {
        Self::best_up_to(Isa::Avx512, Arithmetic::F32)
    }

    /// The fastest kernel of `arithmetic` whose instruction set is at most `max_isa` and that
    /// this CPU runs (e.g. `Isa::Avx2Fma` times an AVX2-only machine on an AVX-512 one).
    pub fn best_up_to(max_isa: Isa, arithmetic: Arithmetic) -> Self {
        Isa::ALL
            .into_iter()
            .rev()
            .filter(|&isa| isa <= max_isa)
            .find_map(|isa| Self::new(isa, arithmetic))
            .unwrap_or(Self {
                kernel: Kernel::Scalar,
                arithmetic,
            })
    }

    /// The kernel for `isa` and `arithmetic`; `None` if this CPU lacks the instruction set.
    pub fn new(isa: Isa, arithmetic: Arithmetic) -> Option<Self> {
        let kernel = match isa {
            Isa::Scalar => Some(Kernel::Scalar),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2Fma => Avx2Kernel::new().map(Kernel::Avx2),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => Avx512Kernel::new().map(Kernel::Avx512),
            #[cfg(not(target_arch = "x86_64"))]
            Isa::Avx2Fma | Isa::Avx512 => None,
        }?;
        Some(Self { kernel, arithmetic })
    }

    /// Every kernel this CPU runs, scalar first.
    pub fn available() -> Vec<Self> {
        [Isa::Scalar, Isa::Avx2Fma, Isa::Avx512]
            .into_iter()
            .flat_map(|isa| {
                [Arithmetic::F32, Arithmetic::I16]
                    .into_iter()
                    .filter_map(move |a| Self::new(isa, a))
            })
            .collect()
    }

    /// The instruction set.
    pub fn isa(&self) -> Isa {
        match self.kernel {
            Kernel::Scalar => Isa::Scalar,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2(_) => Isa::Avx2Fma,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512(_) => Isa::Avx512,
        }
    }

    /// The arithmetic.
    pub fn arithmetic(&self) -> Arithmetic {
        self.arithmetic
    }

    /// A short name, e.g. `"avx512/f32"`, `"avx2+fma/i16"`.
    pub fn name(&self) -> String {
        format!("{}/{}", self.isa().name(), self.arithmetic.name())
    }

    /// The kernel that actually runs on `format` (`"ci8"`, `"ci16"` or `"cf32"`; `"cu8"`,
    /// `"ri8"` and `"ri16"`, which the receiver holds as ci16, as ci16) at `fs_hz`, e.g.
    /// `"avx2+fma/i16 (16 lanes)"`: an I16 correlator runs the F32 kernel on cf32, the
    /// int16-lane kernels take the integer formats from about 1.1 MHz (AVX2, 16 lanes; AVX-512
    /// with VNNI from about 2.27 MHz, 32 lanes, else the AVX2 one), and [`Arithmetic::Auto`]
    /// resolves as [`Arithmetic::Auto`] says.
    pub fn kernel_for(&self, format: &str, fs_hz: f64) -> String {
        let integer = is_integer_format(format);
        let arithmetic = self.resolve_arithmetic(integer, fs_hz);
        let (isa, lanes) = match (self.isa(), arithmetic) {
            (Isa::Scalar, _) => (Isa::Scalar, ""),
            (isa, Arithmetic::I16) if integer && fs_hz >= INT16_LANES_16_FS_HZ => {
                match self.kernel {
                    #[cfg(target_arch = "x86_64")]
                    Kernel::Avx512(k) if k.has_vnni() && fs_hz >= INT16_LANES_32_FS_HZ => {
                        (Isa::Avx512, " (32 lanes)")
                    }
                    _ => (isa.min(Isa::Avx2Fma), " (16 lanes)"),
                }
            }
            (Isa::Avx2Fma, _) => (Isa::Avx2Fma, " (8 lanes)"),
            (isa, _) => (isa, " (16 lanes)"),
        };
        let arithmetic = match (arithmetic, format) {
            (Arithmetic::I16, "cf32") => Arithmetic::F32,
            (a, _) => a,
        };
        format!("{}/{}{lanes}", isa.name(), arithmetic.name())
    }

    /// The explicit correlator (no [`Arithmetic::Auto`]) that runs blocks of `format`
    /// (as in [`Correlator::kernel_for`]) at `fs_hz`: this one with its arithmetic resolved.
    pub fn resolved_for(&self, format: &str, fs_hz: f64) -> Correlator {
        let integer = is_integer_format(format);
        Correlator {
            kernel: self.kernel,
            arithmetic: self.resolve_arithmetic(integer, fs_hz),
        }
    }

    /// The arithmetic a block runs ([`Arithmetic::Auto`] resolved): `integer` for ci8 / ci16.
    fn resolve_arithmetic(&self, integer: bool, fs_hz: f64) -> Arithmetic {
        match self.arithmetic {
            Arithmetic::Auto
                if integer && self.isa() >= Isa::Avx2Fma && fs_hz >= INT16_LANES_16_FS_HZ =>
            {
                Arithmetic::I16
            }
            Arithmetic::Auto => Arithmetic::F32,
            a => a,
        }
    }

    /// Correlates `samples` with the replica of `code` described by `state`, one sum per entry
    /// of `tap_offsets_chips`, into `out` (same length). Packs the code on the stack first (about
    /// 1 us); hold a [`PackedCode`] and call [`Correlator::correlate_packed`] in a loop instead.
    pub fn correlate(
        &self,
        samples: SampleSlice<'_>,
        fs_hz: f64,
        code: &[i8; CA_CODE_LENGTH],
        state: &ReplicaState,
        tap_offsets_chips: &[f64],
        out: &mut [Complex32],
    ) {
        let packed = PackedCode::new(code);
        self.correlate_packed(samples, fs_hz, &packed, state, tap_offsets_chips, out);
    }

    /// [`Correlator::correlate`] with a prepared code. Allocates nothing; more than
    /// [`MAX_TAPS`] taps are processed in chunks of [`MAX_TAPS`] (one pass each). The SIMD
    /// kernels need a code step of at most 2 chips per sample (`fs >= rc / 2`); below that
    /// they fall back to the scalar kernel.
    ///
    /// A meaningless block description (`fs_hz` not finite and positive, a non-finite state
    /// or tap offset) writes NaN to every output. Panics only if
    /// `out.len() != tap_offsets_chips.len()` (a programming error).
    pub fn correlate_packed(
        &self,
        samples: SampleSlice<'_>,
        fs_hz: f64,
        code: &PackedCode,
        state: &ReplicaState,
        tap_offsets_chips: &[f64],
        out: &mut [Complex32],
    ) {
        assert_eq!(out.len(), tap_offsets_chips.len(), "one output per tap");
        if !super::is_meaningful(fs_hz, state, tap_offsets_chips) {
            out.fill(Complex32::new(f32::NAN, f32::NAN));
            return;
        }
        let integer = !matches!(samples, SampleSlice::Cf32(_));
        let (kernel, arithmetic) = (self.kernel, self.resolve_arithmetic(integer, fs_hz));
        for (taps, out) in tap_offsets_chips
            .chunks(MAX_TAPS)
            .zip(out.chunks_mut(MAX_TAPS))
        {
            let done = match kernel {
                Kernel::Scalar => false,
                #[cfg(target_arch = "x86_64")]
                Kernel::Avx2(k) => k.correlate(arithmetic, samples, fs_hz, code, state, taps, out),
                #[cfg(target_arch = "x86_64")]
                Kernel::Avx512(k) => {
                    k.correlate(arithmetic, samples, fs_hz, code, state, taps, out)
                }
            };
            if !done {
                scalar_kernel(arithmetic, samples, fs_hz, code, state, taps, out);
            }
        }
    }
}

/// Whether blocks of `format` reach the correlators as integers: ci8 and ci16, and cu8, ri8
/// and ri16, which the receiver converts to ci16 when it reads them.
fn is_integer_format(format: &str) -> bool {
    matches!(format, "ci8" | "ci16" | "cu8" | "ri8" | "ri16")
}

fn scalar_kernel(
    arithmetic: Arithmetic,
    samples: SampleSlice<'_>,
    fs_hz: f64,
    code: &PackedCode,
    state: &ReplicaState,
    taps: &[f64],
    out: &mut [Complex32],
) {
    let chips = code.chips();
    match (arithmetic, samples) {
        (_, SampleSlice::Cf32(x)) => scalar::correlate_f32(x, fs_hz, chips, state, taps, out),
        (Arithmetic::I16, SampleSlice::Ci16(x)) => {
            scalar::correlate_i16(x, fs_hz, chips, state, taps, out)
        }
        (Arithmetic::I16, SampleSlice::Ci8(x)) => {
            scalar::correlate_i16(x, fs_hz, chips, state, taps, out)
        }
        // F32 (and an unresolved Auto: `resolve` never passes one).
        (_, SampleSlice::Ci16(x)) => scalar::correlate_f32(x, fs_hz, chips, state, taps, out),
        (_, SampleSlice::Ci8(x)) => scalar::correlate_f32(x, fs_hz, chips, state, taps, out),
    }
}
