//! The experiment's fixed parameters (seed 001 section 3.3: a camera ranges landmarks within
//! 70 m with about 2 % of the distance).

/// Site: Seoul, ellipsoidal height 40 m (degrees, degrees, m).
pub const SITE_LLH: (f64, f64, f64) = (37.5665, 126.978, 40.0);
/// GPS week of the broadcast file (brdc0010.22n, 2022-01-01).
pub const WEEK: u32 = 2190;
/// First and last time of week drawn for an epoch, s (the file's day, 2 h margins).
pub const TOW_RANGE_S: (f64, f64) = (525_600.0, 597_600.0);
/// Elevation mask of the satellites drawn, deg.
pub const ELEVATION_MASK_DEG: f64 = 10.0;
/// Satellite counts studied.
pub const SATELLITES: std::ops::RangeInclusive<usize> = 3..=9;
/// Landmark counts studied.
pub const LANDMARKS: std::ops::RangeInclusive<usize> = 0..=2;
/// Landmark range drawn uniformly in this interval, m (within the camera's 70 m).
pub const LANDMARK_RANGE_M: (f64, f64) = (10.0, 70.0);
/// Landmark range sigma as a fraction of the range (2 %).
pub const LANDMARK_SIGMA_FRACTION: f64 = 0.02;
/// Pseudorange sigma, m (carrier-smoothed code).
pub const PSEUDORANGE_SIGMA_M: f64 = 1.5;
/// A fix counts as available when the solver returns one with PDOP at most this.
pub const USABLE_PDOP: f64 = 10.0;
/// Monte Carlo geometries per cell (satellites x landmarks), full run and `--quick`.
pub const TRIALS: usize = 400;
/// Geometries per cell with `--quick`.
pub const TRIALS_QUICK: usize = 60;
