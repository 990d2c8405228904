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
//!   "captures": [{ "core:sample_start": 0, "core:frequency": 1575420000.0 }],
//!   "annotations": []
//! }
//! ```
//!
//! `gpsrx:if_hz` is the intermediate frequency of the samples (0 for complex baseband),
//! `gpsrx:invert_q` says the Q channel must be negated (x = I - jQ), `gpsrx:packed_map` gives the
//! value of 2-bit codes 0b00..0b11. The packed datatypes `ci2`, `ri2`, `ci1` are gpsrx names, not
//! SigMF 1.x ones (see [`crate::format`]).

use std::path::{Path, PathBuf};

use serde_json::{json, Map, Value};

use crate::error::SampleError;
use crate::format::SampleFormat;

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
    /// Every other global key, e.g. `gpsrx:start_gps_week`, `gpsrx:start_tow_s`, `core:author`.
    pub extra: Map<String, Value>,
}

impl SigmfMeta {
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
            extra: Map::new(),
        }
    }
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
                        "core:datatype {:?} is not one gpsrx reads: give --format, one of {}",
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
    let doc = json!({ "global": global, "captures": [capture], "annotations": [] });
    let text = serde_json::to_string_pretty(&doc).map_err(|e| SampleError::SigmfInvalid {
        path: meta_path.clone(),
        reason: format!("cannot serialise metadata: {e}"),
    })?;
    std::fs::write(&meta_path, text + "\n").map_err(|e| SampleError::io("write", &meta_path, e))?;
    Ok(meta_path)
}

/// Reads a `.sigmf-meta` file. Requires `global.core:datatype`; everything else is optional.
pub fn read_sigmf_meta(path: &Path) -> Result<SigmfMeta, SampleError> {
    let text = std::fs::read_to_string(path).map_err(|e| SampleError::io("read", path, e))?;
    let invalid = |reason: String| SampleError::SigmfInvalid {
        path: path.to_path_buf(),
        reason,
    };
    let doc: Value =
        serde_json::from_str(&text).map_err(|e| invalid(format!("not valid JSON ({e})")))?;
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
    let frequency_hz = doc
        .get("captures")
        .and_then(Value::as_array)
        .and_then(|c| c.first())
        .and_then(|c| c.get("core:frequency"))
        .and_then(Value::as_f64);
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
