//! The INS input file (`--ins FILE.csv`).
//!
//! Columns (header required, any order, extra columns ignored): `t_s` (seconds from the first
//! sample of the IF recording), `x_m,y_m,z_m` (ECEF position), `vx_mps,vy_mps,vz_mps` (ECEF
//! velocity), and optionally `gps_tow_s` as an alternative time base. Rows must be in time
//! order, at 10 Hz or faster; a gap longer than `max_gap_s` is an error (the aiding would
//! extrapolate blindly). Between rows, position follows a cubic Hermite curve through the
//! positions and velocities, and velocity its derivative, so both are continuous; `gps_tow_s` is
//! interpolated linearly.
//!
//! Every row is checked: finite numbers, `|(x, y, z)|` between [`MIN_RADIUS_M`] and
//! [`MAX_RADIUS_M`] from the Earth's centre (metres, ECEF), speed `|(vx, vy, vz)|` at most
//! [`MAX_SPEED_MPS`], `gps_tow_s` in `[0, 604800)` and increasing (a week rollover is allowed).
//! Errors name the file, the line and what to do. [`write_ins_csv`] writes the same format.

use nalgebra::Vector3;
use std::io::Write;
use std::path::Path;

/// Smallest accepted distance of an INS position from the Earth's centre, m (6000 km).
pub const MIN_RADIUS_M: f64 = 6.0e6;
/// Largest accepted distance of an INS position from the Earth's centre, m (50 000 km).
pub const MAX_RADIUS_M: f64 = 5.0e7;
/// Largest accepted INS speed, m/s.
pub const MAX_SPEED_MPS: f64 = 1.0e4;
/// Seconds in a GPS week.
const WEEK_S: f64 = 604_800.0;

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
    /// The file cannot be written.
    #[error("cannot write INS file {path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// An INS error-model setting (the simulator's `[ins]` table) or argument is invalid.
    #[error("INS error model: {0}")]
    Config(String),
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
    /// With no `t_s` column: the `gps_tow_s` of the first row, from which `t_s` was counted.
    gps_time_base_tow_s: Option<f64>,
}

/// Reads and validates an INS file: times strictly increasing, no gap above `max_gap_s`
/// (default choice: 0.5 s, i.e. a 10 Hz file may lose four rows), finite values, positions
/// within [`MIN_RADIUS_M`]..[`MAX_RADIUS_M`] of the Earth's centre, speeds up to
/// [`MAX_SPEED_MPS`], `gps_tow_s` (if present) in `[0, 604800)` and increasing modulo the week.
///
/// The steps: the header (`InsColumns::from_header`), then per row the record
/// (`read_record`), its numbers (`InsColumns::parse_row`), the row's own checks
/// (`check_row`) and those against the previous row (`check_step`); at the end, at least 2
/// rows.
pub fn read_ins_csv(path: &Path, max_gap_s: f64) -> Result<InsTrack, InsError> {
    let p = path.display().to_string();
    if max_gap_s.is_nan() || max_gap_s <= 0.0 {
        return Err(InsError::Config(format!(
            "the INS gap limit {max_gap_s} s must be positive (0.5 s suits a 10 Hz INS)"
        )));
    }
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|e| InsError::Io {
            path: p.clone(),
            message: e.to_string(),
        })?;
    let cols = InsColumns::from_header(&mut rdr, &p)?;
    let mut samples: Vec<InsSample> = Vec::new();
    let mut first_tow: Option<f64> = None;
    let mut last_line = cols.header_line;
    for (i, rec) in rdr.records().enumerate() {
        let (rec, line) = read_record(rec, i, &p)?;
        last_line = line;
        let sample = cols.parse_row(&rec, line, &p, &mut first_tow)?;
        check_row(&sample, line, &p)?;
        if let Some(last) = samples.last() {
            check_step(last, &sample, max_gap_s, line, &p)?;
        }
        samples.push(sample);
    }
    if samples.len() < 2 {
        return Err(InsError::Row {
            path: p,
            line: last_line,
            message: format!(
                "an INS file needs at least 2 rows (found {}): record the INS over the whole recording",
                samples.len()
            ),
        });
    }
    Ok(InsTrack {
        samples,
        gps_time_base_tow_s: first_tow,
    })
}

