//! Errors of the RINEX navigation reader. Every variant about file content carries the 1-based
//! line number; [`RinexError::InFile`] adds the file path.

use std::path::PathBuf;

/// What went wrong while reading a RINEX GPS navigation file, where, and what to do.
#[derive(Debug, thiserror::Error)]
pub enum RinexError {
    /// The file could not be opened or read.
    #[error(
        "cannot read RINEX navigation file `{path}`: {source}; check the path and permissions"
    )]
    Io {
        /// File that failed.
        path: PathBuf,
        /// Underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A content error inside the file at `path`.
    #[error("{path}: {source}")]
    InFile {
        /// File containing the error.
        path: PathBuf,
        /// The content error (with its line number).
        #[source]
        source: Box<RinexError>,
    },
    /// The input has no `RINEX VERSION / TYPE` line.
    #[error("line 1: expected a `RINEX VERSION / TYPE` header line (label in columns 61-80); this is not a RINEX navigation file")]
    NotRinex,
    /// The header never ends.
    #[error(
        "line {line}: end of input before `END OF HEADER`; the file is truncated or not RINEX"
    )]
    MissingHeaderEnd {
        /// Last line read.
        line: usize,
    },
    /// A RINEX version this reader does not handle.
    #[error("line {line}: RINEX version `{version}` is not supported; convert the file to RINEX 2.x or 3.x navigation (e.g. with RTKLIB convbin or gfzrnx)")]
    UnsupportedVersion {
        /// Line number (1-based).
        line: usize,
        /// Version text as found.
        version: String,
    },
    /// The file is a navigation file for another system only.
    #[error("line {line}: file type `{found}` is not GPS navigation data (need type `N` with system `G` or `M`); use the GPS (or mixed) broadcast file")]
    NotGpsNav {
        /// Line number (1-based).
        line: usize,
        /// Type/system text as found.
        found: String,
    },
    /// A numeric field could not be read.
    #[error("line {line}, columns {col_start}-{col_end}: cannot read {field} from `{text}`: {reason}; fix or delete this record")]
    Field {
        /// Line number (1-based).
        line: usize,
        /// First column of the field (1-based).
        col_start: usize,
        /// Last column of the field (1-based, inclusive).
        col_end: usize,
        /// Name of the field.
        field: &'static str,
        /// The offending text.
        text: String,
        /// Why it was rejected.
        reason: &'static str,
    },
    /// A value was read but is physically or ICD-wise impossible.
    #[error("line {line}: {field} = {value} is out of range (allowed: {allowed}); the record is corrupt, fix or delete it")]
    OutOfRange {
        /// Line number (1-based).
        line: usize,
        /// Name of the field.
        field: &'static str,
        /// Value as read.
        value: f64,
        /// Allowed range, in words.
        allowed: &'static str,
    },
    /// A record ends before all its lines.
    #[error("line {line}: record for {sat} starting at line {start_line} needs {expected} lines but the file ends after {found}; the file is truncated")]
    TruncatedRecord {
        /// Line number where the input ended.
        line: usize,
        /// Line number of the record's epoch line.
        start_line: usize,
        /// Satellite identifier text.
        sat: String,
        /// Lines the record needs.
        expected: usize,
        /// Lines available.
        found: usize,
    },
    /// A RINEX 3 record starts with an unknown system letter.
    #[error("line {line}: unknown satellite system letter `{system}` at the start of a record (expected one of G R E C J I S); the record layout is broken near here")]
    UnknownSystem {
        /// Line number (1-based).
        line: usize,
        /// The letter found.
        system: char,
    },
}

impl RinexError {
    /// 1-based line number of a content error, if there is one.
    pub fn line(&self) -> Option<usize> {
        match self {
            RinexError::Io { .. } => None,
            RinexError::InFile { source, .. } => source.line(),
            RinexError::NotRinex => Some(1),
            RinexError::MissingHeaderEnd { line }
            | RinexError::UnsupportedVersion { line, .. }
            | RinexError::NotGpsNav { line, .. }
            | RinexError::Field { line, .. }
            | RinexError::OutOfRange { line, .. }
            | RinexError::TruncatedRecord { line, .. }
            | RinexError::UnknownSystem { line, .. } => Some(*line),
        }
    }
}
