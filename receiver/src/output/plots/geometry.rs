//! The pure geometry of the plots: local east/north/up offsets from an origin, the median
//! position as that origin, and the skyplot's polar mapping.

use gpsrx_nav::frames::{enu_rotation, Llh, Vector3};

/// A local east-north-up frame at an origin on the WGS-84 ellipsoid.
#[derive(Debug, Clone, Copy)]
pub struct LocalFrame {
    origin_ecef_m: Vector3<f64>,
    rotation: nalgebra::Matrix3<f64>,
}

impl LocalFrame {
    /// The frame at the ECEF point `origin_ecef_m` (m): east, north and up are the unit
    /// vectors of [`enu_rotation`] at its geodetic latitude and longitude.
    pub fn at(origin_ecef_m: [f64; 3]) -> Self {
        let o = Vector3::from(origin_ecef_m);
        Self {
            origin_ecef_m: o,
            rotation: enu_rotation(&Llh::from_ecef(&o)),
        }
    }

    /// East, north and up of the ECEF point `ecef_m` from the origin, m:
    /// `[e, n, u] = R_enu (r - r_0)`.
    pub fn enu_m(&self, ecef_m: [f64; 3]) -> [f64; 3] {
        let d = self.rotation * (Vector3::from(ecef_m) - self.origin_ecef_m);
        [d.x, d.y, d.z]
    }
}

/// The component-wise median of ECEF positions (m): the ground track's origin, robust to a
/// few outlying fixes; `None` for no position.
pub fn median_position(ecef_m: impl Iterator<Item = [f64; 3]>) -> Option<[f64; 3]> {
    let mut axes: [Vec<f64>; 3] = Default::default();
    for p in ecef_m.filter(|p| p.iter().all(|v| v.is_finite())) {
        for (axis, v) in axes.iter_mut().zip(p) {
            axis.push(v);
        }
    }
    if axes[0].is_empty() {
        return None;
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    };
    let [mut x, mut y, mut z] = axes;
    Some([median(&mut x), median(&mut y), median(&mut z)])
}

/// The skyplot position of a satellite at azimuth `az_deg` (clockwise from north) and
/// elevation `el_deg`: polar with the zenith at the centre and the horizon on the unit
/// circle, `r = (90 - el) / 90`, north up and east right: `(x, y) = (r sin az, r cos az)`.
pub fn sky_xy(az_deg: f64, el_deg: f64) -> (f64, f64) {
    let r = (90.0 - el_deg.clamp(-90.0, 90.0)) / 90.0;
    let (s, c) = az_deg.to_radians().sin_cos();
    (r * s, r * c)
}

/// East and north axis ranges (m) that show every point of `en_m` with the same metres per
/// pixel on both axes of a `plot_px` (width, height) plotting area: the points' extent
/// padded by 10 %, at least `min_span_m`, centred.
pub fn equal_scale_ranges(
    en_m: &[(f64, f64)],
    plot_px: (u32, u32),
    min_span_m: f64,
) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let finite = en_m.iter().filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut e0, mut e1, mut n0, mut n1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(e, n) in finite {
        (e0, e1, n0, n1) = (e0.min(e), e1.max(e), n0.min(n), n1.max(n));
    }
    if e0 > e1 {
        (e0, e1, n0, n1) = (0.0, 0.0, 0.0, 0.0);
    }
    let (w, h) = (f64::from(plot_px.0.max(1)), f64::from(plot_px.1.max(1)));
    let m_per_px = ((e1 - e0) / w)
        .max((n1 - n0) / h)
        .max(min_span_m / w.min(h))
        * 1.1;
    let (ce, cn) = (0.5 * (e0 + e1), 0.5 * (n0 + n1));
    let (half_e, half_n) = (0.5 * m_per_px * w, 0.5 * m_per_px * h);
    (ce - half_e..ce + half_e, cn - half_n..cn + half_n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn skyplot_is_north_up_east_right_zenith_centre() {
        let close = |a: (f64, f64), b: (f64, f64)| {
            assert_abs_diff_eq!(a.0, b.0, epsilon = 1e-12);
            assert_abs_diff_eq!(a.1, b.1, epsilon = 1e-12);
        };
        close(sky_xy(123.0, 90.0), (0.0, 0.0)); // zenith
        close(sky_xy(0.0, 0.0), (0.0, 1.0)); // north horizon: top
        close(sky_xy(90.0, 0.0), (1.0, 0.0)); // east horizon: right
        close(sky_xy(180.0, 45.0), (0.0, -0.5)); // south at 45 deg: half way down
        close(sky_xy(270.0, 60.0), (-1.0 / 3.0, 0.0)); // west at 60 deg: a third left
        let h = 0.5f64.sqrt() * 2.0 / 3.0;
        close(sky_xy(45.0, 30.0), (h, h)); // north-east at 30 deg
    }

    #[test]
    fn local_frame_east_north_up_by_hand() {
        // Origin on the equator at the prime meridian: ECEF x is up, y east, z north.
        let a = 6_378_137.0;
        let f = LocalFrame::at([a, 0.0, 0.0]);
        let [e, n, u] = f.enu_m([a + 3.0, 100.0, -50.0]);
        assert_abs_diff_eq!(e, 100.0, epsilon = 1e-6);
        assert_abs_diff_eq!(n, -50.0, epsilon = 1e-6);
        assert_abs_diff_eq!(u, 3.0, epsilon = 1e-6);
        // At longitude 90 deg east, ECEF -x points west.
        let g = LocalFrame::at([0.0, a, 0.0]);
        let [e, n, u] = g.enu_m([-20.0, a, 7.0]);
        assert_abs_diff_eq!(e, 20.0, epsilon = 1e-6);
        assert_abs_diff_eq!(n, 7.0, epsilon = 1e-6);
        assert_abs_diff_eq!(u, 0.0, epsilon = 1e-6);
    }

    #[test]
    fn equal_scale_keeps_metres_per_pixel_equal() {
        // 100 m east by 10 m north on 800x400 px: east sets the scale, 0.1375 m/px.
        let (e, n) = equal_scale_ranges(&[(0.0, 0.0), (100.0, 10.0)], (800, 400), 1.0);
        assert_abs_diff_eq!(
            (e.end - e.start) / 800.0,
            (n.end - n.start) / 400.0,
            epsilon = 1e-12
        );
        assert_abs_diff_eq!(e.end - e.start, 110.0, epsilon = 1e-9);
        assert_abs_diff_eq!(0.5 * (n.start + n.end), 5.0, epsilon = 1e-12);
        // A single point still gets the minimum span on the short side.
        let (e, n) = equal_scale_ranges(&[(3.0, 4.0)], (400, 200), 2.0);
        assert_abs_diff_eq!(n.end - n.start, 2.2, epsilon = 1e-9);
        assert_abs_diff_eq!(e.end - e.start, 4.4, epsilon = 1e-9);
        assert_abs_diff_eq!(0.5 * (e.start + e.end), 3.0, epsilon = 1e-12);
    }

    #[test]
    fn median_ignores_an_outlier() {
        let pts = [
            [1.0, 10.0, 5.0],
            [2.0, 20.0, 6.0],
            [1e6, -1e6, 7.0],
            [3.0, 30.0, f64::NAN],
        ];
        assert_eq!(median_position(pts.into_iter()), Some([2.0, 10.0, 6.0]));
        assert_eq!(median_position(std::iter::empty()), None);
    }
}
