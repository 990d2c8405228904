//! RINEX 2.x and 3.x GPS broadcast navigation files (RINEX 2.11 and 3.05 format
//! descriptions). Non-GPS records of mixed RINEX 3 files are skipped and counted.

mod error;
mod fields;
mod header;
mod record;

pub use error::RinexError;

use crate::atmosphere::KlobucharParams;
use crate::ephemeris::{select_ephemeris, Ephemeris, HealthPolicy};
use crate::time::GpsTime;
use crate::utc::UtcParams;
use header::Major;
use std::collections::BTreeMap;
use std::path::Path;

/// GPS broadcast data of one navigation file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NavData {
    /// GPS ephemerides in file order.
    pub ephemerides: Vec<Ephemeris>,
    /// Klobuchar coefficients (`ION ALPHA`/`ION BETA` or `IONOSPHERIC CORR` GPSA/GPSB).
    pub iono: Option<KlobucharParams>,
    /// GPS-UTC parameters (`DELTA-UTC` or `TIME SYSTEM CORR` GPUT, with `LEAP SECONDS`).
    pub utc: Option<UtcParams>,
    /// Current leap seconds GPS - UTC (`LEAP SECONDS`).
    pub leap_seconds: Option<i32>,
}

/// Parse result with the bookkeeping a caller may want to log.
#[derive(Debug, Clone, PartialEq)]
pub struct RinexNavReport {
    /// The GPS data.
    pub nav: NavData,
    /// RINEX version from the header (e.g. 2.11, 3.04).
    pub version: f64,
    /// Non-GPS records skipped, by RINEX system letter.
    pub skipped_records: BTreeMap<char, usize>,
}

pub use crate::ephemeris::MAX_EPHEMERIS_AGE_S;

impl NavData {
    /// The healthy (`sv_health == 0`) ephemeris of `prn` whose toe is nearest to `t`, provided
    /// |t - toe| <= 4 h, or half the curve-fit interval when that is longer (fit interval
    /// flag set, IS-GPS-200 20.3.4.4). Ties go to the first in file order.
    /// [`select_ephemeris`] with [`HealthPolicy::HealthyOnly`].
    pub fn select(&self, prn: u8, t: GpsTime) -> Option<&Ephemeris> {
        self.select_with(prn, t, HealthPolicy::HealthyOnly)
    }

    /// [`select_ephemeris`] over this file's ephemerides with the given health policy.
    pub fn select_with(&self, prn: u8, t: GpsTime, health: HealthPolicy) -> Option<&Ephemeris> {
        select_ephemeris(&self.ephemerides, prn, t, health)
    }

    /// PRNs that have at least one ephemeris, ascending.
    pub fn prns(&self) -> Vec<u8> {
        let mut prns: Vec<u8> = self.ephemerides.iter().map(|e| e.prn).collect();
        prns.sort_unstable();
        prns.dedup();
        prns
    }
}

/// Reads a RINEX 2.x or 3.x GPS (or mixed) navigation file. Errors name the file and line.
pub fn read_rinex_nav(path: &Path) -> Result<NavData, RinexError> {
    read_rinex_nav_report(path).map(|r| r.nav)
}

/// Like [`read_rinex_nav`], also returning the version and the skipped-record counts.
pub fn read_rinex_nav_report(path: &Path) -> Result<RinexNavReport, RinexError> {
    let bytes = std::fs::read(path).map_err(|source| RinexError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = String::from_utf8_lossy(&bytes);
    parse_rinex_nav_report(&text).map_err(|e| RinexError::InFile {
        path: path.to_path_buf(),
        source: Box::new(e),
    })
}

/// Parses the text of a RINEX 2.x or 3.x GPS (or mixed) navigation file. Fortran `D`
/// exponents are accepted. Errors carry the 1-based line number.
pub fn parse_rinex_nav(text: &str) -> Result<NavData, RinexError> {
    parse_rinex_nav_report(text).map(|r| r.nav)
}

/// Like [`parse_rinex_nav`], also returning the version and the skipped-record counts.
pub fn parse_rinex_nav_report(text: &str) -> Result<RinexNavReport, RinexError> {
    let lines: Vec<&str> = text.lines().collect();
    let header = header::parse_header(&lines)?;
    let mut nav = NavData {
        ephemerides: Vec::new(),
        iono: header.iono,
        utc: header.utc,
        leap_seconds: header.leap_seconds,
    };
    let mut skipped_records = BTreeMap::new();
    let mut i = header.body_start;
    while i < lines.len() {
        let line = lines[i];
        if line.trim().is_empty() {
            i += 1;
            continue;
        }
        let (n_lines, system) = match header.major {
            Major::V2 => (8, 'G'),
            Major::V3 => {
                let system = line.chars().next().unwrap_or(' ');
                let n = record::record_lines_v3(system).ok_or(RinexError::UnknownSystem {
                    line: i + 1,
                    system,
                })?;
                (n, system)
            }
        };
        let available = lines.len() - i;
        if available < n_lines {
            return Err(RinexError::TruncatedRecord {
                line: lines.len(),
                start_line: i + 1,
                sat: line.get(0..3).unwrap_or(line).trim().to_string(),
                expected: n_lines,
                found: available,
            });
        }
        if system == 'G' {
            let eph = record::parse_gps_record(&lines[i..i + n_lines], i + 1, header.major)?;
            nav.ephemerides.push(eph);
        } else {
            *skipped_records.entry(system).or_insert(0) += 1;
        }
        i += n_lines;
    }
    Ok(RinexNavReport {
        nav,
        version: header.version,
        skipped_records,
    })
}
