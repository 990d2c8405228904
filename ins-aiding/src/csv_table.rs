//! Shared reading of the small CSV logs (`--dr`, `--accel`): header column lookup and
//! line-numbered, finite-number parsing of each row.

use crate::dr_error::DrError;
use std::io::Write;
use std::path::Path;

/// An open CSV log with its header.
pub(crate) struct CsvTable {
    what: &'static str,
    path: String,
    reader: csv::Reader<std::io::Cursor<Vec<u8>>>,
    /// Byte offsets of the starts of lines 2, 3, ... (for line numbers: the csv crate does not
    /// count blank lines).
    line_starts: Vec<u64>,
    /// Per line (0-based): blank or a `#` comment (the csv crate may point a record's position at
    /// the comment or blank lines before it).
    skippable: Vec<bool>,
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
        // Logs are small (a 10 Hz drive of an hour is about 1 MB): read at once.
        let bytes = std::fs::read(path).map_err(|e| DrError::Io {
            what,
            path: p.clone(),
            message: e.to_string(),
        })?;
        let line_starts = bytes
            .iter()
            .enumerate()
            .filter(|(_, &b)| b == b'\n')
            .map(|(i, _)| i as u64 + 1)
            .collect();
        let skippable = bytes
            .split(|&b| b == b'\n')
            .map(|l| {
                let t = l.trim_ascii();
                t.is_empty() || t.starts_with(b"#")
            })
            .collect();
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(std::io::Cursor::new(bytes));
        let headers = reader
            .headers()
            .map_err(|e| DrError::Row {
                what,
                path: p.clone(),
                line: 1,
                message: e.to_string(),
            })?
            .clone();
        let mut table = CsvTable {
            what,
            path: p,
            reader,
            line_starts,
            skippable,
            headers: headers.clone(),
            header_line: 1,
        };
        table.header_line = headers
            .position()
            .map_or(1, |pos| table.line_of(pos.byte()));
        Ok(table)
    }

    /// The 1-based line holding byte `offset`.
    fn line_of(&self, offset: u64) -> usize {
        let mut i = self.line_starts.partition_point(|&s| s <= offset);
        while self.skippable.get(i).copied().unwrap_or(false) {
            i += 1;
        }
        i + 1
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
                    let line = e.position().map_or(fallback, |p| self.line_of(p.byte()));
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
                .map_or(fallback, |p| self.line_of(p.byte()));
            let row = CsvRow {
                table: self,
                record: record.clone(),
                line,
            };
            f(&row)?;
            i += 1;
        }
    }

    /// Reads every row as `(t_s, value)`: `t_s` from column `t_col` must increase strictly, and
    /// `parse` makes the value. At least 2 rows: `too_few(n)` words the error otherwise.
    pub fn read_series<T>(
        &mut self,
        t_col: usize,
        mut parse: impl FnMut(&CsvRow<'_>) -> Result<T, DrError>,
        too_few: impl Fn(usize) -> String,
    ) -> Result<Vec<(f64, T)>, DrError> {
        let mut rows: Vec<(f64, T)> = Vec::new();
        let mut last_line = self.header_line;
        self.for_each_row(|row| {
            last_line = row.line;
            let t_s = row.number(t_col, "t_s")?;
            let value = parse(row)?;
            if let Some(&(last, _)) = rows.last() {
                if t_s <= last {
                    return Err(row.error(format!(
                        "t_s = {t_s} does not increase (previous {last}): sort the file by t_s and remove duplicate rows"
                    )));
                }
            }
            rows.push((t_s, value));
            Ok(())
        })?;
        if rows.len() < 2 {
            return Err(self.error(last_line, too_few(rows.len())));
        }
        Ok(rows)
    }
}

/// Writes a log: the `header` line, then one line per item of `rows` (each without its newline).
/// Errors name `what` and the path.
pub(crate) fn write_lines(
    path: &Path,
    what: &'static str,
    header: &str,
    rows: impl IntoIterator<Item = String>,
) -> Result<(), DrError> {
    let werr = |e: std::io::Error| DrError::Write {
        what,
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let f = std::fs::File::create(path).map_err(werr)?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(w, "{header}").map_err(werr)?;
    for row in rows {
        writeln!(w, "{row}").map_err(werr)?;
    }
    w.flush().map_err(werr)
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
