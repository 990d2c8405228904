//! WGS-84 geodetic coordinates, ECEF and local East-North-Up frames, and the Earth-rotation
//! (Sagnac) rotation between the ECEF frames of transmission and reception.
//!
//! Ellipsoid parameters from NIMA TR8350.2 (WGS-84) Table 3.1, the frame IS-GPS-200 20.3.3.4.3
//! expresses satellite positions in.

use crate::constants::{OMEGA_E_DOT_RAD_S, WGS84_A_M, WGS84_E2, WGS84_F};
use nalgebra::Matrix3;
pub use nalgebra::Vector3;

/// First eccentricity squared e^2 = f (2 - f).
const E2: f64 = WGS84_E2;
/// Semi-minor axis b = a (1 - f), m.
const B_M: f64 = WGS84_A_M * (1.0 - WGS84_F);
/// Second eccentricity squared e'^2 = e^2 / (1 - e^2).
const EP2: f64 = E2 / (1.0 - E2);

/// Geodetic latitude, longitude (radians, east positive) and height above the WGS-84 ellipsoid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Llh {
    /// Geodetic latitude, rad, north positive.
    pub lat_rad: f64,
    /// Longitude, rad, east positive.
    pub lon_rad: f64,
    /// Height above the WGS-84 ellipsoid, m.
    pub h_m: f64,
}

impl Llh {
    /// Builds a position from degrees (latitude, longitude) and metres (ellipsoidal height).
    pub fn from_degrees(lat_deg: f64, lon_deg: f64, h_m: f64) -> Llh {
        Llh {
            lat_rad: lat_deg.to_radians(),
            lon_rad: lon_deg.to_radians(),
            h_m,
        }
    }

    /// Geodetic to ECEF (closed form): x = (N + h) cos(lat) cos(lon), y = (N + h) cos(lat)
    /// sin(lon), z = (N (1 - e^2) + h) sin(lat), with N = a / sqrt(1 - e^2 sin^2(lat)).
    pub fn to_ecef(&self) -> Vector3<f64> {
        let (slat, clat) = self.lat_rad.sin_cos();
        let (slon, clon) = self.lon_rad.sin_cos();
        let n = WGS84_A_M / (1.0 - E2 * slat * slat).sqrt();
        Vector3::new(
            (n + self.h_m) * clat * clon,
            (n + self.h_m) * clat * slon,
            (n * (1.0 - E2) + self.h_m) * slat,
        )
    }

    /// ECEF to geodetic by Bowring's parametric-latitude iteration (converges to < 1e-15 rad
    /// in two or three steps for any point outside the Earth's core); the height uses
    /// h = p cos(lat) + z sin(lat) - a sqrt(1 - e^2 sin^2(lat)), which is well conditioned at
    /// the poles. The Earth's centre maps to lat = lon = 0, h = -a.
    pub fn from_ecef(ecef: &Vector3<f64>) -> Llh {
        let (x, y, z) = (ecef.x, ecef.y, ecef.z);
        let p = x.hypot(y);
        if p == 0.0 && z == 0.0 {
            return Llh {
                lat_rad: 0.0,
                lon_rad: 0.0,
                h_m: -WGS84_A_M,
            };
        }
        let lon_rad = y.atan2(x);
        let mut beta = z.atan2((1.0 - WGS84_F) * p);
        let mut lat = 0.0_f64;
        for _ in 0..10 {
            let (sb, cb) = beta.sin_cos();
            let new_lat = (z + EP2 * B_M * sb * sb * sb).atan2(p - E2 * WGS84_A_M * cb * cb * cb);
            let converged = (new_lat - lat).abs() < 1e-15;
            lat = new_lat;
            beta = ((1.0 - WGS84_F) * lat.sin()).atan2(lat.cos());
            if converged {
                break;
            }
        }
        let (slat, clat) = lat.sin_cos();
        let h_m = p * clat + z * slat - WGS84_A_M * (1.0 - E2 * slat * slat).sqrt();
        Llh {
            lat_rad: lat,
            lon_rad,
            h_m,
        }
    }
}

/// Rotation from ECEF to the local East-North-Up frame at `origin`: the rows are the E, N and U
/// unit vectors expressed in ECEF, so `enu = R * (ecef - origin_ecef)`.
pub fn enu_rotation(origin: &Llh) -> Matrix3<f64> {
    let (slat, clat) = origin.lat_rad.sin_cos();
    let (slon, clon) = origin.lon_rad.sin_cos();
    Matrix3::new(
        -slon,
        clon,
        0.0,
        -slat * clon,
        -slat * slon,
        clat,
        clat * clon,
        clat * slon,
        slat,
    )
}

