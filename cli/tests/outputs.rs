//! Output writers checked against independent readers: the RINEX navigation file through
//! `gpsrx_nav`'s reader, NMEA checksums through a parser written here, GeoJSON/CSV through
//! serde_json/csv, and the RINEX observation file through RTKLIB's `rnx2rtkp`, whose
//! single-point solution from our synthetic pseudoranges must land on the true position.
//!
//! When `rnx2rtkp` is not installed the RTKLIB test prints a note and passes, except with
//! CI=true, where it fails.

use gpsrx_nav::constants::{F_L1_HZ, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::{
    azimuth_elevation, read_rinex_nav, rotate_for_earth_rotation, Ephemeris, GpsTime, Llh, NavData,
    Vector3,
};
use gpsrx_receiver::output::nmea::{gga, gst, gsv, rmc, zda};
use gpsrx_receiver::output::{
    rinex_nav::write_rinex_nav_file, write_geojson, write_kml, write_rinex_nav, ChannelCsvWriter,
    ChannelRow, Fix, FixQuality, NavHeader, NavRecord, NmeaOptions, NmeaWriter, ObsEpoch,
    ObsHeader, PvtCsvWriter, RinexObsWriter, SatObs, SatView,
};
use std::path::{Path, PathBuf};
use std::process::Command;

fn brdc_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n")
}

fn brdc() -> NavData {
    read_rinex_nav(&brdc_path()).expect("samples/data/brdc0010.22n is part of the repository")
}

/// |a - b| within `rel` of the larger magnitude, or `abs` absolutely.
fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= abs.max(rel * a.abs().max(b.abs()))
}

// ---------------------------------------------------------------- RINEX navigation round trip

#[test]
fn rinex_nav_round_trips_through_the_reader() {
    let nav = brdc();
    assert!(nav.ephemerides.len() > 100);
    let header = NavHeader {
        run_by: "test".to_string(),
        creation_date: Some("20220102 000000 UTC".to_string()),
        iono: nav.iono,
        utc: nav.utc,
        leap_seconds: nav.leap_seconds,
        ..NavHeader::default()
    };
    let records: Vec<NavRecord> = nav
        .ephemerides
        .iter()
        .cloned()
        .map(NavRecord::from)
        .collect();
    let mut bytes = Vec::new();
    write_rinex_nav(&mut bytes, "ephemeris.rnx", &header, &records).expect("writes");
    let text = String::from_utf8(bytes).expect("ASCII");
    assert!(text.starts_with(
        "     3.04           N: GNSS NAV DATA    G: GPS              RINEX VERSION / TYPE\n"
    ));
    for line in text.lines() {
        assert!(line.len() <= 80, "line longer than 80 columns: `{line}`");
    }
    let back = gpsrx_nav::parse_rinex_nav(&text).expect("our file reads back");

    // 12 significant digits in D19.12: relative error <= 5e-12.
    const REL: f64 = 6e-12;
    assert_eq!(back.ephemerides.len(), nav.ephemerides.len());
    for (a, b) in nav.ephemerides.iter().zip(&back.ephemerides) {
        let id = format!("G{:02} toc {:?}", a.prn, a.toc);
        assert_eq!((a.prn, a.toc, a.toe), (b.prn, b.toc, b.toe), "{id}");
        assert_eq!(
            (a.iode, a.iodc, a.ura_index, a.sv_health),
            (b.iode, b.iodc, b.ura_index, b.sv_health),
            "{id}"
        );
        assert_eq!(
            (a.codes_on_l2, a.l2p_data_flag, a.fit_interval_flag),
            (b.codes_on_l2, b.l2p_data_flag, b.fit_interval_flag),
            "{id}"
        );
        let pairs = [
            ("af0", a.af0_s, b.af0_s),
            ("af1", a.af1_s_s, b.af1_s_s),
            ("af2", a.af2_s_s2, b.af2_s_s2),
            ("crs", a.crs_m, b.crs_m),
            ("delta_n", a.delta_n_rad_s, b.delta_n_rad_s),
            ("m0", a.m0_rad, b.m0_rad),
            ("cuc", a.cuc_rad, b.cuc_rad),
            ("e", a.e, b.e),
            ("cus", a.cus_rad, b.cus_rad),
            ("sqrt_a", a.sqrt_a_sqrt_m, b.sqrt_a_sqrt_m),
            ("cic", a.cic_rad, b.cic_rad),
            ("omega0", a.omega0_rad, b.omega0_rad),
            ("cis", a.cis_rad, b.cis_rad),
            ("i0", a.i0_rad, b.i0_rad),
            ("crc", a.crc_m, b.crc_m),
            ("omega", a.omega_rad, b.omega_rad),
            ("omega_dot", a.omega_dot_rad_s, b.omega_dot_rad_s),
            ("idot", a.idot_rad_s, b.idot_rad_s),
            ("tgd", a.tgd_s, b.tgd_s),
        ];
        for (name, x, y) in pairs {
            assert!(
                close(x, y, REL, 0.0),
                "{id} {name}: {x:e} written, {y:e} read"
            );
        }
    }
    let (ia, ib) = (
        nav.iono.expect("brdc has ION ALPHA/BETA"),
        back.iono.expect("written"),
    );
    assert_eq!(ia, ib, "D12.4 holds the 4 digits of the source");
    let (ua, ub) = (
        nav.utc.expect("brdc has DELTA-UTC"),
        back.utc.expect("written"),
    );
    assert!(
        close(ua.a0_s, ub.a0_s, 6e-10, 0.0),
        "A0 {} vs {}",
        ua.a0_s,
        ub.a0_s
    );
    assert!(
        close(ua.a1_s_s, ub.a1_s_s, 6e-9, 0.0),
        "A1 {} vs {}",
        ua.a1_s_s,
        ub.a1_s_s
    );
    assert_eq!(
        (ua.tot_s, ua.wnt, ua.dt_ls_s),
        (ub.tot_s, ub.wnt, ub.dt_ls_s)
    );
    assert_eq!(back.leap_seconds, Some(18));

    // A bad value is an error naming the file, and nothing panics.
    let mut bad = records[0].clone();
    bad.ephemeris.m0_rad = f64::NAN;
    let err = write_rinex_nav(&mut Vec::new(), "ephemeris.rnx", &header, &[bad])
        .expect_err("NaN cannot be written");
    assert!(err.to_string().contains("ephemeris.rnx"), "{err}");
}