/// The required columns of an INS file, in the order of [`InsColumns::idx`].
const COLUMN_NAMES: [&str; 7] = ["t_s", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps"];

/// Where the INS file's header puts each value.
#[derive(Debug, Clone, Copy)]
struct InsColumns {
    /// Column of each of [`COLUMN_NAMES`] (that of `t_s` unused in the GPS time base).
    idx: [usize; 7],
    /// Column of `gps_tow_s`, if any.
    tow_col: Option<usize>,
    /// No `t_s` column but a `gps_tow_s` one: `t_s` counts from the first row's time of week.
    gps_time_base: bool,
    /// 1-based line of the header.
    header_line: usize,
}

impl InsColumns {
    /// Reads the header and finds the columns (any order, extra columns ignored). `t_s` may be
    /// left out when `gps_tow_s` is given (the GPS time base).
    fn from_header(
        rdr: &mut csv::Reader<std::fs::File>,
        path: &str,
    ) -> Result<InsColumns, InsError> {
        let headers = rdr
            .headers()
            .map_err(|e| row_err(path, 1, e.to_string()))?
            .clone();
        let header_line = headers
            .position()
            .map_or(1, |pos| usize::try_from(pos.line()).unwrap_or(1));
        let col = |name: &str| headers.iter().position(|h| h == name);
        let tow_col = col("gps_tow_s");
        // `t_s` may be left out when `gps_tow_s` is given (the GPS time base): t_s then counts
        // from the first row's time of week, and the receiver maps it once it knows the GPS time.
        let gps_time_base = col("t_s").is_none() && tow_col.is_some();
        let mut idx = [0usize; 7];
        for (k, n) in COLUMN_NAMES.iter().enumerate() {
            if k == 0 && gps_time_base {
                continue;
            }
            idx[k] = col(n).ok_or_else(|| {
                row_err(
                    path,
                    header_line,
                    format!(
                        "no column `{n}`: the header must name t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps (ECEF, metres and m/s; gps_tow_s optional, or gps_tow_s instead of t_s)"
                    ),
                )
            })?;
        }
        Ok(InsColumns {
            idx,
            tow_col,
            gps_time_base,
            header_line,
        })
    }

    /// The sample of one row on `line`: every value a finite number; in the GPS time base,
    /// `t_s = (tow - tow_0) mod 604800` from the first row's `tow_0` (kept in `first_tow`), so
    /// that it runs on across a week rollover.
    fn parse_row(
        &self,
        rec: &csv::StringRecord,
        line: usize,
        path: &str,
        first_tow: &mut Option<f64>,
    ) -> Result<InsSample, InsError> {
        let mut v = [0.0; 7];
        for k in usize::from(self.gps_time_base)..7 {
            v[k] = parse_field(rec, self.idx[k], COLUMN_NAMES[k], line, path)?;
        }
        let gps_tow_s = match self.tow_col {
            Some(c) => Some(parse_field(rec, c, "gps_tow_s", line, path)?),
            None => None,
        };
        if let (true, Some(tow)) = (self.gps_time_base, gps_tow_s) {
            // Seconds since the first row, across a week rollover.
            let t0 = *first_tow.get_or_insert(tow);
            v[0] = (tow - t0).rem_euclid(WEEK_S);
        }
        Ok(InsSample {
            t_s: v[0],
            gps_tow_s,
            pos_m: Vector3::new(v[1], v[2], v[3]),
            vel_mps: Vector3::new(v[4], v[5], v[6]),
        })
    }
}

/// A row error of the file `path` on 1-based `line`.
fn row_err(path: &str, line: usize, message: String) -> InsError {
    InsError::Row {
        path: path.to_owned(),
        line,
        message,
    }
}

/// The `i`-th (0-based) data record and its 1-based line (`i + 2` when the reader does not
/// know it); a row with another number of values than the header is an error.
fn read_record(
    rec: Result<csv::StringRecord, csv::Error>,
    i: usize,
    path: &str,
) -> Result<(csv::StringRecord, usize), InsError> {
    let rec = rec.map_err(|e| match e.kind() {
        csv::ErrorKind::UnequalLengths {
            pos,
            expected_len,
            len,
        } => row_err(
            path,
            pos.as_ref()
                .map_or(i + 2, |p| usize::try_from(p.line()).unwrap_or(i + 2)),
            format!(
                "{len} values but the header has {expected_len} columns: every row needs one value per header column"
            ),
        ),
        _ => row_err(path, i + 2, format!("{e}")),
    })?;
    let line = rec
        .position()
        .map_or(i + 2, |pos| usize::try_from(pos.line()).unwrap_or(i + 2));
    Ok((rec, line))
}

/// The value of column `c` (named `name`) of a record on `line`: a finite number, else an error
/// that says whether it is missing or not a number.
fn parse_field(
    rec: &csv::StringRecord,
    c: usize,
    name: &str,
    line: usize,
    path: &str,
) -> Result<f64, InsError> {
    let f = rec.get(c).unwrap_or("");
    f.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            if f.is_empty() {
                row_err(
                    path,
                    line,
                    format!("`{name}` is missing: fill it in or delete the row"),
                )
            } else {
                row_err(
                    path,
                    line,
                    format!("{name} = `{f}` is not a finite number: fix or delete the row"),
                )
            }
        })
}

