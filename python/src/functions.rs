//! The module's functions: `run`, `acquire`, `simulate`, the batch tasks and the study grids.

use crate::convert::{json_to_py, options_table, py_to_json, to_py};
use crate::errors::{recording_error, Error};
use crate::records;
use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_receiver::batch::{self, Manifest, RecordingSpec};
use gpsrx_receiver::output::FileSink;
use gpsrx_receiver::pipeline::Tee;
use gpsrx_receiver::MemorySink;
use gpsrx_samples::sim::Scenario;
use num_complex::Complex32;
use numpy::PyReadonlyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// A recording spec from `run`'s arguments.
#[allow(clippy::too_many_arguments)]
fn spec(
    path: PathBuf,
    format: Option<String>,
    fs_hz: Option<f64>,
    if_hz: f64,
    skip_s: f64,
    duration_s: Option<f64>,
    nav: Option<String>,
    config: Option<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<RecordingSpec> {
    Ok(RecordingSpec {
        format,
        fs_hz,
        if_hz,
        skip_s,
        duration_s,
        nav,
        config,
        options: options_table(options)?,
        ..RecordingSpec::new(path)
    })
}

/// Runs the receiver over a recording, as `gpsrx run` does; returns `{"fixes": columns,
/// "channels": columns, "observables": columns, "events": [dict], "summary": dict,
/// "warnings": [str]}`. With `out`, the standard files are written there too.
#[pyfunction]
#[pyo3(signature = (path, format=None, fs_hz=None, if_hz=0.0, skip_s=0.0, duration_s=None, nav=None, config=None, out=None, **options))]
#[allow(clippy::too_many_arguments)]
pub fn run<'py>(
    py: Python<'py>,
    path: PathBuf,
    format: Option<String>,
    fs_hz: Option<f64>,
    if_hz: f64,
    skip_s: f64,
    duration_s: Option<f64>,
    nav: Option<String>,
    config: Option<PathBuf>,
    out: Option<PathBuf>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = spec(
        path, format, fs_hz, if_hz, skip_s, duration_s, nav, config, options,
    )?;
    let result = py.detach(|| {
        let mut memory = MemorySink::new();
        let outcome = match &out {
            Some(dir) => {
                let run = spec.receiver_config()?.run;
                let files = FileSink::create(dir, run.rate_hz)?.with_plots(run.plots);
                let mut tee = Tee(files, memory);
                let r = batch::run_recording(&spec, &mut tee);
                memory = tee.1;
                r
            }
            None => batch::run_recording(&spec, &mut memory),
        };
        outcome.map(|(summary, warnings)| (summary, warnings, memory))
    });
    let (summary, warnings, memory) = result.map_err(|e| recording_error(&e))?;
    let d = PyDict::new(py);
    d.set_item("fixes", records::fixes(py, &memory.fixes)?)?;
    d.set_item("channels", records::channels(py, &memory.channels)?)?;
    d.set_item(
        "observables",
        records::observables(py, &memory.observables)?,
    )?;
    d.set_item("events", records::events(py, &memory.events)?)?;
    d.set_item("summary", to_py(py, &summary)?)?;
    d.set_item("warnings", warnings)?;
    Ok(d)
}

/// Searches complex baseband samples for satellites (FFT parallel code-phase search); returns
/// one dict per PRN searched: `prn`, `detected`, `doppler_hz`, `code_phase_chips`,
/// `code_phase_samples`, `cn0_dbhz`, `metric`, `threshold`, `peak_ratio`.
#[pyfunction]
#[pyo3(signature = (samples, fs_hz, prns=None, coherent_ms=1, noncoherent=10, doppler_max_hz=5000.0, doppler_center_hz=0.0, pfa=1e-5))]
#[allow(clippy::too_many_arguments)]
pub fn acquire<'py>(
    py: Python<'py>,
    samples: PyReadonlyArray1<'py, Complex32>,
    fs_hz: f64,
    prns: Option<Vec<i64>>,
    coherent_ms: u32,
    noncoherent: u32,
    doppler_max_hz: f64,
    doppler_center_hz: f64,
    pfa: f64,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let targets: Vec<SearchTarget> = match prns {
        Some(list) => list
            .into_iter()
            .map(|p| {
                u8::try_from(p)
                    .ok()
                    .and_then(|p| Prn::new(p).ok())
                    .map(SearchTarget::full)
                    .ok_or_else(|| PyValueError::new_err(format!("PRN {p}: use 1 to 32")))
            })
            .collect::<PyResult<_>>()?,
        None => Prn::all().map(SearchTarget::full).collect(),
    };
    let config = AcqConfig {
        coherent_ms,
        noncoherent,
        doppler_max_hz,
        doppler_center_hz,
        pfa,
        ..AcqConfig::default()
    };
    let block: Vec<Complex32> = samples.as_array().to_vec();
    let results = py
        .detach(|| {
            let engine = AcquisitionEngine::new(fs_hz, config)?;
            engine.search(&block, &targets)
        })
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    results
        .iter()
        .map(|r| {
            let d = PyDict::new(py);
            d.set_item("prn", r.prn.get())?;
            d.set_item("detected", r.detected)?;
            d.set_item("doppler_hz", r.doppler_hz)?;
            d.set_item("code_phase_chips", r.code_phase_chips)?;
            d.set_item("code_phase_samples", r.code_phase_samples)?;
            d.set_item("cn0_dbhz", r.cn0_dbhz.unwrap_or(f64::NAN))?;
            d.set_item("metric", r.metric)?;
            d.set_item("threshold", r.threshold)?;
            d.set_item("peak_ratio", r.peak_ratio)?;
            Ok(d)
        })
        .collect()
}