// ---------------------------------------------------------------------------------- NMEA

/// Independent NMEA check: `$`, body, `*`, two hex digits, CR LF; XOR of the body.
fn parse_nmea(sentence: &str) -> Vec<String> {
    let s = sentence.strip_suffix("\r\n").expect("ends with CR LF");
    let s = s.strip_prefix('$').expect("starts with $");
    let (body, hex) = s.rsplit_once('*').expect("has *");
    assert_eq!(hex.len(), 2, "two checksum digits in `{sentence}`");
    assert_eq!(hex, hex.to_uppercase());
    let want = u8::from_str_radix(hex, 16).expect("hex checksum");
    let mut x = 0u8;
    for b in body.bytes() {
        x ^= b;
    }
    assert_eq!(x, want, "checksum of `{sentence}`");
    body.split(',').map(str::to_string).collect()
}

fn test_fix() -> Fix {
    let llh = Llh::from_degrees(48.1173, 11.516_666_7, 545.4);
    let ecef = llh.to_ecef();
    // 10 m/s due east at this position.
    let east = Vector3::new(-llh.lon_rad.sin(), llh.lon_rad.cos(), 0.0) * 10.0;
    Fix {
        time: GpsTime::from_calendar(2022, 1, 1, 5, 30, 0.0),
        week_known: true,
        ecef_m: [ecef.x, ecef.y, ecef.z],
        llh,
        vel_ecef_mps: Some([east.x, east.y, east.z]),
        clock_bias_m: 12_345.678,
        clock_drift_mps: Some(-0.25),
        n_sv: 8,
        used_prns: vec![1, 3, 6, 14, 17, 19, 22, 30],
        pdop: 1.8,
        hdop: 0.9,
        vdop: 1.5,
        raim: "ok, passed".to_string(),
        quality: FixQuality::Gnss,
        sigma_enu_m: Some([0.8, 1.1, 2.3]),
        sats_in_view: (1..=9)
            .map(|k| SatView {
                prn: k * 3,
                el_deg: 10.0 * f64::from(k),
                az_deg: 40.0 * f64::from(k),
                cn0_dbhz: if k == 9 {
                    None
                } else {
                    Some(35.0 + f64::from(k))
                },
            })
            .collect(),
    }
}

