//! RINEX navigation reader: the IGS file of 2022-01-01 (values read by eye from the file and
//! cross-checked against RTKLIB's reader through the position fixture), a hand-written
//! RINEX 3 mixed file, and malformed input that must report the right line.

use crate::common::{brdc, shipped_data};
use gpsrx_nav::rinex_nav::{parse_rinex_nav_report, RinexError};
use gpsrx_nav::{parse_rinex_nav, read_rinex_nav, GpsTime};

#[test]
fn brdc_header_and_counts() {
    let nav = brdc();
    // 422 GPS records in the file (RTKLIB's readrnx also reads 422).
    assert_eq!(nav.ephemerides.len(), 422);
    let iono = nav.iono.expect("ION ALPHA/BETA");
    assert_eq!(
        iono.alpha,
        [0.1211e-07, -0.7451e-08, -0.5960e-07, 0.1192e-06]
    );
    assert_eq!(
        iono.beta,
        [0.1167e+06, -0.2458e+06, -0.6554e+05, 0.1114e+07]
    );
    let utc = nav.utc.expect("DELTA-UTC");
    assert_eq!(utc.a0_s, 0.279396772385e-08);
    assert_eq!(utc.a1_s_s, 0.799360577730e-14);
    assert_eq!((utc.tot_s, utc.wnt, utc.dt_ls_s), (147_456, 2191, 18));
    assert_eq!(nav.leap_seconds, Some(18));
    let prns = nav.prns();
    assert!(
        prns.len() >= 30 && prns.iter().all(|p| (1..=32).contains(p)),
        "{prns:?}"
    );
}

#[test]
fn brdc_first_record_fields() {
    let nav = brdc();
    let e = &nav.ephemerides[0];
    assert_eq!(e.prn, 1);
    assert_eq!(e.toc, GpsTime::from_calendar(2022, 1, 1, 0, 0, 0.0));
    assert_eq!(e.toc, GpsTime::new(2190, 518_400.0));
    assert_eq!(e.af0_s, 0.469126738608e-03);
    assert_eq!(e.af1_s_s, -0.100044417195e-10);
    assert_eq!(e.af2_s_s2, 0.0);
    assert_eq!((e.iode, e.iodc), (39, 39));
    assert_eq!(e.crs_m, -0.141125000000e+03);
    assert_eq!(e.delta_n_rad_s, 0.398838041777e-08);
    assert_eq!(e.m0_rad, -0.624294238235e+00);
    assert_eq!(e.cuc_rad, -0.736303627491e-05);
    assert_eq!(e.e, 0.112181392033e-01);
    assert_eq!(e.cus_rad, 0.469572842121e-05);
    assert_eq!(e.sqrt_a_sqrt_m, 0.515367499542e+04);
    assert_eq!(e.toe, GpsTime::new(2190, 518_400.0));
    assert_eq!(e.cic_rad, -0.316649675369e-07);
    assert_eq!(e.omega0_rad, -0.103661124009e+01);
    assert_eq!(e.cis_rad, 0.195577740669e-06);
    assert_eq!(e.i0_rad, 0.986418769490e+00);
    assert_eq!(e.crc_m, 0.299750000000e+03);
    assert_eq!(e.omega_rad, 0.884087601569e+00);
    assert_eq!(e.omega_dot_rad_s, -0.813355308085e-08);
    assert_eq!(e.idot_rad_s, -0.377872882780e-09);
    assert_eq!(e.codes_on_l2, 1);
    assert!(!e.l2p_data_flag);
    assert_eq!(e.ura_index, 0); // 2.0 m
    assert_eq!(e.sv_health, 0);
    assert_eq!(e.tgd_s, 0.512227416039e-08);
    assert!(!e.fit_interval_flag); // 4 hours
}

/// A hand-written RINEX 3.04 mixed file: one Galileo, one GPS, one GLONASS record.
const RINEX3_RAW: &str = r"
     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE
gpsrx test          gpsrx               20220102 000000 UTC PGM / RUN BY / DATE
GPSA   1.2110D-08 -7.4510D-09 -5.9600D-08  1.1920D-07       IONOSPHERIC CORR
GPSB   1.1670D+05 -2.4580D+05 -6.5540D+04  1.1140D+06       IONOSPHERIC CORR
GAL    2.5750D+01  2.3438D-01  4.4861D-03  0.0000D+00       IONOSPHERIC CORR
GPUT  2.7939677238D-09 7.993605777D-15 147456 2191          TIME SYSTEM CORR
    18    18  2185     7                                    LEAP SECONDS
                                                            END OF HEADER
E01 2022 01 01 00 10 00-6.588267395273E-04-7.389644451905E-12 0.000000000000E+00
     1.100000000000E+01-2.031250000000E+01 2.889406693727E-09 2.734766152606E+00
    -9.331107139587E-07 2.161774318665E-04 9.404495358467E-06 5.440614227295E+03
     5.190000000000E+05-5.029141902924E-08 2.983003470358E+00-7.450580596924E-09
     9.873389493860E-01 1.375625000000E+02-1.211453451640E+00-5.454509491255E-09
     1.471489857750E-10 5.170000000000E+02 2.190000000000E+03 0.000000000000E+00
     3.120000000000E+00 0.000000000000E+00 4.656612873077E-10 5.122274160385E-09
     5.196450000000E+05
G03 2022 01 01 00 00 00-6.114551797509E-05-1.386979420204E-11 0.000000000000E+00
     3.800000000000E+01-5.975000000000E+01 3.906591296639E-09-1.795256571460E+00
    -3.123655915260E-06 3.840183722787E-03 1.224316656590E-05 5.153710868835E+03
     5.184000000000E+05 9.126961231232E-08-1.327504530180E-03-1.043081283569E-07
     9.724148984010E-01 1.510000000000E+02 9.847857623140E-01-7.513527254280E-09
     4.232319150220E-10 1.000000000000E+00 2.190000000000E+03 0.000000000000E+00
     2.000000000000E+00 0.000000000000E+00 1.862645149231E-09 3.800000000000E+01
     5.114880000000E+05 4.000000000000E+00
R05 2022 01 01 00 15 00 2.309400588274E-05 0.000000000000E+00 5.184000000000E+05
     1.030000000000E+04-1.200000000000E+00 0.000000000000E+00 0.000000000000E+00
     2.000000000000E+04 2.500000000000E+00 9.313225746155E-10 1.000000000000E+00
     1.500000000000E+04 1.900000000000E+00 0.000000000000E+00 0.000000000000E+00
";

/// The RINEX 3 text without the leading newline of the raw literal.
fn rinex3() -> &'static str {
    RINEX3_RAW.strip_prefix('\n').unwrap_or(RINEX3_RAW)
}

/// A header line: content padded to 60 columns, then the label.
fn header_line(content: &str, label: &str) -> String {
    format!("{content:<60}{label}\n")
}

#[test]
fn rinex3_mixed_file() {
    let report = parse_rinex_nav_report(rinex3()).expect("valid RINEX 3");
    assert_eq!(report.version, 3.04);
    assert_eq!(report.skipped_records.get(&'E'), Some(&1));
    assert_eq!(report.skipped_records.get(&'R'), Some(&1));
    let nav = report.nav;
    assert_eq!(nav.ephemerides.len(), 1);
    let e = &nav.ephemerides[0];
    assert_eq!(e.prn, 3);
    assert_eq!(e.toc, GpsTime::new(2190, 518_400.0));
    assert_eq!(e.af0_s, -6.114551797509e-05);
    assert_eq!(e.iode, 38);
    assert_eq!(e.sqrt_a_sqrt_m, 5.153710868835e+03);
    assert_eq!(e.toe, GpsTime::new(2190, 518_400.0));
    assert_eq!(e.idot_rad_s, 4.232319150220e-10);
    assert_eq!(e.tgd_s, 1.862645149231e-09);
    assert_eq!(e.iodc, 38);
    // Same satellite and epoch in the RINEX 2 file: identical values.
    let brdc = crate::common::brdc();
    let e2 = brdc
        .ephemerides
        .iter()
        .find(|x| x.prn == 3 && x.toe == e.toe)
        .expect("PRN 3 at 00:00 in brdc");
    assert_eq!(e2.m0_rad, e.m0_rad);
    assert_eq!(e2.omega_rad, e.omega_rad);
    let iono = nav.iono.expect("GPSA/GPSB");
    assert_eq!(iono.alpha[0], 1.2110e-08);
    assert_eq!(iono.beta[3], 1.1140e+06);
    let utc = nav.utc.expect("GPUT");
    assert_eq!(utc.a0_s, 2.7939677238e-09);
    assert_eq!(utc.a1_s_s, 7.993605777e-15);
    assert_eq!((utc.tot_s, utc.wnt), (147_456, 2191));
    assert_eq!(
        (utc.dt_ls_s, utc.dt_lsf_s, utc.wn_lsf, utc.dn),
        (18, 18, 2185, 7)
    );
    assert_eq!(nav.leap_seconds, Some(18));
}

