//! Shared reading of the small CSV logs (`--dr`, `--accel`): header column lookup and
//! line-numbered, finite-number parsing of each row.

use crate::dr_error::DrError;
use std::path::Path;

/// An open CSV log with its header.
pub(crate) struct CsvTable {
    what: &'static str,
    path: String,
    reader: csv::Reader<std::fs::File>,
    headers: csv::StringRecord,
    header_line: usize,
}

/// One data row with its 1-based line number.
pub(crate) struct CsvRow<'a> {
    table: &'a CsvTable,
    record: csv::StringRecord,
    /// 1-based line number in the file.
    pub line: usize,
}

impl CsvTable {
    /// Opens `path` (`#` comments, values trimmed) and reads its header.
    pub fn open(path: &Path, what: &'static str) -> Result<CsvTable, DrError> {
        let p = path.display().to_string();
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_path(path)
            .map_err(|e| DrError::Io {
                what,
                path: p.clone(),
                message: e.to_string(),
            })?;
        let headers = reader
            .headers()
            .map_err(|e| DrError::Row {
                what,
                path: p.clone(),
                line: 1,
                message: e.to_string(),
            })?
            .clone();
        let header_line = headers
            .position()
            .map_or(1, |pos| usize::try_from(pos.line()).unwrap_or(1));
        Ok(CsvTable {
            what,
            path: p,
            reader,
            headers,
            header_line,
        })
    }

    /// The index of column `name`, if the header has it.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }

    /// An error on `line`.
    pub fn error(&self, line: usize, message: String) -> DrError {
        DrError::Row {
            what: self.what,
            path: self.path.clone(),
            line,
            message,
        }
    }

    /// An error on the header line.
    pub fn header_error(&self, message: String) -> DrError {
        self.error(self.header_line, message)
    }

    /// The header line number.
    pub fn header_line(&self) -> usize {
        self.header_line
    }

    /// Calls `f` on every data row, in order, stopping at the first error.
    pub fn for_each_row(
        &mut self,
        mut f: impl FnMut(&CsvRow<'_>) -> Result<(), DrError>,
    ) -> Result<(), DrError> {
        let mut record = csv::StringRecord::new();
        let mut i = 0usize;
        loop {
            let fallback = self.header_line + 1 + i;
            let more = match self.reader.read_record(&mut record) {
                Ok(more) => more,
                Err(e) => {
                    let line = e
                        .position()
                        .map_or(fallback, |p| usize::try_from(p.line()).unwrap_or(fallback));
                    let message = match e.kind() {
                        csv::ErrorKind::UnequalLengths {
                            expected_len, len, ..
                        } => format!(
                            "{len} values but the header has {expected_len} columns: every row needs one value per header column"
                        ),
                        _ => e.to_string(),
                    };
                    return Err(self.error(line, message));
                }
            };
            if !more {
                return Ok(());
            }
            let line = record
                .position()
                .map_or(fallback, |p| usize::try_from(p.line()).unwrap_or(fallback));
            let row = CsvRow {
                table: self,
                record: record.clone(),
                line,
            };
            f(&row)?;
            i += 1;
        }
    }
}

impl CsvRow<'_> {
    /// The finite number in column `col` (named `name` in messages).
    pub fn number(&self, col: usize, name: &str) -> Result<f64, DrError> {
        let f = self.record.get(col).unwrap_or("");
        if f.is_empty() {
            return Err(self.error(format!("`{name}` is missing: fill it in or delete the row")));
        }
        f.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                self.error(format!(
                    "{name} = `{f}` is not a finite number: fix or delete the row"
                ))
            })
    }

    /// An error on this row.
    pub fn error(&self, message: String) -> DrError {
        self.table.error(self.line, message)
    }
}
