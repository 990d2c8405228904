//! Library errors as Python exceptions, with the messages `gpsrx` prints: a missing file is
//! `FileNotFoundError`, another unreadable file `OSError`, a bad value or option `ValueError`,
//! anything else `gpsrx.Error`.

use gpsrx_receiver::batch::RecordingError;
use gpsrx_receiver::error_message;
use gpsrx_receiver::snapshot::SnapshotError;
use gpsrx_receiver::ReceiverError;
use gpsrx_samples::SampleError;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    _gpsrx,
    Error,
    pyo3::exceptions::PyException,
    "An error of the gpsrx receiver (its message says what to do)."
);

/// The Python exception of a sample-source error.
pub fn sample_error(e: &SampleError, message: String) -> PyErr {
    match e {
        SampleError::NotFound { .. } => PyFileNotFoundError::new_err(message),
        SampleError::Io { .. } => PyOSError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

/// The Python exception of a receiver error.
pub fn receiver_error(e: &ReceiverError) -> PyErr {
    let message = error_message(e);
    match e {
        ReceiverError::Config(_) | ReceiverError::RateMismatch { .. } => {
            PyValueError::new_err(message)
        }
        ReceiverError::Acquisition(_) => PyValueError::new_err(message),
        ReceiverError::Source(s) => sample_error(s, message),
        _ => Error::new_err(message),
    }
}

/// The Python exception of a recording that cannot be processed.
pub fn recording_error(e: &RecordingError) -> PyErr {
    let message = error_message(e);
    match e {
        RecordingError::Config(gpsrx_receiver::config::ConfigError::Read { .. }) => {
            PyOSError::new_err(message)
        }
        RecordingError::Config(_) => PyValueError::new_err(message),
        RecordingError::Source { source, .. } => sample_error(source, message),
        RecordingError::Receiver(r) => receiver_error(r),
        RecordingError::Assistance(_) | RecordingError::Output(_) => PyOSError::new_err(message),
        RecordingError::BuiltinNav(_) => Error::new_err(message),
    }
}

/// The Python exception of a snapshot set that cannot be run: a missing input, navigation or
/// truth file is `FileNotFoundError`, another unreadable one `OSError`, a bad option or missing
/// navigation data `ValueError`.
pub fn snapshot_error(e: &SnapshotError) -> PyErr {
    let message = error_message(e);
    match e {
        SnapshotError::Input { path, .. } | SnapshotError::Nav { path, .. } => {
            if path.exists() {
                PyOSError::new_err(message)
            } else {
                PyFileNotFoundError::new_err(message)
            }
        }
        SnapshotError::NoEphemerides | SnapshotError::Option(_) => PyValueError::new_err(message),
        SnapshotError::Output(_) | SnapshotError::Plot(_) => PyOSError::new_err(message),
    }
}

/// Creates the output directory `dir` (and its parents), or an `OSError` naming it.
pub(crate) fn create_out_dir(dir: &std::path::Path) -> pyo3::PyResult<()> {
    std::fs::create_dir_all(dir).map_err(|e| {
        pyo3::exceptions::PyOSError::new_err(format!(
            "cannot create the output directory {}: {e}",
            dir.display()
        ))
    })
}
