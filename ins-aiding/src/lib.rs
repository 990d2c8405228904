//! Inertial and dead-reckoning sensors for gpsrx: inputs, error models, the INS-velocity Doppler
//! feed-forward (seed 004) and (later) the GPS/DR fusion filters (seeds 000 and 002).
//!
//! - [`ins_file`]: the `--ins FILE.csv` input (ECEF position and velocity at any rate >= 10 Hz),
//!   validated and interpolated to any instant, and its writer;
//! - [`error_model`]: INS error models (accelerometer bias, velocity random walk, scale factor,
//!   latency, band limit) that turn a truth trajectory into a simulated INS output;
//! - [`band_limiter`]: the first-order band limiter `alpha / (s + alpha)` of seed 004 eq. 8;
//! - [`feedforward`]: the line-of-sight Doppler `((v_sv - v_rx) . l) / lambda` of seed 004 eq. 6.
//!
//! This crate depends on no other gpsrx crate: satellite states come in as plain vectors.

pub mod band_limiter;
pub mod error_model;
pub mod feedforward;
pub mod ins_file;

pub use band_limiter::BandLimiter;
pub use error_model::{simulate_ins, InsErrorConfig, TruthState};
pub use feedforward::{los_doppler_hz, LAMBDA_L1_M};
pub use ins_file::{read_ins_csv, write_ins_csv, InsError, InsSample, InsTrack};