/// Replaces the text of 1-based line `line_no` of the brdc file using `f`.
fn brdc_with_line(line_no: usize, f: impl Fn(&str) -> String) -> String {
    let text = std::fs::read_to_string(shipped_data("brdc0010.22n")).expect("readable");
    text.lines()
        .enumerate()
        .map(|(i, l)| {
            if i + 1 == line_no {
                f(l)
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn malformed_number_reports_line_and_field() {
    // Line 19 is the 2nd orbit line of PRN 2 (Cuc, e, Cus, sqrt(A)); break sqrt(A).
    let text = brdc_with_line(19, |l| {
        l.replace("0.515366817474D+04", "0.5153668X7474D+04")
    });
    let err = parse_rinex_nav(&text).expect_err("must fail");
    assert_eq!(err.line(), Some(19));
    let msg = err.to_string();
    assert!(msg.contains("line 19"), "{msg}");
    assert!(msg.contains("sqrt(A)"), "{msg}");
    assert!(msg.contains("0.5153668X7474D+04"), "{msg}");
}

#[test]
fn impossible_value_reports_line() {
    // Eccentricity 1.2 on line 11 (PRN 1, orbit line 2).
    let text = brdc_with_line(11, |l| {
        l.replace("0.112181392033D-01", "0.120000000000D+01")
    });
    let err = parse_rinex_nav(&text).expect_err("must fail");
    assert!(
        matches!(err, RinexError::OutOfRange { line: 11, .. }),
        "{err}"
    );
}

#[test]
fn bad_epoch_and_truncation_report_lines() {
    let text = brdc_with_line(17, |l| l.replacen(" 2 22  1", " 2 22 13", 1));
    let err = parse_rinex_nav(&text).expect_err("month 13");
    assert_eq!(err.line(), Some(17), "{err}");

    let full = std::fs::read_to_string(shipped_data("brdc0010.22n")).expect("readable");
    let lines: Vec<&str> = full.lines().collect();
    let truncated = lines[..lines.len() - 3].join("\n");
    let err = parse_rinex_nav(&truncated).expect_err("truncated");
    assert!(matches!(err, RinexError::TruncatedRecord { .. }), "{err}");
    assert_eq!(err.line(), Some(lines.len() - 3));
}

#[test]
fn header_errors() {
    assert!(matches!(parse_rinex_nav(""), Err(RinexError::NotRinex)));
    let glonass = header_line(
        "     2.11           G: GLONASS NAV DATA",
        "RINEX VERSION / TYPE",
    );
    assert!(matches!(
        parse_rinex_nav(&glonass),
        Err(RinexError::NotGpsNav { line: 1, .. })
    ));
    let galileo = header_line(
        "     3.04           N: GNSS NAV DATA    E: GALILEO",
        "RINEX VERSION / TYPE",
    );
    assert!(matches!(
        parse_rinex_nav(&galileo),
        Err(RinexError::NotGpsNav { line: 1, .. })
    ));
    let v4 = header_line(
        "     4.00           N: GNSS NAV DATA    M: MIXED",
        "RINEX VERSION / TYPE",
    );
    assert!(matches!(
        parse_rinex_nav(&v4),
        Err(RinexError::UnsupportedVersion { .. })
    ));
    let no_end = header_line(
        "     2.11           N: GPS NAV DATA",
        "RINEX VERSION / TYPE",
    );
    assert!(matches!(
        parse_rinex_nav(&no_end),
        Err(RinexError::MissingHeaderEnd { .. })
    ));
    let unknown = rinex3().replace("R05 2022", "X05 2022");
    let err = parse_rinex_nav(&unknown).expect_err("unknown system");
    assert!(
        matches!(
            err,
            RinexError::UnknownSystem {
                system: 'X',
                line: 25
            }
        ),
        "{err}"
    );
}

#[test]
fn file_errors_name_the_path() {
    let missing = std::path::Path::new("/nonexistent/brdc.22n");
    let err = read_rinex_nav(missing).expect_err("missing file");
    assert!(err.to_string().contains("/nonexistent/brdc.22n"), "{err}");

    let dir = std::env::temp_dir().join(format!("gpsrx-nav-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("bad.22n");
    std::fs::write(
        &path,
        brdc_with_line(19, |l| l.replace("0.515366817474D+04", "garbage")),
    )
    .expect("write");
    let err = read_rinex_nav(&path).expect_err("bad content");
    let msg = err.to_string();
    std::fs::remove_dir_all(&dir).ok();
    assert!(msg.contains("bad.22n") && msg.contains("line 19"), "{msg}");
    assert_eq!(err.line(), Some(19));
}

#[test]
fn select_nearest_healthy_within_four_hours() {
    let nav = brdc();
    let t = GpsTime::new(2190, 538_200.0); // 05:30
    let e = nav.select(3, t).expect("PRN 3 has ephemerides");
    // toes of PRN 3 are every 2 h; nearest to 05:30 is 06:00 (TOW 540000).
    assert_eq!(e.toe.tow_s, 540_000.0);
    for other in nav
        .ephemerides
        .iter()
        .filter(|x| x.prn == 3 && x.sv_health == 0)
    {
        assert!(t.diff_s(e.toe).abs() <= t.diff_s(other.toe).abs());
    }
    // Far from any toe (a week later): nothing.
    assert!(nav.select(3, t.add_seconds(604_800.0)).is_none());
    // Unhealthy ephemerides are never selected.
    let mut sick = nav.clone();
    for x in sick.ephemerides.iter_mut().filter(|x| x.prn == 3) {
        x.sv_health = 1;
    }
    assert!(sick.select(3, t).is_none());
    // 4 h limit: take only one PRN 3 ephemeris and move t to 4 h +- 1 s from its toe.
    let only = gpsrx_nav::NavData {
        ephemerides: vec![e.clone()],
        ..Default::default()
    };
    assert!(only
        .select(3, e.toe.add_seconds(4.0 * 3600.0 - 1.0))
        .is_some());
    assert!(only
        .select(3, e.toe.add_seconds(-4.0 * 3600.0 - 1.0))
        .is_none());
}

#[test]
fn health_policies_choose_among_valid_ephemerides() {
    use gpsrx_nav::{select_ephemeris, HealthPolicy};
    let nav = brdc();
    let t = GpsTime::new(2190, 538_200.0); // 05:30: PRN 3's nearest toe is 06:00
    let mut sick = nav.clone();
    // The nearest one unhealthy, the others healthy.
    for x in sick.ephemerides.iter_mut().filter(|x| x.prn == 3) {
        x.sv_health = u8::from(x.toe.tow_s == 540_000.0);
    }
    let pick = |h| {
        sick.select_with(3, t, h)
            .map(|e| (e.toe.tow_s, e.sv_health))
    };
    assert_eq!(pick(HealthPolicy::Ignore), Some((540_000.0, 1)));
    let healthy = pick(HealthPolicy::HealthyOnly).expect("a healthy one within 4 h");
    assert_eq!(healthy.1, 0);
    assert_eq!(pick(HealthPolicy::PreferHealthy), Some(healthy));
    assert_eq!(
        select_ephemeris(&sick.ephemerides, 3, t, HealthPolicy::HealthyOnly).map(|e| e.toe),
        sick.select(3, t).map(|e| e.toe)
    );
    // Every selection is valid at t; nothing a week later.
    assert!(sick
        .ephemerides
        .iter()
        .filter(|e| e.prn == 3)
        .all(|e| e.is_valid_at(t) == (t.diff_s(e.toe).abs() <= e.max_age_s())));
    assert!(sick
        .select_with(3, t.add_seconds(604_800.0), HealthPolicy::Ignore)
        .is_none());
}
