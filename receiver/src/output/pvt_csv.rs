//! CSV logs: `pvt.csv` (one row per fix) and `channels.csv` (one row per channel and epoch).
//!
//! Missing or non-finite values are empty cells. The leading columns of `pvt.csv` are fixed
//! ([`PVT_COLUMNS`]); later columns may be added at the end, so read by name. `gps_week` is
//! empty while the week is unknown ([`crate::pipeline::WeekReference`]): never a week from the
//! system clock.

use super::{create_file, ChannelRow, Fix, OutputError};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Columns of `pvt.csv`: the fixed leading block, then `quality` and `used_prns`
/// (space-separated), the one-sigma uncertainty east, north and up (m, from the solution's
/// covariance) and the UTC time (ISO 8601, from the GPS time and the leap seconds; empty while
/// the week is unknown).
pub const PVT_COLUMNS: [&str; 24] = [
    "gps_week",
    "tow_s",
    "x_m",
    "y_m",
    "z_m",
    "lat_deg",
    "lon_deg",
    "h_m",
    "vx_mps",
    "vy_mps",
    "vz_mps",
    "clock_bias_m",
    "clock_drift_mps",
    "n_sv",
    "pdop",
    "hdop",
    "vdop",
    "raim",
    "quality",
    "used_prns",
    "sigma_e_m",
    "sigma_n_m",
    "sigma_u_m",
    "utc",
];

/// Columns of `channels.csv`. `gps_week` and `tow_s` are the receiver time of the row, empty
/// until it is known (the time of week from frame sync; the week is empty while unknown, see
/// [`crate::pipeline::WeekReference`]); `t_stream_s` is the time from the first sample, always given;
/// `predicted_offset_cycles` is the static phase offset an aided 2nd-order loop keeps under a
/// nominal INS accelerometer bias (empty unaided, or for other loop orders).
pub const CHANNEL_COLUMNS: [&str; 15] = [
    "gps_week",
    "tow_s",
    "channel",
    "prn",
    "state",
    "cn0_dbhz",
    "doppler_hz",
    "code_phase_chips",
    "pll_lock_indicator",
    "code_lock",
    "carrier_lock",
    "bit_sync",
    "frame_sync",
    "t_stream_s",
    "predicted_offset_cycles",
];

/// `v` with `decimals` decimals, or empty when not finite.
fn cell(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        String::new()
    }
}

/// The GPS week, or empty when it is not known (never a week from the system clock).
fn week_cell(week: u32, known: bool) -> String {
    if known {
        week.to_string()
    } else {
        String::new()
    }
}

fn opt_cell(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(String::new, |v| cell(v, decimals))
}

fn csv_err(file: &str) -> impl FnOnce(csv::Error) -> OutputError + '_ {
    move |source| OutputError::Csv {
        file: file.to_string(),
        source,
    }
}

/// Streaming `pvt.csv` writer; the header row is written by [`PvtCsvWriter::new`].
#[derive(Debug)]
pub struct PvtCsvWriter<W: Write> {
    out: csv::Writer<W>,
    file: String,
}

impl PvtCsvWriter<BufWriter<File>> {
    /// Creates the file at `path` and writes the header row.
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        PvtCsvWriter::new(create_file(path)?, path.display().to_string())
    }
}

impl<W: Write> PvtCsvWriter<W> {
    /// A writer to `out` (header row written now); `file` names it in errors.
    pub fn new(out: W, file: impl Into<String>) -> Result<Self, OutputError> {
        let file = file.into();
        let mut out = csv::Writer::from_writer(out);
        out.write_record(PVT_COLUMNS).map_err(csv_err(&file))?;
        Ok(PvtCsvWriter { out, file })
    }

