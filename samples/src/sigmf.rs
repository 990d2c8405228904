//! SigMF metadata (`.sigmf-meta`, SigMF 1.x JSON) beside a recording.
//!
//! What gpsrx writes, for a data file `rec.ci8` (the metadata is `rec.sigmf-meta`):
//!
//! ```json
//! {
//!   "global": {
//!     "core:datatype": "ci8",
//!     "core:sample_rate": 2600000.0,
//!     "core:version": "1.0.0",
//!     "core:description": "...",
//!     "core:extensions": [{ "name": "gpsrx", "version": "0.1.0", "optional": true }],
//!     "gpsrx:if_hz": 0.0,
//!     "gpsrx:invert_q": false,
//!     "gpsrx:packed_map": [1.0, 3.0, -3.0, -1.0],   // only for ci2/ri2
//!     "gpsrx:start_gps_week": 2190                  // any `extra` keys
//!   },
//!   "captures": [{ "core:sample_start": 0, "core:frequency": 1575420000.0,
//!                  "core:datetime": "2022-01-01T05:29:42.000000Z" }],
//!   "annotations": []
//! }
//! ```
//!
//! `gpsrx:if_hz` is the intermediate frequency of the samples (0 for complex baseband); when it
//! is absent (or 0), a `captures[0].core:frequency` other than L1 gives it: the front end was
//! tuned to `core:frequency`, so L1 lies at `IF = 1575.42e6 - core:frequency` in the samples
//! ([`SigmfMeta::described_if_hz`]; gpsrx's simulator writes both, consistently),
//! `gpsrx:invert_q` says the Q channel must be negated (x = I - jQ), `gpsrx:packed_map` gives the
//! value of 2-bit codes 0b00..0b11. The packed datatypes `ci2`, `ri2`, `ci1` are gpsrx names, not
//! SigMF 1.x ones (see [`crate::format`]).
//!
//! `core:datetime` (ISO 8601, UTC) is the time of the capture's first sample
//! (`core:sample_start`): [`SigmfMeta::start_time`] converts it to GPS time (leap seconds
//! from [`gpsrx_nav::utc::leap_seconds_on`]), which dates a receiver's outputs before the
//! broadcast week is decoded. A global `core:datetime` is read too (some tools put it there).

use std::path::{Path, PathBuf};

use serde_json::{json, Map, Value};

use crate::error::SampleError;
use crate::format::SampleFormat;
use gpsrx_nav::utc::{gps_from_utc, utc_from_gps};
use gpsrx_nav::GpsTime;

/// GPS L1 carrier frequency, the default `core:frequency` of a capture (IS-GPS-200 3.3.1.1).
pub use gpsrx_core::constants::F_L1_HZ as GPS_L1_HZ;

/// Global keys that map to [`SigmfMeta`] fields; every other global key lands in `extra`.
const KNOWN_GLOBAL_KEYS: &[&str] = &[
    "core:datatype",
    "core:sample_rate",
    "core:version",
    "core:description",
    "core:extensions",
    "gpsrx:if_hz",
    "gpsrx:invert_q",
    "gpsrx:packed_map",
    "core:datetime",
    "core:dataset",
];

/// The parts of a SigMF metadata file gpsrx uses.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SigmfMeta {
    /// `core:datatype`, e.g. `"ci8"` (see [`crate::format::SampleFormat::name`]).
    pub datatype: String,
    /// `core:sample_rate` in Hz; 0.0 when the file gives none.
    pub sample_rate_hz: f64,
    /// `captures[0].core:frequency` in Hz (the RF centre frequency), if given.
    pub frequency_hz: Option<f64>,
    /// `gpsrx:if_hz`: intermediate frequency of the samples (0 when absent).
    pub if_hz: f64,
    /// `gpsrx:invert_q`: read samples as I - jQ (false when absent).
    pub invert_q: bool,
    /// `gpsrx:packed_map`: value of 2-bit codes 0b00, 0b01, 0b10, 0b11.
    pub packed_map: Option<[f32; 4]>,
    /// `core:description` ("" when absent).
    pub description: String,
    /// `core:datetime` of the first capture (else of the global object): ISO 8601 UTC time of
    /// the capture's first sample, as written (see [`SigmfMeta::start_time`]).
    pub datetime: Option<String>,
    /// `captures[0].core:sample_start`: the sample `datetime` refers to (0 when absent).
    pub capture_sample_start: u64,
    /// Every other global key, e.g. `gpsrx:start_gps_week`, `gpsrx:start_tow_s`, `core:author`.
    pub extra: Map<String, Value>,
}

