//! The dead-reckoning log (`--dr FILE.csv`): a yaw-rate gyro and an odometer (seed 000).
//!
//! Header required, columns in any order, extra columns ignored. `t_s` (seconds from the first IF
//! sample, strictly increasing) and either
//! - raw sensor outputs as in seed 000: `gyro_v` (gyro output voltage averaged over the interval
//!   since the previous row, V) and `odo_pulses` (odometer pulses counted since the previous row,
//!   `>= 0`; a fraction is allowed for interpolated logs), or
//! - engineering units: `yaw_rate_dps` (heading rate, clockwise positive, mean over the interval
//!   since the previous row, deg/s) and `speed_mps` (mean speed over that interval, m/s, `>= 0`).
//!
//! Which one is detected from the header; a file with both sets is refused (say which you mean by
//! deleting the other pair). The first row's interval values are not used (there is no previous
//! row). Every value must be a finite number; errors name the file, the line and what to do.
//! The nominal sensor parameters (`Sf_G` deg/s/V, `V_nom` V, `Sf_N` m/pulse) are not in the file:
//! they come from the configuration ([`crate::DrParams`]).

use crate::csv_table::{write_lines, CsvTable};
use crate::dr_error::DrError;
use std::path::Path;

const WHAT: &str = "DR log";

/// One DR sensor reading, for the interval since the previous sample.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum DrReading {
    /// Raw outputs (seed 000 eqs. 2-3).
    Raw {
        /// Gyro output voltage, mean over the interval, V.
        gyro_v: f64,
        /// Odometer pulses counted over the interval.
        odo_pulses: f64,
    },
    /// Engineering units.
    Engineering {
        /// Heading rate (clockwise from north positive), mean over the interval, deg/s.
        yaw_rate_dps: f64,
        /// Speed, mean over the interval, m/s.
        speed_mps: f64,
    },
}

impl DrReading {
    /// True for [`DrReading::Raw`].
    pub fn is_raw(&self) -> bool {
        matches!(self, DrReading::Raw { .. })
    }

    fn check(&self) -> Result<(), String> {
        match *self {
            DrReading::Raw { gyro_v, odo_pulses } => {
                if !gyro_v.is_finite() || !odo_pulses.is_finite() {
                    return Err("gyro_v and odo_pulses must be finite numbers".into());
                }
                if odo_pulses < 0.0 {
                    return Err(format!(
                        "odo_pulses = {odo_pulses} is negative: give the pulse count since the previous row (>= 0)"
                    ));
                }
            }
            DrReading::Engineering {
                yaw_rate_dps,
                speed_mps,
            } => {
                if !yaw_rate_dps.is_finite() || !speed_mps.is_finite() {
                    return Err("yaw_rate_dps and speed_mps must be finite numbers".into());
                }
                if speed_mps < 0.0 {
                    return Err(format!(
                        "speed_mps = {speed_mps} is negative: the odometer speed is a magnitude (>= 0)"
                    ));
                }
            }
        }
        Ok(())
    }
}

/// One row of a DR log.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DrSample {
    /// Seconds from the first IF sample (end of the interval the reading covers).
    pub t_s: f64,
    /// The sensor outputs over the interval since the previous row.
    pub reading: DrReading,
}

/// A validated DR log: at least 2 rows, `t_s` finite and strictly increasing, one kind of reading
/// (all raw or all engineering), finite values, no negative pulse count or speed.
#[derive(Debug, Clone)]
pub struct DrLog {
    samples: Vec<DrSample>,
}

impl DrLog {
    /// Checks samples already in memory (e.g. from [`crate::simulate_dr`]) like a file.
    pub fn from_samples(samples: Vec<DrSample>) -> Result<DrLog, DrError> {
        if samples.len() < 2 {
            return Err(DrError::Config(format!(
                "a DR log needs at least 2 samples (found {})",
                samples.len()
            )));
        }
        let raw = samples[0].reading.is_raw();
        for (i, s) in samples.iter().enumerate() {
            let bad = |m: String| Err(DrError::Config(format!("DR sample {i}: {m}")));
            if !s.t_s.is_finite() {
                return bad(format!("t_s = {} is not finite", s.t_s));
            }
            if let Err(m) = s.reading.check() {
                return bad(m);
            }
            if s.reading.is_raw() != raw {
                return bad("raw and engineering readings are mixed: use one kind".into());
            }
            if i > 0 && s.t_s <= samples[i - 1].t_s {
                return bad(format!(
                    "t_s = {} does not increase (previous {})",
                    s.t_s,
                    samples[i - 1].t_s
                ));
            }
        }
        Ok(DrLog { samples })
    }

    /// The samples, in time order.
    pub fn samples(&self) -> &[DrSample] {
        &self.samples
    }

    /// True when the log holds raw `gyro_v`/`odo_pulses` readings.
    pub fn is_raw(&self) -> bool {
        self.samples[0].reading.is_raw()
    }

