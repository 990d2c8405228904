//! SnapperGPS JSON input (`{"deviceID": .., "snapshots": [{"timestamp": ISO-8601 UTC,
//! "data": base64, ..}]}`, as the SnapperGPS app exports them) and its truth files
//! (`[{"time": "HH:MM:SS", "latitude": deg, "longitude": deg}]`).
//!
//! Each `data` field holds 1-bit real samples, least-significant bit first, bit 0 = +1
//! (`ri1_lsb`), at 4.092 MHz with the MAX2769's IF equal to fs: the spectrum folded around
//! 0 Hz. The timestamp is the device clock (whole seconds, not GPS-accurate) in UTC; it becomes
//! the a-priori time of the snapshot's first sample through the leap-second table
//! ([`gpsrx_nav::utc::gps_from_utc`]).

use super::input::{read_all, Snapshot};
use super::SnapshotError;
use gpsrx_nav::time::GpsTime;
use gpsrx_nav::utc::gps_from_utc;
use gpsrx_samples::{ReaderSource, SampleFormat, SourceConfig};
use std::path::Path;

/// SnapperGPS sampling rate, Hz.
pub const SNAPPERGPS_FS_HZ: f64 = 4.092e6;

/// The SnapperGPS sample format: `ri1_lsb`.
pub fn snappergps_format() -> SampleFormat {
    SampleFormat::Packed1Real { lsb_first: true }
}

#[derive(Debug, serde::Deserialize)]
struct File {
    snapshots: Vec<Entry>,
}

#[derive(Debug, serde::Deserialize)]
struct Entry {
    timestamp: Option<String>,
    data: Option<String>,
}

