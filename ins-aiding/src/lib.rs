//! Inertial and dead-reckoning sensors for gpsrx: inputs, error models, the INS-velocity Doppler
//! feed-forward (seed 004) and the GPS/DR fusion filters (seeds 000 and 002).
//!
//! INS (seed 004):
//! - [`ins_file`]: the `--ins FILE.csv` input (ECEF position and velocity at any rate >= 10 Hz),
//!   validated and interpolated to any instant, and its writer;
//! - [`error_model`]: INS error models (accelerometer bias, velocity random walk, scale factor,
//!   latency, band limit) that turn a truth trajectory into a simulated INS output;
//! - [`band_limiter`]: the first-order band limiter `alpha / (s + alpha)` of seed 004 eq. 8;
//! - [`velocity_calibration`]: [`InsVelocityCalibration`], the INS velocity error (offset and
//!   drift) followed from the GNSS velocity fixes, so the feed-forward carries no INS drift;
//! - the line-of-sight Doppler `((v_sv - v_rx) . l) / lambda` of seed 004 eq. 6 is
//!   [`gpsrx_core::los_doppler_hz`].
//!
//! Dead reckoning (seed 000) and the speed filter (seed 002):
//! - [`dr_log`]: the `--dr FILE.csv` input: [`DrSample`] `{ t_s, reading: DrReading }` with
//!   [`DrReading::Raw`] `{ gyro_v, odo_pulses }` or [`DrReading::Engineering`]
//!   `{ yaw_rate_dps, speed_mps }`; [`read_dr_csv`] -> [`DrLog`] (`samples()`), [`write_dr_csv`];
//! - [`accel_log`]: the `--accel FILE.csv` input: [`AccelSample`] `{ t_s, a_long_mps2 }`,
//!   [`read_accel_csv`] -> [`AccelLog`], [`write_accel_csv`];
//! - [`vehicle`]: [`VehicleTruth`] (ENU position, speed, heading clockwise from north, yaw rate,
//!   longitudinal acceleration, road pitch), the input of the sensor models;
//! - [`dr_sensors`]: simulated sensors with seed 000's errors: [`DrSensorConfig`] (gyro bias
//!   voltage, tilt, noise; odometer scale error and quantisation) and [`simulate_dr`];
//!   [`AccelSensorConfig`] (bias, vibration, slope `g sin(pitch)`) and [`simulate_accel`];
//! - [`dr_mechanization`]: [`DrParams`] (`Sf_G`, `V_nom`, `Sf_N`; `load`/`save` as TOML) and
//!   [`DrMechanization`] (seed 000 eqs. 1-3) producing [`DrState`];
//! - [`dr_filter`]: [`DrFusion`] with [`DrFilterKind::Proposed8`] (seed 000 eqs. 5-14: position,
//!   velocity, heading, `Sf_G`, `V_nom`, `Sf_N` errors; GNSS position and velocity updates) or
//!   [`DrFilterKind::Conventional4`] (eq. 7: position, heading, `Sf_N`; position updates only),
//!   closed loop: `new(kind, nominal_params, east_m, north_m, heading_rad, DrFilterConfig)`,
//!   optionally `.with_calibration(DrParams::load(path)?)` (a previous run's parameters; the
//!   nominal ones still convert engineering-unit rows), then `propagate(&DrSample)` per DR row,
//!   `update_position(e, n, cov)` -> NIS and `update_velocity(ve, vn, cov)` -> `Some(NIS)` (None
//!   for the 4-state filter) at the time of the last row, `state()` ([`DrState`]: position,
//!   heading, speed, yaw rate, velocity), `params()` (the calibration to save),
//!   `covariance()`, `position_covariance()`, `fix_source(max_age_s)` -> [`FixSource`];
//!   [`heading_from_velocity`] initialises the heading from the GNSS course. The transition is
//!   the exact Jacobian of the mechanization ([`row_model`], tested against finite differences);
//!   process noise and its units are in [`DrFilterConfig`] and the module documentation;
//! - [`speed_filter`]: seed 002's [`AccelSmoother`] (KF1) and [`SpeedFilter`] (KF2:
//!   `predict(a_long_mps2, dt)`, `update_speed(v_mps, sigma)`, `speed_mps()`), and the
//!   [`HoldLastSpeed`] baseline.
//!
//! Errors of all the DR parts are [`DrError`]; every log error names its file and line.
//! This crate depends on no other gpsrx crate: satellite states come in as plain vectors.

pub mod accel_log;
pub mod band_limiter;
mod csv_table;
pub mod dr_error;
pub mod dr_filter;
pub mod dr_log;
pub mod dr_mechanization;
pub mod dr_sensors;
pub mod error_model;
pub mod ins_file;
pub mod speed_filter;
pub mod vehicle;
pub mod velocity_calibration;

pub use accel_log::{read_accel_csv, write_accel_csv, AccelLog, AccelSample};
pub use band_limiter::BandLimiter;
pub use dr_error::DrError;
pub use dr_filter::{
    heading_from_velocity, row_model, DrFilterConfig, DrFilterKind, DrFusion, FixSource,
    MIN_COURSE_SPEED_MPS,
};
pub use dr_log::{read_dr_csv, write_dr_csv, DrLog, DrReading, DrSample};
pub use dr_mechanization::{dr_step, DrMechanization, DrParams, DrState, DrStep};
pub use dr_sensors::{
    simulate_accel, simulate_dr, AccelSensorConfig, DrSensorConfig, GRAVITY_MPS2,
    SEED000_SF_G_DPS_PER_V,
};
pub use error_model::{simulate_ins, InsErrorConfig, TruthState};
pub use ins_file::{read_ins_csv, write_ins_csv, InsError, InsSample, InsTrack};
pub use speed_filter::{AccelSmoother, HoldLastSpeed, SpeedFilter, SpeedFilterConfig};
pub use vehicle::{interpolate_truth, validate_truth, wrap_pi, VehicleTruth};
pub use velocity_calibration::InsVelocityCalibration;