    /// First and last `t_s`.
    pub fn time_span_s(&self) -> (f64, f64) {
        (
            self.samples[0].t_s,
            self.samples[self.samples.len() - 1].t_s,
        )
    }
}

/// Reads and validates a DR log (see the module documentation for the format).
pub fn read_dr_csv(path: &Path) -> Result<DrLog, DrError> {
    let mut table = CsvTable::open(path, WHAT)?;
    let t_col = table.column("t_s").ok_or_else(|| {
        table.header_error(
            "no column `t_s`: the header must name t_s and either gyro_v,odo_pulses (raw) or yaw_rate_dps,speed_mps (engineering units)".into(),
        )
    })?;
    let raw_cols = (table.column("gyro_v"), table.column("odo_pulses"));
    let eng_cols = (table.column("yaw_rate_dps"), table.column("speed_mps"));
    let (raw, a, b) = match (raw_cols, eng_cols) {
        ((Some(_), Some(_)), (Some(_), _) | (_, Some(_))) => {
            return Err(table.header_error(
                "both raw (gyro_v, odo_pulses) and engineering (yaw_rate_dps, speed_mps) columns: keep one pair".into(),
            ))
        }
        ((Some(g), Some(o)), _) => (true, g, o),
        (_, (Some(y), Some(s))) => (false, y, s),
        _ => {
            return Err(table.header_error(
                "the header needs gyro_v and odo_pulses (raw sensor outputs) or yaw_rate_dps and speed_mps (engineering units)".into(),
            ))
        }
    };
    let (na, nb) = if raw {
        ("gyro_v", "odo_pulses")
    } else {
        ("yaw_rate_dps", "speed_mps")
    };
    let rows = table.read_series(
        t_col,
        |row| {
            let x = row.number(a, na)?;
            let y = row.number(b, nb)?;
            let reading = if raw {
                DrReading::Raw {
                    gyro_v: x,
                    odo_pulses: y,
                }
            } else {
                DrReading::Engineering {
                    yaw_rate_dps: x,
                    speed_mps: y,
                }
            };
            reading.check().map_err(|m| row.error(m))?;
            Ok(reading)
        },
        |n| {
            format!(
                "a DR log needs at least 2 rows (found {n}): log the sensors over the whole drive"
            )
        },
    )?;
    let samples = rows
        .into_iter()
        .map(|(t_s, reading)| DrSample { t_s, reading })
        .collect();
    Ok(DrLog { samples })
}

