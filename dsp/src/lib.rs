//! Signal math on sample slices for the gpsrx GPS L1 C/A receiver.
//!
//! This crate knows nothing about files, threads of a pipeline or the command line: it holds pure
//! functions and small structs over slices of samples, each testable on its own.
//!
//! - [`ca_code`]: the GPS L1 C/A Gold codes (IS-GPS-200 section 3.3.2.3).
//! - [`synthetic`]: noise plus C/A signals of known delay and Doppler (benchmarks, examples).
//! - [`nco`]: numerically controlled oscillators (fixed-point phase accumulators and sine tables).
//! - [`constants`]: GPS L1 C/A signal constants.
//! - [`correlator`]: block correlators (carrier wipe-off and E/P/L accumulation in one pass):
//!   the scalar reference and run-time chosen AVX2/AVX-512 kernels ([`Correlator`]) reading
//!   cf32, ci16 or ci8 samples in place.

pub mod acquisition;
pub mod ca_code;
pub mod constants;
pub mod correlator;
pub mod nco;
pub mod synthetic;

pub use ca_code::{CaCode, Prn, PrnError};
pub use correlator::{Correlator, PackedCode, SampleSlice};
pub use nco::{PhaseAccumulator, SinCosTable};