/// The checks of one row `s` on `line`: `|(x, y, z)|` in [`MIN_RADIUS_M`]..=[`MAX_RADIUS_M`]
/// (ECEF metres), `|(vx, vy, vz)|` at most [`MAX_SPEED_MPS`], `gps_tow_s` in `[0, 604800)`.
fn check_row(s: &InsSample, line: usize, path: &str) -> Result<(), InsError> {
    let r = s.pos_m.norm();
    if !(MIN_RADIUS_M..=MAX_RADIUS_M).contains(&r) {
        return Err(row_err(
            path,
            line,
            format!(
                "the position is {:.1} km from the Earth's centre, outside {:.0}-{:.0} km: x_m,y_m,z_m must be ECEF in metres (not km, not latitude/longitude)",
                r / 1e3,
                MIN_RADIUS_M / 1e3,
                MAX_RADIUS_M / 1e3
            ),
        ));
    }
    let speed = s.vel_mps.norm();
    if speed > MAX_SPEED_MPS {
        return Err(row_err(
            path,
            line,
            format!(
                "the speed {speed:.1} m/s is above {MAX_SPEED_MPS} m/s: vx_mps,vy_mps,vz_mps must be ECEF velocity in m/s"
            ),
        ));
    }
    if let Some(tow) = s.gps_tow_s {
        if !(0.0..WEEK_S).contains(&tow) {
            return Err(row_err(
                path,
                line,
                format!("gps_tow_s = {tow} is outside a GPS week [0, 604800) s: give the time of week in seconds"),
            ));
        }
    }
    Ok(())
}

/// The checks of row `s` on `line` against the previous row `last`: `t_s` strictly increasing,
/// a step of at most `max_gap_s`, and `gps_tow_s` increasing (a decrease by more than half a
/// week is a week rollover).
fn check_step(
    last: &InsSample,
    s: &InsSample,
    max_gap_s: f64,
    line: usize,
    path: &str,
) -> Result<(), InsError> {
    if s.t_s <= last.t_s {
        return Err(row_err(
            path,
            line,
            format!(
                "t_s = {} does not increase (previous {}): sort the file by t_s and remove duplicate rows",
                s.t_s, last.t_s
            ),
        ));
    }
    if s.t_s - last.t_s > max_gap_s {
        return Err(row_err(path, line, format!("gap of {:.3} s before this row (limit {max_gap_s} s): the INS must run at 10 Hz or faster without gaps", s.t_s - last.t_s)));
    }
    if let (Some(a), Some(b)) = (last.gps_tow_s, s.gps_tow_s) {
        // A decrease by more than half a week is a week rollover, not a step back.
        if b <= a && a - b < WEEK_S / 2.0 {
            return Err(row_err(
                path,
                line,
                format!("gps_tow_s = {b} does not increase (previous {a}): the GPS time of week must advance with t_s"),
            ));
        }
    }
    Ok(())
}

