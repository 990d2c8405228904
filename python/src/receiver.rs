//! `gpsrx.Receiver`: the receiver fed with numpy arrays of complex samples.

use crate::convert::{options_table, to_py};
use crate::errors::{receiver_error, recording_error};
use crate::records;
use gpsrx_receiver::batch::RecordingSpec;
use gpsrx_receiver::{MemorySink, Receiver};
use num_complex::Complex32;
use numpy::PyReadonlyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The GPS receiver on pushed sample blocks (complex baseband, IF removed).
///
/// `Receiver(fs_hz, nav=None, config=None, **options)`: `nav` a RINEX navigation file or
/// `"builtin:brdc0010.22n"`, `config` a `gpsrx.toml`, options by name as `gpsrx run` takes
/// them (`rate_hz=1`, `tropo="none"`, `approx_llh=[lat, lon, h]`, `tracking.cn0_lost_dbhz`
/// via a dict). Any chunking of the samples gives the same fixes.
#[pyclass(name = "Receiver", module = "gpsrx._gpsrx")]
pub struct PyReceiver {
    inner: Receiver,
    sink: MemorySink,
}

impl std::fmt::Debug for PyReceiver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Receiver(fs_hz={})", self.inner.fs_hz())
    }
}

/// What the sink holds, as Python records, and the sink emptied.
fn drain<'py>(py: Python<'py>, sink: &mut MemorySink) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("fixes", records::fixes(py, &sink.fixes)?)?;
    d.set_item("observables", records::observables(py, &sink.observables)?)?;
    d.set_item("channels", records::channels(py, &sink.channels)?)?;
    d.set_item("events", records::events(py, &sink.events)?)?;
    sink.fixes.clear();
    sink.observables.clear();
    sink.channels.clear();
    sink.events.clear();
    Ok(d)
}

#[pymethods]
impl PyReceiver {
    #[new]
    #[pyo3(signature = (fs_hz, nav=None, config=None, **options))]
    fn new(
        fs_hz: f64,
        nav: Option<String>,
        config: Option<std::path::PathBuf>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        if !(fs_hz.is_finite() && fs_hz > 0.0) {
            return Err(PyValueError::new_err(format!(
                "sampling rate {fs_hz} Hz: give the rate of the samples in Hz (> 0), e.g. 2.048e6"
            )));
        }
        let spec = RecordingSpec {
            nav,
            config,
            options: options_table(options)?,
            ..RecordingSpec::new("")
        };
        let cfg = spec
            .receiver_config()
            .map_err(|e| recording_error(&gpsrx_receiver::batch::RecordingError::Config(e)))?;
        let source = gpsrx_samples::SourceConfig::new("");
        let assistance = spec.assistance(&source).map_err(|e| recording_error(&e))?;
        let inner = Receiver::new(&cfg, fs_hz, assistance).map_err(|e| receiver_error(&e))?;
        Ok(Self {
            inner,
            sink: MemorySink::new(),
        })
    }

    /// The sampling rate, Hz.
    #[getter]
    fn fs_hz(&self) -> f64 {
        self.inner.fs_hz()
    }

    /// Takes the next samples (a 1-D complex64 array, any length); returns what they produced:
    /// `{"fixes": columns, "observables": columns, "channels": columns, "events": [dict]}`.
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        samples: PyReadonlyArray1<'py, Complex32>,
    ) -> PyResult<Bound<'py, PyDict>> {
        // A copy: other Python threads may change the array while the GIL is released.
        let block: Vec<Complex32> = samples.as_array().to_vec();
        let (inner, sink) = (&mut self.inner, &mut self.sink);
        py.detach(|| inner.push(&block, sink))
            .map_err(|e| receiver_error(&e))?;
        drain(py, &mut self.sink)
    }

    /// Ends the stream: processes what is left; returns the last products as `push` does and
    /// the run's `summary` (a dict).
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (inner, sink) = (&mut self.inner, &mut self.sink);
        let summary = py
            .detach(|| inner.finish(sink))
            .map_err(|e| receiver_error(&e))?;
        let d = drain(py, &mut self.sink)?;
        d.set_item("summary", to_py(py, &summary)?)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("{self:?}")
    }
}