#[test]
fn gga_known_answer_and_checksums() {
    let fix = test_fix();
    // The geoid separation set to 0 (the default is EGM96: receiver's nmea tests).
    let opts = NmeaOptions {
        geoid_separation_m: Some(0.0),
        ..NmeaOptions::default()
    };
    // 05:30:00 GPST - 18 s = 05:29:42 UTC; 6 decimals of minutes (11.5166667 deg is
    // 11 deg 31.000002'); the checksum 55 was computed outside this code.
    assert_eq!(
        gga(&fix, &opts),
        "$GPGGA,052942.00,4807.038000,N,01131.000002,E,1,08,0.9,545.400,M,0.000,M,,*55\r\n"
    );
    // GST: the error ellipse from the east/north sigmas (0.8, 1.1 m: major axis north), the
    // latitude, longitude and altitude sigmas; ZDA: the UTC date. Checksums 40 and 6C computed
    // outside this code.
    assert_eq!(
        gst(&fix, &opts),
        "$GPGST,052942.00,,1.10,0.80,0.0,1.10,0.80,2.30*40\r\n"
    );
    assert_eq!(zda(&fix, &opts), "$GPZDA,052942.00,01,01,2022,00,00*6C\r\n");
    let undated = Fix {
        week_known: false,
        ..fix.clone()
    };
    assert!(zda(&undated, &opts).starts_with("$GPZDA,052942.00,,,,00,00*"));
    let with_geoid = gga(
        &fix,
        &NmeaOptions {
            geoid_separation_m: Some(47.4),
            ..opts.clone()
        },
    );
    let f = parse_nmea(&with_geoid);
    assert_eq!((f[9].as_str(), f[11].as_str()), ("498.000", "47.400"));

    let mut dr = fix.clone();
    dr.quality = FixQuality::DeadReckoning;
    assert_eq!(parse_nmea(&gga(&dr, &opts))[6], "6");
    let mut none = fix.clone();
    none.quality = FixQuality::None;
    let f = parse_nmea(&gga(&none, &opts));
    assert_eq!((f[2].as_str(), f[6].as_str(), f[9].as_str()), ("", "0", ""));
    let mut south_west = fix.clone();
    south_west.llh = Llh::from_degrees(-33.5, -70.25, 500.0);
    let f = parse_nmea(&gga(&south_west, &opts));
    assert_eq!(&f[2..6], ["3330.000000", "S", "07015.000000", "W"]);

    let f = parse_nmea(&rmc(&fix, &opts));
    assert_eq!(f[0], "GPRMC");
    assert_eq!(
        (f[1].as_str(), f[2].as_str(), f[9].as_str()),
        ("052942.00", "A", "010122")
    );
    assert_eq!(
        (f[7].as_str(), f[8].as_str()),
        ("19.44", "90.0"),
        "10 m/s east"
    );
    assert_eq!(f[12], "A");
    // The week unknown: the time of day stands, the date is left empty (never invented).
    let undated = Fix {
        week_known: false,
        ..fix.clone()
    };
    let f = parse_nmea(&rmc(&undated, &opts));
    assert_eq!((f[1].as_str(), f[9].as_str()), ("052942.00", ""));

    let gsv = gsv(&fix);
    assert_eq!(gsv.len(), 3, "9 satellites, 4 per sentence");
    for (k, s) in gsv.iter().enumerate() {
        let f = parse_nmea(s);
        assert_eq!(f[1], "3");
        assert_eq!(f[2], (k + 1).to_string());
        assert_eq!(f[3], "09");
        let n = if k < 2 { 4 } else { 1 };
        assert_eq!(f.len(), 4 + 4 * n, "`{s}`");
    }
    let last = parse_nmea(&gsv[2]);
    assert_eq!(
        &last[4..8],
        ["27", "90", "000", ""],
        "az 360 -> 000, no C/N0 -> empty SNR"
    );

    let mut w = NmeaWriter::new(Vec::new(), "pvt.nmea", opts);
    w.write_fix(&fix).expect("in memory");
    let text = String::from_utf8(w.finish().expect("flush")).expect("ASCII");
    let sentences: Vec<String> = text.split_inclusive("\r\n").map(str::to_string).collect();
    assert_eq!(sentences.len(), 8, "GGA, RMC, GSA, 3 GSV, GST and ZDA");
    for s in &sentences {
        parse_nmea(s);
    }
    let gsa = parse_nmea(&sentences[2]);
    assert_eq!(gsa.len(), 18);
    assert_eq!(&gsa[..4], ["GPGSA", "A", "3", "01"]);
    assert_eq!(&gsa[15..], ["1.8", "0.9", "1.5"]);
}