/// When a recording started, as its metadata says.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingStart {
    /// GPS time of the first sample of the data file.
    pub time: GpsTime,
    /// Where it comes from, for messages (e.g. `core:datetime 2022-01-01T05:29:42Z of
    /// rec.sigmf-meta`).
    pub origin: String,
}

impl SigmfMeta {
    /// The intermediate frequency of the samples, Hz, and where it comes from: `gpsrx:if_hz`
    /// when non-zero; else `L1 - captures[0].core:frequency` when that is not L1 (a front end
    /// tuned off L1 puts the carrier at the difference; IS-GPS-200 3.3.1.1 for L1); else 0.
    pub fn described_if_hz(&self) -> (f64, &'static str) {
        if self.if_hz != 0.0 {
            return (self.if_hz, "gpsrx:if_hz");
        }
        match self.frequency_hz.filter(|f| f.is_finite()) {
            Some(f) if f != GPS_L1_HZ => (GPS_L1_HZ - f, "core:frequency"),
            _ => (0.0, "none"),
        }
    }

    /// Metadata for `datatype` at `sample_rate_hz`, complex baseband at GPS L1, nothing else set.
    pub fn new(datatype: impl Into<String>, sample_rate_hz: f64) -> Self {
        SigmfMeta {
            datatype: datatype.into(),
            sample_rate_hz,
            frequency_hz: Some(GPS_L1_HZ),
            if_hz: 0.0,
            invert_q: false,
            packed_map: None,
            description: String::new(),
            datetime: None,
            capture_sample_start: 0,
            extra: Map::new(),
        }
    }

    /// GPS time of the data file's first sample: `core:datetime` (UTC, converted with the leap
    /// seconds) less `core:sample_start` samples, else `gpsrx:start_gps_week` with
    /// `gpsrx:start_tow_s` (what older gpsrx simulations wrote). `Ok(None)` when neither is
    /// given; an error (the reason) when `core:datetime` is not an ISO 8601 date and time.
    pub fn start_time(&self) -> Result<Option<(GpsTime, String)>, String> {
        if let Some(text) = &self.datetime {
            let t = parse_datetime_utc(text)?;
            let before_s = if self.sample_rate_hz > 0.0 {
                self.capture_sample_start as f64 / self.sample_rate_hz
            } else {
                0.0
            };
            return Ok(Some((
                t.add_seconds(-before_s),
                format!("core:datetime {text}"),
            )));
        }
        let week = self
            .extra
            .get("gpsrx:start_gps_week")
            .and_then(Value::as_u64);
        let tow = self.extra.get("gpsrx:start_tow_s").and_then(Value::as_f64);
        Ok(match (week.and_then(|w| u32::try_from(w).ok()), tow) {
            (Some(w), Some(tow)) if tow.is_finite() => {
                Some((GpsTime::new(w, tow), format!("gpsrx:start_gps_week {w}")))
            }
            _ => None,
        })
    }
}

