//! Snapshot sets from Python: `snapshot` (a whole set, as `gpsrx snapshot` runs it) and
//! `process_snapshots` (one batch task), over [`gpsrx_receiver::snapshot::set`].

use crate::convert::{py_to_json, to_py};
use crate::errors::snapshot_error;
use crate::records;
use gpsrx_receiver::batch;
use gpsrx_receiver::snapshot::{run_set, write_set, SnapshotSetSpec};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// A set spec from a dict (keys of [`SnapshotSetSpec`]; an unknown key is a `ValueError`).
fn spec_from(d: &Bound<'_, PyAny>) -> PyResult<SnapshotSetSpec> {
    let json = py_to_json(d)?;
    let mut spec: SnapshotSetSpec = serde_json::from_value(json)
        .map_err(|e| PyValueError::new_err(format!("snapshot set: {e}")))?;
    if spec.name.is_empty() {
        spec.name = SnapshotSetSpec::new(&spec.path, None, [0.0; 3]).name;
    }
    Ok(spec)
}

/// Positions a snapshot set as `gpsrx snapshot` does: `path` a SnapperGPS JSON file, a SigMF
/// recording with one capture per snapshot, or a raw recording of one snapshot (`format`,
/// `fs_hz`, `if_hz`, `time="WEEK:TOW"`); `nav` a RINEX navigation file; `approx_llh`
/// `[lat_deg, lon_deg, h_m]`. Other keywords: `time`, `format`, `map`, `fs_hz`, `if_hz`,
/// `height_sigma_m`, `max_speed_mps`, `coherent_ms`, `coherent_look`, `smooth_accel_mps2`, `truth`,
/// `truth_h_m`, `truth_ecef_m`. Returns `{"snapshots": columns (one row per input snapshot),
/// "summary": dict}`; with `out`, `snapshots.csv` and the tracks are written there too.
#[pyfunction]
#[pyo3(signature = (path, nav, approx_llh, out=None, **options))]
pub fn snapshot<'py>(
    py: Python<'py>,
    path: PathBuf,
    nav: Option<PathBuf>,
    approx_llh: [f64; 3],
    out: Option<PathBuf>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    if let Some(o) = options {
        d.update(o.as_mapping())?;
    }
    d.set_item("path", path)?;
    d.set_item("nav", nav)?;
    d.set_item("approx_llh", approx_llh.to_vec())?;
    let spec = spec_from(d.as_any())?;
    let result = py
        .detach(|| {
            let r = run_set(&spec, |_| {})?;
            if let Some(dir) = &out {
                write_set(dir, &r)?;
            }
            Ok(r)
        })
        .map_err(|e| snapshot_error(&e))?;
    let row = batch::BatchRow::snapshot_set(&spec.name, &spec.path.display().to_string(), &result);
    let out = PyDict::new(py);
    out.set_item(
        "snapshots",
        records::snapshots(py, &result.outcomes, &result.errors)?,
    )?;
    out.set_item("summary", to_py(py, &row)?)?;
    Ok(out)
}

/// One batch task: the snapshot set of `spec` (a dict with the keys of `gpsrx.snapshot`, and
/// `name`) positioned into `out_root/NAME/`; returns its summary row. Never raises for a bad
/// set: the row's `status` is `error` and `message` says why.
#[pyfunction]
pub fn process_snapshots<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyAny>,
    out_root: PathBuf,
) -> PyResult<Bound<'py, PyAny>> {
    let spec = spec_from(spec)?;
    crate::errors::create_out_dir(&out_root)?;
    let row = py.detach(|| batch::process_snapshots(&spec, &out_root));
    to_py(py, &row)
}
