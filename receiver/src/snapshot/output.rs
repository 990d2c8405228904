//! Outputs of a snapshot run: `snapshots.csv` (one row per input snapshot, in input order),
//! the GeoJSON, KML and GPX tracks of the positions ([`crate::output`]), and the horizontal errors
//! against a truth (a SnapperGPS truth file matched by UTC second, or one static reference).

use super::driver::SnapshotOutcome;
use super::snappergps::{utc_seconds_of_day, TruthPoint};
use super::{SnapshotError, SnapshotQuality};
use crate::output::{
    create_file, geojson::write_geojson, gpx::write_gpx, kml::write_kml, Fix, FixQuality,
    OutputError,
};
use gpsrx_core::frames::enu_rotation;
use gpsrx_nav::utc::utc_from_gps;
use gpsrx_nav::{Llh, Vector3};
use std::io::Write;
use std::path::Path;

/// Header of `snapshots.csv`.
pub const CSV_HEADER: &str = "index,label,time_utc,gps_week,tow_s,lat_deg,lon_deg,h_m,n_sv,\
hdop,pdop,quality,reason,residual_rms_m,time_correction_s,clock_bias_m,fe_offset_hz,searched,\
detected,used_prns,excluded_prns,rejected_prns,h_error_m";

fn opt(v: Option<f64>, digits: usize) -> String {
    v.filter(|x| x.is_finite())
        .map_or_else(String::new, |x| format!("{x:.digits$}"))
}

fn prns(p: &[u8]) -> String {
    p.iter().map(u8::to_string).collect::<Vec<_>>().join(" ")
}

fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "'"))
}

/// UTC text `YYYY-MM-DDTHH:MM:SS.mmmZ` of a GPS time.
pub fn utc_text(t: gpsrx_nav::GpsTime) -> String {
    let (y, mo, d, h, mi, s) = utc_from_gps(t);
    let ms = (s * 1000.0).round() as i64;
    format!(
        "{y:04}-{mo:02}-{d:02}T{h:02}:{mi:02}:{:02}.{:03}Z",
        ms / 1000,
        ms % 1000
    )
}

/// One CSV line (without the newline) for `o`, with its horizontal error if scored.
pub fn csv_row(o: &SnapshotOutcome, h_error_m: Option<f64>) -> String {
    let time = o.time.or(o.apriori_time);
    let llh = o.llh;
    [
        o.index.to_string(),
        quoted(&o.label),
        time.map_or_else(String::new, utc_text),
        time.map_or_else(String::new, |t| t.week.to_string()),
        opt(time.map(|t| t.tow_s), 6),
        opt(llh.map(|l| l.lat_rad.to_degrees()), 8),
        opt(llh.map(|l| l.lon_rad.to_degrees()), 8),
        opt(llh.map(|l| l.h_m), 2),
        o.used_prns.len().to_string(),
        opt(o.hdop, 2),
        opt(o.pdop, 2),
        o.quality.name().to_string(),
        quoted(&o.reason),
        opt(o.residual_rms_m, 2),
        opt(o.time_correction_s, 4),
        opt(o.clock_bias_m, 1),
        opt(o.fe_offset_hz, 0),
        o.searched.to_string(),
        o.detected.to_string(),
        prns(&o.used_prns),
        prns(&o.excluded_prns),
        prns(&o.rejected_prns),
        opt(h_error_m, 2),
    ]
    .join(",")
}

/// Writes `snapshots.csv` to `path`; `errors` parallel to `outcomes` (or empty).
pub fn write_csv(
    path: &Path,
    outcomes: &[SnapshotOutcome],
    errors: &[Option<f64>],
) -> Result<(), OutputError> {
    let name = path.display().to_string();
    let mut f = create_file(path)?;
    writeln!(f, "{CSV_HEADER}").map_err(OutputError::io(&name))?;
    for (k, o) in outcomes.iter().enumerate() {
        let e = errors.get(k).copied().flatten();
        writeln!(f, "{}", csv_row(o, e)).map_err(OutputError::io(&name))?;
    }
    f.flush().map_err(OutputError::io(&name))
}

/// The positions as [`Fix`]es (for the track writers): rows with a position only.
pub fn fixes(outcomes: &[SnapshotOutcome]) -> Vec<Fix> {
    outcomes
        .iter()
        .filter_map(|o| {
            let (llh, x, t) = (o.llh?, o.ecef_m?, o.time?);
            Some(Fix {
                time: t,
                week_known: true,
                ecef_m: [x.x, x.y, x.z],
                llh,
                vel_ecef_mps: None,
                clock_bias_m: o.clock_bias_m.unwrap_or(f64::NAN),
                clock_drift_mps: None,
                n_sv: o.used_prns.len(),
                used_prns: o.used_prns.clone(),
                pdop: o.pdop.unwrap_or(f64::NAN),
                hdop: o.hdop.unwrap_or(f64::NAN),
                vdop: f64::NAN,
                raim: match o.quality {
                    SnapshotQuality::Fix => "ok".into(),
                    _ => "unverified".into(),
                },
                quality: FixQuality::Gnss,
                sigma_enu_m: None,
                sats_in_view: Vec::new(),
            })
        })
        .collect()
}

/// Writes the track of the positions into `dir`: `track.geojson`, `track.kml` and
/// `track.gpx` ([`crate::output`]'s writers; rows with a position only).
pub fn write_tracks(dir: &Path, outcomes: &[SnapshotOutcome]) -> Result<(), OutputError> {
    let fixes = fixes(outcomes);
    let path = dir.join("track.geojson");
    let name = path.display().to_string();
    let mut f = create_file(&path)?;
    write_geojson(&mut f, &name, &fixes)?;
    f.flush().map_err(OutputError::io(&name))?;
    let path = dir.join("track.kml");
    let name = path.display().to_string();
    write_kml(&mut create_file(&path)?, &name, "gpsrx snapshot", &fixes)?;
    let path = dir.join("track.gpx");
    let name = path.display().to_string();
    write_gpx(&mut create_file(&path)?, &name, "gpsrx snapshot", &fixes)
}