/// The GPS time of an ISO 8601 date and time in UTC: `YYYY-MM-DDTHH:MM:SS[.fraction]` followed
/// by `Z` (SigMF's form), or by an offset `+HH:MM`/`-HH:MM` (applied), or by nothing (read as
/// UTC). The error says what is wrong.
pub fn parse_datetime_utc(text: &str) -> Result<GpsTime, String> {
    let bad = |why: &str| {
        format!("{text:?} is not an ISO 8601 UTC date and time (YYYY-MM-DDTHH:MM:SS[.fff]Z): {why}")
    };
    let s = text.trim();
    if !s.is_ascii() {
        return Err(bad("non-ASCII characters"));
    }
    if s.len() < 19 {
        return Err(bad("too short"));
    }
    let (date, rest) = s.split_at(10);
    let sep = rest.as_bytes()[0];
    if !matches!(sep, b'T' | b't' | b' ') {
        return Err(bad("no `T` between the date and the time"));
    }
    let rest = &rest[1..];
    // The zone: `Z`, `+HH:MM`, `-HH:MM`, `+HHMM` or nothing.
    let (clock, offset_s) = if let Some(c) = rest.strip_suffix(['Z', 'z']) {
        (c, 0.0)
    } else if let Some(i) = rest.rfind(['+', '-']) {
        let zone = rest[i + 1..].replace(':', "");
        let (Some(hh), Some(mm)) = (
            zone.get(..2).and_then(|v| v.parse::<u32>().ok()),
            zone.get(2..).and_then(|v| v.parse::<u32>().ok()),
        ) else {
            return Err(bad("the zone offset is not +HH:MM"));
        };
        if zone.len() != 4 || hh > 23 || mm > 59 {
            return Err(bad("the zone offset is not +HH:MM"));
        }
        let sign = if rest.as_bytes()[i] == b'-' {
            -1.0
        } else {
            1.0
        };
        (&rest[..i], sign * f64::from(hh * 3600 + mm * 60))
    } else {
        (rest, 0.0)
    };
    let field = |v: Option<&str>, lo: u32, hi: u32, name: &str| -> Result<u32, String> {
        v.filter(|v| !v.is_empty() && v.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|v| v.parse::<u32>().ok())
            .filter(|n| (lo..=hi).contains(n))
            .ok_or_else(|| bad(&format!("bad {name}")))
    };
    let mut d = date.split('-');
    let (year, month, day) = (
        field(d.next(), 1980, 9999, "year")?,
        field(d.next(), 1, 12, "month")?,
        field(d.next(), 1, 31, "day")?,
    );
    if d.next().is_some() || date.len() != 10 {
        return Err(bad("the date is not YYYY-MM-DD"));
    }
    let mut c = clock.splitn(3, ':');
    let (hour, min) = (
        field(c.next(), 0, 23, "hour")?,
        field(c.next(), 0, 59, "minute")?,
    );
    let sec_text = c.next().unwrap_or_default();
    let (whole, frac) = sec_text.split_once('.').unwrap_or((sec_text, ""));
    let whole = field(Some(whole), 0, 60, "second")?;
    if !frac.bytes().all(|b| b.is_ascii_digit()) {
        return Err(bad("bad fraction of a second"));
    }
    let frac: f64 = if frac.is_empty() {
        0.0
    } else {
        format!("0.{frac}")
            .parse()
            .map_err(|_| bad("bad fraction of a second"))?
    };
    let year = i32::try_from(year).map_err(|_| bad("bad year"))?;
    Ok(gps_from_utc(year, month, day, hour, min, f64::from(whole) + frac).add_seconds(-offset_s))
}

/// ISO 8601 UTC text (`YYYY-MM-DDTHH:MM:SS.ffffffZ`, microseconds) of GPS time `t`, as SigMF's
/// `core:datetime` wants it.
pub fn format_datetime_utc(t: GpsTime) -> String {
    // Round on the microsecond first, so the seconds never print as 60.
    let t = GpsTime::new(t.week, (t.tow_s * 1e6).round() * 1e-6);
    let (y, mo, d, h, mi, s) = utc_from_gps(t);
    let micros = ((s * 1e6).round() as u64).min(59_999_999);
    format!(
        "{y:04}-{mo:02}-{d:02}T{h:02}:{mi:02}:{:02}.{:06}Z",
        micros / 1_000_000,
        micros % 1_000_000
    )
}

impl SigmfMeta {
    /// Metadata for samples in `format` at `sample_rate_hz`: the datatype name and, for 2-bit
    /// formats, the value map.
    pub fn for_format(format: &SampleFormat, sample_rate_hz: f64) -> Self {
        let mut meta = SigmfMeta::new(format.name(), sample_rate_hz);
        if let SampleFormat::Packed2 { map, .. } = format {
            meta.packed_map = Some(*map);
        }
        meta
    }

    /// The sample format this metadata describes (`core:datatype` with `gpsrx:packed_map`).
    /// `meta_path` is only for the error message.
    pub fn sample_format(&self, meta_path: &Path) -> Result<SampleFormat, SampleError> {
        let mut format: SampleFormat =
            self.datatype
                .parse()
                .map_err(|_| SampleError::SigmfInvalid {
                    path: meta_path.to_path_buf(),
                    reason: format!(
                    "core:datatype {:?} is not one gpsrx reads: give the sample format, one of {}",
                    self.datatype,
                    SampleFormat::SUPPORTED.join(", ")
                ),
                })?;
        if let (SampleFormat::Packed2 { map, .. }, Some(m)) = (&mut format, self.packed_map) {
            *map = m;
        }
        Ok(format)
    }
}

