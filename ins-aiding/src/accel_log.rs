//! The accelerometer log (`--accel FILE.csv`): longitudinal specific force at any rate (seed 002).
//!
//! Header required, columns in any order, extra columns ignored: `t_s` (seconds from the first IF
//! sample, strictly increasing) and `a_long_mps2` (longitudinal accelerometer output, m/s^2,
//! forward positive; on a slope it includes `g sin(pitch)`). Every value must be a finite number;
//! errors name the file, the line and what to do.

use crate::csv_table::{write_lines, CsvTable};
use crate::dr_error::DrError;
use std::path::Path;

const WHAT: &str = "accelerometer log";

/// One accelerometer output.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AccelSample {
    /// Seconds from the first IF sample.
    pub t_s: f64,
    /// Longitudinal accelerometer output (specific force), m/s^2.
    pub a_long_mps2: f64,
}

/// A validated accelerometer log: at least 2 rows, finite values, `t_s` strictly increasing.
#[derive(Debug, Clone)]
pub struct AccelLog {
    samples: Vec<AccelSample>,
}

impl AccelLog {
    /// Checks samples already in memory (e.g. from [`crate::simulate_accel`]) like a file.
    pub fn from_samples(samples: Vec<AccelSample>) -> Result<AccelLog, DrError> {
        if samples.len() < 2 {
            return Err(DrError::Config(format!(
                "an accelerometer log needs at least 2 samples (found {})",
                samples.len()
            )));
        }
        for (i, s) in samples.iter().enumerate() {
            if !(s.t_s.is_finite() && s.a_long_mps2.is_finite()) {
                return Err(DrError::Config(format!(
                    "accelerometer sample {i}: t_s and a_long_mps2 must be finite"
                )));
            }
            if i > 0 && s.t_s <= samples[i - 1].t_s {
                return Err(DrError::Config(format!(
                    "accelerometer sample {i}: t_s = {} does not increase",
                    s.t_s
                )));
            }
        }
        Ok(AccelLog { samples })
    }

    /// The samples, in time order.
    pub fn samples(&self) -> &[AccelSample] {
        &self.samples
    }
}

/// Reads and validates an accelerometer log (see the module documentation).
pub fn read_accel_csv(path: &Path) -> Result<AccelLog, DrError> {
    let mut table = CsvTable::open(path, WHAT)?;
    let t_col = table.column("t_s");
    let a_col = table.column("a_long_mps2");
    let (Some(t_col), Some(a_col)) = (t_col, a_col) else {
        return Err(table.header_error(
            "the header must name t_s and a_long_mps2 (longitudinal acceleration, m/s^2)".into(),
        ));
    };
    let rows = table.read_series(
        t_col,
        |row| row.number(a_col, "a_long_mps2"),
        |n| format!("an accelerometer log needs at least 2 rows (found {n})"),
    )?;
    let samples = rows
        .into_iter()
        .map(|(t_s, a_long_mps2)| AccelSample { t_s, a_long_mps2 })
        .collect();
    Ok(AccelLog { samples })
}

/// Writes samples as an accelerometer log [`read_accel_csv`] reads back (`t_s,a_long_mps2`, to
/// 1e-9).
pub fn write_accel_csv(path: &Path, samples: &[AccelSample]) -> Result<(), DrError> {
    let rows = samples
        .iter()
        .map(|s| format!("{:.9},{:.9}", s.t_s, s.a_long_mps2));
    write_lines(path, WHAT, "t_s,a_long_mps2", rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error_of(text: &str) -> String {
        let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
        std::fs::write(f.path(), text).unwrap_or_else(|e| panic!("{e}"));
        read_accel_csv(f.path())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    }

    #[test]
    fn round_trip() {
        let samples: Vec<AccelSample> = (0..200)
            .map(|k| AccelSample {
                t_s: 0.02 * f64::from(k),
                a_long_mps2: (0.37 * f64::from(k)).sin() - 0.123456789,
            })
            .collect();
        let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
        write_accel_csv(f.path(), &samples).unwrap_or_else(|e| panic!("{e}"));
        let log = read_accel_csv(f.path()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(log.samples().len(), samples.len());
        for (a, b) in log.samples().iter().zip(&samples) {
            assert!((a.t_s - b.t_s).abs() < 1e-9 && (a.a_long_mps2 - b.a_long_mps2).abs() < 1e-9);
        }
        assert!(AccelLog::from_samples(samples).is_ok());
    }

    #[test]
    fn bad_files_name_the_line() {
        let cases = [
            ("t_s,a_mps2\n0,0\n0.1,0\n", "line 1", "a_long_mps2"),
            (
                "t_s,a_long_mps2\n0,0\n0.1,NaN\n",
                "line 3",
                "a_long_mps2 = `NaN`",
            ),
            ("t_s,a_long_mps2\n0,0\n0.1,\n", "line 3", "missing"),
            (
                "t_s,a_long_mps2\n0,0\n0.1,0\n0.05,0\n",
                "line 4",
                "does not increase",
            ),
            (
                "t_s,a_long_mps2\n0,0\n0.1,0,7\n",
                "line 3",
                "3 values but the header has 2",
            ),
            ("t_s,a_long_mps2\n0,0\n", "line 2", "at least 2 rows"),
        ];
        for (text, line, what) in cases {
            let e = error_of(text);
            assert!(
                e.contains(line) && e.contains(what) && e.contains("accelerometer log file"),
                "{text:?}: got `{e}`"
            );
        }
        let bad = AccelLog::from_samples(vec![
            AccelSample {
                t_s: 0.0,
                a_long_mps2: 0.0,
            },
            AccelSample {
                t_s: 0.1,
                a_long_mps2: f64::INFINITY,
            },
        ]);
        assert!(bad.is_err());
    }
}