/// Horizontal distance between two positions, m (east/north at `truth`).
pub fn horizontal_error_m(pos: &Llh, truth: &Llh) -> f64 {
    let d: Vector3<f64> = enu_rotation(truth) * (pos.to_ecef() - truth.to_ecef());
    d.x.hypot(d.y)
}

/// A truth to score against.
#[derive(Debug, Clone, PartialEq)]
pub enum Truth {
    /// Points by UTC second of the day (SnapperGPS truth), height `h_m` for all.
    Track {
        /// The points.
        points: Vec<TruthPoint>,
        /// Ellipsoidal height, m.
        h_m: f64,
    },
    /// One position for every snapshot.
    Static(Llh),
}

impl Truth {
    /// The truth position of a snapshot row (SnapperGPS: the point of its time tag's second).
    pub fn at(&self, o: &SnapshotOutcome) -> Option<Llh> {
        match self {
            Truth::Static(l) => Some(*l),
            Truth::Track { points, h_m } => {
                let s = utc_seconds_of_day(&o.label)?.round();
                let p = points.iter().find(|p| (p.utc_s_of_day - s).abs() < 0.5)?;
                Some(Llh::from_degrees(p.lat_deg, p.lon_deg, *h_m))
            }
        }
    }

    /// Horizontal error of each row with a position.
    pub fn errors(&self, outcomes: &[SnapshotOutcome]) -> Vec<Option<f64>> {
        outcomes
            .iter()
            .map(|o| Some(horizontal_error_m(&o.llh?, &self.at(o)?)))
            .collect()
    }
}

/// Summary of a scored run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    /// Snapshots in the input.
    pub snapshots: usize,
    /// Rows of quality `fix`.
    pub fixes: usize,
    /// Rows of quality `unverified`.
    pub unverified: usize,
    /// Median horizontal error of the `fix` rows, m.
    pub median_m: f64,
    /// 95th percentile, m.
    pub p95_m: f64,
    /// Largest, m.
    pub max_m: f64,
}

/// Percentile `q` (0..=1) of sorted values by linear interpolation (NaN when empty).
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let x = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] + f * (sorted[j] - sorted[i])
}

/// Scores the rows of quality `fix` against their errors.
pub fn score(outcomes: &[SnapshotOutcome], errors: &[Option<f64>]) -> Score {
    let mut e: Vec<f64> = outcomes
        .iter()
        .zip(errors)
        .filter(|(o, _)| o.quality == SnapshotQuality::Fix)
        .filter_map(|(_, e)| *e)
        .collect();
    e.sort_by(f64::total_cmp);
    Score {
        snapshots: outcomes.len(),
        fixes: outcomes
            .iter()
            .filter(|o| o.quality == SnapshotQuality::Fix)
            .count(),
        unverified: outcomes
            .iter()
            .filter(|o| o.quality == SnapshotQuality::Unverified)
            .count(),
        median_m: percentile(&e, 0.5),
        p95_m: percentile(&e, 0.95),
        max_m: e.last().copied().unwrap_or(f64::NAN),
    }
}

/// Draws `errors.png`: the horizontal error of every `fix` row against its index, and the
/// median as a dashed line ([`crate::output::plots::draw_line_plot`]).
pub fn draw_errors(
    path: &Path,
    outcomes: &[SnapshotOutcome],
    errors: &[Option<f64>],
) -> Result<(), crate::output::plots::PlotError> {
    use crate::output::plots::{draw_line_plot, LinePlot, Series};
    let points: Vec<(f64, f64)> = outcomes
        .iter()
        .zip(errors)
        .filter(|(o, _)| o.quality == SnapshotQuality::Fix)
        .filter_map(|(o, e)| Some((o.index as f64, (*e)?)))
        .collect();
    let s = score(outcomes, errors);
    let last = outcomes.len().saturating_sub(1) as f64;
    let plot = LinePlot {
        file_name: "errors.png".into(),
        title: format!(
            "Snapshot fixes against the truth: median {:.1} m, 95 % {:.1} m",
            s.median_m, s.p95_m
        ),
        x_label: "snapshot index".into(),
        y_label: "horizontal error (m)".into(),
        series: vec![
            Series {
                name: "horizontal error".into(),
                points,
                reference: false,
            },
            Series {
                name: "median".into(),
                points: vec![(0.0, s.median_m), (last.max(1.0), s.median_m)],
                reference: true,
            },
        ],
        ..LinePlot::default()
    };
    draw_line_plot(&plot, path)
}

/// Reads a truth: a SnapperGPS truth JSON file (height `h_m`).
pub fn read_truth_track(path: &Path, h_m: f64) -> Result<Truth, SnapshotError> {
    Ok(Truth::Track {
        points: super::snappergps::read_truth(path)?,
        h_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(percentile(&v, 0.5), 3.0);
        assert!((percentile(&v, 0.95) - 4.8).abs() < 1e-12);
        assert!(percentile(&[], 0.5).is_nan());
    }

    #[test]
    fn horizontal_error_of_a_known_offset() {
        let t = Llh::from_degrees(51.76, -1.257, 112.0);
        // 0.001 deg of latitude is about 111.3 m; a height change does not count.
        let p = Llh::from_degrees(51.761, -1.257, 150.0);
        let e = horizontal_error_m(&p, &t);
        assert!((e - 111.3).abs() < 0.5, "{e}");
    }
}