// ------------------------------------------------------------- GeoJSON, KML and the CSVs

fn track() -> Vec<Fix> {
    (0..5)
        .map(|k| {
            let mut f = test_fix();
            f.time = f.time.add_seconds(f64::from(k));
            f.llh.lon_rad += f64::from(k) * 1e-6;
            if k == 2 {
                f.quality = FixQuality::None;
                f.hdop = f64::NAN;
            }
            f
        })
        .collect()
}

#[test]
fn geojson_and_kml_hold_the_track() {
    let fixes = track();
    let mut bytes = Vec::new();
    write_geojson(&mut bytes, "track.geojson", &fixes).expect("in memory");
    let v: serde_json::Value = serde_json::from_slice(&bytes).expect("valid JSON");
    assert_eq!(v["type"], "FeatureCollection");
    let features = v["features"].as_array().expect("features");
    assert_eq!(features.len(), 5, "one LineString + 4 valid points");
    assert_eq!(features[0]["geometry"]["type"], "LineString");
    let coords = features[0]["geometry"]["coordinates"]
        .as_array()
        .expect("coords");
    assert_eq!(coords.len(), 4);
    assert!((coords[0][0].as_f64().unwrap_or(0.0) - 11.516_666_7).abs() < 1e-8);
    assert!((coords[0][1].as_f64().unwrap_or(0.0) - 48.1173).abs() < 1e-8);
    let p = &features[1]["properties"];
    assert_eq!(p["time_gpst"], "2022-01-01T05:30:00.000");
    assert_eq!(p["raim"], "ok, passed");
    assert_eq!(p["n_sv"], 8);

    let mut kml = Vec::new();
    write_kml(&mut kml, "track.kml", "run & test", &fixes).expect("in memory");
    let kml = String::from_utf8(kml).expect("UTF-8");
    assert!(kml.starts_with("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">"));
    assert!(kml.contains("<name>run &amp; test</name>"));
    for tag in ["kml", "Document", "Placemark", "LineString", "coordinates"] {
        assert_eq!(
            kml.matches(&format!("<{tag}>")).count() + kml.matches(&format!("<{tag} ")).count(),
            1,
            "{tag}"
        );
        assert_eq!(kml.matches(&format!("</{tag}>")).count(), 1, "{tag}");
    }
    let inner = kml
        .split("<coordinates>")
        .nth(1)
        .and_then(|s| s.split("</coordinates>").next())
        .expect("coordinates");
    assert_eq!(inner.split_whitespace().count(), 4);
}

#[test]
fn pvt_and_channel_csv_columns() {
    let mut w = PvtCsvWriter::new(Vec::new(), "pvt.csv").expect("header");
    for f in &track() {
        w.write_fix(f).expect("in memory");
    }
    // A fix whose week is unknown: gps_week empty, the time of week kept.
    w.write_fix(&Fix {
        week_known: false,
        ..track()[0].clone()
    })
    .expect("in memory");
    let bytes = w.finish().expect("flush");
    let mut r = csv::Reader::from_reader(bytes.as_slice());
    let header: Vec<String> = r
        .headers()
        .expect("header")
        .iter()
        .map(str::to_string)
        .collect();
    let leading = "gps_week,tow_s,x_m,y_m,z_m,lat_deg,lon_deg,h_m,vx_mps,vy_mps,vz_mps,clock_bias_m,clock_drift_mps,n_sv,pdop,hdop,vdop,raim";
    assert_eq!(header[..18].join(","), leading);
    let rows: Vec<csv::StringRecord> = r.records().map(|x| x.expect("row")).collect();
    assert_eq!(rows.len(), 6);
    assert_eq!(&rows[0][0], "2190");
    assert_eq!(&rows[0][1], "538200.000");
    assert_eq!((&rows[5][0], &rows[5][1]), ("", "538200.000"));
    assert_eq!(&rows[0][17], "ok, passed", "quoted comma survives");
    assert_eq!(&rows[2][15], "", "NaN HDOP is an empty cell");
    let lat: f64 = rows[0][5].parse().expect("lat");
    assert!((lat - 48.1173).abs() < 1e-9);
    // The uncertainty and the UTC time at the end: week 2190, TOW 538200 s is 2022-01-01
    // 05:30:00 GPS time, 05:29:42 UTC (18 leap seconds); no UTC while the week is unknown.
    assert_eq!(header[20..].join(","), "sigma_e_m,sigma_n_m,sigma_u_m,utc");
    assert_eq!(
        (&rows[0][20], &rows[0][21], &rows[0][22]),
        ("0.800", "1.100", "2.300")
    );
    assert_eq!(&rows[0][23], "2022-01-01T05:29:42.000000Z");
    assert_eq!(&rows[5][23], "");

    let mut w = ChannelCsvWriter::new(Vec::new(), "channels.csv").expect("header");
    let row = ChannelRow {
        time: Some(GpsTime::new(2190, 541_800.0)),
        week_known: true,
        t_stream_s: 12.5,
        channel: 3,
        prn: 14,
        state: "tracking".to_string(),
        cn0_dbhz: Some(44.5),
        doppler_hz: Some(-1520.25),
        code_phase_chips: None,
        pll_lock_indicator: Some(0.98),
        code_lock: true,
        carrier_lock: true,
        bit_sync: true,
        frame_sync: false,
        predicted_offset_cycles: None,
    };
    w.write_row(&row).expect("in memory");
    // The week unknown (never a system-clock week), then the time not yet known at all.
    w.write_row(&ChannelRow {
        week_known: false,
        ..row.clone()
    })
    .expect("in memory");
    w.write_row(&ChannelRow {
        time: None,
        week_known: false,
        t_stream_s: 0.25,
        ..row.clone()
    })
    .expect("in memory");
    // An aided 2nd-order loop's predicted static phase offset.
    w.write_row(&ChannelRow {
        predicted_offset_cycles: Some(0.15672),
        ..row
    })
    .expect("in memory");
    let text = String::from_utf8(w.finish().expect("flush")).expect("UTF-8");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "gps_week,tow_s,channel,prn,state,cn0_dbhz,doppler_hz,code_phase_chips,pll_lock_indicator,code_lock,carrier_lock,bit_sync,frame_sync,t_stream_s,predicted_offset_cycles");
    assert_eq!(
        lines[1],
        "2190,541800.000,3,14,tracking,44.50,-1520.250,,0.980,1,1,1,0,12.500,"
    );
    assert_eq!(
        lines[2],
        ",541800.000,3,14,tracking,44.50,-1520.250,,0.980,1,1,1,0,12.500,"
    );
    assert_eq!(
        lines[3],
        ",,3,14,tracking,44.50,-1520.250,,0.980,1,1,1,0,0.250,"
    );
    assert_eq!(
        lines[4],
        "2190,541800.000,3,14,tracking,44.50,-1520.250,,0.980,1,1,1,0,12.500,0.1567"
    );
}

// ------------------------------------------------------------ RINEX observations via RTKLIB

/// True receiver position for the synthetic observations.
fn truth() -> Llh {
    Llh::from_degrees(48.1173, 11.516_666_7, 545.4)
}

/// Receiver clock offset at epoch `k` (100 us plus 20 ns/s drift), s.
fn rx_clock_s(k: u32) -> f64 {
    1e-4 + 2e-8 * f64::from(k)
}

/// Geometric range (with light time and Earth rotation), satellite clock offset (with
/// relativity and T_GD, as the L1 C/A user applies it) and range rate of `eph` seen from
/// `rx` at true reception time `t`.
fn forward(eph: &Ephemeris, rx: &Vector3<f64>, t: GpsTime) -> (f64, f64, f64, Vector3<f64>) {
    let mut tau = 0.075;
    let mut range = 0.0;
    let mut sv = eph.sv_state(t);
    let mut pos = sv.pos_m;
    for _ in 0..8 {
        sv = eph.sv_state(t.add_seconds(-tau));
        pos = rotate_for_earth_rotation(&sv.pos_m, tau);
        range = (pos - rx).norm();
        tau = range / SPEED_OF_LIGHT_MPS;
    }
    let los = (pos - rx) / range;
    let range_rate = sv.vel_mps.dot(&los);
    (
        range,
        sv.clock_bias_s,
        range_rate - SPEED_OF_LIGHT_MPS * sv.clock_drift_s_s,
        pos,
    )
}

/// Ten 1 s epochs from 2022-01-01 05:30:00 GPST, satellites above 10 degrees.
fn synthetic_epochs(nav: &NavData) -> Vec<ObsEpoch> {
    let rx = truth().to_ecef();
    let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
    let t0 = GpsTime::from_calendar(2022, 1, 1, 5, 30, 0.0);
    (0..10)
        .map(|k| {
            let t_true = t0.add_seconds(f64::from(k));
            let dt_r = rx_clock_s(k);
            let mut sats = Vec::new();
            for prn in nav.prns() {
                let Some(eph) = nav.select(prn, t_true) else {
                    continue;
                };
                let (range, dts, rate, pos) = forward(eph, &rx, t_true);
                let (_, el) = azimuth_elevation(&rx, &pos);
                if el.to_degrees() < 10.0 {
                    continue;
                }
                let p = range + SPEED_OF_LIGHT_MPS * (dt_r - dts);
                sats.push(SatObs {
                    prn,
                    pseudorange_m: Some(p),
                    carrier_cycles: Some(p / lambda),
                    doppler_hz: Some(-(rate + SPEED_OF_LIGHT_MPS * 2e-8) / lambda),
                    cn0_dbhz: Some(44.0),
                    loss_of_lock: k == 0,
                    half_cycle_ambiguous: false,
                });
            }
            ObsEpoch {
                // The receiver's time tag carries its clock error.
                time: t_true.add_seconds(dt_r),
                clock_offset_s: None,
                sats,
            }
        })
        .collect()
}

/// Runs `rnx2rtkp` single-point on `obs` with `nav` (atmosphere off on both sides: the
/// synthetic model has none), checks RTKLIB read all `n_obs` records without errors or
/// warnings, and returns (epochs solved, worst 3D error to the truth in m, RTKLIB's count of
/// navigation records as its trace prints it).
fn rtklib_spp(dir: &Path, obs: &Path, nav: &Path, tag: &str, n_obs: usize) -> (usize, f64, String) {
    let conf = dir.join("spp.conf");
    std::fs::write(
        &conf,
        "pos1-posmode       =single\npos1-navsys        =1\npos1-elmask        =10\n\
         pos1-ionoopt       =off\npos1-tropopt       =off\npos1-sateph       =brdc\n",
    )
    .expect("write conf");
    let pos_path = dir.join(format!("{tag}.pos"));
    let output = Command::new("rnx2rtkp")
        .arg("-k")
        .arg(&conf)
        .args(["-p", "0", "-sys", "G", "-e", "-x", "3", "-o"])
        .arg(&pos_path)
        .arg(obs)
        .arg(nav)
        .output()
        .expect("run rnx2rtkp");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "rnx2rtkp failed: {stderr}");
    // Trace level 3: levels 1-2 are RTKLIB's errors and warnings; `sortobs: nobs=N` counts the
    // observation records it read.
    let trace = std::fs::read_to_string(dir.join(format!("{tag}.pos.trace"))).unwrap_or_default();
    let complaints: Vec<&str> = trace
        .lines()
        .filter(|l| l.starts_with("1 ") || l.starts_with("2 "))
        .collect();
    assert!(
        complaints.is_empty(),
        "{tag}: RTKLIB errors/warnings: {complaints:?}"
    );
    assert!(
        trace.contains(&format!("sortobs: nobs={n_obs}")),
        "{tag}: RTKLIB did not read all {n_obs} observation records (trace level 3):\n{trace}"
    );

    let pos = std::fs::read_to_string(&pos_path).expect("rnx2rtkp wrote a solution file");
    let rx = truth().to_ecef();
    let mut n = 0;
    let mut worst: f64 = 0.0;
    for line in pos
        .lines()
        .filter(|l| !l.starts_with('%') && !l.trim().is_empty())
    {
        // Two time tokens (`week tow` or `date time`), then x, y, z, Q, ns, ...
        let tokens: Vec<&str> = line.split_whitespace().collect();
        let num = |k: usize| tokens.get(k).and_then(|t| t.parse::<f64>().ok());
        let (Some(x), Some(y), Some(z), Some(q), Some(ns)) =
            (num(2), num(3), num(4), num(5), num(6))
        else {
            panic!("{tag}: unexpected solution line `{line}`");
        };
        assert_eq!(q, 5.0, "{tag}: Q=5 (single) expected: `{line}`");
        let err = (Vector3::new(x, y, z) - rx).norm();
        println!(
            "{tag}: RTKLIB {} {}: ns {ns} error {err:.3} m",
            tokens[0], tokens[1]
        );
        worst = worst.max(err);
        n += 1;
    }
    println!("{tag}: RTKLIB read {n_obs} observation records without errors or warnings; {n} epochs solved, worst 3D error {worst:.3} m");
    let neph = trace
        .lines()
        .find_map(|l| l.split("uniqnav: ").nth(1))
        .unwrap_or("")
        .to_string();
    (n, worst, neph)
}

