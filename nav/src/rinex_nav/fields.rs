//! Fixed-column field access for RINEX lines (RINEX 2.11 and 3.0x format descriptions:
//! Fortran `Dw.d`, `Fw.d` and `Iw` fields, with `D` or `E` exponents).

use super::RinexError;

/// Text of columns `start..start+len` (0-based, clipped to the line length), trimmed.
pub(crate) fn column<'a>(
    line: &'a str,
    line_no: usize,
    start: usize,
    len: usize,
    field: &'static str,
) -> Result<&'a str, RinexError> {
    let bytes = line.as_bytes();
    if start >= bytes.len() {
        return Ok("");
    }
    let end = (start + len).min(bytes.len());
    std::str::from_utf8(&bytes[start..end])
        .map(str::trim)
        .map_err(|_| RinexError::Field {
            line: line_no,
            col_start: start + 1,
            col_end: start + len,
            field,
            text: String::from_utf8_lossy(&bytes[start..end]).into_owned(),
            reason: "non-ASCII characters",
        })
}

/// Parses a Fortran floating-point field (`D` or `E` exponent). A blank field reads as 0, as
/// RINEX allows for missing trailing values.
pub(crate) fn float(
    line: &str,
    line_no: usize,
    start: usize,
    len: usize,
    field: &'static str,
) -> Result<f64, RinexError> {
    let text = column(line, line_no, start, len, field)?;
    if text.is_empty() {
        return Ok(0.0);
    }
    parse_fortran_f64(text).ok_or_else(|| RinexError::Field {
        line: line_no,
        col_start: start + 1,
        col_end: start + len,
        field,
        text: text.to_string(),
        reason: "expected a Fortran number such as 0.123456789012D+03",
    })
}

/// Parses `0.1211D-07`, `-.5E+2`, `147456`; rejects non-finite values and embedded blanks.
pub(crate) fn parse_fortran_f64(text: &str) -> Option<f64> {
    let s: String = text
        .trim()
        .chars()
        .map(|c| if c == 'D' || c == 'd' { 'E' } else { c })
        .collect();
    if s.is_empty() || !s.chars().all(|c| c.is_ascii_digit() || "+-.Ee".contains(c)) {
        return None;
    }
    s.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Parses an integer field (blank reads as `None`).
pub(crate) fn int(
    line: &str,
    line_no: usize,
    start: usize,
    len: usize,
    field: &'static str,
) -> Result<Option<i64>, RinexError> {
    let text = column(line, line_no, start, len, field)?;
    if text.is_empty() {
        return Ok(None);
    }
    text.parse::<i64>()
        .map(Some)
        .map_err(|_| RinexError::Field {
            line: line_no,
            col_start: start + 1,
            col_end: start + len,
            field,
            text: text.to_string(),
            reason: "expected an integer",
        })
}

/// Header label (columns 61-80), trimmed; empty if the line is shorter.
pub(crate) fn label(line: &str) -> &str {
    line.get(60..).map_or("", str::trim)
}
