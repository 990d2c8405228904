//! GPX 1.1 track (`track.gpx`, <https://www.topografix.com/GPX/1/1/>): one `trk` with one
//! `trkseg` of the valid fixes, each `trkpt` with its height (`ele`, above the WGS-84
//! ellipsoid: GPX asks for the geoid, which gpsrx does not model; said in the `desc`), UTC
//! time (when the GPS week is known), fix type, satellites used and DOPs.

use super::kml::xml_escape;
use super::{Fix, FixQuality, OutputError};
use gpsrx_samples::sigmf::format_datetime_utc;
use std::fmt::Write as _;
use std::io::Write;

/// The GPX document of the valid fixes, the track named `name`.
pub fn track_gpx(name: &str, fixes: &[Fix]) -> String {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s.push_str(
        "<gpx version=\"1.1\" creator=\"gpsrx\" xmlns=\"http://www.topografix.com/GPX/1/1\">\n",
    );
    s.push_str("  <trk>\n");
    let _ = writeln!(s, "    <name>{}</name>", xml_escape(name));
    s.push_str("    <desc>gpsrx fixes; ele is the height above the WGS-84 ellipsoid</desc>\n");
    s.push_str("    <trkseg>\n");
    for f in fixes.iter().filter(|f| valid(f)) {
        trkpt(&mut s, f);
    }
    s.push_str("    </trkseg>\n");
    s.push_str("  </trk>\n");
    s.push_str("</gpx>\n");
    s
}

/// A fix worth a track point: valid, with a finite position.
fn valid(f: &Fix) -> bool {
    f.quality != FixQuality::None
        && f.llh.lat_rad.is_finite()
        && f.llh.lon_rad.is_finite()
        && f.llh.h_m.is_finite()
}

/// One `trkpt`, its children in the order GPX 1.1's `wptType` requires.
fn trkpt(s: &mut String, f: &Fix) {
    let _ = writeln!(
        s,
        "      <trkpt lat=\"{:.9}\" lon=\"{:.9}\">",
        f.llh.lat_rad.to_degrees(),
        f.llh.lon_rad.to_degrees()
    );
    let _ = writeln!(s, "        <ele>{:.3}</ele>", f.llh.h_m);
    if f.week_known {
        let _ = writeln!(s, "        <time>{}</time>", format_datetime_utc(f.time));
    }
    // GPX has no dead-reckoning fix type: DR-only points say so in their type instead.
    if f.quality == FixQuality::DeadReckoning {
        s.push_str("        <type>dead reckoning</type>\n");
    } else {
        let fix = if f.n_sv >= 4 { "3d" } else { "2d" };
        let _ = writeln!(s, "        <fix>{fix}</fix>");
    }
    if f.n_sv > 0 {
        let _ = writeln!(s, "        <sat>{}</sat>", f.n_sv);
    }
    for (tag, v) in [("hdop", f.hdop), ("vdop", f.vdop), ("pdop", f.pdop)] {
        if v.is_finite() {
            let _ = writeln!(s, "        <{tag}>{v:.2}</{tag}>");
        }
    }
    s.push_str("      </trkpt>\n");
}

/// Writes the GPX track to `out`; `file` names it in errors.
pub fn write_gpx<W: Write>(
    out: &mut W,
    file: &str,
    name: &str,
    fixes: &[Fix],
) -> Result<(), OutputError> {
    out.write_all(track_gpx(name, fixes).as_bytes())
        .map_err(OutputError::io(file))?;
    out.flush().map_err(OutputError::io(file))
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_nav::{GpsTime, Llh};

    fn fix(quality: FixQuality, week_known: bool) -> Fix {
        Fix {
            time: GpsTime::new(2190, 538_200.0),
            week_known,
            ecef_m: [0.0; 3],
            llh: Llh::from_degrees(37.5665, 126.978, 40.0),
            vel_ecef_mps: None,
            clock_bias_m: 0.0,
            clock_drift_mps: None,
            n_sv: 8,
            used_prns: Vec::new(),
            pdop: 1.8,
            hdop: 0.9,
            vdop: f64::NAN,
            raim: String::new(),
            quality,
            sigma_enu_m: None,
            sats_in_view: Vec::new(),
        }
    }

    #[test]
    fn valid_fixes_become_track_points_in_the_schema_order() {
        let doc = track_gpx(
            "run <1>",
            &[
                fix(FixQuality::Gnss, true),
                fix(FixQuality::None, true),
                fix(FixQuality::Gnss, false),
            ],
        );
        assert_eq!(doc.matches("<trkpt ").count(), 2, "{doc}");
        assert!(doc.contains("<name>run &lt;1&gt;</name>"));
        // 05:30:00 GPS time is 05:29:42 UTC; the undated point has no time.
        assert_eq!(
            doc.matches("<time>2022-01-01T05:29:42.000000Z</time>")
                .count(),
            1
        );
        // wptType order: ele, time, fix, sat, hdop, (no vdop: NaN), pdop.
        let first = &doc[doc.find("<trkpt ").unwrap_or(0)..];
        let at = |tag: &str| first.find(tag).unwrap_or(usize::MAX);
        assert!(at("<ele>") < at("<time>") && at("<time>") < at("<fix>3d"));
        assert!(at("<fix>") < at("<sat>8") && at("<sat>") < at("<hdop>0.90"));
        assert!(at("<hdop>") < at("<pdop>1.80") && !first[..at("</trkpt>")].contains("vdop"));
    }
}
