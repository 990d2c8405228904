//! RINEX navigation header: version/type, broadcast ionosphere, GPS-UTC and leap seconds.
//! Labels: RINEX 2.11 Table A3 (`ION ALPHA`, `ION BETA`, `DELTA-UTC: A0,A1,T,W`,
//! `LEAP SECONDS`) and RINEX 3.0x Table A5 (`IONOSPHERIC CORR` GPSA/GPSB,
//! `TIME SYSTEM CORR` GPUT, `LEAP SECONDS`).

use super::fields::{column, float, int, label};
use super::RinexError;
use crate::atmosphere::KlobucharParams;
use crate::utc::UtcParams;

/// RINEX major version handled by the reader.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Major {
    /// RINEX 2.x (GPS navigation file, type `N`).
    V2,
    /// RINEX 3.x (type `N`, system `G` or `M`).
    V3,
}

/// What the header says.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Header {
    pub major: Major,
    pub version: f64,
    pub iono: Option<KlobucharParams>,
    pub utc: Option<UtcParams>,
    pub leap_seconds: Option<i32>,
    /// Index (0-based) of the first line after `END OF HEADER`.
    pub body_start: usize,
}

/// Leap-second line contents (RINEX 3 adds the future/past event).
#[derive(Debug, Clone, Copy)]
struct Leap {
    dt_ls_s: i32,
    dt_lsf_s: Option<i32>,
    wn_lsf: Option<u32>,
    dn: Option<u32>,
}

fn to_i32(v: i64, line: usize, field: &'static str) -> Result<i32, RinexError> {
    i32::try_from(v).map_err(|_| RinexError::OutOfRange {
        line,
        field,
        value: v as f64,
        allowed: "a 32-bit integer",
    })
}

fn to_u32(v: i64, line: usize, field: &'static str) -> Result<u32, RinexError> {
    u32::try_from(v).map_err(|_| RinexError::OutOfRange {
        line,
        field,
        value: v as f64,
        allowed: "a non-negative integer",
    })
}