    /// Writes one fix.
    pub fn write_fix(&mut self, fix: &Fix) -> Result<(), OutputError> {
        let vel = fix.vel_ecef_mps;
        let prns: Vec<String> = fix.used_prns.iter().map(u8::to_string).collect();
        let row = [
            week_cell(fix.time.week, fix.week_known),
            cell(fix.time.tow_s, 3),
            cell(fix.ecef_m[0], 3),
            cell(fix.ecef_m[1], 3),
            cell(fix.ecef_m[2], 3),
            cell(fix.llh.lat_rad.to_degrees(), 9),
            cell(fix.llh.lon_rad.to_degrees(), 9),
            cell(fix.llh.h_m, 3),
            opt_cell(vel.map(|v| v[0]), 3),
            opt_cell(vel.map(|v| v[1]), 3),
            opt_cell(vel.map(|v| v[2]), 3),
            cell(fix.clock_bias_m, 3),
            opt_cell(fix.clock_drift_mps, 3),
            fix.n_sv.to_string(),
            cell(fix.pdop, 2),
            cell(fix.hdop, 2),
            cell(fix.vdop, 2),
            fix.raim.clone(),
            fix.quality.name().to_string(),
            prns.join(" "),
            opt_cell(fix.sigma_enu_m.map(|s| s[0]), 3),
            opt_cell(fix.sigma_enu_m.map(|s| s[1]), 3),
            opt_cell(fix.sigma_enu_m.map(|s| s[2]), 3),
            if fix.week_known {
                gpsrx_samples::sigmf::format_datetime_utc(fix.time)
            } else {
                String::new()
            },
        ];
        self.out.write_record(&row).map_err(csv_err(&self.file))
    }

    /// Pushes the rows written so far to the destination.
    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.out.flush().map_err(OutputError::io(&self.file))
    }

    /// Flushes and returns the destination.
    pub fn finish(self) -> Result<W, OutputError> {
        let file = self.file;
        self.out.into_inner().map_err(|e| OutputError::Io {
            file,
            source: e.into_error(),
        })
    }
}

/// Streaming `channels.csv` writer; the header row is written by [`ChannelCsvWriter::new`].
#[derive(Debug)]
pub struct ChannelCsvWriter<W: Write> {
    out: csv::Writer<W>,
    file: String,
}

impl ChannelCsvWriter<BufWriter<File>> {
    /// Creates the file at `path` and writes the header row.
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        ChannelCsvWriter::new(create_file(path)?, path.display().to_string())
    }
}

impl<W: Write> ChannelCsvWriter<W> {
    /// A writer to `out` (header row written now); `file` names it in errors.
    pub fn new(out: W, file: impl Into<String>) -> Result<Self, OutputError> {
        let file = file.into();
        let mut out = csv::Writer::from_writer(out);
        out.write_record(CHANNEL_COLUMNS).map_err(csv_err(&file))?;
        Ok(ChannelCsvWriter { out, file })
    }

    /// Writes one channel row.
    pub fn write_row(&mut self, row: &ChannelRow) -> Result<(), OutputError> {
        let flag = |b: bool| u8::from(b).to_string();
        let record = [
            row.time
                .map_or_else(String::new, |t| week_cell(t.week, row.week_known)),
            row.time.map_or_else(String::new, |t| cell(t.tow_s, 3)),
            row.channel.to_string(),
            row.prn.to_string(),
            row.state.clone(),
            opt_cell(row.cn0_dbhz, 2),
            opt_cell(row.doppler_hz, 3),
            opt_cell(row.code_phase_chips, 4),
            opt_cell(row.pll_lock_indicator, 3),
            flag(row.code_lock),
            flag(row.carrier_lock),
            flag(row.bit_sync),
            flag(row.frame_sync),
            cell(row.t_stream_s, 3),
            opt_cell(row.predicted_offset_cycles, 4),
        ];
        self.out.write_record(&record).map_err(csv_err(&self.file))
    }

    /// Pushes the rows written so far to the destination.
    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.out.flush().map_err(OutputError::io(&self.file))
    }

    /// Flushes and returns the destination.
    pub fn finish(self) -> Result<W, OutputError> {
        let file = self.file;
        self.out.into_inner().map_err(|e| OutputError::Io {
            file,
            source: e.into_error(),
        })
    }
}
