//! KML 2.2 track (`track.kml`, OGC 07-147r2): a Document with one LineString Placemark of the
//! valid fixes (without geometry when fewer than two fixes are valid).
//!
//! Coordinates are `lon,lat,height`, with the height above the WGS-84 ellipsoid. KML's
//! `absolute` altitude mode means height above sea level, so the placemark uses
//! `clampToGround`: the track is drawn on the terrain and the height is kept only as data.

use super::{Fix, FixQuality, OutputError};
use std::io::Write;

/// Escapes the five XML special characters.
pub(crate) fn xml_escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            c if c.is_control() && c != '\n' && c != '\t' => s.push('?'),
            c => s.push(c),
        }
    }
    s
}

/// The KML document for `fixes`, named `name`.
pub fn track_kml(name: &str, fixes: &[Fix]) -> String {
    let coords: Vec<String> = fixes
        .iter()
        .filter(|f| {
            f.quality != FixQuality::None
                && f.llh.lat_rad.is_finite()
                && f.llh.lon_rad.is_finite()
                && f.llh.h_m.is_finite()
        })
        .map(|f| {
            format!(
                "{:.9},{:.9},{:.3}",
                f.llh.lon_rad.to_degrees(),
                f.llh.lat_rad.to_degrees(),
                f.llh.h_m
            )
        })
        .collect();
    let name = xml_escape(name);
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s.push_str("<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n");
    s.push_str("  <Document>\n");
    s.push_str(&format!("    <name>{name}</name>\n"));
    s.push_str("    <Style id=\"track\"><LineStyle><color>ff0000ff</color><width>3</width></LineStyle></Style>\n");
    s.push_str("    <Placemark>\n");
    s.push_str(&format!("      <name>{name} track</name>\n"));
    s.push_str(&format!(
        "      <description>{} fixes; heights above the WGS-84 ellipsoid</description>\n",
        coords.len()
    ));
    s.push_str("      <styleUrl>#track</styleUrl>\n");
    // KML 2.2 (OGC 07-147r2, kml:LineString): two or more coordinate tuples are required.
    if coords.len() >= 2 {
        s.push_str("      <LineString>\n");
        s.push_str("        <tessellate>1</tessellate>\n");
        s.push_str("        <altitudeMode>clampToGround</altitudeMode>\n");
        s.push_str("        <coordinates>\n");
        for c in &coords {
            s.push_str("          ");
            s.push_str(c);
            s.push('\n');
        }
        s.push_str("        </coordinates>\n");
        s.push_str("      </LineString>\n");
    }
    s.push_str("    </Placemark>\n");
    s.push_str("  </Document>\n");
    s.push_str("</kml>\n");
    s
}

/// Writes the KML track to `out`; `file` names it in errors.
pub fn write_kml<W: Write>(
    out: &mut W,
    file: &str,
    name: &str,
    fixes: &[Fix],
) -> Result<(), OutputError> {
    out.write_all(track_kml(name, fixes).as_bytes())
        .map_err(OutputError::io(file))?;
    out.flush().map_err(OutputError::io(file))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_escaped() {
        assert_eq!(xml_escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        let doc = track_kml("run <1>", &[]);
        assert!(doc.contains("<name>run &lt;1&gt;</name>"));
    }
}