/// Writes samples as a DR log [`read_dr_csv`] reads back: `t_s,gyro_v,odo_pulses` or
/// `t_s,yaw_rate_dps,speed_mps` after the kind of the first sample (all must be of that kind);
/// times to 1e-9 s, voltages to 1e-9 V, pulses and rates to 1e-9.
pub fn write_dr_csv(path: &Path, samples: &[DrSample]) -> Result<(), DrError> {
    let raw = samples.first().is_none_or(|s| s.reading.is_raw());
    if let Some(i) = samples.iter().position(|s| s.reading.is_raw() != raw) {
        return Err(DrError::Write {
            what: WHAT,
            path: path.display().to_string(),
            message: format!(
                "sample {i} is of another kind (raw/engineering) than the first: a log holds one kind"
            ),
        });
    }
    let header = if raw {
        "t_s,gyro_v,odo_pulses"
    } else {
        "t_s,yaw_rate_dps,speed_mps"
    };
    let rows = samples.iter().map(|s| {
        let (a, b) = match s.reading {
            DrReading::Raw { gyro_v, odo_pulses } => (gyro_v, odo_pulses),
            DrReading::Engineering {
                yaw_rate_dps,
                speed_mps,
            } => (yaw_rate_dps, speed_mps),
        };
        format!("{:.9},{a:.9},{b:.9}", s.t_s)
    });
    write_lines(path, WHAT, header, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(text: &str) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
        std::fs::write(f.path(), text).unwrap_or_else(|e| panic!("{e}"));
        f
    }

    fn error_of(text: &str) -> String {
        let f = write(text);
        read_dr_csv(f.path())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    }

    #[test]
    fn raw_and_engineering_logs_round_trip() {
        let raw: Vec<DrSample> = (0..50)
            .map(|k| DrSample {
                t_s: 0.1 * f64::from(k) + 0.123456789,
                reading: DrReading::Raw {
                    gyro_v: 2.5 + 0.01 * f64::from(k).sin(),
                    odo_pulses: f64::from(k % 17),
                },
            })
            .collect();
        let eng: Vec<DrSample> = raw
            .iter()
            .map(|s| DrSample {
                t_s: s.t_s,
                reading: DrReading::Engineering {
                    yaw_rate_dps: -3.25 + s.t_s,
                    speed_mps: 12.5 + 0.1 * s.t_s,
                },
            })
            .collect();
        for samples in [raw, eng] {
            let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
            write_dr_csv(f.path(), &samples).unwrap_or_else(|e| panic!("{e}"));
            let log = read_dr_csv(f.path()).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(log.samples().len(), samples.len());
            assert_eq!(log.is_raw(), samples[0].reading.is_raw());
            for (a, b) in log.samples().iter().zip(&samples) {
                assert!((a.t_s - b.t_s).abs() < 1e-9);
                let pair = |r: &DrReading| match *r {
                    DrReading::Raw { gyro_v, odo_pulses } => (gyro_v, odo_pulses),
                    DrReading::Engineering {
                        yaw_rate_dps,
                        speed_mps,
                    } => (yaw_rate_dps, speed_mps),
                };
                let (x, y) = (pair(&a.reading), pair(&b.reading));
                assert!((x.0 - y.0).abs() < 1e-9 && (x.1 - y.1).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn columns_in_any_order_with_comments_and_extra_columns() {
        let f = write("# a DR log\nodo_pulses,note,t_s,gyro_v\n0,a,0.0,2.5\n3,b,0.1,2.6\n");
        let log = read_dr_csv(f.path()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            log.samples()[1],
            DrSample {
                t_s: 0.1,
                reading: DrReading::Raw {
                    gyro_v: 2.6,
                    odo_pulses: 3.0
                }
            }
        );
        assert_eq!(log.time_span_s(), (0.0, 0.1));
    }

    #[test]
    fn bad_files_name_the_line_and_the_fix() {
        let cases = [
            (
                "gyro_v,odo_pulses\n2.5,0\n2.5,1\n",
                "line 1",
                "no column `t_s`",
            ),
            (
                "t_s,gyro_v\n0,2.5\n0.1,2.5\n",
                "line 1",
                "needs gyro_v and odo_pulses",
            ),
            (
                "t_s,gyro_v,odo_pulses,speed_mps\n0,2.5,0,1\n0.1,2.5,1,1\n",
                "line 1",
                "keep one pair",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0.1,NaN,1\n",
                "line 3",
                "gyro_v = `NaN` is not a finite number",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0.1,2.5,inf\n",
                "line 3",
                "odo_pulses = `inf`",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0.1,2.5,x\n",
                "line 3",
                "not a finite number",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0.1,,1\n",
                "line 3",
                "`gyro_v` is missing",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0.1,2.5,-1\n",
                "line 3",
                "negative",
            ),
            (
                "t_s,yaw_rate_dps,speed_mps\n0,0,0\n0.1,1,-2\n",
                "line 3",
                "speed_mps = -2 is negative",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0.2,2.5,1\n0.1,2.5,1\n",
                "line 4",
                "does not increase",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0,2.5,1\n",
                "line 3",
                "remove duplicate rows",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n0.1,2.5\n",
                "line 3",
                "2 values but the header has 3",
            ),
            (
                "t_s,gyro_v,odo_pulses\n0,2.5,0\n",
                "line 2",
                "at least 2 rows",
            ),
            (
                "# c\n\nt_s,gyro_v,odo_pulses\n0,2.5,0\n# c\n0.1,nan,0\n",
                "line 6",
                "`nan`",
            ),
        ];
        for (text, line, what) in cases {
            let e = error_of(text);
            assert!(
                e.contains(line) && e.contains(what),
                "{text:?}: got `{e}`, expected {line} and `{what}`"
            );
            assert!(e.contains("DR log file"), "{e}");
        }
        let missing = read_dr_csv(Path::new("/nonexistent/dr.csv"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            missing.contains("cannot read DR log file /nonexistent/dr.csv"),
            "{missing}"
        );
    }

    #[test]
    fn in_memory_logs_are_checked_like_files() {
        let s = |t_s: f64, gyro_v: f64| DrSample {
            t_s,
            reading: DrReading::Raw {
                gyro_v,
                odo_pulses: 1.0,
            },
        };
        assert!(DrLog::from_samples(vec![s(0.0, 2.5), s(0.1, 2.5)]).is_ok());
        assert!(DrLog::from_samples(vec![s(0.0, 2.5)]).is_err());
        assert!(DrLog::from_samples(vec![s(0.0, 2.5), s(0.0, 2.5)]).is_err());
        assert!(DrLog::from_samples(vec![s(0.0, 2.5), s(0.1, f64::NAN)]).is_err());
        let eng = DrSample {
            t_s: 0.2,
            reading: DrReading::Engineering {
                yaw_rate_dps: 0.0,
                speed_mps: 1.0,
            },
        };
        let mixed = DrLog::from_samples(vec![s(0.0, 2.5), s(0.1, 2.5), eng]);
        assert!(mixed.err().is_some_and(|e| e.to_string().contains("mixed")));
        let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
        assert!(write_dr_csv(f.path(), &[s(0.0, 2.5), eng]).is_err());
    }
}
