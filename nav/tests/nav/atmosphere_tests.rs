//! Klobuchar against RTKLIB `ionmodel` and the night-time oracle; Saastamoinen against RTKLIB
//! `tropmodel` and its closed-form properties.

use crate::common::Table;
use gpsrx_nav::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::{klobuchar_delay_s, saastamoinen_delay_m, KlobucharParams, Llh};

fn params(t: &Table, row: &[String]) -> KlobucharParams {
    let g = |c: &str| t.f64(row, c);
    KlobucharParams {
        alpha: [g("a0"), g("a1"), g("a2"), g("a3")],
        beta: [g("b0"), g("b1"), g("b2"), g("b3")],
    }
}

#[test]
fn klobuchar_matches_rtklib() {
    let t = Table::read("rtklib_klobuchar.csv");
    let mut max_err = 0.0f64;
    let mut max_delay = 0.0f64;
    for row in &t.rows {
        let p = params(&t, row);
        let rx = Llh::from_degrees(
            t.f64(row, "lat_deg"),
            t.f64(row, "lon_deg"),
            t.f64(row, "h_m"),
        );
        let d_m = SPEED_OF_LIGHT_MPS
            * klobuchar_delay_s(
                &p,
                t.f64(row, "tow_s"),
                &rx,
                t.f64(row, "az_deg").to_radians(),
                t.f64(row, "el_deg").to_radians(),
            );
        let truth = t.f64(row, "delay_m");
        max_err = max_err.max((d_m - truth).abs());
        max_delay = max_delay.max(truth);
    }
    eprintln!("Klobuchar vs RTKLIB ionmodel over {} cases: max diff {max_err:.3e} m (delays up to {max_delay:.2} m)", t.rows.len());
    assert!(max_err < 1e-6, "max difference {max_err} m");
    assert!(
        max_delay > 20.0,
        "fixture should include large day-time delays"
    );
}

#[test]
fn klobuchar_night_floor_at_zenith() {
    // Oracle (oracles.md): at night the delay is 5 ns times the obliquity factor
    // F = 1 + 16 (0.53 - E)^3, E = 0.5 semicircle at zenith -> 1.000432; 5 ns * c * F = 1.4996 m.
    let p = KlobucharParams {
        alpha: [0.1211e-07, -0.7451e-08, -0.5960e-07, 0.1192e-06],
        beta: [0.1167e+06, -0.2458e+06, -0.6554e+05, 0.1114e+07],
    };
    let rx = Llh::from_degrees(37.5665, 126.978, 40.0);
    // Local time at the pierce point ~ 02:00 (far from the 14:00 peak): TOW of 17:30 UTC.
    let tow = 6.0 * 86_400.0 + 17.5 * 3600.0;
    let d_m =
        klobuchar_delay_s(&p, tow, &rx, 0.0, std::f64::consts::FRAC_PI_2) * SPEED_OF_LIGHT_MPS;
    let expected = 5e-9 * SPEED_OF_LIGHT_MPS * (1.0 + 16.0 * 0.03f64.powi(3));
    assert!((d_m - expected).abs() < 1e-9, "{d_m} vs {expected}");
    assert!((d_m - 1.4996).abs() < 5e-5);
    // Zero amplitude gives the floor at any time, scaled by the obliquity at low elevation.
    let flat = KlobucharParams {
        alpha: [0.0; 4],
        beta: p.beta,
    };
    let el = 10f64.to_radians();
    let e_sc = el / gpsrx_nav::constants::GPS_PI;
    let f = 1.0 + 16.0 * (0.53 - e_sc).powi(3);
    let d = klobuchar_delay_s(&flat, 50_400.0, &rx, 1.0, el);
    assert!((d - 5e-9 * f).abs() < 1e-20);
    // Below the horizon: zero.
    assert_eq!(klobuchar_delay_s(&p, tow, &rx, 0.0, -0.1), 0.0);
}

#[test]
fn saastamoinen_matches_rtklib() {
    let t = Table::read("rtklib_saastamoinen.csv");
    let mut max_err = 0.0f64;
    for row in &t.rows {
        let rx = Llh::from_degrees(t.f64(row, "lat_deg"), 10.0, t.f64(row, "h_m"));
        let d = saastamoinen_delay_m(&rx, t.f64(row, "el_deg").to_radians());
        max_err = max_err.max((d - t.f64(row, "delay_m")).abs());
    }
    eprintln!(
        "Saastamoinen vs RTKLIB tropmodel over {} cases: max diff {max_err:.3e} m",
        t.rows.len()
    );
    assert!(max_err < 1e-9, "max difference {max_err} m");
}

