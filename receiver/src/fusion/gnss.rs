//! A GNSS fix as a measurement for the DR filters: position and velocity with their
//! covariances, at the file time of its epoch.

use gpsrx_nav::frames::{enu_rotation, Llh};
use gpsrx_nav::pvt::PvtSolution;
use gpsrx_nav::time::GpsTime;
use nalgebra::{Matrix2, Matrix3, Vector3};

/// One GNSS fix for fusion.
#[derive(Debug, Clone, PartialEq)]
pub struct GnssFix {
    /// Seconds since the first IF sample of the epoch (the DR log's time base).
    pub t_s: f64,
    /// GPS time of the fix.
    pub time: GpsTime,
    /// ECEF position, m.
    pub pos_ecef_m: Vector3<f64>,
    /// ECEF position covariance, m^2.
    pub pos_cov_m2: Matrix3<f64>,
    /// ECEF velocity, m/s (Doppler/carrier solution), if any.
    pub vel_ecef_mps: Option<Vector3<f64>>,
    /// ECEF velocity covariance, (m/s)^2.
    pub vel_cov: Option<Matrix3<f64>>,
    /// Satellites used.
    pub n_sv: usize,
    /// PRNs used (a change of the set can make the position bias jump).
    pub used_prns: Vec<u8>,
}

impl GnssFix {
    /// From a PVT solution of the epoch at file time `t_s`.
    pub fn from_solution(t_s: f64, sol: &PvtSolution) -> GnssFix {
        GnssFix {
            t_s,
            time: sol.time,
            pos_ecef_m: sol.pos_ecef_m,
            pos_cov_m2: sol.covariance.fixed_view::<3, 3>(0, 0).into_owned(),
            vel_ecef_mps: sol.vel_ecef_mps,
            vel_cov: sol
                .vel_covariance
                .map(|c| c.fixed_view::<3, 3>(0, 0).into_owned()),
            n_sv: sol.n_sv,
            used_prns: sol.used_prns.clone(),
        }
    }

    /// East/north position relative to `origin`, m, and its 2x2 covariance.
    pub fn en_position(&self, origin: &Llh) -> ([f64; 2], Matrix2<f64>) {
        let r = enu_rotation(origin);
        let p = r * (self.pos_ecef_m - origin.to_ecef());
        let c = r * self.pos_cov_m2 * r.transpose();
        ([p.x, p.y], c.fixed_view::<2, 2>(0, 0).into_owned())
    }

    /// East/north velocity, m/s, and its 2x2 covariance (None without a velocity).
    pub fn en_velocity(&self, origin: &Llh) -> Option<([f64; 2], Matrix2<f64>)> {
        let r = enu_rotation(origin);
        let v = r * self.vel_ecef_mps?;
        let c = self
            .vel_cov
            .map(|c| r * c * r.transpose())
            .unwrap_or_else(|| Matrix3::identity() * 0.01);
        Some(([v.x, v.y], c.fixed_view::<2, 2>(0, 0).into_owned()))
    }
}