#[test]
fn rtklib_single_point_solution_from_our_rinex_files_is_on_the_truth() {
    let have_rtklib = Command::new("rnx2rtkp").arg("-?").output().is_ok();
    if !have_rtklib {
        if std::env::var("CI").as_deref() == Ok("true") {
            panic!("rnx2rtkp (RTKLIB) is required with CI=true");
        }
        println!("note: rnx2rtkp (RTKLIB) not installed; RINEX validation skipped");
        return;
    }
    let nav = brdc();
    let epochs = synthetic_epochs(&nav);
    let n_obs: usize = epochs.iter().map(|e| e.sats.len()).sum();
    let dir = tempfile::tempdir().expect("temp dir");
    let obs_path = dir.path().join("observables.rnx");
    let header = ObsHeader {
        interval_s: Some(1.0),
        leap_seconds: Some(18),
        comments: vec!["synthetic observations, gpsrx output test".to_string()],
        ..ObsHeader::default()
    };
    let mut w = RinexObsWriter::create(&obs_path, header).expect("create obs file");
    for e in &epochs {
        w.write_epoch(e).expect("write epoch");
    }
    assert_eq!(w.blanked_values(), 0);
    w.finish().expect("finish");

    // Our observation file with the IGS navigation file.
    let (n, worst, neph_igs) = rtklib_spp(dir.path(), &obs_path, &brdc_path(), "igs-nav", n_obs);
    assert_eq!(n, epochs.len(), "RTKLIB must solve every epoch");
    assert!(worst < 3.0, "RTKLIB position {worst:.3} m from the truth");

    // Both files ours: the RINEX 3.04 navigation file must give the same solution.
    let nav_path = dir.path().join("ephemeris.rnx");
    let header = NavHeader {
        iono: nav.iono,
        utc: nav.utc,
        leap_seconds: nav.leap_seconds,
        ..NavHeader::default()
    };
    let records: Vec<NavRecord> = nav
        .ephemerides
        .iter()
        .cloned()
        .map(NavRecord::from)
        .collect();
    write_rinex_nav_file(&nav_path, &header, &records).expect("write nav file");
    let (n, worst_ours, neph_ours) = rtklib_spp(dir.path(), &obs_path, &nav_path, "our-nav", n_obs);
    assert_eq!(
        n,
        epochs.len(),
        "RTKLIB must solve every epoch with our nav file"
    );
    println!("RTKLIB navigation records: IGS file `{neph_igs}`, ours `{neph_ours}`");
    assert!(!neph_ours.is_empty() && neph_ours == neph_igs);
    assert!(
        worst_ours < 3.0,
        "RTKLIB position {worst_ours:.3} m from the truth (our nav file)"
    );
}
