//! Output files of the receiver: standard formats other tools read, and CSV logs.
//!
//! - [`rinex_obs`]: RINEX 3.04 GPS observation file (`observables.rnx`), streamed epoch by epoch;
//! - [`rinex_nav`]: RINEX 3.04 GPS navigation file (`ephemeris.rnx`);
//! - [`yuma`]: the decoded almanac as a YUMA file (`almanac.yuma`);
//! - [`nmea`]: NMEA 0183 GGA, RMC, GSA, GSV, GST and ZDA sentences (`pvt.nmea`);
//! - [`geojson`], [`kml`] and [`gpx`]: the track for maps (`track.geojson`, `track.kml`,
//!   `track.gpx`);
//! - [`plots`]: PNG plots of the run (`track.png`, `skyplot.png`, `cn0.png`, `dop.png`,
//!   `dr.png`) and the studies' line plots;
//! - [`pvt_csv`]: one row per fix (`pvt.csv`) and one row per channel and epoch
//!   (`channels.csv`).
//!
//! The writers take the small, format-neutral products of the pipeline ([`ObsEpoch`], [`Fix`],
//! [`ChannelRow`], defined with the sink in [`crate::pipeline::sink`] and re-exported here); the
//! pipeline converts its own types into them. Every writer takes any
//! [`std::io::Write`] plus the file name used in error messages, and reports failures as
//! [`OutputError`]. Bad values (NaN, out-of-range numbers) never panic: they are written as
//! empty fields where the format allows it and reported as errors where it does not.

pub mod file_sink;
pub mod geojson;
pub mod gpx;
pub mod kml;
pub mod nmea;
pub mod plots;
pub mod pvt_csv;
pub mod rinex_nav;
pub mod rinex_obs;
pub mod yuma;

use gpsrx_nav::GpsTime;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

pub use crate::pipeline::sink::{ChannelRow, Fix, FixQuality, ObsEpoch, SatObs, SatView};
pub use file_sink::FileSink;
pub use geojson::write_geojson;
pub use gpx::write_gpx;
pub use kml::write_kml;
pub use nmea::{NmeaOptions, NmeaWriter};
pub use pvt_csv::{ChannelCsvWriter, PvtCsvWriter};
pub use rinex_nav::{write_rinex_nav, NavHeader, NavRecord};
pub use rinex_obs::{ObsHeader, RinexObsWriter};

/// Why an output file could not be written. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Creating, writing or flushing the file failed.
    #[error("cannot write output file `{file}`: {source}; check the directory exists, is writable and the disk is not full")]
    Io {
        /// File being written.
        file: String,
        /// Underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The CSV writer failed (normally an I/O error underneath).
    #[error("cannot write CSV file `{file}`: {source}")]
    Csv {
        /// File being written.
        file: String,
        /// Underlying CSV error.
        #[source]
        source: csv::Error,
    },
    /// The JSON serialiser failed (normally an I/O error underneath).
    #[error("cannot write JSON file `{file}`: {source}")]
    Json {
        /// File being written.
        file: String,
        /// Underlying JSON error.
        #[source]
        source: serde_json::Error,
    },
    /// An input value the format cannot represent.
    #[error("`{file}`: {reason}")]
    InvalidInput {
        /// File being written.
        file: String,
        /// What was wrong, with the value.
        reason: String,
    },
    /// A file that needs at least one record was finished with none.
    #[error("`{file}`: no {what} to write, so the file would not be valid; nothing was written")]
    Empty {
        /// File being written.
        file: String,
        /// What was missing (`epochs`, `fixes`).
        what: &'static str,
    },
}

impl OutputError {
    pub(crate) fn io(file: &str) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
        move |source| OutputError::Io {
            file: file.to_string(),
            source,
        }
    }

    pub(crate) fn invalid(file: &str, reason: String) -> OutputError {
        OutputError::InvalidInput {
            file: file.to_string(),
            reason,
        }
    }
}

/// Creates (truncates) `path` for buffered writing; the error names the file.
pub fn create_file(path: &Path) -> Result<BufWriter<File>, OutputError> {
    File::create(path)
        .map(BufWriter::new)
        .map_err(OutputError::io(&path.display().to_string()))
}

