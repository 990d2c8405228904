//! `fused.csv`: one row per fused output instant (see [`super::fuse`]).

use super::fuse::FusedFix;
use crate::output::{create_file, Fix, FixQuality, OutputError};
use gpsrx_core::frames::{enu_rotation, Vector3};
use gpsrx_ins_aiding::FixSource;
use std::path::Path;

/// Column names of `fused.csv`.
pub const FUSED_COLUMNS: [&str; 17] = [
    "gps_week",
    "tow_s",
    "lat_deg",
    "lon_deg",
    "h_m",
    "ve_mps",
    "vn_mps",
    "heading_deg",
    "source",
    "t_s",
    "sigma_east_m",
    "sigma_north_m",
    "n_sv",
    "sf_g_dps_per_v",
    "v_nom_v",
    "sf_n_m_per_pulse",
    "speed_filter_mps",
];

/// Writes `fixes` to `path`.
pub fn write_fused_csv(path: &Path, fixes: &[FusedFix]) -> Result<(), OutputError> {
    let file = path.display().to_string();
    let err = |source: csv::Error| OutputError::Csv {
        file: file.clone(),
        source,
    };
    let mut w = csv::Writer::from_writer(create_file(path)?);
    w.write_record(FUSED_COLUMNS).map_err(err)?;
    for f in fixes {
        let p = f.params;
        let opt = |v: Option<f64>, d: usize| v.map(|v| format!("{v:.d$}")).unwrap_or_default();
        w.write_record([
            f.time.week.to_string(),
            format!("{:.3}", f.time.tow_s),
            format!("{:.9}", f.llh.lat_rad.to_degrees()),
            format!("{:.9}", f.llh.lon_rad.to_degrees()),
            format!("{:.3}", f.llh.h_m),
            format!("{:.3}", f.vel_en_mps[0]),
            format!("{:.3}", f.vel_en_mps[1]),
            format!("{:.3}", f.heading_rad.to_degrees().rem_euclid(360.0)),
            f.source.as_str().to_string(),
            format!("{:.3}", f.t_s),
            format!("{:.3}", f.sigma_en_m[0]),
            format!("{:.3}", f.sigma_en_m[1]),
            f.n_sv.to_string(),
            opt(p.map(|p| p.sf_g_dps_per_v), 4),
            opt(p.map(|p| p.v_nom_v), 5),
            opt(p.map(|p| p.sf_n_m_per_pulse), 6),
            opt(f.speed_filter_mps, 3),
        ])
        .map_err(err)?;
    }
    w.flush().map_err(|source| OutputError::Io {
        file: file.clone(),
        source,
    })
}

/// The fused rows as [`Fix`]es for the NMEA, GeoJSON and KML writers (GGA quality 1 for GNSS
/// and fused rows, 6 for DR only).
pub fn fused_as_fixes(fixes: &[FusedFix]) -> Vec<Fix> {
    fixes
        .iter()
        .map(|f| {
            // East/north velocity to ECEF (no vertical component): R_enu^T v_enu.
            let [ve, vn] = f.vel_en_mps;
            let v = enu_rotation(&f.llh).transpose() * Vector3::new(ve, vn, 0.0);
            let vel = [v.x, v.y, v.z];
            Fix {
                time: f.time,
                // Fused rows start at the first GNSS fix, which has the week.
                week_known: true,
                ecef_m: [f.ecef_m.x, f.ecef_m.y, f.ecef_m.z],
                llh: f.llh,
                vel_ecef_mps: Some(vel),
                clock_bias_m: 0.0,
                clock_drift_mps: None,
                n_sv: f.n_sv,
                used_prns: Vec::new(),
                pdop: f64::NAN,
                hdop: f64::NAN,
                vdop: f64::NAN,
                raim: String::new(),
                quality: match f.source {
                    FixSource::Gnss => FixQuality::Gnss,
                    FixSource::Fused => FixQuality::Fused,
                    FixSource::DrOnly => FixQuality::DeadReckoning,
                },
                sigma_enu_m: None,
                sats_in_view: Vec::new(),
            }
        })
        .collect()
}
