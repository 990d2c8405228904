//! Frames: LLH <-> ECEF and az/el against pymap3d 3.2.0 (fixture), closed-form points and a
//! property-based round trip.

use crate::common::Table;
use gpsrx_nav::constants::{OMEGA_E_DOT_RAD_S, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::{azimuth_elevation, enu_rotation, rotate_for_earth_rotation, Llh, Vector3};
use proptest::prelude::*;

const A: f64 = 6_378_137.0;
const B: f64 = 6_356_752.314_245_179; // WGS-84 semi-minor axis (NIMA TR8350.2)

#[test]
fn llh_to_ecef_matches_pymap3d() {
    let t = Table::read("pymap3d_frames.csv");
    let mut max_err = 0.0f64;
    for row in &t.rows {
        let llh = Llh::from_degrees(
            t.f64(row, "lat_deg"),
            t.f64(row, "lon_deg"),
            t.f64(row, "h_m"),
        );
        let truth = Vector3::new(t.f64(row, "x_m"), t.f64(row, "y_m"), t.f64(row, "z_m"));
        max_err = max_err.max((llh.to_ecef() - truth).norm());
        // And back: ECEF -> LLH recovers the geodetic point.
        let back = Llh::from_ecef(&truth);
        assert!((back.lat_rad - llh.lat_rad).abs() < 1e-12, "{row:?}");
        assert!((back.h_m - llh.h_m).abs() < 1e-6, "{row:?} h {}", back.h_m);
        let dlon = (back.lon_rad - llh.lon_rad).sin().abs();
        assert!(dlon < 1e-12, "{row:?}");
    }
    assert!(max_err < 1e-6, "max ECEF difference {max_err} m");
}

#[test]
fn az_el_matches_pymap3d() {
    let t = Table::read("pymap3d_frames.csv");
    for row in &t.rows {
        let rx = Llh::from_degrees(
            t.f64(row, "lat_deg"),
            t.f64(row, "lon_deg"),
            t.f64(row, "h_m"),
        )
        .to_ecef();
        let sv = Vector3::new(
            t.f64(row, "sv_x_m"),
            t.f64(row, "sv_y_m"),
            t.f64(row, "sv_z_m"),
        );
        let (az, el) = azimuth_elevation(&rx, &sv);
        let az_truth = t.f64(row, "az_deg").to_radians();
        let el_truth = t.f64(row, "el_deg").to_radians();
        assert!(
            (el - el_truth).abs() < 1e-10,
            "{row:?}: el {el} vs {el_truth}"
        );
        // Azimuth is ill-defined only at the zenith; compare on the circle.
        let daz = (az - az_truth).sin().abs() + ((az - az_truth).cos() - 1.0).abs();
        assert!(
            daz < 1e-9 || el_truth.to_degrees() > 89.99,
            "{row:?}: az {az} vs {az_truth}"
        );
        assert!((0.0..2.0 * std::f64::consts::PI).contains(&az));
    }
}

#[test]
fn closed_form_points() {
    let eq = Llh::from_degrees(0.0, 0.0, 0.0).to_ecef();
    assert!((eq - Vector3::new(A, 0.0, 0.0)).norm() < 1e-9);
    let east = Llh::from_degrees(0.0, 90.0, 100.0).to_ecef();
    assert!((east - Vector3::new(0.0, A + 100.0, 0.0)).norm() < 1e-9);
    let pole = Llh::from_degrees(90.0, 0.0, 0.0).to_ecef();
    assert!((pole - Vector3::new(0.0, 0.0, B)).norm() < 1e-6);
    let p = Llh::from_ecef(&Vector3::new(0.0, 0.0, -B - 10.0));
    assert!((p.lat_rad + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert!((p.h_m - 10.0).abs() < 1e-6);
    // Earth's centre: defined, no panic.
    let c = Llh::from_ecef(&Vector3::zeros());
    assert_eq!((c.lat_rad, c.lon_rad, c.h_m), (0.0, 0.0, -A));
}

#[test]
fn enu_rotation_is_orthonormal_and_up_is_the_normal() {
    let o = Llh::from_degrees(37.5665, 126.978, 40.0);
    let r = enu_rotation(&o);
    assert!((r * r.transpose() - nalgebra::Matrix3::identity()).norm() < 1e-14);
    assert!((r.determinant() - 1.0).abs() < 1e-14);
    // Moving 1 m up along the ellipsoid normal gives enu = (0, 0, 1).
    let up = Llh {
        h_m: o.h_m + 1.0,
        ..o
    }
    .to_ecef()
        - o.to_ecef();
    let enu = r * up;
    assert!((enu - Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-9);
}

#[test]
fn az_el_simple_geometry_and_unknown_receiver() {
    let o = Llh::from_degrees(10.0, 20.0, 0.0);
    let rx = o.to_ecef();
    let r = enu_rotation(&o);
    // A point 1 km north and 1 km up: az 0, el 45 deg.
    let sv = rx + r.transpose() * Vector3::new(0.0, 1000.0, 1000.0);
    let (az, el) = azimuth_elevation(&rx, &sv);
    assert!(az.sin().abs() < 1e-12 && az.cos() > 0.0);
    assert!((el.to_degrees() - 45.0).abs() < 1e-9);
    // Due east at the horizon: az 90 deg, el 0.
    let sv = rx + r.transpose() * Vector3::new(5000.0, 0.0, 0.0);
    let (az, el) = azimuth_elevation(&rx, &sv);
    assert!((az.to_degrees() - 90.0).abs() < 1e-9 && el.abs() < 1e-12);
    // Unknown receiver (origin): zenith by convention.
    let (az, el) = azimuth_elevation(&Vector3::zeros(), &sv);
    assert_eq!((az, el), (0.0, std::f64::consts::FRAC_PI_2));
}

#[test]
fn earth_rotation_correction_matches_range_form() {
    // oracles.md: rotating the SV by OMEGA_E tau about z is equivalent (to < 1 mm) to adding
    // OMEGA_E (x_s y_r - y_s x_r) / c to the geometric range.
    let rx = Llh::from_degrees(37.5665, 126.978, 40.0).to_ecef();
    for sv in [
        Vector3::new(15_600e3, 7_540e3, 20_140e3),
        Vector3::new(-12_000e3, 20_000e3, 10_000e3),
        Vector3::new(-5_000e3, -24_000e3, 9_000e3),
    ] {
        let tau = (sv - rx).norm() / SPEED_OF_LIGHT_MPS;
        let rotated = (rotate_for_earth_rotation(&sv, tau) - rx).norm();
        let sagnac =
            (sv - rx).norm() + OMEGA_E_DOT_RAD_S * (sv.x * rx.y - sv.y * rx.x) / SPEED_OF_LIGHT_MPS;
        assert!((rotated - sagnac).abs() < 1e-3, "{rotated} vs {sagnac}");
        assert!(
            (rotated - (sv - rx).norm()).abs() > 1.0,
            "correction is tens of metres here"
        );
    }
}

proptest! {
    #[test]
    fn llh_ecef_round_trip(lat in -90.0f64..=90.0, lon in -180.0f64..180.0, h in -10_000.0f64..5.0e7) {
        let llh = Llh::from_degrees(lat, lon, h);
        let ecef = llh.to_ecef();
        let back = Llh::from_ecef(&ecef);
        prop_assert!((back.to_ecef() - ecef).norm() < 1e-6);
        prop_assert!((back.lat_rad - llh.lat_rad).abs() < 1e-12);
        prop_assert!((back.h_m - h).abs() < 1e-6);
        if lat.abs() < 89.999 {
            prop_assert!((back.lon_rad - llh.lon_rad).sin().abs() < 1e-12);
        }
    }
}

#[test]
fn light_time_solves_the_rotated_range_equation() {
    use gpsrx_nav::constants::SPEED_OF_LIGHT_MPS;
    use gpsrx_nav::{light_time, SvState};
    // A satellite moving at 3.9 km/s; the transmit time is t_rx - tau.
    let state_at = |tau: f64| SvState {
        pos_m: Vector3::new(15_600e3, 7_540e3, 20_140e3) - Vector3::new(0.0, 3_900.0, 0.0) * tau,
        vel_mps: Vector3::new(0.0, 3_900.0, 0.0),
        clock_bias_s: 1e-4,
        clock_drift_s_s: 1e-11,
    };
    let rx = Llh::from_degrees(37.5665, 126.978, 40.0).to_ecef();
    let seen = light_time(state_at, &rx, 0.075, 3);
    let tau = seen.flight_time_s;
    let residual = (rotate_for_earth_rotation(&state_at(tau).pos_m, tau) - rx).norm()
        - SPEED_OF_LIGHT_MPS * tau;
    assert!(residual.abs() < 1e-6, "{residual}");
    assert!((seen.range_m - SPEED_OF_LIGHT_MPS * tau).abs() < 1e-9);
    assert!(
        (seen.sv.vel_mps - rotate_for_earth_rotation(&state_at(tau).vel_mps, tau)).norm() < 1e-9
    );
    assert_eq!(seen.sv.clock_bias_s, 1e-4);
}
