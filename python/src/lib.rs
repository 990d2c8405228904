//! The Python package `gpsrx` (module `gpsrx._gpsrx`, built by maturin from `pyproject.toml`):
//! the receiver fed with numpy arrays ([`receiver`]), whole runs, acquisition, the simulator,
//! batch tasks and study grids ([`functions`]), snapshot sets ([`snapshot`]), with library errors as Python exceptions
//! ([`errors`]) and products as pandas-ready columns ([`records`]). The GIL is released while
//! the receiver works.
//!
//! The pure-Python part (`gpsrx/__init__.py`, `gpsrx/batch.py` for Dask) and the type stubs
//! are in `python/gpsrx/`; the tests in `python/tests/` (pytest).

pub mod convert;
pub mod errors;
pub mod functions;
pub mod receiver;
pub mod records;
pub mod snapshot;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _gpsrx(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<errors::Error>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<receiver::PyReceiver>()?;
    m.add_function(wrap_pyfunction!(functions::run, m)?)?;
    m.add_function(wrap_pyfunction!(functions::acquire, m)?)?;
    m.add_function(wrap_pyfunction!(functions::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(functions::read_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(functions::process_recording, m)?)?;
    m.add_function(wrap_pyfunction!(functions::study_cases, m)?)?;
    m.add_function(wrap_pyfunction!(functions::run_study_case, m)?)?;
    m.add_function(wrap_pyfunction!(snapshot::snapshot, m)?)?;
    m.add_function(wrap_pyfunction!(snapshot::process_snapshots, m)?)?;
    Ok(())
}
