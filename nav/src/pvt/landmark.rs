//! Ranges to surveyed landmarks as extra observations (seed 001 eqs. 3.8-3.12).
//!
//! A landmark range PV = |r_L - r_rx| + e (eq. 3.8) has no receiver clock term. Linearised at
//! the current estimate it adds the row K = [u^T, 0] (u = (r_rx - r_L)/|r_rx - r_L|, eq. 3.9)
//! with weight 1/sigma_m^2, and the least squares becomes eq. 3.10. So 3 satellites and 1
//! landmark (4 observations, rank 4) already fix position and clock.
//!
//! With exactly 4 observations the non-linear problem can have two solutions (the
//! pseudorange locus of 3 satellites, a curve, crosses the sphere of radius PV around the
//! landmark twice); the solver returns the one the iteration reaches from its start, so give
//! a `prior` (e.g. the last fix) when satellites are this scarce.

use super::PvtError;
use crate::frames::Vector3;

/// A range measured to a surveyed 3D point (e.g. a building recognised by a camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landmark {
    /// Surveyed position, WGS-84 ECEF, m.
    pub ecef_m: Vector3<f64>,
    /// Measured range from the receiver antenna to the point, m.
    pub range_m: f64,
    /// Standard deviation of the range, m (seed 001: about 2 % of the range).
    pub sigma_m: f64,
}

/// Rejects landmarks with non-finite values, negative ranges or non-positive sigmas.
pub fn validate(landmarks: &[Landmark]) -> Result<(), PvtError> {
    for (index, lm) in landmarks.iter().enumerate() {
        let bad = |field, value| {
            Err(PvtError::InvalidLandmark {
                index,
                field,
                value,
            })
        };
        if let Some(v) = lm.ecef_m.iter().find(|v| !v.is_finite()) {
            return bad("ecef_m", *v);
        }
        if !(lm.range_m.is_finite() && lm.range_m >= 0.0) {
            return bad("range_m", lm.range_m);
        }
        if !(lm.sigma_m.is_finite() && lm.sigma_m > 0.0) {
            return bad("sigma_m", lm.sigma_m);
        }
    }
    Ok(())
}
