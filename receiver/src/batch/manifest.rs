//! The manifest of a batch: which recordings to process, how to read them and with which
//! options (and, for the studies, which grids to run case by case).
//!
//! # TOML
//!
//! ```toml
//! [defaults]                 # optional: any key of a recording (options merge key by key)
//! format = "ci8"
//! fs_hz = 2.048e6
//! options = { tropo = "none" }
//!
//! [[recording]]
//! path = "day1.bin"          # relative paths are relative to the manifest
//! nav = "brdc0010.22n"       # or builtin:brdc0010.22n
//! options = { rate_hz = 1, approx_llh = [36.37, 127.36, 80.0] }
//!
//! [[recording]]
//! name = "day2"              # default: the file name without its extension
//! path = "day2.sigmf-meta"
//!
//! [[snapshots]]              # a snapshot set (crate::snapshot::SnapshotSetSpec's keys)
//! path = "walk.json"         # SnapperGPS JSON, SigMF with one capture per snapshot, or raw
//! nav = "walk.nav"
//! approx_llh = [52.03, -1.2574, 112.0]
//! truth = "walk_truth.json"  # optional: scored against it
//! truth_h_m = 112.4
//!
//! [[study]]                  # a study grid, one case (or chunk of cases) per task
//! name = "steady-state"
//! cases = [0, 20]            # case indices start..end (default: all)
//! chunk = 5                  # cases per task (default 1)
//! ```
//!
//! # CSV
//!
//! A header line, then one recording per line. `path` is required; `name`, `format`,
//! `fs_hz`, `if_hz`, `invert_q`, `skip_s`, `duration_s`, `nav` and `config` are the keys of a
//! [`RecordingSpec`]; every other column is an option ([`super::options`]), its cell a TOML value
//! (`1`, `true`, `[1, 2]`) or else a string (`none`). An empty cell leaves the key unset.

use crate::snapshot::SnapshotSetSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// One recording of a batch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordingSpec {
    /// Name in the summary and of the output directory (default: the file stem).
    #[serde(default)]
    pub name: String,
    /// The recording (raw samples, .wav, or SigMF).
    pub path: PathBuf,
    /// Sample format (`ci8`, `cf32_le`, ...; default: from SigMF or WAV metadata).
    #[serde(default)]
    pub format: Option<String>,
    /// Sampling rate, Hz (default: from SigMF or WAV metadata).
    #[serde(default)]
    pub fs_hz: Option<f64>,
    /// Intermediate frequency, Hz.
    #[serde(default)]
    pub if_hz: f64,
    /// Read the samples as I - jQ.
    #[serde(default)]
    pub invert_q: bool,
    /// Seconds skipped at the start.
    #[serde(default)]
    pub skip_s: f64,
    /// Seconds read after the skip (default: to the end).
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// RINEX navigation file, or `builtin:brdc0010.22n`.
    #[serde(default)]
    pub nav: Option<String>,
    /// A `gpsrx.toml` configuration file, under the options.
    #[serde(default)]
    pub config: Option<PathBuf>,
    /// Receiver options by name ([`super::options`]).
    #[serde(default)]
    pub options: toml::Table,
}

impl RecordingSpec {
    /// A recording read with everything from its metadata and the default options.
    pub fn new(path: impl Into<PathBuf>) -> Self {
        let path = path.into();
        Self {
            name: default_name(&path),
            path,
            format: None,
            fs_hz: None,
            if_hz: 0.0,
            invert_q: false,
            skip_s: 0.0,
            duration_s: None,
            nav: None,
            config: None,
            options: toml::Table::new(),
        }
    }
}

/// A study grid of a batch, run case by case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// The study (`steady-state`).
    pub name: String,
    /// Case indices `[start, end)` (default: all).
    #[serde(default)]
    pub cases: Option<[usize; 2]>,
    /// Cases per task (at least 1).
    #[serde(default = "one")]
    pub chunk: usize,
    /// The study's `--quick` grid.
    #[serde(default)]
    pub quick: bool,
}