/// Parses the header from `lines` (whole file).
pub(crate) fn parse_header(lines: &[&str]) -> Result<Header, RinexError> {
    let first = lines.first().ok_or(RinexError::NotRinex)?;
    if label(first) != "RINEX VERSION / TYPE" {
        return Err(RinexError::NotRinex);
    }
    let version_text = column(first, 1, 0, 9, "RINEX version")?;
    let version = super::fields::parse_fortran_f64(version_text).ok_or_else(|| {
        RinexError::UnsupportedVersion {
            line: 1,
            version: version_text.to_string(),
        }
    })?;
    let major = if (2.0..3.0).contains(&version) {
        Major::V2
    } else if (3.0..4.0).contains(&version) {
        Major::V3
    } else {
        return Err(RinexError::UnsupportedVersion {
            line: 1,
            version: version_text.to_string(),
        });
    };
    let file_type = column(first, 1, 20, 1, "file type")?;
    let system = column(first, 1, 40, 1, "satellite system")?;
    let is_gps = match major {
        Major::V2 => file_type == "N",
        Major::V3 => file_type == "N" && (system == "G" || system == "M" || system.is_empty()),
    };
    if !is_gps {
        return Err(RinexError::NotGpsNav {
            line: 1,
            found: format!("type `{file_type}`, system `{system}`"),
        });
    }

    let mut alpha: Option<[f64; 4]> = None;
    let mut beta: Option<[f64; 4]> = None;
    let mut utc_poly: Option<(f64, f64, u32, u32)> = None;
    let mut leap: Option<Leap> = None;
    for (idx, line) in lines.iter().enumerate().skip(1) {
        let n = idx + 1;
        match label(line) {
            "END OF HEADER" => {
                let leap_seconds = leap.map(|l| l.dt_ls_s);
                let utc = utc_poly.map(|(a0_s, a1_s_s, tot_s, wnt)| {
                    let l = leap.unwrap_or(Leap {
                        dt_ls_s: 0,
                        dt_lsf_s: None,
                        wn_lsf: None,
                        dn: None,
                    });
                    UtcParams {
                        a0_s,
                        a1_s_s,
                        tot_s,
                        wnt,
                        dt_ls_s: l.dt_ls_s,
                        // RINEX 2 has no leap-second event: describe a past event with no
                        // change (WN_LSF = WN_t, DN = 1, Delta t_LSF = Delta t_LS), which the
                        // ICD's UTC algorithm treats as "no leap second pending".
                        wn_lsf: l.wn_lsf.unwrap_or(wnt),
                        dn: l.dn.unwrap_or(1),
                        dt_lsf_s: l.dt_lsf_s.unwrap_or(l.dt_ls_s),
                    }
                });
                let iono = match (alpha, beta) {
                    (Some(alpha), Some(beta)) => Some(KlobucharParams { alpha, beta }),
                    _ => None,
                };
                return Ok(Header {
                    major,
                    version,
                    iono,
                    utc,
                    leap_seconds,
                    body_start: idx + 1,
                });
            }
            // RINEX 2: (2X,4D12.4)
            "ION ALPHA" if major == Major::V2 => alpha = Some(four(line, n, 2, 12, "ION ALPHA")?),
            "ION BETA" if major == Major::V2 => beta = Some(four(line, n, 2, 12, "ION BETA")?),
            // RINEX 2: (3X,2D19.12,2I9)
            "DELTA-UTC: A0,A1,T,W" if major == Major::V2 => {
                let a0 = float(line, n, 3, 19, "DELTA-UTC A0")?;
                let a1 = float(line, n, 22, 19, "DELTA-UTC A1")?;
                let t = int(line, n, 41, 9, "DELTA-UTC T")?.unwrap_or(0);
                let w = int(line, n, 50, 9, "DELTA-UTC W")?.unwrap_or(0);
                utc_poly = Some((
                    a0,
                    a1,
                    to_u32(t, n, "DELTA-UTC T")?,
                    to_u32(w, n, "DELTA-UTC W")?,
                ));
            }
            // RINEX 3: (A4,1X,4D12.4)
            "IONOSPHERIC CORR" => match column(line, n, 0, 4, "correction type")? {
                "GPSA" => alpha = Some(four(line, n, 5, 12, "IONOSPHERIC CORR GPSA")?),
                "GPSB" => beta = Some(four(line, n, 5, 12, "IONOSPHERIC CORR GPSB")?),
                _ => {}
            },
            // RINEX 3: (A4,1X,D17.10,D16.9,I7,I5)
            "TIME SYSTEM CORR" if column(line, n, 0, 4, "correction type")? == "GPUT" => {
                let a0 = float(line, n, 5, 17, "GPUT a0")?;
                let a1 = float(line, n, 22, 16, "GPUT a1")?;
                let t = int(line, n, 38, 7, "GPUT T")?.unwrap_or(0);
                let w = int(line, n, 45, 5, "GPUT W")?.unwrap_or(0);
                utc_poly = Some((a0, a1, to_u32(t, n, "GPUT T")?, to_u32(w, n, "GPUT W")?));
            }
            // RINEX 2: (I6); RINEX 3: (4I6) Delta t_LS, Delta t_LSF, WN_LSF, DN.
            "LEAP SECONDS" => {
                let dt_ls = int(line, n, 0, 6, "LEAP SECONDS")?.unwrap_or(0);
                let (dt_lsf, wn_lsf, dn) = if major == Major::V3 {
                    (
                        int(line, n, 6, 6, "future leap seconds")?,
                        int(line, n, 12, 6, "leap-second week")?,
                        int(line, n, 18, 6, "leap-second day")?,
                    )
                } else {
                    (None, None, None)
                };
                leap = Some(Leap {
                    dt_ls_s: to_i32(dt_ls, n, "LEAP SECONDS")?,
                    dt_lsf_s: dt_lsf
                        .map(|v| to_i32(v, n, "future leap seconds"))
                        .transpose()?,
                    wn_lsf: wn_lsf
                        .map(|v| to_u32(v, n, "leap-second week"))
                        .transpose()?,
                    dn: dn.map(|v| to_u32(v, n, "leap-second day")).transpose()?,
                });
            }
            _ => {}
        }
    }
    Err(RinexError::MissingHeaderEnd { line: lines.len() })
}

fn four(
    line: &str,
    n: usize,
    start: usize,
    width: usize,
    field: &'static str,
) -> Result<[f64; 4], RinexError> {
    let mut out = [0.0; 4];
    for (k, v) in out.iter_mut().enumerate() {
        *v = float(line, n, start + k * width, width, field)?;
    }
    Ok(out)
}
