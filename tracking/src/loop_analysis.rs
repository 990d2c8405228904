//! The closed digital loop formed by a [`LoopFilter`], the discriminators and the channel's NCO:
//! transfer function, stability and noise bandwidth.
//!
//! # Timing model (what the channel does)
//!
//! Interval `k` runs from `t_k` to `t_k + T`. The NCO holds the frequency `f_k` over it, so its
//! phase is `phi(t) = phi_k + f_k (t - t_k)` and `phi_{k+1} = phi_k + f_k T` (a boxcar integrator
//! of frequency, Kaplan Fig. 5.21a). The integrate-and-dump correlator measures the *average*
//! phase error over the interval, `e_k = mean(theta) - (phi_k + phi_{k+1})/2`. After the dump
//! the loop filter computes `f_{k+1}` from `e_k`. Seen from the discriminator the NCO is therefore
//!
//! `N(z) = z^-1 (T/2)(1 + z^-1)/(1 - z^-1)`  (cycles of average phase per Hz commanded),
//!
//! a trapezoidal integrator behind one interval of delay. An FLL discriminator on consecutive
//! prompts measures `D_f(z) = (1 - z^-1)/T` (Hz per cycle), so it sees the NCO frequency through
//! `M(z) = D_f N = z^-1 (1 + z^-1)/2`, the mean of the frequencies held over the two intervals
//! whose centres it spans.
//!
//! - Loops with a phase input (PLL, FLL-assisted PLL): with the filter's `F_p(z)` (phase input)
//!   and `F_f(z)` (FLL input) the open loop is `L = F_p N + F_f M` and the closed loop from input
//!   phase (or from discriminator noise) to NCO phase is `H = L/(1 + L)`.
//! - A pure FLL has no phase reference: any constant phase offset is an equilibrium, a pole at
//!   `z = 1` of the phase loop. It is analysed as the frequency loop it is, `L_f = F_f M`,
//!   `H_f = L_f/(1 + L_f)` from input frequency (or FLL discriminator noise) to NCO frequency as
//!   the discriminator sees it; its noise bandwidth is the FLL's Bn of the table.
//!
//! # Noise bandwidth of a discrete loop
//!
//! One-sided `Bn = integral_0^{1/(2T)} |H(e^{j 2 pi f T})|^2 df`. By Parseval, white noise of
//! variance `s^2` per update on the discriminator output gives an NCO-phase variance
//! `s^2 sum_k h_k^2 = s^2 T integral_{-1/2T}^{1/2T} |H|^2 df = 2 Bn T s^2`; this is the relation the
//! closed-loop tests use to measure Bn.

use num_complex::Complex64;

use crate::loop_filter::LoopFilter;

/// A rational transfer function `num(z^-1)/den(z^-1)`, coefficients in ascending powers of
/// `z^-1`.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction {
    /// Numerator coefficients, ascending powers of `z^-1`.
    pub num: Vec<f64>,
    /// Denominator coefficients, ascending powers of `z^-1`.
    pub den: Vec<f64>,
}

fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

fn poly_add(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len().max(b.len())];
    for (i, x) in a.iter().enumerate() {
        out[i] += x;
    }
    for (i, y) in b.iter().enumerate() {
        out[i] += y;
    }
    out
}

fn poly_eval(p: &[f64], zinv: Complex64) -> Complex64 {
    p.iter()
        .rev()
        .fold(Complex64::new(0.0, 0.0), |acc, c| acc * zinv + c)
}

impl TransferFunction {
    /// A constant gain.
    pub fn constant(g: f64) -> Self {
        Self {
            num: vec![g],
            den: vec![1.0],
        }
    }

    /// The bilinear integrator `(T/2)(1 + z^-1)/(1 - z^-1)` (Kaplan Fig. 5.21b).
    pub fn bilinear_integrator(t_s: f64) -> Self {
        Self {
            num: vec![0.5 * t_s, 0.5 * t_s],
            den: vec![1.0, -1.0],
        }
    }