/// Writes `samples` as an INS file [`read_ins_csv`] reads back: the header
/// `t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps` (plus `gps_tow_s` when the samples have it), times to
/// 1e-9 s, positions to 1e-6 m, velocities to 1e-9 m/s. Either every sample has `gps_tow_s` or
/// none does.
pub fn write_ins_csv(path: &Path, samples: &[InsSample]) -> Result<(), InsError> {
    let p = path.display().to_string();
    let werr = |message: String| InsError::Write {
        path: p.clone(),
        message,
    };
    let with_tow = samples.first().is_some_and(|s| s.gps_tow_s.is_some());
    if let Some(i) = samples
        .iter()
        .position(|s| s.gps_tow_s.is_some() != with_tow)
    {
        return Err(werr(format!(
            "sample {i} {} gps_tow_s but the first sample {}: give it to every sample or to none",
            if with_tow { "has no" } else { "has a" },
            if with_tow { "has one" } else { "has none" }
        )));
    }
    let f = std::fs::File::create(path).map_err(|e| werr(e.to_string()))?;
    let mut w = std::io::BufWriter::new(f);
    let io = |e: std::io::Error| werr(e.to_string());
    write!(w, "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps").map_err(io)?;
    if with_tow {
        write!(w, ",gps_tow_s").map_err(io)?;
    }
    writeln!(w).map_err(io)?;
    for s in samples {
        write!(
            w,
            "{:.9},{:.6},{:.6},{:.6},{:.9},{:.9},{:.9}",
            s.t_s, s.pos_m.x, s.pos_m.y, s.pos_m.z, s.vel_mps.x, s.vel_mps.y, s.vel_mps.z
        )
        .map_err(io)?;
        if let Some(tow) = s.gps_tow_s {
            write!(w, ",{tow:.9}").map_err(io)?;
        }
        writeln!(w).map_err(io)?;
    }
    w.flush().map_err(io)
}

impl InsTrack {
    /// A track from samples already in memory (e.g. [`crate::error_model::simulate_ins`]),
    /// checked like a file: at least 2 rows, `t_s` strictly increasing, finite values.
    pub fn from_samples(samples: Vec<InsSample>) -> Result<InsTrack, InsError> {
        if samples.len() < 2 {
            return Err(InsError::Config(
                "an INS track needs at least 2 samples".into(),
            ));
        }
        for (i, w) in samples.windows(2).enumerate() {
            let finite = |s: &InsSample| {
                s.t_s.is_finite()
                    && s.pos_m.iter().all(|v| v.is_finite())
                    && s.vel_mps.iter().all(|v| v.is_finite())
            };
            if !(finite(&w[0]) && finite(&w[1]) && w[1].t_s > w[0].t_s) {
                return Err(InsError::Config(format!(
                    "INS samples {i} and {}: times must increase and every value be finite",
                    i + 1
                )));
            }
        }
        Ok(InsTrack {
            samples,
            gps_time_base_tow_s: None,
        })
    }

    /// For a file without `t_s` (GPS time base): the time of week its `t_s` counts from. The
    /// receiver must then map its own time to the file's, see [`InsTrack::t_s_from_tow`].
    pub fn gps_time_base_tow_s(&self) -> Option<f64> {
        self.gps_time_base_tow_s
    }

    /// The track time `t_s` of a GPS time of week, for a file in the GPS time base (None for a
    /// file with a `t_s` column).
    pub fn t_s_from_tow(&self, tow_s: f64) -> Option<f64> {
        let base = self.gps_time_base_tow_s?;
        let mut dt = tow_s - base;
        dt -= (dt / WEEK_S).round() * WEEK_S;
        Some(dt)
    }

    /// The rows of the file, in time order.
    pub fn samples(&self) -> &[InsSample] {
        &self.samples
    }

    /// GPS time of week at `t_s`, interpolated linearly between the two rows around it
    /// (`tow = tow_a + (tow_b - tow_a) (t - t_a) / (t_b - t_a)`, across a week rollover too);
    /// None without a `gps_tow_s` column or outside the file's span.
    pub fn gps_tow_at(&self, t_s: f64) -> Option<f64> {
        let (a, b) = self.rows_around(t_s)?;
        let (ta, mut tb) = (a.gps_tow_s?, b.gps_tow_s?);
        if tb < ta {
            tb += WEEK_S;
        }
        let u = (t_s - a.t_s) / (b.t_s - a.t_s);
        Some((ta + (tb - ta) * u).rem_euclid(WEEK_S))
    }

    /// The two rows whose times enclose `t_s`, or None outside the span.
    fn rows_around(&self, t_s: f64) -> Option<(&InsSample, &InsSample)> {
        let (t0, t1) = self.span_s();
        if !(t0..=t1).contains(&t_s) {
            return None;
        }
        let i = self
            .samples
            .partition_point(|s| s.t_s <= t_s)
            .clamp(1, self.samples.len() - 1);
        Some((&self.samples[i - 1], &self.samples[i]))
    }

    /// The time span covered, s.
    pub fn span_s(&self) -> (f64, f64) {
        (
            self.samples[0].t_s,
            self.samples[self.samples.len() - 1].t_s,
        )
    }