fn one() -> usize {
    1
}

/// A batch: recordings, snapshot sets and study grids.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The recordings, in order.
    pub recordings: Vec<RecordingSpec>,
    /// The snapshot sets, in order (TOML `[[snapshots]]` tables).
    #[serde(default)]
    pub snapshots: Vec<SnapshotSetSpec>,
    /// The study grids.
    pub studies: Vec<StudySpec>,
}

/// A manifest that cannot be used: the message names the file, the entry and what to do.
#[derive(Debug, thiserror::Error)]
#[error("manifest {path}: {message}")]
pub struct ManifestError {
    /// The manifest.
    pub path: String,
    /// What is wrong.
    pub message: String,
}

/// The keys of a recording that are not options (CSV columns).
const SPEC_KEYS: [&str; 10] = [
    "name",
    "path",
    "format",
    "fs_hz",
    "if_hz",
    "invert_q",
    "skip_s",
    "duration_s",
    "nav",
    "config",
];

impl Manifest {
    /// Reads a TOML (`.toml`) or CSV (any other extension) manifest; relative paths in it are
    /// taken relative to its directory.
    pub fn read(path: &Path) -> Result<Self, ManifestError> {
        let err = |message: String| ManifestError {
            path: path.display().to_string(),
            message,
        };
        let text =
            std::fs::read_to_string(path).map_err(|e| err(format!("cannot read it: {e}")))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let is_toml = path.extension().is_some_and(|e| e == "toml");
        let mut m = if is_toml {
            Self::from_toml(&text)
        } else {
            Self::from_csv(&text)
        }
        .map_err(err)?;
        m.resolve_paths(base);
        Ok(m)
    }