    /// The NCO as seen by the averaging discriminator, `z^-1 (T/2)(1 + z^-1)/(1 - z^-1)`
    /// (module docs).
    pub fn nco_average_phase(t_s: f64) -> Self {
        Self {
            num: vec![0.0, 0.5 * t_s, 0.5 * t_s],
            den: vec![1.0, -1.0],
        }
    }

    /// The FLL discriminator on consecutive prompts, `D_f = (1 - z^-1)/T` Hz per cycle.
    pub fn fll_discriminator(t_s: f64) -> Self {
        Self {
            num: vec![1.0 / t_s, -1.0 / t_s],
            den: vec![1.0],
        }
    }

    /// The NCO frequency as the FLL discriminator sees it, `M = D_f N = z^-1 (1 + z^-1)/2`.
    pub fn nco_frequency_seen_by_fll() -> Self {
        Self {
            num: vec![0.0, 0.5, 0.5],
            den: vec![1.0],
        }
    }

    /// Product (series connection).
    pub fn mul(&self, o: &Self) -> Self {
        Self {
            num: poly_mul(&self.num, &o.num),
            den: poly_mul(&self.den, &o.den),
        }
    }

    /// Sum (parallel connection). Equal denominators are kept as they are.
    pub fn add(&self, o: &Self) -> Self {
        if self.den == o.den {
            Self {
                num: poly_add(&self.num, &o.num),
                den: self.den.clone(),
            }
        } else {
            Self {
                num: poly_add(&poly_mul(&self.num, &o.den), &poly_mul(&o.num, &self.den)),
                den: poly_mul(&self.den, &o.den),
            }
        }
    }

    /// The unity-feedback closed loop `L/(1 + L)`.
    pub fn feedback(&self) -> Self {
        Self {
            num: self.num.clone(),
            den: poly_add(&self.den, &self.num),
        }
    }

    /// Value at `z` (complex).
    pub fn eval(&self, z: Complex64) -> Complex64 {
        let zinv = z.inv();
        poly_eval(&self.num, zinv) / poly_eval(&self.den, zinv)
    }

    /// Runs the difference equation `den * y = num * x` over `x` from rest.
    pub fn filter(&self, x: &[f64]) -> Vec<f64> {
        let d0 = self.den.first().copied().unwrap_or(1.0);
        let mut y = vec![0.0; x.len()];
        for k in 0..x.len() {
            let mut acc = 0.0;
            for (i, b) in self.num.iter().enumerate() {
                if i <= k {
                    acc += b * x[k - i];
                }
            }
            for (i, a) in self.den.iter().enumerate().skip(1) {
                if i <= k {
                    acc -= a * y[k - i];
                }
            }
            y[k] = acc / d0;
        }
        y
    }
}

/// Whether all roots of `a0 + a1 z^-1 + ... + an z^-n` lie strictly inside the unit circle.
///
/// The bilinear map `w = (z - 1) / (z + 1)` takes the unit disc to the left half plane, so
/// the test is Routh-Hurwitz on `Q(w) = sum_k a_k (1 - w)^k (1 + w)^(n-k)` (the polynomial
/// times `(1 + w)^n`, with `z^-1 = (1 - w) / (1 + w)`): all first-column entries of its Routh
/// array of one sign and none zero.
///
/// Why not Schur-Cohn on the `a_k` (as before, issue 25): a narrow loop's poles crowd
/// `z = 1` (`1 - s_i T`, `|s_i T|` ~ 1e-4 for a 3rd-order 0.1 Hz loop at 1 ms), its reflection
/// coefficients approach 1 with `1 - k^2` ~ 1e-12, and the recursion lost the sign: the stable
/// 3rd-order loop at 0.1 Hz was refused as unstable. In `w` the same poles sit at `-s_i T / 2`,
/// and the small low-order coefficients of `Q` keep their relative precision.
pub fn polynomial_is_stable(coeffs: &[f64]) -> bool {
    if coeffs.iter().any(|c| !c.is_finite()) {
        return false;
    }
    let scale = coeffs.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    if scale <= 0.0 {
        return false;
    }
    let mut a: Vec<f64> = coeffs.iter().map(|c| c / scale).collect();
    while a.len() > 1 && a.last().is_some_and(|c| *c == 0.0) {
        a.pop(); // roots at z = 0
    }
    if a.first().is_none_or(|c| *c == 0.0) {
        return false; // a root at infinity
    }
    let n = a.len() - 1;
    // Q(w), ascending powers of w.
    let mut q = vec![0.0; n + 1];
    for (k, ak) in a.iter().enumerate() {
        let mut term = vec![*ak];
        for _ in 0..k {
            term = poly_mul(&term, &[1.0, -1.0]);
        }
        for _ in 0..(n - k) {
            term = poly_mul(&term, &[1.0, 1.0]);
        }
        for (qi, ti) in q.iter_mut().zip(&term) {
            *qi += ti;
        }
    }
    routh_hurwitz_stable(&q)
}

