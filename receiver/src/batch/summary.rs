//! The summary table of a batch: one row per recording, with its outcome.

use crate::pipeline::RunSummary;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// How a recording ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Processed, with at least one valid fix.
    Ok,
    /// Processed to the end without a valid fix.
    NoFix,
    /// Not processed: the error says why.
    Error,
}

impl Status {
    /// The name in the table.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::NoFix => "no_fix",
            Status::Error => "error",
        }
    }
}

/// One row of the summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BatchRow {
    /// The recording's name.
    pub name: String,
    /// The recording.
    pub path: String,
    /// How it ended.
    pub status: Status,
    /// The error (status `error`), or the source's warnings; empty if none.
    pub message: String,
    /// Seconds of signal processed.
    pub duration_s: f64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Valid fixes.
    pub fixes: usize,
    /// Solutions flagged by RAIM.
    pub invalid_fixes: usize,
    /// Satellites tracked, ascending, space-separated.
    pub tracked_prns: String,
    /// Stream time of the first fix, s (NaN: none).
    pub first_fix_s: f64,
    /// Mean latitude of the fixes, degrees (NaN: none).
    pub mean_lat_deg: f64,
    /// Mean longitude, degrees (NaN: none).
    pub mean_lon_deg: f64,
    /// Mean ellipsoidal height, m (NaN: none).
    pub mean_h_m: f64,
    /// Mean PDOP (NaN: none).
    pub mean_pdop: f64,
}

impl BatchRow {
    /// The row of a processed recording.
    pub fn done(name: &str, path: &str, s: &RunSummary, warnings: &[String]) -> Self {
        let (lat, lon, h) = s.mean_llh.unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        Self {
            name: name.to_string(),
            path: path.to_string(),
            status: if s.fixes > 0 {
                Status::Ok
            } else {
                Status::NoFix
            },
            message: warnings.join("; "),
            duration_s: s.duration_s,
            wall_s: s.wall_s,
            fixes: s.fixes,
            invalid_fixes: s.invalid_fixes,
            tracked_prns: s
                .tracked_prns
                .iter()
                .map(u8::to_string)
                .collect::<Vec<_>>()
                .join(" "),
            first_fix_s: s.first_fix_s.unwrap_or(f64::NAN),
            mean_lat_deg: lat,
            mean_lon_deg: lon,
            mean_h_m: h,
            mean_pdop: s.mean_pdop.unwrap_or(f64::NAN),
        }
    }

    /// The row of a recording that failed with `message`.
    pub fn failed(name: &str, path: &str, message: String) -> Self {
        Self {
            status: Status::Error,
            message,
            ..Self::done(name, path, &RunSummary::default(), &[])
        }
    }
}

/// The CSV columns, in order.
pub const COLUMNS: [&str; 14] = [
    "name",
    "path",
    "status",
    "message",
    "duration_s",
    "wall_s",
    "fixes",
    "invalid_fixes",
    "tracked_prns",
    "first_fix_s",
    "mean_lat_deg",
    "mean_lon_deg",
    "mean_h_m",
    "mean_pdop",
];

/// Writes the summary as CSV (NaN as an empty cell).
pub fn write_summary_csv(path: &Path, rows: &[BatchRow]) -> std::io::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    w.write_record(COLUMNS)?;
    let num = |v: f64, digits: usize| {
        if v.is_finite() {
            format!("{v:.digits$}")
        } else {
            String::new()
        }
    };
    for r in rows {
        w.write_record([
            r.name.clone(),
            r.path.clone(),
            r.status.name().to_string(),
            r.message.clone(),
            num(r.duration_s, 3),
            num(r.wall_s, 3),
            r.fixes.to_string(),
            r.invalid_fixes.to_string(),
            r.tracked_prns.clone(),
            num(r.first_fix_s, 3),
            num(r.mean_lat_deg, 8),
            num(r.mean_lon_deg, 8),
            num(r.mean_h_m, 3),
            num(r.mean_pdop, 3),
        ])?;
    }
    w.flush()
}

/// The summary for people: one line per recording, the error in full.
pub fn print_summary(out: &mut dyn Write, rows: &[BatchRow]) -> std::io::Result<()> {
    writeln!(
        out,
        "{:<20} {:<7} {:>8} {:>7} {:>6} {:>9} {:>9}  satellites / message",
        "recording", "status", "signal_s", "wall_s", "fixes", "1st_fix_s", "mean_pdop"
    )?;
    for r in rows {
        let text = match r.status {
            Status::Error => r.message.clone(),
            _ => r.tracked_prns.clone(),
        };
        writeln!(
            out,
            "{:<20} {:<7} {:>8.1} {:>7.1} {:>6} {:>9.2} {:>9.2}  {text}",
            r.name,
            r.status.name(),
            r.duration_s,
            r.wall_s,
            r.fixes,
            r.first_fix_s,
            r.mean_pdop
        )?;
    }
    let ok = rows.iter().filter(|r| r.status == Status::Ok).count();
    let failed = rows.iter().filter(|r| r.status == Status::Error).count();
    writeln!(
        out,
        "{} recordings: {ok} with fixes, {} without a fix, {failed} failed",
        rows.len(),
        rows.len() - ok - failed
    )
}
