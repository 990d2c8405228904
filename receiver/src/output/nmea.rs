//! NMEA 0183 (version 2.3 fields) GGA, RMC, GSA, GSV, GST and ZDA sentences (`pvt.nmea`),
//! talker `GP`. Latitude and longitude carry 6 decimals of minutes (2 mm).
//!
//! Each sentence is `$<body>*hh\r\n` where `hh` is the XOR of every byte between `$` and `*`
//! as two upper-case hexadecimal digits. Times are UTC = GPS time - leap seconds
//! ([`NmeaOptions::leap_seconds`]; by default the count in effect at the fix's date, 18 s
//! since 2017-01-01, from the leap-second table). While the GPS week is unknown
//! ([`Fix::week_known`]) the RMC date is left empty.
//!
//! **Altitude.** GGA field 9 is the altitude above mean sea level (the geoid), H = h - N, and
//! field 11 the geoid separation N (the geoid's height above the WGS-84 ellipsoid), so
//! altitude + separation is the ellipsoidal height h. N comes from the EGM96 model at the
//! fix ([`gpsrx_nav::geoid::egm96_separation_m`], a 1-degree grid, within 0.5 m of the full
//! model), unless the caller gives [`NmeaOptions::geoid_separation_m`] (0 writes the
//! ellipsoidal height as the altitude).

use super::{calendar_rounded, create_file, Fix, FixQuality, OutputError};
use gpsrx_nav::{enu_rotation, GpsTime, Vector3};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Knots per metre per second (1 international nautical mile = 1852 m).
const KNOTS_PER_MPS: f64 = 3600.0 / 1852.0;
/// Satellites per GSV sentence.
const GSV_SATS_PER_SENTENCE: usize = 4;
/// GSV message numbers are one digit.
const GSV_MAX_SENTENCES: usize = 9;
/// GSA lists at most 12 PRNs.
const GSA_MAX_PRNS: usize = 12;

/// How sentences are formed.
/// The default: leap seconds from the table at each fix's date, EGM96 geoid separation.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NmeaOptions {
    /// GPS - UTC, s; `None`: the count in effect at each fix's date (18 since 2017-01-01).
    pub leap_seconds: Option<i32>,
    /// Geoid separation N at every fix, m, overriding the EGM96 model (`None`: EGM96 at each
    /// fix; `Some(0.0)`: the ellipsoidal height as the altitude).
    pub geoid_separation_m: Option<f64>,
}

/// `$body*hh\r\n` with the NMEA checksum.
pub fn sentence(body: &str) -> String {
    format!("${body}*{:02X}\r\n", checksum(body))
}

/// XOR of all bytes of `body` (the text between `$` and `*`).
pub fn checksum(body: &str) -> u8 {
    body.bytes().fold(0, |acc, b| acc ^ b)
}

/// `t` moved back by the leap seconds, `leap_seconds` or else the count in effect at `t`'s
/// date (a GPS time whose calendar fields read as UTC).
fn utc_of(t: GpsTime, leap_seconds: Option<i32>) -> GpsTime {
    let leap = leap_seconds.unwrap_or_else(|| {
        let (y, m, ..) = t.add_seconds(-18.0).to_calendar();
        gpsrx_nav::utc::leap_seconds_on(y, m)
    });
    t.add_seconds(-f64::from(leap))
}

/// UTC time `hhmmss.ss` and date `ddmmyy` of `t`, rounded to 0.01 s.
fn utc_fields(t: GpsTime, leap_seconds: Option<i32>) -> (String, String) {
    match calendar_rounded(utc_of(t, leap_seconds), 2) {
        Some(c) => (
            format!("{:02}{:02}{:02}.{:02}", c.hour, c.minute, c.second, c.frac),
            format!("{:02}{:02}{:02}", c.day, c.month, c.year.rem_euclid(100)),
        ),
        None => (String::new(), String::new()),
    }
}

/// Ticks of minutes of arc per minute: 6 decimals (1e-6 minute is 1.9 mm of latitude).
const MINUTE_TICKS: u64 = 1_000_000;

/// `ddmm.mmmmmm,N` / `dddmm.mmmmmm,E` for an angle in degrees (rounded on 1e-6 minute, so the
/// minutes never print as 60). Empty fields for a non-finite angle.
fn angle_fields(deg: f64, deg_digits: usize, pos: char, neg: char) -> String {
    if !deg.is_finite() || deg.abs() > 180.0 {
        return ",".to_string();
    }
    let hemi = if deg < 0.0 { neg } else { pos };
    let ticks = (deg.abs() * 60.0 * MINUTE_TICKS as f64).round() as u64;
    let whole_deg = ticks / (60 * MINUTE_TICKS);
    let min_ticks = ticks % (60 * MINUTE_TICKS);
    format!(
        "{whole_deg:0deg_digits$}{:02}.{:06},{hemi}",
        min_ticks / MINUTE_TICKS,
        min_ticks % MINUTE_TICKS
    )
}