/// The metadata path gpsrx writes for a data file: `DATA_STEM.sigmf-meta` beside it.
pub fn meta_path_for(data_path: &Path) -> PathBuf {
    data_path.with_extension("sigmf-meta")
}

/// Writes `DATA_STEM.sigmf-meta` next to `data_path` and returns its path.
pub fn write_sigmf_meta(data_path: &Path, meta: &SigmfMeta) -> Result<PathBuf, SampleError> {
    let meta_path = meta_path_for(data_path);
    if meta_path == data_path {
        return Err(SampleError::SigmfInvalid {
            path: meta_path,
            reason: "the data file itself ends in .sigmf-meta: name the data file .sigmf-data or by its format".into(),
        });
    }
    let mut global = Map::new();
    global.insert("core:datatype".into(), json!(meta.datatype));
    global.insert("core:sample_rate".into(), json!(meta.sample_rate_hz));
    global.insert("core:version".into(), json!("1.0.0"));
    global.insert("core:description".into(), json!(meta.description));
    global.insert(
        "core:extensions".into(),
        json!([{ "name": "gpsrx", "version": env!("CARGO_PKG_VERSION"), "optional": true }]),
    );
    // SigMF names the data `STEM.sigmf-data`; a data file named by its format (`signal.ci8`)
    // is a "non-conforming dataset", named in `core:dataset` so that other readers find it.
    let conforming = data_path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("sigmf-data"));
    if let (false, Some(name)) = (conforming, data_path.file_name().and_then(|n| n.to_str())) {
        global.insert("core:dataset".into(), json!(name));
    }
    global.insert("gpsrx:if_hz".into(), json!(meta.if_hz));
    global.insert("gpsrx:invert_q".into(), json!(meta.invert_q));
    if let Some(map) = meta.packed_map {
        global.insert("gpsrx:packed_map".into(), json!(map));
    }
    for (k, v) in &meta.extra {
        if !KNOWN_GLOBAL_KEYS.contains(&k.as_str()) {
            global.insert(k.clone(), v.clone());
        }
    }
    let mut capture = Map::new();
    capture.insert("core:sample_start".into(), json!(0));
    if let Some(f) = meta.frequency_hz {
        capture.insert("core:frequency".into(), json!(f));
    }
    if let Some(t) = &meta.datetime {
        capture.insert("core:datetime".into(), json!(t));
    }
    let doc = json!({ "global": global, "captures": [capture], "annotations": [] });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| SampleError::SigmfInvalid {
        path: meta_path.clone(),
        reason: format!("cannot serialise metadata: {e}"),
    })?;
    std::fs::write(&meta_path, text + "\n").map_err(|e| SampleError::io("write", &meta_path, e))?;
    Ok(meta_path)
}

/// The JSON document of a `.sigmf-meta` file (an unreadable file or invalid JSON: an error
/// naming it).
pub(crate) fn read_meta_json(path: &Path) -> Result<Value, SampleError> {
    let text = std::fs::read_to_string(path).map_err(|e| SampleError::io("read", path, e))?;
    serde_json::from_str(&text).map_err(|e| SampleError::SigmfInvalid {
        path: path.to_path_buf(),
        reason: format!("not valid JSON ({e})"),
    })
}

/// One capture of a SigMF recording: its first sample in the data file and its
/// `core:datetime`, as written.
#[derive(Debug, Clone, PartialEq)]
pub struct Capture {
    /// `core:sample_start` (0 when absent).
    pub sample_start: u64,
    /// `core:datetime` (ISO 8601 UTC), if given.
    pub datetime: Option<String>,
}

/// The captures of a `.sigmf-meta` file, in sample order (none when it has no `captures`).
pub fn read_captures(meta_path: &Path) -> Result<Vec<Capture>, SampleError> {
    let doc = read_meta_json(meta_path)?;
    let mut out: Vec<Capture> = doc
        .get("captures")
        .and_then(Value::as_array)
        .map_or(&[][..], Vec::as_slice)
        .iter()
        .map(|c| Capture {
            sample_start: c
                .get("core:sample_start")
                .and_then(Value::as_u64)
                .unwrap_or(0),
            datetime: c
                .get("core:datetime")
                .and_then(Value::as_str)
                .map(str::to_string),
        })
        .collect();
    out.sort_by_key(|c| c.sample_start);
    Ok(out)
}