/// Routh-Hurwitz: whether every root of `q0 + q1 w + ... + qn w^n` has a negative real part
/// (the first column of the Routh array has no zero and no sign change).
fn routh_hurwitz_stable(q: &[f64]) -> bool {
    let desc: Vec<f64> = q.iter().rev().copied().collect();
    if desc.first().is_none_or(|c| *c == 0.0) {
        return false; // degree dropped: a root of the z-polynomial at z = -1
    }
    let mut prev: Vec<f64> = desc.iter().step_by(2).copied().collect();
    let mut cur: Vec<f64> = desc.iter().skip(1).step_by(2).copied().collect();
    let sign = desc[0].signum();
    for _ in 1..desc.len() {
        let Some(&c0) = cur.first() else { return false };
        if c0 == 0.0 || c0.signum() != sign {
            return false;
        }
        let next: Vec<f64> = (0..prev.len().saturating_sub(1))
            .map(|i| {
                let p1 = prev.get(i + 1).copied().unwrap_or(0.0);
                let c1 = cur.get(i + 1).copied().unwrap_or(0.0);
                (c0 * p1 - prev[0] * c1) / c0
            })
            .collect();
        prev = cur;
        cur = next;
    }
    true
}

/// The open loop of `filter` updated every `t_s` (module docs): `L = F_p N + F_f M` with a phase
/// input, `L_f = F_f M` for a pure FLL.
pub fn open_loop(filter: &LoopFilter, t_s: f64) -> TransferFunction {
    let (fp, ff) = filter.transfer_functions(t_s);
    let m = TransferFunction::nco_frequency_seen_by_fll();
    if !filter.has_primary() {
        return ff.mul(&m);
    }
    // M written over the NCO's denominator (1 - z^-1), so that both paths share one denominator
    // and no pole-zero pair at z = 1 is created by the sum.
    let m_over_nco = TransferFunction {
        num: poly_mul(&m.num, &[1.0, -1.0]),
        den: vec![1.0, -1.0],
    };
    fp.mul(&TransferFunction::nco_average_phase(t_s))
        .add(&ff.mul(&m_over_nco))
}

/// The closed loop `H = L/(1 + L)`: input phase (or discriminator noise) to NCO phase, or for a
/// pure FLL input frequency (or FLL discriminator noise) to the NCO frequency it sees.
pub fn closed_loop(filter: &LoopFilter, t_s: f64) -> TransferFunction {
    open_loop(filter, t_s).feedback()
}

/// Whether the closed loop is stable.
pub fn is_stable(filter: &LoopFilter, t_s: f64) -> bool {
    polynomial_is_stable(&closed_loop(filter, t_s).den)
}