fn position_valid(fix: &Fix) -> bool {
    fix.quality != FixQuality::None
        && fix.llh.lat_rad.is_finite()
        && fix.llh.lon_rad.is_finite()
        && fix.llh.h_m.is_finite()
}

fn lat_lon(fix: &Fix) -> String {
    if !position_valid(fix) {
        return ",,,".to_string();
    }
    format!(
        "{},{}",
        angle_fields(fix.llh.lat_rad.to_degrees(), 2, 'N', 'S'),
        angle_fields(fix.llh.lon_rad.to_degrees(), 3, 'E', 'W')
    )
}

fn opt_num(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        String::new()
    }
}

/// GGA: time, position, quality (1 GNSS or GNSS/DR fix, 6 dead reckoning only, 0 invalid), satellites used,
/// HDOP, altitude (see the module note), geoid separation.
pub fn gga(fix: &Fix, opts: &NmeaOptions) -> String {
    let (time, _) = utc_fields(fix.time, opts.leap_seconds);
    let quality = match fix.quality {
        FixQuality::Gnss | FixQuality::Fused => 1,
        FixQuality::DeadReckoning => 6,
        FixQuality::None => 0,
    };
    let n_sv = fix.n_sv.min(99);
    let (alt, sep) = if position_valid(fix) {
        let n = opts
            .geoid_separation_m
            .filter(|n| n.is_finite())
            .unwrap_or_else(|| {
                gpsrx_nav::geoid::egm96_separation_m(
                    fix.llh.lat_rad.to_degrees(),
                    fix.llh.lon_rad.to_degrees(),
                )
            });
        (opt_num(fix.llh.h_m - n, 3), opt_num(n, 3))
    } else {
        (String::new(), String::new())
    };
    sentence(&format!(
        "GPGGA,{time},{},{quality},{n_sv:02},{},{alt},M,{sep},M,,",
        lat_lon(fix),
        opt_num(fix.hdop, 1)
    ))
}

/// Speed over ground (knots) and course over ground (degrees true, [0, 360)) from the ECEF
/// velocity rotated to local East-North-Up; `None` without a finite velocity.
pub fn speed_course(fix: &Fix) -> Option<(f64, f64)> {
    let v = fix.vel_ecef_mps?;
    let enu = enu_rotation(&fix.llh) * Vector3::new(v[0], v[1], v[2]);
    let speed_mps = enu.x.hypot(enu.y);
    if !speed_mps.is_finite() {
        return None;
    }
    let mut course = enu.x.atan2(enu.y).to_degrees();
    if course < 0.0 {
        course += 360.0;
    }
    if course >= 359.95 {
        // Would print as 360.0.
        course = 0.0;
    }
    Some((speed_mps * KNOTS_PER_MPS, course))
}

/// RMC: time, status (A valid / V invalid), position, speed (knots), course (deg true), date,
/// magnetic variation (empty), mode (A autonomous, E estimated/dead reckoning, N invalid).
pub fn rmc(fix: &Fix, opts: &NmeaOptions) -> String {
    let (time, mut date) = utc_fields(fix.time, opts.leap_seconds);
    if !fix.week_known {
        // The time of day is known, the date is not (never one from the system clock).
        date.clear();
    }
    let valid = position_valid(fix);
    let (status, mode) = match fix.quality {
        _ if !valid => ('V', 'N'),
        FixQuality::Gnss | FixQuality::Fused => ('A', 'A'),
        FixQuality::DeadReckoning => ('A', 'E'),
        FixQuality::None => ('V', 'N'),
    };
    let (speed, course) = match speed_course(fix).filter(|_| valid) {
        Some((kn, deg)) => (format!("{kn:.2}"), format!("{deg:.1}")),
        None => (String::new(), String::new()),
    };
    sentence(&format!(
        "GPRMC,{time},{status},{},{speed},{course},{date},,,{mode}",
        lat_lon(fix)
    ))
}

