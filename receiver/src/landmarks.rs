//! Landmark range observations (seed 001): `--landmarks FILE.csv`.
//!
//! Columns (header required, any order): `tow_s` (GPS time of week of the observation, s),
//! `x_m,y_m,z_m` (surveyed landmark position, WGS-84 ECEF), `range_m` (measured range from the
//! antenna), `sigma_m` (its standard deviation). Each observation joins the fix whose epoch is
//! within half an epoch interval of `tow_s`.

use anyhow::{bail, Context};
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

/// Reads a landmark CSV; bad rows are errors naming the line.
pub fn read_landmarks(path: &Path) -> anyhow::Result<Vec<LandmarkObservation>> {
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .with_context(|| format!("cannot read landmarks {}", path.display()))?;
    let headers = rdr.headers()?.clone();
    let col = |name: &str| {
        headers.iter().position(|h| h == name).with_context(|| {
            format!(
                "{}: no column `{name}` (need tow_s,x_m,y_m,z_m,range_m,sigma_m)",
                path.display()
            )
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
        let rec = rec.with_context(|| format!("{} line {line}", path.display()))?;
        let mut v = [0.0; 6];
        for (k, &c) in idx.iter().enumerate() {
            let field = rec.get(c).unwrap_or("");
            v[k] = match field.parse::<f64>() {
                Ok(x) if x.is_finite() => x,
                _ => bail!(
                    "{} line {line}: `{field}` is not a finite number",
                    path.display()
                ),
            };
        }
        if v[4] <= 0.0 || v[5] <= 0.0 {
            bail!(
                "{} line {line}: range and sigma must be positive",
                path.display()
            );
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