    /// Position and velocity at `t_s`, or None outside the file's span.
    pub fn at(&self, t_s: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let (a, b) = self.rows_around(t_s)?;
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
            Vector3::new(-3.05e6, 4.04e6, 3.86e6),
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

    const HEADER: &str = "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n";
    /// A valid row body (ECEF point on the equator, 10 m/s) after `t_s,`.
    const ROW: &str = "6378137,0,0,0,10,0";

    fn error_of(text: &str) -> String {
        let f = write(text);
        read_ins_csv(f.path(), 0.5)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    }

    #[test]
    fn bad_files_name_the_line() {
        let cases = [
            (
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps\n0,6378137,0,0,0,10\n".to_string(),
                "no column `vz_mps`",
            ),
            (
                format!("{HEADER}0,{ROW}\n0.1,6378137,0,x,0,10,0\n"),
                "line 3: z_m = `x` is not a finite number",
            ),
            (
                format!("{HEADER}0,{ROW}\n0,{ROW}\n"),
                "line 3: t_s = 0 does not increase",
            ),
            (
                format!("{HEADER}0,{ROW}\n0.2,{ROW}\n0.1,{ROW}\n"),
                "line 4: t_s = 0.1 does not increase",
            ),
            (
                format!("{HEADER}0,{ROW}\n2,{ROW}\n"),
                "line 3: gap of 2.000 s",
            ),
            (
                format!("{HEADER}0,6378137,0,0,0,10,NaN\n"),
                "vz_mps = `NaN` is not a finite number",
            ),
            (
                format!("{HEADER}0,{ROW}\n,{ROW}\n"),
                "line 3: `t_s` is missing",
            ),
            (
                format!("{HEADER}0,{ROW}\n0.1,6378.137,0,0,0,10,0\n"),
                "line 3: the position is 6.4 km from the Earth's centre",
            ),
            (
                format!("{HEADER}0,{ROW}\n0.1,6e10,0,0,0,10,0\n"),
                "outside 6000-50000 km",
            ),
            (
                format!("{HEADER}0,{ROW}\n0.1,6378137,0,0,0,10001,0\n"),
                "line 3: the speed 10001.0 m/s is above 10000 m/s",
            ),
            (
                format!("{HEADER}0,{ROW}\n0.1,{ROW},9\n"),
                "line 3: 8 values but the header has 7 columns",
            ),
            (format!("{HEADER}0,{ROW}\n"), "at least 2 rows (found 1)"),
            (
                format!(
                    "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,gps_tow_s\n0,{ROW},100\n0.1,{ROW},99.9\n"
                ),
                "line 3: gps_tow_s = 99.9 does not increase",
            ),
            (
                format!("t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,gps_tow_s\n0,{ROW},604800\n"),
                "line 2: gps_tow_s = 604800 is outside a GPS week",
            ),
            (
                format!(
                    "# a comment line\n{HEADER}0,{ROW}\n# another\n0.1,{ROW}\n0.2,1,2,3,4,5,6\n"
                ),
                "line 6: the position",
            ),
        ];
        for (text, needle) in cases {
            let e = error_of(&text);
            assert!(e.contains(needle), "{e} (wanted {needle})");
        }
        let e = read_ins_csv(Path::new("/nonexistent/ins.csv"), 0.5)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("cannot read INS file"), "{e}");
        let f = write(&format!("{HEADER}0,{ROW}\n0.1,{ROW}\n"));
        let e = read_ins_csv(f.path(), 0.0)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("gap limit 0 s must be positive"), "{e}");
    }

    /// Samples of a constant-acceleration motion with a GPS time of week that crosses the end
    /// of the week.
    fn accelerating_samples(with_tow: bool) -> Vec<InsSample> {
        let (p0, v0, a) = (
            Vector3::new(-3_052_000.123_456_7, 4_043_000.987_654_3, 3_858_000.5),
            Vector3::new(29.123_456_789, -5.5, 0.25),
            Vector3::new(0.5, 2.0, -1.0),
        );
        (0..50)
            .map(|i| {
                let t = 0.02 * f64::from(i);
                InsSample {
                    t_s: t,
                    gps_tow_s: with_tow.then(|| (604_799.5 + t) % 604_800.0),
                    pos_m: p0 + v0 * t + a * (0.5 * t * t),
                    vel_mps: v0 + a * t,
                }
            })
            .collect()
    }

    #[test]
    fn written_files_read_back_to_the_stated_precision() {
        for with_tow in [false, true] {
            let samples = accelerating_samples(with_tow);
            let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
            write_ins_csv(f.path(), &samples).unwrap_or_else(|e| panic!("{e}"));
            let text = std::fs::read_to_string(f.path()).unwrap_or_else(|e| panic!("{e}"));
            let header = text.lines().next().unwrap_or_default();
            let expected = if with_tow {
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,gps_tow_s"
            } else {
                "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps"
            };
            assert_eq!(header, expected);
            let track = read_ins_csv(f.path(), 0.5).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(track.samples().len(), samples.len());
            for (r, s) in track.samples().iter().zip(&samples) {
                assert!((r.t_s - s.t_s).abs() <= 1e-9);
                assert!((r.pos_m - s.pos_m).amax() <= 1e-6);
                assert!((r.vel_mps - s.vel_mps).amax() <= 1e-9);
                match (r.gps_tow_s, s.gps_tow_s) {
                    (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-9),
                    (None, None) => {}
                    other => panic!("gps_tow_s {other:?}"),
                }
            }
            if with_tow {
                // Linear interpolation of the time of week, across the week rollover at t = 0.5 s.
                for &t in &[0.0, 0.13, 0.49, 0.51, 0.777, 0.98] {
                    let tow = track.gps_tow_at(t).unwrap_or_else(|| panic!("t {t}"));
                    let want = (604_799.5 + t) % 604_800.0;
                    assert!((tow - want).abs() < 1e-8, "t {t}: {tow} vs {want}");
                }
                assert!(track.gps_tow_at(0.99).is_none());
                assert!(track.gps_tow_at(-0.01).is_none());
            } else {
                assert!(track.gps_tow_at(0.5).is_none());
            }
        }
    }

    #[test]
    fn writer_refuses_mixed_time_bases() {
        let mut samples = accelerating_samples(true);
        samples[3].gps_tow_s = None;
        let f = tempfile::NamedTempFile::new().unwrap_or_else(|e| panic!("{e}"));
        let e = write_ins_csv(f.path(), &samples)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("sample 3 has no gps_tow_s"), "{e}");
        let e = write_ins_csv(Path::new("/nonexistent/dir/ins.csv"), &samples[..2])
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("cannot write INS file"), "{e}");
    }

    #[test]
    fn gps_time_base_without_t_s() {
        // 10 Hz rows across the week rollover, no t_s column.
        let mut text = String::from("x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,gps_tow_s\n");
        for i in 0..10 {
            let tow = (604_799.75 + 0.1 * f64::from(i)) % 604_800.0;
            text += &format!("{},0,0,0,10,0,{tow}\n", 6_378_137.0 + f64::from(i));
        }
        let f = write(&text);
        let track = read_ins_csv(f.path(), 0.5).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(track.gps_time_base_tow_s(), Some(604_799.75));
        let (t0, t1) = track.span_s();
        assert!(t0.abs() < 1e-9 && (t1 - 0.9).abs() < 1e-9, "{t0} {t1}");
        // 0.35 s after the first row is TOW 0.1 of the next week.
        let t = track.t_s_from_tow(0.1).unwrap_or(f64::NAN);
        assert!((t - 0.35).abs() < 1e-9, "{t}");
        let (p, _) = track.at(t).unwrap_or_else(|| panic!("inside"));
        assert!((p.x - (6_378_137.0 + 3.5)).abs() < 1e-6, "{}", p.x);
        // A file with t_s is not in the GPS time base.
        let f = write(&format!(
            "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n0,{ROW}\n0.1,{ROW}\n"
        ));
        let track = read_ins_csv(f.path(), 0.5).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(track.t_s_from_tow(1.0), None);
        // Neither t_s nor gps_tow_s: the error names t_s.
        let f = write(&format!("x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n{ROW}\n{ROW}\n"));
        let e = match read_ins_csv(f.path(), 0.5) {
            Ok(_) => panic!("a file without times must be refused"),
            Err(e) => e.to_string(),
        };
        assert!(e.contains("no column `t_s`"), "{e}");
    }

    #[test]
    fn from_samples_checks_order() {
        let s = |t: f64| InsSample {
            t_s: t,
            gps_tow_s: None,
            pos_m: Vector3::new(6.4e6, 0.0, 0.0),
            vel_mps: Vector3::zeros(),
        };
        assert!(InsTrack::from_samples(vec![s(0.0), s(0.1)]).is_ok());
        assert!(InsTrack::from_samples(vec![s(0.1), s(0.1)]).is_err());
        assert!(InsTrack::from_samples(vec![s(0.0)]).is_err());
    }
}
