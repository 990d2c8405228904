//! GPS time: calendar conversions against published GPS-week facts, normalisation, rollover.

use gpsrx_nav::time::resolve_week_modulo;
use gpsrx_nav::GpsTime;
use proptest::prelude::*;

#[test]
fn known_calendar_dates() {
    // Published facts: GPS epoch 1980-01-06 is week 0; first rollover 1999-08-22 is week 1024;
    // second rollover 2019-04-07 is week 2048; the simulator recording starts
    // 2022-01-01 05:30:00 GPST = week 2190 TOW 538200 (shared/data/README.md).
    let cases = [
        ((1980, 1, 6, 0, 0, 0.0), (0, 0.0)),
        ((1999, 8, 22, 0, 0, 0.0), (1024, 0.0)),
        ((1999, 8, 21, 23, 59, 59.0), (1023, 604_799.0)),
        ((2019, 4, 7, 0, 0, 0.0), (2048, 0.0)),
        ((2022, 1, 1, 5, 30, 0.0), (2190, 538_200.0)),
        ((2022, 1, 2, 0, 0, 0.0), (2191, 0.0)),
        // 2024-02-29 (leap day) 12:34:56.5 is a Thursday of week 2303.
        (
            (2024, 2, 29, 12, 34, 56.5),
            (2303, 4.0 * 86_400.0 + 45_296.5),
        ),
    ];
    for ((y, mo, d, h, mi, s), (week, tow)) in cases {
        let t = GpsTime::from_calendar(y, mo, d, h, mi, s);
        assert_eq!((t.week, t.tow_s), (week, tow), "{y}-{mo}-{d} {h}:{mi}:{s}");
        let (y2, mo2, d2, h2, mi2, s2) = t.to_calendar();
        assert_eq!((y2, mo2, d2, h2, mi2), (y, mo, d, h, mi));
        assert!((s2 - s).abs() < 1e-9);
    }
}

#[test]
fn calendar_rolls_over_out_of_range_fields() {
    assert_eq!(
        GpsTime::from_calendar(2021, 13, 1, 0, 0, 0.0),
        GpsTime::from_calendar(2022, 1, 1, 0, 0, 0.0)
    );
    assert_eq!(
        GpsTime::from_calendar(2022, 1, 1, 24, 0, 0.0),
        GpsTime::from_calendar(2022, 1, 2, 0, 0, 0.0)
    );
    // Before the epoch: week saturates at 0 with a negative TOW.
    let t = GpsTime::from_calendar(1980, 1, 5, 0, 0, 0.0);
    assert_eq!((t.week, t.tow_s), (0, -86_400.0));
}

#[test]
fn new_normalises_tow() {
    assert_eq!(
        GpsTime::new(2190, 604_800.0),
        GpsTime {
            week: 2191,
            tow_s: 0.0
        }
    );
    assert_eq!(
        GpsTime::new(2191, -1.0),
        GpsTime {
            week: 2190,
            tow_s: 604_799.0
        }
    );
    assert_eq!(
        GpsTime::new(10, 3.0 * 604_800.0 + 5.0),
        GpsTime {
            week: 13,
            tow_s: 5.0
        }
    );
    assert_eq!(
        GpsTime::new(0, -5.0),
        GpsTime {
            week: 0,
            tow_s: -5.0
        }
    );
    let nan = GpsTime::new(7, f64::NAN);
    assert_eq!(nan.week, 7);
    assert!(nan.tow_s.is_nan());
}

#[test]
fn add_and_diff_across_week_boundary() {
    let a = GpsTime::new(2190, 604_790.0);
    let b = a.add_seconds(20.0);
    assert_eq!(
        b,
        GpsTime {
            week: 2191,
            tow_s: 10.0
        }
    );
    assert_eq!(b.diff_s(a), 20.0);
    assert_eq!(a.diff_s(b), -20.0);
    assert!(b > a);
    // Precision survives large week differences: 1000 weeks + 1 microsecond.
    let c = GpsTime::new(1190, 0.25);
    let d = GpsTime::new(2190, 0.250_001);
    assert!((d.diff_s(c) - (1000.0 * 604_800.0 + 1e-6)).abs() < 1e-9);
}

#[test]
fn ten_bit_week_resolution() {
    assert_eq!(GpsTime::resolve_week_10bit(2190 % 1024, 2200), 2190);
    assert_eq!(GpsTime::resolve_week_10bit(2190 % 1024, 1700), 2190);
    assert_eq!(GpsTime::resolve_week_10bit(2190 % 1024, 2600), 2190);
    assert_eq!(GpsTime::resolve_week_10bit(1023, 2048), 2047);
    assert_eq!(GpsTime::resolve_week_10bit(0, 2047), 2048);
    assert_eq!(GpsTime::resolve_week_10bit(5, 100), 5);
    // Near week 0 the result never goes negative.
    assert_eq!(GpsTime::resolve_week_10bit(1000, 3), 1000);
    // Values >= 1024 are taken modulo 1024.
    assert_eq!(GpsTime::resolve_week_10bit(1024 + 142, 2190), 2190);
    // 8-bit WN_t style.
    assert_eq!(resolve_week_modulo(2191 % 256, 2190, 256), 2191);
}