/// The data file a `.sigmf-meta` file names in `global.core:dataset` (a "non-conforming
/// dataset", beside the metadata), if it names one.
pub fn dataset_path(meta_path: &Path) -> Result<Option<PathBuf>, SampleError> {
    let doc = read_meta_json(meta_path)?;
    let name = doc
        .get("global")
        .and_then(|g| g.get("core:dataset"))
        .and_then(Value::as_str);
    Ok(name.map(|n| meta_path.parent().unwrap_or(Path::new("")).join(n)))
}

/// Reads a `.sigmf-meta` file. Requires `global.core:datatype`; everything else is optional.
pub fn read_sigmf_meta(path: &Path) -> Result<SigmfMeta, SampleError> {
    let doc = read_meta_json(path)?;
    let invalid = |reason: String| SampleError::SigmfInvalid {
        path: path.to_path_buf(),
        reason,
    };
    let global = doc
        .get("global")
        .and_then(Value::as_object)
        .ok_or_else(|| invalid("no \"global\" object".into()))?;
    let number = |key: &str| -> Result<Option<f64>, SampleError> {
        match global.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(v) => v
                .as_f64()
                .map(Some)
                .ok_or_else(|| invalid(format!("{key} is {v}, not a number"))),
        }
    };
    let datatype = global
        .get("core:datatype")
        .and_then(Value::as_str)
        .ok_or_else(|| invalid("global has no core:datatype string".into()))?
        .to_string();
    let sample_rate_hz = number("core:sample_rate")?.unwrap_or(0.0);
    let if_hz = number("gpsrx:if_hz")?.unwrap_or(0.0);
    let invert_q = match global.get("gpsrx:invert_q") {
        None | Some(Value::Null) => false,
        Some(v) => v
            .as_bool()
            .ok_or_else(|| invalid(format!("gpsrx:invert_q is {v}, not true/false")))?,
    };
    let packed_map = match global.get("gpsrx:packed_map") {
        None | Some(Value::Null) => None,
        Some(v) => Some(parse_map(v).ok_or_else(|| {
            invalid(format!(
                "gpsrx:packed_map is {v}, not an array of 4 numbers"
            ))
        })?),
    };
    let description = global
        .get("core:description")
        .and_then(Value::as_str)
        .unwrap_or_default()
        .to_string();
    let capture = doc
        .get("captures")
        .and_then(Value::as_array)
        .and_then(|c| c.first());
    let frequency_hz = capture
        .and_then(|c| c.get("core:frequency"))
        .and_then(Value::as_f64);
    let datetime = capture
        .and_then(|c| c.get("core:datetime"))
        .or_else(|| global.get("core:datetime"))
        .and_then(Value::as_str)
        .map(str::to_string);
    let capture_sample_start = capture
        .and_then(|c| c.get("core:sample_start"))
        .and_then(Value::as_u64)
        .unwrap_or(0);
    let extra = global
        .iter()
        .filter(|(k, _)| !KNOWN_GLOBAL_KEYS.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    Ok(SigmfMeta {
        datatype,
        sample_rate_hz,
        frequency_hz,
        if_hz,
        invert_q,
        packed_map,
        description,
        datetime,
        capture_sample_start,
        extra,
    })
}

fn parse_map(v: &Value) -> Option<[f32; 4]> {
    let a = v.as_array()?;
    if a.len() != 4 {
        return None;
    }
    let mut map = [0.0f32; 4];
    for (m, x) in map.iter_mut().zip(a) {
        *m = x.as_f64()? as f32;
    }
    Some(map)
}

/// The start of the recording at `path` (a data file or its `.sigmf-meta`), when SigMF
/// metadata beside it gives one ([`SigmfMeta::start_time`]); `Ok(None)` for standard input,
/// a recording without metadata, or metadata without a date. An unreadable `core:datetime` is
/// an error ([`SampleError::SigmfInvalid`]).
pub fn recording_start(path: &Path) -> Result<Option<RecordingStart>, SampleError> {
    if crate::stream_source::is_stdin_path(path) || !path.exists() {
        return Ok(None);
    }
    let (_, Some(meta_path)) = crate::resolve::locate(path)? else {
        return Ok(None);
    };
    let meta = read_sigmf_meta(&meta_path)?;
    let start = meta
        .start_time()
        .map_err(|reason| SampleError::SigmfInvalid {
            path: meta_path.clone(),
            reason,
        })?;
    Ok(start.map(|(time, what)| RecordingStart {
        time,
        origin: format!("{what} of {}", meta_path.display()),
    }))
}