    /// Parses a TOML manifest (paths as written).
    pub fn from_toml(text: &str) -> Result<Self, String> {
        let mut doc: toml::Table = toml::from_str(text).map_err(|e| e.message().to_string())?;
        let defaults = match doc.remove("defaults") {
            Some(toml::Value::Table(t)) => t,
            Some(_) => return Err("[defaults] must be a table".into()),
            None => toml::Table::new(),
        };
        let recordings = take_array(&mut doc, "recording")?;
        let snapshots = take_array(&mut doc, "snapshots")?;
        let studies = take_array(&mut doc, "study")?;
        if let Some(key) = doc.keys().next() {
            return Err(format!(
                "unknown key `{key}`: a manifest has [defaults], [[recording]], [[snapshots]] \
                 and [[study]] tables"
            ));
        }
        let recordings = recordings
            .into_iter()
            .enumerate()
            .map(|(i, t)| {
                spec_from_table(merge_defaults(&defaults, t))
                    .map_err(|e| format!("[[recording]] number {}: {e}", i + 1))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let studies = studies
            .into_iter()
            .enumerate()
            .map(|(i, t)| {
                toml::Value::Table(t)
                    .try_into::<StudySpec>()
                    .map_err(|e| format!("[[study]] number {}: {}", i + 1, e.message().trim()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let snapshots = snapshots
            .into_iter()
            .enumerate()
            .map(|(i, t)| {
                let mut spec: SnapshotSetSpec = toml::Value::Table(t).try_into().map_err(|e| {
                    format!("[[snapshots]] number {}: {}", i + 1, e.message().trim())
                })?;
                if spec.name.is_empty() {
                    spec.name = default_name(&spec.path);
                }
                Ok(spec)
            })
            .collect::<Result<Vec<_>, String>>()?;
        Self::checked(recordings, snapshots, studies)
    }

    /// Parses a CSV manifest (paths as written).
    pub fn from_csv(text: &str) -> Result<Self, String> {
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| format!("cannot read the header line: {e}"))?
            .iter()
            .map(str::to_string)
            .collect();
        if !header.iter().any(|h| h == "path") {
            return Err(format!(
                "no `path` column in the header ({}): the first line names the columns, e.g. path,format,fs_hz",
                header.join(",")
            ));
        }
        let mut recordings = Vec::new();
        for (i, row) in reader.records().enumerate() {
            let line = i + 2;
            let row = row.map_err(|e| format!("line {line}: {e}"))?;
            let mut table = toml::Table::new();
            let mut options = toml::Table::new();
            for (key, cell) in header.iter().zip(row.iter()) {
                if cell.is_empty() {
                    continue;
                }
                let value = csv_value(key, cell);
                if SPEC_KEYS.contains(&key.as_str()) {
                    table.insert(key.clone(), value);
                } else {
                    options.insert(key.clone(), value);
                }
            }
            table.insert("options".into(), toml::Value::Table(options));
            recordings.push(spec_from_table(table).map_err(|e| format!("line {line}: {e}"))?);
        }
        Self::checked(recordings, Vec::new(), Vec::new())
    }

    /// Checks the entries: chunks of at least one case (the rest in [`Self::check_names`]).
    fn checked(
        recordings: Vec<RecordingSpec>,
        snapshots: Vec<SnapshotSetSpec>,
        studies: Vec<StudySpec>,
    ) -> Result<Self, String> {
        if let Some(s) = studies.iter().find(|s| s.chunk == 0) {
            return Err(format!(
                "[[study]] {}: chunk = 0: use 1 or more cases per task",
                s.name
            ));
        }
        let m = Self {
            recordings,
            snapshots,
            studies,
        };
        m.check_names()?;
        Ok(m)
    }

    /// At least one entry; recordings and snapshot sets with names of their own (each names
    /// its output directory).
    fn check_names(&self) -> Result<(), String> {
        if self.recordings.is_empty() && self.snapshots.is_empty() && self.studies.is_empty() {
            return Err(
                "no recording, snapshot set or study: add [[recording]] tables with a `path` (TOML) or lines under a header with a `path` column (CSV)".into(),
            );
        }
        let mut names = BTreeSet::new();
        let all = self
            .recordings
            .iter()
            .map(|r| r.name.as_str())
            .chain(self.snapshots.iter().map(|s| s.name.as_str()));
        for name in all {
            if !names.insert(name) {
                return Err(format!(
                    "two entries are named `{name}`: give each a `name` of its own (it names its output directory)"
                ));
            }
        }
        Ok(())
    }

    /// Takes relative paths relative to `base`.
    fn resolve_paths(&mut self, base: &Path) {
        let resolve = |p: &Path| -> PathBuf {
            if p.is_relative() && p != Path::new("-") {
                base.join(p)
            } else {
                p.to_path_buf()
            }
        };
        for s in &mut self.snapshots {
            s.path = resolve(&s.path);
            s.truth = s.truth.as_deref().map(resolve);
            if let Some(nav) = &s.nav {
                if !nav.starts_with("builtin:") {
                    s.nav = Some(resolve(Path::new(nav)).display().to_string());
                }
            }
        }
        for r in &mut self.recordings {
            r.path = resolve(&r.path);
            r.config = r.config.as_deref().map(resolve);
            if let Some(nav) = &r.nav {
                if !nav.starts_with("builtin:") {
                    r.nav = Some(resolve(Path::new(nav)).display().to_string());
                }
            }
        }
    }
}

/// The array of tables `key` of `doc` (none if absent).
fn take_array(doc: &mut toml::Table, key: &str) -> Result<Vec<toml::Table>, String> {
    match doc.remove(key) {
        None => Ok(Vec::new()),
        Some(toml::Value::Array(items)) => items
            .into_iter()
            .map(|v| match v {
                toml::Value::Table(t) => Ok(t),
                _ => Err(format!("[[{key}]] entries must be tables")),
            })
            .collect(),
        Some(_) => Err(format!(
            "`{key}` must be an array of tables: write [[{key}]]"
        )),
    }
}

/// `defaults` under `table`; the `options` tables merge key by key.
fn merge_defaults(defaults: &toml::Table, mut table: toml::Table) -> toml::Table {
    for (k, v) in defaults {
        match (table.get_mut(k), v) {
            (Some(toml::Value::Table(mine)), toml::Value::Table(theirs)) if k == "options" => {
                for (ok, ov) in theirs {
                    mine.entry(ok.clone()).or_insert_with(|| ov.clone());
                }
            }
            (Some(_), _) => {}
            (None, v) => {
                table.insert(k.clone(), v.clone());
            }
        }
    }
    table
}

/// A recording from its table, named after its file if it has no name.
fn spec_from_table(table: toml::Table) -> Result<RecordingSpec, String> {
    let mut spec: RecordingSpec = toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| e.message().trim().to_string())?;
    if spec.name.is_empty() {
        spec.name = default_name(&spec.path);
    }
    Ok(spec)
}

/// The file name without its extension(s) `.sigmf-meta`, `.sigmf-data`, `.bin`, ...
fn default_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| path.display().to_string())
}

/// A CSV cell: a TOML value if it reads as one (numbers, booleans, arrays), else a string; the
/// spec's text columns always stay strings (a file named `2022`).
fn csv_value(key: &str, cell: &str) -> toml::Value {
    let text_column = matches!(key, "name" | "path" | "format" | "nav" | "config");
    if !text_column {
        if let Ok(t) = toml::from_str::<toml::Table>(&format!("v = {cell}")) {
            if let Some(v) = t.get("v") {
                return v.clone();
            }
        }
    }
    toml::Value::String(cell.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_defaults_merge_under_each_recording() {
        let m = Manifest::from_toml(
            r#"
            [defaults]
            format = "ci8"
            fs_hz = 2.048e6
            options = { tropo = "none", rate_hz = 1 }
            [[recording]]
            path = "a.bin"
            options = { rate_hz = 2 }
            [[recording]]
            path = "b.bin"
            format = "cf32_le"
            [[study]]
            name = "steady-state"
            cases = [0, 20]
            chunk = 5
            "#,
        )
        .expect("valid manifest");
        let [a, b] = &m.recordings[..] else {
            panic!("two recordings: {m:?}")
        };
        assert_eq!((a.name.as_str(), a.format.as_deref()), ("a", Some("ci8")));
        assert_eq!(a.options.get("rate_hz"), Some(&toml::Value::Integer(2)));
        assert_eq!(
            a.options.get("tropo"),
            Some(&toml::Value::String("none".into()))
        );
        assert_eq!(
            (b.format.as_deref(), b.fs_hz),
            (Some("cf32_le"), Some(2.048e6))
        );
        assert_eq!(m.studies[0].cases, Some([0, 20]));
        assert_eq!(m.studies[0].chunk, 5);
    }

    #[test]
    fn csv_columns_beyond_the_spec_are_options() {
        let m = Manifest::from_csv(
            "path,format,fs_hz,tropo,rate_hz,nav\nx/a.bin,ci8,2048000,none,1,\nb.sigmf-meta,,,,,builtin:brdc0010.22n\n",
        )
        .expect("valid");
        let a = &m.recordings[0];
        assert_eq!((a.name.as_str(), a.fs_hz), ("a", Some(2.048e6)));
        assert_eq!(
            a.options.get("tropo"),
            Some(&toml::Value::String("none".into()))
        );
        assert_eq!(a.options.get("rate_hz"), Some(&toml::Value::Integer(1)));
        let b = &m.recordings[1];
        assert!(b.options.is_empty() && b.format.is_none());
        assert_eq!(b.nav.as_deref(), Some("builtin:brdc0010.22n"));
    }

    #[test]
    fn bad_manifests_say_what_to_do() {
        let e = Manifest::from_csv("file,format\na.bin,ci8\n").expect_err("no path column");
        assert!(e.contains("no `path` column"), "{e}");
        let e = Manifest::from_toml("[[recording]]\npath = \"a.bin\"\nfs = 2e6")
            .expect_err("unknown key");
        assert!(e.contains("number 1") && e.contains("fs"), "{e}");
        let e = Manifest::from_toml(
            "[[recording]]\npath = \"x/a.bin\"\n[[recording]]\npath = \"y/a.bin\"",
        )
        .expect_err("same name");
        assert!(e.contains("named `a`"), "{e}");
        let e = Manifest::from_toml("").expect_err("empty");
        assert!(e.contains("no recording"), "{e}");
    }

    #[test]
    fn relative_paths_are_taken_from_the_manifest_directory() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("m.csv");
        std::fs::write(
            &path,
            "path,nav\nrec/a.bin,brdc.22n\n/abs/b.bin,builtin:brdc0010.22n\n",
        )
        .expect("write");
        let m = Manifest::read(&path).expect("valid");
        assert_eq!(m.recordings[0].path, dir.path().join("rec/a.bin"));
        let nav = dir.path().join("brdc.22n").display().to_string();
        assert_eq!(m.recordings[0].nav.as_deref(), Some(nav.as_str()));
        assert_eq!(m.recordings[1].path, PathBuf::from("/abs/b.bin"));
        assert_eq!(m.recordings[1].nav.as_deref(), Some("builtin:brdc0010.22n"));
    }

    #[test]
    fn snapshot_sets_are_read_with_their_paths_resolved_and_names_checked() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("m.toml");
        std::fs::write(
            &path,
            "[[snapshots]]\npath = \"walk/w00.json\"\nnav = \"w00.nav\"\n\
             approx_llh = [52.03, -1.2574, 112.0]\ntruth = \"walk/truth.json\"\n\
             smooth_accel_mps2 = 0.5\n\
             [[snapshots]]\nname = \"air\"\npath = \"/abs/air.stream\"\n\
             nav = \"builtin:brdc0010.22n\"\napprox_llh = [52.6, 10.9, 0.0]\n\
             format = \"ri2_lsb\"\nmap = [0.5, 1.5, -1.5, -0.5]\nheight_sigma_m = 0.0\n",
        )
        .expect("write");
        let m = Manifest::read(&path).expect("valid");
        assert!(m.recordings.is_empty());
        let [walk, air] = &m.snapshots[..] else {
            panic!("two sets: {m:?}")
        };
        assert_eq!(walk.name, "w00");
        assert_eq!(walk.path, dir.path().join("walk/w00.json"));
        assert_eq!(walk.truth, Some(dir.path().join("walk/truth.json")));
        let nav = dir.path().join("w00.nav").display().to_string();
        assert_eq!(walk.nav.as_deref(), Some(nav.as_str()));
        assert_eq!(walk.smooth_accel_mps2, Some(0.5));
        assert_eq!((air.name.as_str(), air.height_sigma_m), ("air", 0.0));
        assert_eq!(air.path, PathBuf::from("/abs/air.stream"));
        assert_eq!(air.nav.as_deref(), Some("builtin:brdc0010.22n"));
        // A set named as a recording; a set without its a-priori.
        let e = Manifest::from_toml(
            "[[recording]]\npath = \"x/a.bin\"\n[[snapshots]]\npath = \"y/a.json\"\n\
             approx_llh = [0.0, 0.0, 0.0]",
        )
        .expect_err("same name");
        assert!(e.contains("named `a`"), "{e}");
        let e = Manifest::from_toml("[[snapshots]]\npath = \"a.json\"").expect_err("no a-priori");
        assert!(
            e.contains("[[snapshots]] number 1") && e.contains("approx_llh"),
            "{e}"
        );
    }
}
