//! Least-squares polynomials through sampled points (carrier-phase extrapolation in the
//! receiver, the error fits of the studies).

/// A polynomial in powers of `t - t_center`.
#[derive(Debug, Clone, PartialEq)]
pub struct Polynomial {
    /// Coefficients from `(t - t_center)^0` up.
    pub coeffs: Vec<f64>,
    /// The mean time of the fitted points (the fit is made about it: well conditioned).
    pub t_center: f64,
}

impl Polynomial {
    /// The least-squares polynomial of `degree` through `(t, y)`: the SVD of the Vandermonde
    /// matrix in `t - t_center`. `None` with fewer points than coefficients or non-finite ones.
    pub fn fit(pts: &[(f64, f64)], degree: usize) -> Option<Self> {
        let n = degree + 1;
        if pts.len() < n || pts.iter().any(|p| !(p.0.is_finite() && p.1.is_finite())) {
            return None;
        }
        let t_center = pts.iter().map(|p| p.0).sum::<f64>() / pts.len() as f64;
        let a =
            nalgebra::DMatrix::from_fn(pts.len(), n, |i, k| (pts[i].0 - t_center).powi(k as i32));
        let y = nalgebra::DVector::from_iterator(pts.len(), pts.iter().map(|p| p.1));
        let c = a.svd(true, true).solve(&y, 1e-12).ok()?;
        Some(Self {
            coeffs: c.iter().copied().collect(),
            t_center,
        })
    }

    /// Its value at `t` (Horner).
    pub fn at(&self, t: f64) -> f64 {
        let x = t - self.t_center;
        self.coeffs.iter().rev().fold(0.0, |acc, &c| acc * x + c)
    }

    /// Its derivative at `t`: `sum_k k c_k (t - t_center)^(k - 1)`.
    pub fn slope_at(&self, t: f64) -> f64 {
        let x = t - self.t_center;
        self.coeffs
            .iter()
            .enumerate()
            .skip(1)
            .rev()
            .fold(0.0, |acc, (k, &c)| acc * x + k as f64 * c)
    }

    /// The RMS of its residuals at `pts`.
    pub fn rms(&self, pts: &[(f64, f64)]) -> f64 {
        let ss: f64 = pts.iter().map(|&(t, y)| (y - self.at(t)).powi(2)).sum();
        (ss / pts.len().max(1) as f64).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cubic_is_recovered_exactly_and_a_line_fits_it_with_the_legendre_residual() {
        let f = |t: f64| 2.0 - 0.5 * t + 0.25 * t * t - 0.125 * t * t * t;
        let pts: Vec<(f64, f64)> = (0..21)
            .map(|k| (100.0 + 0.1 * k as f64, f(0.1 * k as f64)))
            .collect();
        let p = Polynomial::fit(&pts, 3).expect("fit");
        for &(t, y) in &pts {
            assert!((p.at(t) - y).abs() < 1e-9, "{t}: {} vs {y}", p.at(t));
        }
        assert!(p.rms(&pts) < 1e-9);
        // Too few points, a non-finite one.
        assert!(Polynomial::fit(&pts[..3], 3).is_none());
        assert!(Polynomial::fit(&[(0.0, 1.0), (1.0, f64::NAN)], 1).is_none());
        // y = t^2 on [-1, 1] sampled densely, fitted by a constant: residual RMS of t^2 about
        // its mean 1/3 is sqrt(4/45) = 0.298.
        let sq: Vec<(f64, f64)> = (0..=2000)
            .map(|k| {
                let t = -1.0 + k as f64 / 1000.0;
                (t, t * t)
            })
            .collect();
        let c = Polynomial::fit(&sq, 0).expect("fit");
        assert!(
            (c.rms(&sq) - (4.0_f64 / 45.0).sqrt()).abs() < 1e-3,
            "{}",
            c.rms(&sq)
        );
    }

    #[test]
    fn the_slope_is_the_derivative() {
        // y = 2 - 3 t + 0.5 t^2 + 0.25 t^3: y' = -3 + t + 0.75 t^2.
        let pts: Vec<(f64, f64)> = (0..9)
            .map(|i| {
                let t = 10.0 + 0.1 * i as f64;
                (t, 2.0 - 3.0 * t + 0.5 * t * t + 0.25 * t * t * t)
            })
            .collect();
        let p = Polynomial::fit(&pts, 3).expect("fit");
        for t in [10.0, 10.4, 11.3] {
            let want = -3.0 + t + 0.75 * t * t;
            assert!(
                (p.slope_at(t) - want).abs() < 1e-6,
                "{t}: {} vs {want}",
                p.slope_at(t)
            );
        }
        let line = Polynomial::fit(&[(0.0, 1.0), (1.0, 3.0)], 1).expect("line");
        assert!((line.slope_at(5.0) - 2.0).abs() < 1e-12);
    }
}