/// One-sided noise bandwidth (Hz) of the closed loop, `integral_0^{1/(2T)} |H|^2 df`, by
/// composite Simpson integration on a grid dense near DC; `None` if the loop is unstable.
pub fn noise_bandwidth_hz(filter: &LoopFilter, t_s: f64) -> Option<f64> {
    if !(t_s.is_finite() && t_s > 0.0 && is_stable(filter, t_s)) {
        return None;
    }
    let h = closed_loop(filter, t_s);
    let f_max = 0.5 / t_s;
    // f = f_max u^2, df = 2 f_max u du: fine resolution near DC where narrow loops live.
    let n = 1 << 16;
    let integrand = |u: f64| {
        let f = f_max * u * u;
        let z = Complex64::from_polar(1.0, 2.0 * std::f64::consts::PI * f * t_s);
        h.eval(z).norm_sqr() * 2.0 * f_max * u
    };
    let du = 1.0 / n as f64;
    let mut sum = integrand(0.0) + integrand(1.0);
    for i in 1..n {
        let w = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += w * integrand(i as f64 * du);
    }
    Some(sum * du / 3.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fll_sees_the_nco_through_m() {
        // D_f N must equal M: compare at a few points on the unit circle.
        let t = 2e-3;
        let dn =
            TransferFunction::fll_discriminator(t).mul(&TransferFunction::nco_average_phase(t));
        let m = TransferFunction::nco_frequency_seen_by_fll();
        for w in [0.1, 1.0, 2.5] {
            let z = Complex64::from_polar(1.0, w);
            assert!((dn.eval(z) - m.eval(z)).norm() < 1e-12);
        }
    }

    #[test]
    fn stability_test_on_known_roots() {
        // (1 - 0.5 z^-1)(1 + 0.9 z^-1): stable. (1 - 1.1 z^-1): unstable. (1 - z^-1): marginal.
        assert!(polynomial_is_stable(&poly_mul(&[1.0, -0.5], &[1.0, 0.9])));
        assert!(!polynomial_is_stable(&[1.0, -1.1]));
        assert!(!polynomial_is_stable(&[1.0, -1.0]));
        // Complex pair at radius 0.95 and 1.05.
        let r: f64 = 0.95;
        assert!(polynomial_is_stable(&[
            1.0,
            -2.0 * r * 0.3_f64.cos(),
            r * r
        ]));
        let r: f64 = 1.05;
        assert!(!polynomial_is_stable(&[
            1.0,
            -2.0 * r * 0.3_f64.cos(),
            r * r
        ]));
        assert!(!polynomial_is_stable(&[]));
        assert!(!polynomial_is_stable(&[f64::NAN, 1.0]));
    }

    /// Issue 25: the 3rd-order loop at 0.1 Hz (and 0.05 Hz) is stable at 1 and 20 ms, as its
    /// analog prototype is at any bandwidth (its poles `1 - s_i T`, `|s_i T|` <= 2e-3); the
    /// Schur-Cohn test refused it. The known limits stay: unstable well beyond `Bn T` = 0.56.
    #[test]
    fn narrow_third_order_loops_are_stable() {
        for (bn, t) in [(0.1, 1e-3), (0.05, 1e-3), (0.1, 20e-3), (0.4, 1e-3)] {
            let f = LoopFilter::pll(3, bn).ok();
            assert!(f.is_some_and(|f| is_stable(&f, t)), "{bn} Hz at {t} s");
        }
        let f = LoopFilter::pll(3, 0.7 / 1e-3).ok();
        assert!(f.is_some_and(|f| !is_stable(&f, 1e-3)));
    }

    #[test]
    fn first_order_noise_bandwidth_closed_form() {
        // For the 1st-order loop of this timing model the sum of h_k^2 gives exactly
        // Bn_digital = Bn / (1 - 2 Bn T) (derived from the impulse response; also measured).
        for bnt in [0.001, 0.01, 0.05, 0.2] {
            let t = 1e-3;
            let bn = bnt / t;
            let f = LoopFilter::pll(1, bn).ok();
            let got = f.and_then(|f| noise_bandwidth_hz(&f, t)).unwrap_or(0.0);
            let want = bn / (1.0 - 2.0 * bnt);
            assert!((got / want - 1.0).abs() < 1e-6, "{bnt}: {got} vs {want}");
        }
    }
}
