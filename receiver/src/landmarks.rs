//! Landmark range observations (seed 001): `--landmarks FILE.csv`.
//!
//! Columns (header required, any order): `tow_s` (GPS time of week of the observation, s),
//! `x_m,y_m,z_m` (surveyed landmark position, WGS-84 ECEF), `range_m` (measured range from the
//! antenna), `sigma_m` (its standard deviation). Each observation joins the fix whose epoch is
//! within half an epoch interval of `tow_s`.

use gpsrx_nav::frames::Vector3;
use gpsrx_nav::pvt::Landmark;
use std::path::Path;

/// One timed landmark observation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LandmarkObservation {
    /// GPS time of week, s.
    pub tow_s: f64,
    /// The observation.
    pub landmark: Landmark,
}

/// A landmark file that cannot be used: the message names the file, the line and the problem.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct LandmarkError(String);

/// Reads a landmark CSV; bad rows are errors naming the line.
pub fn read_landmarks(path: &Path) -> Result<Vec<LandmarkObservation>, LandmarkError> {
    let fail = |what: String| LandmarkError(format!("{}: {what}", path.display()));
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|e| fail(format!("cannot read landmarks: {e}")))?;
    let headers = rdr
        .headers()
        .map_err(|e| fail(format!("no header line: {e}")))?
        .clone();
    let col = |name: &str| {
        headers.iter().position(|h| h == name).ok_or_else(|| {
            fail(format!(
                "no column `{name}` (need tow_s,x_m,y_m,z_m,range_m,sigma_m)"
            ))
        })
    };
    let idx = [
        col("tow_s")?,
        col("x_m")?,
        col("y_m")?,
        col("z_m")?,
        col("range_m")?,
        col("sigma_m")?,
    ];
    let mut out = Vec::new();
    for (i, rec) in rdr.records().enumerate() {
        let line = i + 2;
        let rec = rec.map_err(|e| fail(format!("line {line}: {e}")))?;
        let mut v = [0.0; 6];
        for (k, &c) in idx.iter().enumerate() {
            let field = rec.get(c).unwrap_or("");
            v[k] = match field.parse::<f64>() {
                Ok(x) if x.is_finite() => x,
                _ => {
                    return Err(fail(format!(
                        "line {line}: `{field}` is not a finite number"
                    )))
                }
            };
        }
        if v[4] <= 0.0 || v[5] <= 0.0 {
            return Err(fail(format!(
                "line {line}: range and sigma must be positive"
            )));
        }
        out.push(LandmarkObservation {
            tow_s: v[0],
            landmark: Landmark {
                ecef_m: Vector3::new(v[1], v[2], v[3]),
                range_m: v[4],
                sigma_m: v[5],
            },
        });
    }
    Ok(out)
}