/// The scenario: a TOML file, TOML text, or `"default"` (the built-in default scenario); and
/// the directory its relative paths are taken from.
fn scenario(text_or_path: &str) -> PyResult<(Scenario, PathBuf)> {
    let err = |e: &dyn std::fmt::Display| PyValueError::new_err(e.to_string());
    if text_or_path == "default" {
        return Ok((
            Scenario::default_scenario().map_err(|e| err(&e))?,
            PathBuf::new(),
        ));
    }
    let path = Path::new(text_or_path);
    if !text_or_path.contains('\n') && !text_or_path.contains('=') {
        if !path.exists() {
            return Err(pyo3::exceptions::PyFileNotFoundError::new_err(format!(
                "scenario {text_or_path} does not exist: give a scenario file, its TOML text or \"default\""
            )));
        }
        return Scenario::load(path).map_err(|e| err(&e));
    }
    let base = std::env::current_dir().unwrap_or_default();
    Ok((
        Scenario::from_toml(text_or_path).map_err(|e| err(&e))?,
        base,
    ))
}

/// Simulates a scenario into `out_dir` as `gpsrx simulate` does: the recording, its
/// `.sigmf-meta`, `truth.csv`, `truth_sv.csv` (and the sensor logs its tables ask for).
/// Returns the report (paths, satellites, rate, duration) as a dict.
#[pyfunction]
#[pyo3(signature = (scenario, out_dir, duration_s=None, seed=None, format=None, fs_hz=None))]
pub fn simulate<'py>(
    py: Python<'py>,
    scenario: PathBuf,
    out_dir: PathBuf,
    duration_s: Option<f64>,
    seed: Option<u64>,
    format: Option<String>,
    fs_hz: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (mut sc, base) = self::scenario(&scenario.to_string_lossy())?;
    if let Some(d) = duration_s {
        sc.duration_s = d;
    }
    if let Some(s) = seed {
        sc.seed = s;
    }
    if let Some(f) = format {
        sc.output.format = f;
    }
    if let Some(f) = fs_hz {
        sc.output.fs_hz = f;
    }
    let (report, sensors) = py
        .detach(|| gpsrx_receiver::simulate::simulate(&sc, &base, &out_dir, &|_| ()))
        .map_err(|e| Error::new_err(gpsrx_receiver::error_message(&e)))?;
    let mut v = serde_json::to_value(&report).map_err(|e| Error::new_err(e.to_string()))?;
    let sensors = serde_json::to_value(&sensors).map_err(|e| Error::new_err(e.to_string()))?;
    if let (Some(map), serde_json::Value::Object(s)) = (v.as_object_mut(), sensors) {
        map.extend(s);
    }
    json_to_py(py, &v)
}

/// Reads a batch manifest (TOML or CSV): `{"recordings": [spec dict], "studies": [dict]}`,
/// paths made relative to the manifest's directory.
#[pyfunction]
pub fn read_manifest<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let m = Manifest::read(&path).map_err(|e| {
        if path.exists() {
            PyValueError::new_err(e.to_string())
        } else {
            pyo3::exceptions::PyFileNotFoundError::new_err(e.to_string())
        }
    })?;
    to_py(py, &m)
}

/// One batch task: the recording of `spec` (a dict as `read_manifest` gives) processed into
/// `out_root/NAME/`; returns its summary row. Never raises for a bad recording: the row's
/// `status` is `error` and `message` says why.
#[pyfunction]
pub fn process_recording<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyAny>,
    out_root: PathBuf,
) -> PyResult<Bound<'py, PyAny>> {
    let json = py_to_json(spec)?;
    let spec: RecordingSpec = serde_json::from_value(json)
        .map_err(|e| PyValueError::new_err(format!("recording spec: {e}")))?;
    crate::errors::create_out_dir(&out_root)?;
    let row = py.detach(|| batch::process(&spec, &out_root));
    to_py(py, &row)
}

/// The cases of a study grid (`study="steady-state"`), each a dict of its parameters with its
/// index `case`.
#[pyfunction]
#[pyo3(signature = (study="steady-state", quick=true))]
pub fn study_cases<'py>(py: Python<'py>, study: &str, quick: bool) -> PyResult<Bound<'py, PyAny>> {
    let cases = gpsrx_studies::grid::cases(study, quick)
        .map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    to_py(py, &cases)
}

/// Runs case `index` of a study grid: its parameters and results as one dict (what the whole
/// study computes for that case).
#[pyfunction]
#[pyo3(signature = (index, study="steady-state", quick=true))]
pub fn run_study_case<'py>(
    py: Python<'py>,
    index: usize,
    study: &str,
    quick: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let row = py
        .detach(|| gpsrx_studies::grid::run_case(study, quick, index))
        .map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    to_py(py, &row)
}