/// Azimuth (rad, clockwise from north, in `[0, 2 pi)`) and elevation (rad, `[-pi/2, pi/2]`) of
/// the satellite at `sv_ecef` seen from the receiver at `rx_ecef`, in the receiver's local
/// geodetic ENU frame.
///
/// If the receiver position is unknown (within 1 m of the Earth's centre) the satellite is
/// reported at the zenith (az = 0, el = pi/2), so that elevation masks and mapping functions
/// stay neutral before the first fix. Coincident positions also give (0, pi/2).
pub fn azimuth_elevation(rx_ecef: &Vector3<f64>, sv_ecef: &Vector3<f64>) -> (f64, f64) {
    if rx_ecef.norm() < 1.0 {
        return (0.0, std::f64::consts::FRAC_PI_2);
    }
    let los = sv_ecef - rx_ecef;
    let range = los.norm();
    if range == 0.0 || !range.is_finite() {
        return (0.0, std::f64::consts::FRAC_PI_2);
    }
    let enu = enu_rotation(&Llh::from_ecef(rx_ecef)) * los;
    let mut az = enu.x.atan2(enu.y);
    if az < 0.0 {
        az += 2.0 * std::f64::consts::PI;
    }
    let el = (enu.z / range).clamp(-1.0, 1.0).asin();
    (az, el)
}

/// Satellite ECEF vector (position or velocity) at transmission re-expressed in the ECEF frame
/// of reception: `R3(OmegaE tau) v`, the rotation about z by `OmegaE * flight_time_s`
///
/// ```text
/// R3(theta) = [  cos theta  sin theta  0 ]
///             [ -sin theta  cos theta  0 ]
///             [      0          0      1 ]
/// ```
///
/// (IS-GPS-200 20.3.3.4.3.3.2, Earth rotation correction; the Sagnac effect). The Earth turns
/// by about 1.4 urad during the 70-90 ms flight, moving the satellite by ~30 m in the frame of
/// reception.
pub fn rotate_for_earth_rotation(sv_ecef: &Vector3<f64>, flight_time_s: f64) -> Vector3<f64> {
    let (s, c) = (OMEGA_E_DOT_RAD_S * flight_time_s).sin_cos();
    Vector3::new(
        c * sv_ecef.x + s * sv_ecef.y,
        -s * sv_ecef.x + c * sv_ecef.y,
        sv_ecef.z,
    )
}

/// Time derivative of the Earth-rotation matrix applied to `v`: `d/dtau [R3(w tau) v] =
/// w dR3/dtheta v`, with `R3` as in [`rotate_for_earth_rotation`] (the flight-time rate term of
/// the range rate, IS-GPS-200 20.3.3.4.3.3.2 differentiated).
pub fn rotation_rate_times(v: &Vector3<f64>, tau_s: f64) -> Vector3<f64> {
    let (s, c) = (OMEGA_E_DOT_RAD_S * tau_s).sin_cos();
    OMEGA_E_DOT_RAD_S * Vector3::new(-s * v.x + c * v.y, -c * v.x - s * v.y, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geodetic_round_trip_and_rotation() {
        let p = Llh::from_degrees(37.5665, 126.978, 40.0);
        let back = Llh::from_ecef(&p.to_ecef());
        assert!((back.lat_rad - p.lat_rad).abs() < 1e-14);
        assert!((back.lon_rad - p.lon_rad).abs() < 1e-14);
        assert!((back.h_m - p.h_m).abs() < 1e-8);
        // A quarter turn of the Earth takes x to -y (the frame turns east under the vector).
        let tau = std::f64::consts::FRAC_PI_2 / OMEGA_E_DOT_RAD_S;
        let r = rotate_for_earth_rotation(&Vector3::new(1.0, 0.0, 2.0), tau);
        assert!((r - Vector3::new(0.0, -1.0, 2.0)).norm() < 1e-12);
        // rotation_rate_times is the derivative of the rotation.
        let v = Vector3::new(2.0e7, -1.0e7, 5.0e6);
        let h = 1e-3;
        let num = (rotate_for_earth_rotation(&v, 0.07 + h)
            - rotate_for_earth_rotation(&v, 0.07 - h))
            / (2.0 * h);
        assert!((num - rotation_rate_times(&v, 0.07)).norm() < 1e-4);
    }
}
