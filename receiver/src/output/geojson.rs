//! GeoJSON track (`track.geojson`, RFC 7946): a FeatureCollection holding one LineString of
//! the valid fixes (when there are at least two, as RFC 7946 3.1.4 requires) and one Point
//! feature per valid fix with its time, quality, DOPs and RAIM outcome as properties.
//!
//! Positions are `[longitude, latitude, height]` in degrees and metres, WGS-84; the height is
//! above the ellipsoid (RFC 7946 3.1.1 leaves the meaning of the third value to the producer).

use super::{calendar_rounded, Fix, FixQuality, OutputError};
use serde_json::{json, Value};
use std::io::Write;

/// Rounds to `decimals` decimals (keeps the file small; 1e-9 deg is 0.1 mm).
fn round_to(v: f64, decimals: i32) -> f64 {
    let s = 10f64.powi(decimals);
    (v * s).round() / s
}

/// A JSON number, or `null` for a non-finite value.
fn num(v: f64, decimals: i32) -> Value {
    if v.is_finite() {
        json!(round_to(v, decimals))
    } else {
        Value::Null
    }
}

fn has_position(fix: &Fix) -> bool {
    fix.quality != FixQuality::None
        && fix.llh.lat_rad.is_finite()
        && fix.llh.lon_rad.is_finite()
        && fix.llh.h_m.is_finite()
}

fn position(fix: &Fix) -> Value {
    json!([
        round_to(fix.llh.lon_rad.to_degrees(), 9),
        round_to(fix.llh.lat_rad.to_degrees(), 9),
        round_to(fix.llh.h_m, 3)
    ])
}

/// GPS time as ISO 8601 text in the GPS time scale (no leap seconds), e.g.
/// `2022-01-01T05:30:00.000`.
pub(crate) fn gps_iso(fix: &Fix) -> String {
    calendar_rounded(fix.time, 3).map_or_else(String::new, |c| {
        format!(
            "{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:03}",
            c.year, c.month, c.day, c.hour, c.minute, c.second, c.frac
        )
    })
}

/// Builds the FeatureCollection. Fixes without a valid position are left out.
pub fn track_feature_collection(fixes: &[Fix]) -> Value {
    let valid: Vec<&Fix> = fixes.iter().filter(|f| has_position(f)).collect();
    let mut features = Vec::with_capacity(valid.len() + 1);
    if valid.len() >= 2 {
        features.push(json!({
            "type": "Feature",
            "geometry": {
                "type": "LineString",
                "coordinates": valid.iter().map(|f| position(f)).collect::<Vec<_>>(),
            },
            "properties": { "name": "track", "fixes": valid.len() },
        }));
    }
    for f in &valid {
        features.push(json!({
            "type": "Feature",
            "geometry": { "type": "Point", "coordinates": position(f) },
            "properties": {
                "gps_week": if f.week_known { json!(f.time.week) } else { Value::Null },
                "tow_s": num(f.time.tow_s, 3),
                "time_gpst": if f.week_known { json!(gps_iso(f)) } else { Value::Null },
                "h_m": num(f.llh.h_m, 3),
                "quality": f.quality.name(),
                "n_sv": f.n_sv,
                "used_prns": f.used_prns,
                "pdop": num(f.pdop, 2),
                "hdop": num(f.hdop, 2),
                "vdop": num(f.vdop, 2),
                "clock_bias_m": num(f.clock_bias_m, 3),
                "speed_mps": super::nmea::speed_course(f)
                    .map_or(Value::Null, |(kn, _)| num(kn * 1852.0 / 3600.0, 3)),
                "raim": f.raim,
            },
        }));
    }
    json!({ "type": "FeatureCollection", "features": features })
}

/// Writes the track as GeoJSON to `out`; `file` names it in errors.
pub fn write_geojson<W: Write>(out: &mut W, file: &str, fixes: &[Fix]) -> Result<(), OutputError> {
    serde_json::to_writer_pretty(&mut *out, &track_feature_collection(fixes)).map_err(
        |source| OutputError::Json {
            file: file.to_string(),
            source,
        },
    )?;
    out.write_all(b"\n").map_err(OutputError::io(file))?;
    out.flush().map_err(OutputError::io(file))
}
