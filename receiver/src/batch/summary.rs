//! The summary table of a batch: one row per recording or snapshot set, with its outcome.

use crate::pipeline::RunSummary;
use crate::snapshot::{SetResult, SnapshotQuality};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// How a recording ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Processed, with at least one valid fix (a snapshot set: one row of quality `fix`).
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
    /// What the entry is: `recording` or `snapshots`.
    pub kind: String,
    /// Snapshots in a set (0 for a recording).
    pub snapshots: usize,
    /// Median horizontal error of a set's fixes against its truth, m (NaN: not scored).
    pub h_error_median_m: f64,
    /// 95th percentile of the same, m (NaN: not scored).
    pub h_error_p95_m: f64,
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
            kind: KIND_RECORDING.into(),
            snapshots: 0,
            h_error_median_m: f64::NAN,
            h_error_p95_m: f64::NAN,
        }
    }

    /// The row of a positioned snapshot set: `fixes` counts the rows of quality `fix`,
    /// `invalid_fixes` those `unverified`; the means are over the `fix` rows; the duration is
    /// the seconds of samples.
    pub fn snapshot_set(name: &str, path: &str, r: &SetResult) -> Self {
        let fixes: Vec<_> = r
            .outcomes
            .iter()
            .filter(|o| o.quality == SnapshotQuality::Fix)
            .collect();
        let mean = |f: &dyn Fn(&crate::snapshot::SnapshotOutcome) -> Option<f64>| {
            let v: Vec<f64> = fixes.iter().filter_map(|o| f(o)).collect();
            if v.is_empty() {
                f64::NAN
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        };
        let mut prns: Vec<u8> = fixes.iter().flat_map(|o| o.used_prns.clone()).collect();
        prns.sort_unstable();
        prns.dedup();
        let without = r.score.snapshots - r.score.fixes - r.score.unverified;
        let mut message = format!(
            "{without} of {} snapshots without a position",
            r.score.snapshots
        );
        if r.scored {
            message = format!(
                "horizontal error median {:.1} m, 95th percentile {:.1} m; {message}",
                r.score.median_m, r.score.p95_m
            );
        }
        Self {
            name: name.to_string(),
            path: path.to_string(),
            status: if fixes.is_empty() {
                Status::NoFix
            } else {
                Status::Ok
            },
            message,
            duration_s: r.signal_s,
            wall_s: r.elapsed_s,
            fixes: fixes.len(),
            invalid_fixes: r.score.unverified,
            tracked_prns: prns.iter().map(u8::to_string).collect::<Vec<_>>().join(" "),
            first_fix_s: f64::NAN,
            mean_lat_deg: mean(&|o| o.llh.map(|l| l.lat_rad.to_degrees())),
            mean_lon_deg: mean(&|o| o.llh.map(|l| l.lon_rad.to_degrees())),
            mean_h_m: mean(&|o| o.llh.map(|l| l.h_m)),
            mean_pdop: mean(&|o| o.pdop),
            kind: KIND_SNAPSHOTS.into(),
            snapshots: r.score.snapshots,
            h_error_median_m: if r.scored { r.score.median_m } else { f64::NAN },
            h_error_p95_m: if r.scored { r.score.p95_m } else { f64::NAN },
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

    /// The row of a snapshot set that failed with `message`.
    pub fn failed_set(name: &str, path: &str, message: String) -> Self {
        Self {
            kind: KIND_SNAPSHOTS.into(),
            ..Self::failed(name, path, message)
        }
    }
}

/// [`BatchRow::kind`] of a recording.
pub const KIND_RECORDING: &str = "recording";
/// [`BatchRow::kind`] of a snapshot set.
pub const KIND_SNAPSHOTS: &str = "snapshots";

/// The CSV columns, in order (later ones are added at the end: read by name).
pub const COLUMNS: [&str; 18] = [
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
    "kind",
    "snapshots",
    "h_error_median_m",
    "h_error_p95_m",
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
            r.kind.clone(),
            r.snapshots.to_string(),
            num(r.h_error_median_m, 2),
            num(r.h_error_p95_m, 2),
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
        let text = if r.status == Status::Error || r.kind == KIND_SNAPSHOTS {
            r.message.clone()
        } else {
            r.tracked_prns.clone()
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
    for (kind, what) in [
        (KIND_RECORDING, "recordings"),
        (KIND_SNAPSHOTS, "snapshot sets"),
    ] {
        let of_kind: Vec<_> = rows.iter().filter(|r| r.kind == kind).collect();
        if of_kind.is_empty() {
            continue;
        }
        let ok = of_kind.iter().filter(|r| r.status == Status::Ok).count();
        let failed = of_kind.iter().filter(|r| r.status == Status::Error).count();
        writeln!(
            out,
            "{} {what}: {ok} with fixes, {} without a fix, {failed} failed",
            of_kind.len(),
            of_kind.len() - ok - failed
        )?;
    }
    Ok(())
}