#[test]
fn saastamoinen_physical_properties() {
    let sea = Llh::from_degrees(45.0, 0.0, 0.0);
    let zenith = saastamoinen_delay_m(&sea, std::f64::consts::FRAC_PI_2);
    // Zenith dry delay ~2.3 m at sea level (oracles.md) plus a wet part of ~0.1-0.2 m at
    // 15 C and 70 % humidity.
    let dry = 0.0022768 * 1013.25 / (1.0 - 0.00266 * (2.0 * 45f64.to_radians()).cos());
    assert!((dry - 2.3).abs() < 0.02, "dry {dry}");
    assert!(zenith > dry + 0.05 && zenith < dry + 0.3, "zenith {zenith}");
    // Decreases with height.
    let mut prev = zenith;
    for h in [500.0, 1000.0, 2000.0, 4000.0, 8000.0] {
        let d = saastamoinen_delay_m(&Llh { h_m: h, ..sea }, std::f64::consts::FRAC_PI_2);
        assert!(d < prev, "not decreasing at {h} m");
        prev = d;
    }
    // Grows as 1 / sin(el).
    for el_deg in [5.0f64, 15.0, 30.0, 60.0] {
        let d = saastamoinen_delay_m(&sea, el_deg.to_radians());
        assert!((d * el_deg.to_radians().sin() - zenith).abs() < 1e-12);
    }
    assert_eq!(saastamoinen_delay_m(&sea, 0.0), 0.0);
}

/// Above 10 km the delay goes on falling smoothly (RTKLIB's `tropmodel` drops to 0 there: a
/// step of metres at low elevations as an aircraft climbs through it), with the pressure of
/// the U.S. Standard Atmosphere 1976 (NOAA-S/T 76-1562, table I: 226.32 hPa at 11 km,
/// 54.749 hPa at 20 km) in the hydrostatic term; above 20 km (where that atmosphere warms again
/// and the model stays isothermal) within 6 % of it (11.970 hPa at 30 km: 1.3 mm of 2.7 cm).
#[test]
fn saastamoinen_is_continuous_through_10_km_and_follows_the_standard_atmosphere_above() {
    let zenith = std::f64::consts::FRAC_PI_2;
    let at = |h_m: f64, el: f64| saastamoinen_delay_m(&Llh::from_degrees(37.5, 127.0, h_m), el);
    // No step anywhere from 9 to 40 km, at the zenith or at 5 degrees.
    for el in [zenith, 5f64.to_radians()] {
        let mut prev = at(9_000.0, el);
        let mut h = 9_000.0;
        while h < 40_000.0 {
            h += 10.0;
            let d = at(h, el);
            assert!(d < prev, "not decreasing at {h} m");
            // 10 m of climb takes about 0.15 % of the delay (pressure scale height 6-8 km),
            // never a step.
            assert!(prev - d < 3e-3 * prev, "a step of {} m at {h} m", prev - d);
            prev = d;
        }
    }
    // Above 50 km nothing (a spacecraft; the height term of the dry delay would divide by
    // zero at 3570 km), and the step there is a millimetre at the zenith.
    for h_m in [50_001.0, 1e5, 3.57e6, 2e7] {
        assert_eq!(at(h_m, zenith), 0.0, "{h_m} m");
    }
    assert!(at(50_000.0, zenith) < 2e-3);
    // The hydrostatic term against the standard atmosphere's pressure (the wet term is under
    // a millimetre at 216.66 K).
    let lat = 37.5f64.to_radians();
    for (h_m, p_hpa, tol) in [
        (11_000.0, 226.32, 0.005),
        (20_000.0, 54.749, 0.005),
        (30_000.0, 11.970, 0.06),
    ] {
        let dry = 0.0022768 * p_hpa / (1.0 - 0.00266 * (2.0 * lat).cos() - 0.00028 * h_m / 1e3);
        let d = at(h_m, zenith);
        assert!(
            (d - dry).abs() < tol * dry + 1e-3,
            "{h_m} m: {d} m against {dry} m"
        );
    }
}
