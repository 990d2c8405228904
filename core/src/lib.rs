//! The GNSS concepts several gpsrx crates share, in one place: physical and GPS constants
//! (IS-GPS-200), the PRN type, WGS-84 geodetic/ECEF/ENU frames, the Earth-rotation (Sagnac)
//! correction, the line-of-sight Doppler, the vehicle state of the dead-reckoning models, and
//! least-squares polynomials (the receiver's carrier extrapolation and the studies' error fits).
//!
//! This crate depends on no other gpsrx crate; every other crate may depend on it.

pub mod constants;
pub mod doppler;
pub mod frames;
pub mod polyfit;
pub mod prn;
pub mod vehicle;

pub use doppler::{los_doppler_hz, range_rate_mps, PosVel};
pub use frames::{
    azimuth_elevation, enu_rotation, rotate_for_earth_rotation, rotation_rate_times, Llh, Vector3,
};
pub use polyfit::Polynomial;
pub use prn::{Prn, PrnError};
pub use vehicle::VehicleState;
