//! The INS input file (`--ins FILE.csv`).
//!
//! Columns (header required, any order, extra columns ignored): `t_s` (seconds from the first
//! sample of the IF recording), `x_m,y_m,z_m` (ECEF position), `vx_mps,vy_mps,vz_mps` (ECEF
//! velocity), and optionally `gps_tow_s` as an alternative time base. Rows must be in time
//! order, at 10 Hz or faster; a gap longer than `max_gap_s` is an error (the aiding would
//! extrapolate blindly). Between rows, position follows a cubic Hermite curve through the
//! positions and velocities, and velocity its derivative, so both are continuous.

use nalgebra::Vector3;
use std::path::Path;

/// INS file problems, with the line they were found on.
#[derive(Debug, thiserror::Error)]
pub enum InsError {
    /// The file cannot be read.
    #[error("cannot read INS file {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// A row or the header is wrong.
    #[error("INS file {path} line {line}: {message}")]
    Row {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong and what to do.
        message: String,
    },
}

/// One INS output: time, ECEF position and velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InsSample {
    /// Seconds from the first IF sample.
    pub t_s: f64,
    /// GPS time of week, if the file has it.
    pub gps_tow_s: Option<f64>,
    /// ECEF position, m.
    pub pos_m: Vector3<f64>,
    /// ECEF velocity, m/s.
    pub vel_mps: Vector3<f64>,
}

/// A validated INS track, interpolated on demand.
#[derive(Debug, Clone)]
pub struct InsTrack {
    samples: Vec<InsSample>,
}

/// Reads and validates an INS file: times strictly increasing, no gap above `max_gap_s`
/// (default choice: 0.5 s, i.e. a 10 Hz file may lose four rows), finite values.
pub fn read_ins_csv(path: &Path, max_gap_s: f64) -> Result<InsTrack, InsError> {
    let p = path.display().to_string();
    let row_err = |line: usize, message: String| InsError::Row {
        path: p.clone(),
        line,
        message,
    };
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|e| InsError::Io {
            path: p.clone(),
            message: e.to_string(),
        })?;
    let headers = rdr
        .headers()
        .map_err(|e| row_err(1, e.to_string()))?
        .clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let names = ["t_s", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps"];
    let mut idx = [0usize; 7];
    for (k, n) in names.iter().enumerate() {
        idx[k] = col(n).ok_or_else(|| {
            row_err(
                1,
                format!(
                    "no column `{n}`: the header must name t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps"
                ),
            )
        })?;
    }
    let tow_col = col("gps_tow_s");
    let mut samples: Vec<InsSample> = Vec::new();
    for (i, rec) in rdr.records().enumerate() {
        let line = i + 2;
        let rec = rec.map_err(|e| row_err(line, e.to_string()))?;
        let num = |c: usize| -> Result<f64, InsError> {
            let f = rec.get(c).unwrap_or("");
            f.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| row_err(line, format!("`{f}` is not a finite number")))
        };
        let mut v = [0.0; 7];
        for k in 0..7 {
            v[k] = num(idx[k])?;
        }
        let gps_tow_s = match tow_col {
            Some(c) => Some(num(c)?),
            None => None,
        };
        if let Some(last) = samples.last() {
            if v[0] <= last.t_s {
                return Err(row_err(
                    line,
                    format!(
                        "t_s = {} does not increase (previous {}): sort the file",
                        v[0], last.t_s
                    ),
                ));
            }
            if v[0] - last.t_s > max_gap_s {
                return Err(row_err(line, format!("gap of {:.3} s before this row (limit {max_gap_s} s): the INS must run at 10 Hz or faster without gaps", v[0] - last.t_s)));
            }
        }
        samples.push(InsSample {
            t_s: v[0],
            gps_tow_s,
            pos_m: Vector3::new(v[1], v[2], v[3]),
            vel_mps: Vector3::new(v[4], v[5], v[6]),
        });
    }
    if samples.len() < 2 {
        return Err(InsError::Row {
            path: p,
            line: samples.len() + 1,
            message: "an INS file needs at least 2 rows".into(),
        });
    }
    Ok(InsTrack { samples })
}