/// A calendar date and time rounded to a number of decimals of the second, without ever
/// producing second 60 by rounding (the rounding is done on the time of week first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Calendar {
    pub year: i32,
    pub month: u32,
    pub day: u32,
    pub hour: u32,
    pub minute: u32,
    pub second: u32,
    /// Fraction of the second in units of 10^-decimals s.
    pub frac: u64,
}

/// Calendar of `t` in its own time scale, rounded to `decimals` (0-9) decimals of the second.
/// `None` for a non-finite or negative time of week.
pub(crate) fn calendar_rounded(t: GpsTime, decimals: u32) -> Option<Calendar> {
    const WEEK_S: u64 = 604_800;
    const DAY_S: u64 = 86_400;
    let scale = 10u64.checked_pow(decimals.min(9))?;
    let ticks_f = (t.tow_s * scale as f64).round();
    if !ticks_f.is_finite() || ticks_f < 0.0 || ticks_f > 2.0 * (WEEK_S * scale) as f64 {
        return None;
    }
    let mut ticks = ticks_f as u64;
    let mut week = t.week;
    while ticks >= WEEK_S * scale {
        ticks -= WEEK_S * scale;
        week = week.checked_add(1)?;
    }
    let day_in_week = ticks / (DAY_S * scale);
    let sod_ticks = ticks % (DAY_S * scale);
    let (year, month, day, _, _, _) =
        GpsTime::new(week, (day_in_week * DAY_S) as f64).to_calendar();
    let sod = sod_ticks / scale;
    Some(Calendar {
        year,
        month,
        day,
        hour: (sod / 3600) as u32,
        minute: ((sod % 3600) / 60) as u32,
        second: (sod % 60) as u32,
        frac: sod_ticks % scale,
    })
}

/// Current UTC date as `yyyymmdd hhmmss UTC`, the RINEX 3 `PGM / RUN BY / DATE` form.
pub(crate) fn rinex_creation_date_now() -> String {
    /// Seconds from 1970-01-01 to 1980-01-06.
    const UNIX_TO_GPS_EPOCH_S: u64 = 315_964_800;
    let unix_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    // Used purely as a calendar conversion (no leap seconds added), so the result is UTC.
    let t = GpsTime::new(0, unix_s.saturating_sub(UNIX_TO_GPS_EPOCH_S) as f64);
    match calendar_rounded(t, 0) {
        Some(c) => format!(
            "{:04}{:02}{:02} {:02}{:02}{:02} UTC",
            c.year, c.month, c.day, c.hour, c.minute, c.second
        ),
        None => String::new(),
    }
}

/// `text` made printable ASCII and fitted to exactly `width` columns (truncated or padded on
/// the right), for fixed-column formats.
pub(crate) fn fit_ascii(text: &str, width: usize) -> String {
    let mut s: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() || c == ' ' {
                c
            } else {
                '?'
            }
        })
        .take(width)
        .collect();
    while s.len() < width {
        s.push(' ');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calendar_rounding_never_gives_second_60() {
        let t = GpsTime::from_calendar(2022, 1, 1, 23, 59, 59.999_999_99);
        let c = calendar_rounded(t, 7).expect("finite time");
        assert_eq!(
            (c.year, c.month, c.day, c.hour, c.minute, c.second, c.frac),
            (2022, 1, 2, 0, 0, 0, 0)
        );
        let end_of_week = GpsTime::new(2190, 604_799.999_999_999);
        let c = calendar_rounded(end_of_week, 3).expect("finite time");
        assert_eq!((c.hour, c.minute, c.second, c.frac), (0, 0, 0, 0));
        assert_eq!(c.day, 2);
        assert!(calendar_rounded(
            GpsTime {
                week: 1,
                tow_s: f64::NAN
            },
            3
        )
        .is_none());
    }

    #[test]
    fn fit_ascii_pads_truncates_and_cleans() {
        assert_eq!(fit_ascii("ab", 4), "ab  ");
        assert_eq!(fit_ascii("abcdef", 4), "abcd");
        assert_eq!(fit_ascii("é\tx", 3), "??x");
    }
}