/// GSA: automatic mode, fix type (1 none, 2 2D, 3 3D), up to 12 PRNs used, PDOP, HDOP, VDOP.
pub fn gsa(fix: &Fix) -> String {
    let fix_type = if !position_valid(fix) {
        1
    } else if fix.used_prns.len() == 3 {
        2
    } else {
        3
    };
    let mut prns: Vec<String> = fix
        .used_prns
        .iter()
        .take(GSA_MAX_PRNS)
        .map(|p| format!("{p:02}"))
        .collect();
    prns.resize(GSA_MAX_PRNS, String::new());
    sentence(&format!(
        "GPGSA,A,{fix_type},{},{},{},{}",
        prns.join(","),
        opt_num(fix.pdop, 1),
        opt_num(fix.hdop, 1),
        opt_num(fix.vdop, 1)
    ))
}

/// GSV: satellites in view, 4 per sentence (at most 9 sentences): PRN, elevation (deg,
/// 0-90), azimuth (deg true, 0-359), SNR (C/N0, dB-Hz, 0-99, empty when not tracked).
pub fn gsv(fix: &Fix) -> Vec<String> {
    let sats: Vec<_> = fix
        .sats_in_view
        .iter()
        .take(GSV_SATS_PER_SENTENCE * GSV_MAX_SENTENCES)
        .collect();
    let total = sats.len().div_ceil(GSV_SATS_PER_SENTENCE).max(1);
    (0..total)
        .map(|k| {
            let mut body = format!("GPGSV,{total},{},{:02}", k + 1, sats.len());
            for s in sats
                .iter()
                .skip(k * GSV_SATS_PER_SENTENCE)
                .take(GSV_SATS_PER_SENTENCE)
            {
                let el = if s.el_deg.is_finite() {
                    format!("{:02}", s.el_deg.round().clamp(0.0, 90.0) as u32)
                } else {
                    String::new()
                };
                let az = if s.az_deg.is_finite() {
                    format!("{:03}", (s.az_deg.round().rem_euclid(360.0) as u32) % 360)
                } else {
                    String::new()
                };
                let snr = s
                    .cn0_dbhz
                    .filter(|c| c.is_finite())
                    .map(|c| format!("{:02}", c.round().clamp(0.0, 99.0) as u32))
                    .unwrap_or_default();
                body.push_str(&format!(",{:02},{el},{az},{snr}", s.prn));
            }
            sentence(&body)
        })
        .collect()
}

/// GST: time, RMS of the pseudorange residuals (empty: not carried), the horizontal error
/// ellipse (semi-major, semi-minor, orientation of the major axis from true north; from the
/// east and north one-sigma uncertainties, the axes along them), and the one-sigma latitude,
/// longitude and altitude errors, m. Empty error fields when the fix has no uncertainty.
pub fn gst(fix: &Fix, opts: &NmeaOptions) -> String {
    let (time, _) = utc_fields(fix.time, opts.leap_seconds);
    let errors = match fix.sigma_enu_m.filter(|_| position_valid(fix)) {
        Some([e, n, u]) => {
            let (major, minor, orient) = if n >= e { (n, e, 0.0) } else { (e, n, 90.0) };
            format!(
                "{},{},{},{},{},{}",
                opt_num(major, 2),
                opt_num(minor, 2),
                opt_num(orient, 1),
                opt_num(n, 2),
                opt_num(e, 2),
                opt_num(u, 2)
            )
        }
        None => ",,,,,".to_string(),
    };
    sentence(&format!("GPGST,{time},,{errors}"))
}

/// ZDA: UTC time, day, month, year, local zone 00:00; the date fields are empty while the GPS
/// week is unknown.
pub fn zda(fix: &Fix, opts: &NmeaOptions) -> String {
    let (time, _) = utc_fields(fix.time, opts.leap_seconds);
    let date = match calendar_rounded(utc_of(fix.time, opts.leap_seconds), 2) {
        Some(c) if fix.week_known => format!("{:02},{:02},{:04}", c.day, c.month, c.year),
        _ => ",,".to_string(),
    };
    sentence(&format!("GPZDA,{time},{date},00,00"))
}

/// Streams GGA, RMC, GSA, GSV, GST and ZDA sentences for each fix.
#[derive(Debug)]
pub struct NmeaWriter<W: Write> {
    out: W,
    file: String,
    opts: NmeaOptions,
}

impl NmeaWriter<BufWriter<File>> {
    /// Creates the file at `path`.
    pub fn create(path: &Path, opts: NmeaOptions) -> Result<Self, OutputError> {
        Ok(NmeaWriter::new(
            create_file(path)?,
            path.display().to_string(),
            opts,
        ))
    }
}

