//! Errors of the dead-reckoning inputs, sensor models, parameter files and fusion filters.

/// Dead-reckoning and accelerometer problems: files (with the line), configurations, filter input.
#[derive(Debug, thiserror::Error)]
pub enum DrError {
    /// A file cannot be read.
    #[error("cannot read {what} file {path}: {message}")]
    Io {
        /// What the file is ("DR log", "accelerometer log", "DR parameter").
        what: &'static str,
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// A row or the header of a CSV log is wrong.
    #[error("{what} file {path} line {line}: {message}")]
    Row {
        /// What the file is.
        what: &'static str,
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong and what to do.
        message: String,
    },
    /// A file cannot be written.
    #[error("cannot write {what} file {path}: {message}")]
    Write {
        /// What the file is.
        what: &'static str,
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// A sensor-model or filter setting, or a parameter file's content, is invalid.
    #[error("{0}")]
    Config(String),
    /// A value handed to a filter or to the mechanization is invalid (NaN, not positive definite).
    #[error("DR filter input: {0}")]
    Input(String),
}