impl InsTrack {
    /// The time span covered, s.
    pub fn span_s(&self) -> (f64, f64) {
        (
            self.samples[0].t_s,
            self.samples[self.samples.len() - 1].t_s,
        )
    }

    /// Position and velocity at `t_s`, or None outside the file's span.
    pub fn at(&self, t_s: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let (t0, t1) = self.span_s();
        if !(t0..=t1).contains(&t_s) {
            return None;
        }
        let i = self
            .samples
            .partition_point(|s| s.t_s <= t_s)
            .clamp(1, self.samples.len() - 1);
        let (a, b) = (&self.samples[i - 1], &self.samples[i]);
        let h = b.t_s - a.t_s;
        let u = (t_s - a.t_s) / h;
        // Cubic Hermite basis and derivatives.
        let (u2, u3) = (u * u, u * u * u);
        let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
        let h10 = u3 - 2.0 * u2 + u;
        let h01 = -2.0 * u3 + 3.0 * u2;
        let h11 = u3 - u2;
        let d00 = (6.0 * u2 - 6.0 * u) / h;
        let d10 = 3.0 * u2 - 4.0 * u + 1.0;
        let d01 = (-6.0 * u2 + 6.0 * u) / h;
        let d11 = 3.0 * u2 - 2.0 * u;
        let pos = a.pos_m * h00 + a.vel_mps * (h * h10) + b.pos_m * h01 + b.vel_mps * (h * h11);
        let vel = a.pos_m * d00 + a.vel_mps * d10 + b.pos_m * d01 + b.vel_mps * d11;
        Some((pos, vel))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(text: &str) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
        std::fs::write(f.path(), text).unwrap_or_else(|e| panic!("{e}"));
        f
    }

    #[test]
    fn constant_acceleration_is_interpolated_exactly() {
        // p = p0 + v0 t + a t^2 / 2 is a cubic: Hermite through (p, v) at 10 Hz is exact.
        let (p0, v0, a) = (
            Vector3::new(1e6, 2e6, 3e6),
            Vector3::new(10.0, -5.0, 1.0),
            Vector3::new(0.5, 2.0, -1.0),
        );
        let mut text = String::from("t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n");
        for i in 0..30 {
            let t = f64::from(i) * 0.1;
            let p = p0 + v0 * t + a * (0.5 * t * t);
            let v = v0 + a * t;
            text.push_str(&format!(
                "{t},{},{},{},{},{},{}\n",
                p.x, p.y, p.z, v.x, v.y, v.z
            ));
        }
        let f = write(&text);
        let track = read_ins_csv(f.path(), 0.5).unwrap_or_else(|e| panic!("{e}"));
        for &t in &[0.05, 1.234, 2.8] {
            let (p, v) = track.at(t).unwrap_or_else(|| panic!("span"));
            assert!((p - (p0 + v0 * t + a * (0.5 * t * t))).norm() < 1e-6);
            // Positions of 1e6 m differenced over 0.1 s: f64 rounding allows ~1e-8 m/s.
            assert!((v - (v0 + a * t)).norm() < 1e-6);
        }
        assert!(track.at(3.5).is_none());
    }

    #[test]
    fn bad_files_name_the_line() {
        let cases = [
            (
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps\n0,1,2,3,4,5\n",
                "no column `vz_mps`",
            ),
            (
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n0,1,2,3,4,5,6\n0.1,1,2,x,4,5,6\n",
                "line 3",
            ),
            (
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n0,1,2,3,4,5,6\n0,1,2,3,4,5,6\n",
                "does not increase",
            ),
            (
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n0,1,2,3,4,5,6\n2,1,2,3,4,5,6\n",
                "gap of 2.000 s",
            ),
            (
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n0,1,2,3,4,5,NaN\n",
                "not a finite number",
            ),
        ];
        for (text, needle) in cases {
            let f = write(text);
            let e = read_ins_csv(f.path(), 0.5)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(e.contains(needle), "{e} (wanted {needle})");
        }
        let e = read_ins_csv(Path::new("/nonexistent/ins.csv"), 0.5)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("cannot read INS file"), "{e}");
    }
}