impl<W: Write> NmeaWriter<W> {
    /// A writer to `out`; `file` names the destination in errors.
    pub fn new(out: W, file: impl Into<String>, opts: NmeaOptions) -> Self {
        NmeaWriter {
            out,
            file: file.into(),
            opts,
        }
    }

    /// Writes GGA, RMC, GSA, the GSV group, GST and ZDA of one fix.
    pub fn write_fix(&mut self, fix: &Fix) -> Result<(), OutputError> {
        let mut text = gga(fix, &self.opts);
        text.push_str(&rmc(fix, &self.opts));
        text.push_str(&gsa(fix));
        for s in gsv(fix) {
            text.push_str(&s);
        }
        text.push_str(&gst(fix, &self.opts));
        text.push_str(&zda(fix, &self.opts));
        self.out
            .write_all(text.as_bytes())
            .map_err(OutputError::io(&self.file))
    }

    /// Pushes what was written so far to the destination (a live stream, line by line).
    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.out.flush().map_err(OutputError::io(&self.file))
    }

    /// Flushes and returns the destination.
    pub fn finish(mut self) -> Result<W, OutputError> {
        self.out.flush().map_err(OutputError::io(&self.file))?;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_round_without_sixty_minutes() {
        assert_eq!(angle_fields(48.117_3, 2, 'N', 'S'), "4807.038000,N");
        assert_eq!(angle_fields(-11.516_666_7, 3, 'E', 'W'), "01131.000002,W");
        assert_eq!(angle_fields(9.999_999_999_99, 2, 'N', 'S'), "1000.000000,N");
        assert_eq!(angle_fields(f64::NAN, 2, 'N', 'S'), ",");
    }

    #[test]
    fn utc_takes_the_leap_seconds_of_the_date() {
        // 16 s until 2015-07-01, 17 until 2017-01-01, 18 since (IERS Bulletin C).
        for (year, want_second) in [(2015, 44.0), (2016, 43.0), (2022, 42.0)] {
            let t = GpsTime::from_calendar(year, 3, 1, 12, 0, 0.0);
            let (_, _, _, h, mi, sec) = utc_of(t, None).to_calendar();
            assert_eq!((h, mi), (11, 59), "{year}");
            assert!((sec - want_second).abs() < 1e-6, "{year}: {sec}");
        }
        let t = GpsTime::from_calendar(2022, 3, 1, 12, 0, 0.0);
        let (.., sec) = utc_of(t, Some(20)).to_calendar();
        assert!((sec - 40.0).abs() < 1e-6);
    }

    #[test]
    fn checksum_of_a_textbook_sentence() {
        // Widely published example GGA sentence; its checksum is 47.
        let body = "GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,";
        assert_eq!(checksum(body), 0x47);
    }

    #[test]
    fn gga_altitude_is_above_the_egm96_geoid() {
        use gpsrx_nav::Llh;
        // Munich, h = 545.4 m above the ellipsoid. EGM96 there: 45.51 m (GeographicLib's
        // egm96-5 grid, bilinear).
        let llh = Llh::from_degrees(48.1173, 11.516_666_7, 545.4);
        let e = llh.to_ecef();
        let fix = Fix {
            time: GpsTime::from_calendar(2022, 1, 1, 5, 30, 0.0),
            week_known: true,
            ecef_m: [e.x, e.y, e.z],
            llh,
            vel_ecef_mps: None,
            clock_bias_m: 0.0,
            clock_drift_mps: None,
            n_sv: 8,
            used_prns: Vec::new(),
            pdop: 1.8,
            hdop: 0.9,
            vdop: 1.5,
            raim: String::new(),
            quality: FixQuality::Gnss,
            sigma_enu_m: None,
            sats_in_view: Vec::new(),
        };
        let fields = |opts: &NmeaOptions| -> (f64, f64) {
            let s = gga(&fix, opts);
            let f: Vec<&str> = s.split(',').collect();
            let num = |i: usize| f[i].parse::<f64>().unwrap_or(f64::NAN);
            (num(9), num(11))
        };
        let (alt, sep) = fields(&NmeaOptions::default());
        assert!((sep - 45.51).abs() < 0.5, "N = {sep}");
        assert!((alt + sep - 545.4).abs() < 1e-3, "H + N = h: {alt} + {sep}");
        // The override: 0 writes the ellipsoidal height.
        let zero = NmeaOptions {
            geoid_separation_m: Some(0.0),
            ..NmeaOptions::default()
        };
        assert_eq!(fields(&zero), (545.4, 0.0));
    }
}