proptest! {
    #[test]
    fn calendar_round_trip(week in 0u32..5000, tow in 0.0f64..604_800.0) {
        let t = GpsTime::new(week, tow);
        let (y, mo, d, h, mi, s) = t.to_calendar();
        let back = GpsTime::from_calendar(y, mo, d, h, mi, s);
        prop_assert_eq!(back.week, t.week);
        prop_assert!((back.tow_s - t.tow_s).abs() < 1e-7);
    }

    #[test]
    fn ten_bit_resolution_recovers_week(week in 0u32..4000, offset in -511i64..=511) {
        let reference = (i64::from(week) + offset).max(0) as u32;
        prop_assert_eq!(GpsTime::resolve_week_10bit(week % 1024, reference), week);
    }

    #[test]
    fn add_then_diff(week in 0u32..4000, tow in 0.0f64..604_800.0, dt in -2e6f64..2e6) {
        let t = GpsTime::new(week, tow);
        let u = t.add_seconds(dt);
        prop_assert!((u.diff_s(t) - dt).abs() < 1e-6);
        if f64::from(week) * 604_800.0 + tow + dt >= 0.0 {
            prop_assert!(u.tow_s >= 0.0 && u.tow_s < 604_800.0);
        } else {
            // Before the GPS epoch: documented saturation at week 0 with a negative TOW.
            prop_assert!(u.week == 0 && u.tow_s < 0.0);
        }
    }
}

#[test]
fn gps_minus_utc_from_brdc() {
    // brdc0010.22n: A0 = 2.79e-9 s, A1 = 8.0e-15 s/s, t_ot = 147456 of week 2191, 18 leap s.
    let utc = crate::common::brdc().utc.expect("DELTA-UTC");
    let t = GpsTime::new(2190, 538_200.0);
    let expected =
        18.0 + 0.279396772385e-08 + 0.799360577730e-14 * (-(604_800.0 - 538_200.0) - 147_456.0);
    assert!((utc.gps_minus_utc_s(t) - expected).abs() < 1e-15);
}

#[test]
fn utc_and_gps_time_differ_by_the_leap_seconds_of_the_date() {
    use gpsrx_nav::utc::{gps_from_utc, leap_seconds_on, utc_from_gps};
    assert_eq!(leap_seconds_on(1980, 1), 0);
    assert_eq!(leap_seconds_on(1998, 12), 12);
    assert_eq!(leap_seconds_on(1999, 1), 13);
    assert_eq!(leap_seconds_on(2016, 12), 17);
    assert_eq!(leap_seconds_on(2017, 1), 18);
    assert_eq!(leap_seconds_on(2026, 11), 18);
    // 2022-01-01 05:29:42 UTC is week 2190, TOW 538200 (05:30:00 GPS time).
    let t = gps_from_utc(2022, 1, 1, 5, 29, 42.0);
    assert_eq!((t.week, t.tow_s), (2190, 538_200.0));
    let (y, mo, d, h, mi, s) = utc_from_gps(t);
    assert_eq!((y, mo, d, h, mi), (2022, 1, 1, 5, 29));
    assert!((s - 42.0).abs() < 1e-9);
    // Either side of the leap second at the end of 2016 (17 s, then 18 s).
    let before = gps_from_utc(2016, 12, 31, 23, 59, 59.0);
    let after = gps_from_utc(2017, 1, 1, 0, 0, 0.0);
    assert!(
        (after.diff_s(before) - 2.0).abs() < 1e-9,
        "the inserted second"
    );
    let (y, mo, d, h, mi, s) = utc_from_gps(before);
    assert_eq!((y, mo, d, h, mi), (2016, 12, 31, 23, 59));
    assert!((s - 59.0).abs() < 1e-9);
    let (y, mo, d, h, mi, s) = utc_from_gps(after);
    assert_eq!((y, mo, d, h, mi), (2017, 1, 1, 0, 0));
    assert!(s.abs() < 1e-9);
}

#[test]
fn tow_differences_fold_across_the_week_crossover() {
    // Received 0.07 s into a week, sent 0.07 s before its end: 0.14 s of travel, not -604800 s.
    let d = GpsTime::fold_tow_difference_s(0.07 - 604_799.93);
    assert!((d - 0.14).abs() < 1e-9, "{d}");
    assert!((GpsTime::fold_tow_difference_s(-0.075) + 0.075).abs() < 1e-12);
    assert!((GpsTime::fold_tow_difference_s(604_799.5 - 0.5) + 1.0).abs() < 1e-9);
}