/// Reads every snapshot of a SnapperGPS JSON file. A snapshot whose data cannot be decoded
/// comes back empty (its row then says why: too short); the file itself must be valid JSON
/// with a `snapshots` array.
pub fn read_snappergps(path: &Path) -> Result<Vec<Snapshot>, SnapshotError> {
    let bad = |reason: String| SnapshotError::Input {
        path: path.to_path_buf(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let file: File = serde_json::from_str(&text)
        .map_err(|e| bad(format!("not a SnapperGPS JSON file ({e})")))?;
    let mut out = Vec::with_capacity(file.snapshots.len());
    for (index, e) in file.snapshots.iter().enumerate() {
        let label = e.timestamp.clone().unwrap_or_default();
        let approx_time = e.timestamp.as_deref().and_then(parse_iso_utc);
        let bytes = e
            .data
            .as_deref()
            .and_then(decode_base64)
            .unwrap_or_default();
        let samples = decode_ri1(&bytes).map_err(|e| bad(e.to_string()))?;
        out.push(Snapshot {
            index,
            samples,
            fs_hz: SNAPPERGPS_FS_HZ,
            folded: true,
            approx_time,
            label,
        });
    }
    Ok(out)
}

/// Decodes `ri1_lsb` bytes to samples through the library's reader (IF = fs: no mixing).
fn decode_ri1(bytes: &[u8]) -> Result<Vec<num_complex::Complex32>, gpsrx_samples::SampleError> {
    if bytes.is_empty() {
        return Ok(Vec::new());
    }
    let cfg = SourceConfig {
        format: Some(snappergps_format()),
        fs_hz: Some(SNAPPERGPS_FS_HZ),
        if_hz: SNAPPERGPS_FS_HZ,
        ..SourceConfig::new("snapshot")
    };
    let mut src = ReaderSource::new(std::io::Cursor::new(bytes), &cfg)?;
    read_all(&mut src, bytes.len() * 8)
}

/// Parses `YYYY-MM-DDTHH:MM:SS[.fff][Z]` (UTC) into GPS time; `None` when malformed.
pub fn parse_iso_utc(text: &str) -> Option<GpsTime> {
    let t = text.trim().trim_end_matches('Z');
    let (date, time) = t.split_once(['T', ' '])?;
    let mut d = date.split('-');
    let year: i32 = d.next()?.parse().ok()?;
    let month: u32 = d.next()?.parse().ok()?;
    let day: u32 = d.next()?.parse().ok()?;
    let mut h = time.split(':');
    let hour: u32 = h.next()?.parse().ok()?;
    let min: u32 = h.next()?.parse().ok()?;
    let sec: f64 = h.next()?.parse().ok()?;
    let valid = (1980..=2200).contains(&year)
        && (1..=12).contains(&month)
        && (1..=31).contains(&day)
        && hour < 24
        && min < 60
        && (0.0..61.0).contains(&sec);
    valid.then(|| gps_from_utc(year, month, day, hour, min, sec))
}

/// Standard base64 (RFC 4648, with or without padding; whitespace ignored); `None` on any
/// other character.
pub fn decode_base64(text: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    };
    let mut out = Vec::with_capacity(text.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in text.bytes().filter(|c| !c.is_ascii_whitespace()) {
        if c == b'=' {
            break;
        }
        acc = (acc << 6) | value(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// One truth point of a SnapperGPS walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthPoint {
    /// UTC seconds of the day.
    pub utc_s_of_day: f64,
    /// Latitude, deg.
    pub lat_deg: f64,
    /// Longitude, deg.
    pub lon_deg: f64,
}

#[derive(Debug, serde::Deserialize)]
struct TruthEntry {
    time: String,
    latitude: f64,
    longitude: f64,
}

/// Reads a SnapperGPS truth file (`[{"time": "HH:MM:SS", "latitude", "longitude"}]`).
pub fn read_truth(path: &Path) -> Result<Vec<TruthPoint>, SnapshotError> {
    let bad = |reason: String| SnapshotError::Input {
        path: path.to_path_buf(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| bad(e.to_string()))?;
    let entries: Vec<TruthEntry> = serde_json::from_str(&text)
        .map_err(|e| bad(format!("not a truth list of time/latitude/longitude ({e})")))?;
    entries
        .iter()
        .map(|e| {
            let mut p = e.time.split(':').map(|v| v.trim().parse::<f64>());
            match (p.next(), p.next(), p.next()) {
                (Some(Ok(h)), Some(Ok(m)), Some(Ok(s))) => Ok(TruthPoint {
                    utc_s_of_day: h * 3600.0 + m * 60.0 + s,
                    lat_deg: e.latitude,
                    lon_deg: e.longitude,
                }),
                _ => Err(bad(format!("time {:?} is not HH:MM:SS", e.time))),
            }
        })
        .collect()
}

/// UTC seconds of the day of a SnapperGPS timestamp (`...THH:MM:SS...`), to match truth points.
pub fn utc_seconds_of_day(label: &str) -> Option<f64> {
    let (_, time) = label.trim().trim_end_matches('Z').split_once(['T', ' '])?;
    let mut h = time.split(':').map(|v| v.parse::<f64>());
    match (h.next(), h.next(), h.next()) {
        (Some(Ok(h)), Some(Ok(m)), Some(Ok(s))) => Some(h * 3600.0 + m * 60.0 + s),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_rfc4648_vectors() {
        assert_eq!(decode_base64("Zm9vYmFy").as_deref(), Some(&b"foobar"[..]));
        assert_eq!(decode_base64("Zm9vYg==").as_deref(), Some(&b"foob"[..]));
        assert_eq!(decode_base64("Zm9v\nYmE=").as_deref(), Some(&b"fooba"[..]));
        assert_eq!(decode_base64("Zm9*"), None);
    }

    #[test]
    fn timestamps_become_gps_time_with_leap_seconds() {
        // 2021-11-22 12:40:00 UTC: Monday, GPS week 2185, TOW 1 d + 12 h 40 min + 18 s.
        let t = parse_iso_utc("2021-11-22T12:40:00.000Z").expect("valid");
        assert_eq!(t.week, 2185);
        assert!(
            (t.tow_s - (86_400.0 + 45_600.0 + 18.0)).abs() < 1e-6,
            "{t:?}"
        );
        assert!(parse_iso_utc("2021-13-22T12:40:00Z").is_none());
        assert!(parse_iso_utc("yesterday").is_none());
        assert_eq!(
            utc_seconds_of_day("2021-11-22T12:40:05.000Z"),
            Some(45_605.0)
        );
    }

    #[test]
    fn ri1_bytes_decode_lsb_first_with_zero_positive() {
        let s = decode_ri1(&[0b0000_0010]).expect("decodes");
        let v: Vec<f32> = s.iter().map(|c| c.re).collect();
        assert_eq!(v, vec![1.0, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]);
        assert!(s.iter().all(|c| c.im == 0.0));
    }
}
