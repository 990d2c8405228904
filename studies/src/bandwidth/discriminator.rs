//! Statistics of the channel's discriminators at the prompt SNR: Costas `atan(Q/I)` and the
//! normalised early-minus-late envelope.

use super::formulas::lin;
use std::f64::consts::PI;

/// A discriminator linearised at zero error: mean output slope (output units per unit error)
/// and output noise variance (output units^2) per update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscriminatorStats {
    /// `d E[D] / d e` at `e = 0`.
    pub slope: f64,
    /// `var(D)` at `e = 0`.
    pub noise_var: f64,
}

/// Complementary error function, fractional error < 1.2e-7 (Numerical Recipes `erfcc`,
/// Chebyshev fit).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Probability density of the phase `psi` (rad) of a unit-phasor carrier in complex Gaussian
/// noise at SNR `rho = A^2/(2 sigma^2)`:
/// `p(psi) = (1/(2 pi)) [exp(-rho) + sqrt(pi rho) cos(psi) exp(-rho sin^2 psi)
/// erfc(-sqrt(rho) cos psi)]`.
pub fn carrier_phase_pdf(psi: f64, rho: f64) -> f64 {
    let c = psi.cos();
    let s = psi.sin();
    ((-rho).exp() + (PI * rho).sqrt() * c * (-rho * s * s).exp() * erfc(-rho.sqrt() * c))
        / (2.0 * PI)
}

/// Composite Simpson's rule of `f` over `[a, b]` with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let n = n + n % 2;
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
    }
    s * h / 3.0
}

/// Statistics of the Costas `atan(Q/I)` discriminator in cycles at the prompt SNR
/// `rho = CN0 T`: its output is the prompt's phase folded into `(-pi/2, pi/2]`, so with the
/// density [`carrier_phase_pdf`] the mean output at a phase error `phi` is
/// `m(phi) = integral fold(psi + phi) p(psi) dpsi`; the fold's jumps of `-pi` at `+-pi/2` give the
/// slope `m'(0) = 1 - pi (p(pi/2) + p(-pi/2)) = 1 - exp(-rho)`, and the variance is
/// `integral fold(psi)^2 p(psi) dpsi` (numerically; `-> 1/(2 rho)` rad^2 at high SNR, the
/// formula's coherent term, and `pi^2/12` at rho = 0).
pub fn costas_atan_stats(cn0_dbhz: f64, t_s: f64) -> DiscriminatorStats {
    let rho = lin(cn0_dbhz) * t_s;
    let n = 1 << 16;
    let half = PI / 2.0;
    let mid = simpson(|x| x * x * carrier_phase_pdf(x, rho), -half, half, n);
    // |psi| > pi/2 folds to psi -+ pi.
    let hi = simpson(
        |x| (x - PI).powi(2) * carrier_phase_pdf(x, rho),
        half,
        PI,
        n / 4,
    );
    let lo = simpson(
        |x| (x + PI).powi(2) * carrier_phase_pdf(x, rho),
        -PI,
        -half,
        n / 4,
    );
    DiscriminatorStats {
        slope: 1.0 - (-rho).exp(),
        noise_var: (mid + hi + lo) / (4.0 * PI * PI),
    }
}

/// Gauss-Hermite nodes and weights for `integral exp(-x^2) f(x) dx` (Newton on the orthonormal
/// Hermite recurrence; Numerical Recipes `gauher`).
pub fn gauss_hermite(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let pim4 = PI.powf(-0.25);
    let nf = n as f64;
    let mut z = 0.0;
    for i in 0..n.div_ceil(2) {
        z = match i {
            0 => (2.0 * nf + 1.0).sqrt() - 1.855_75 * (2.0 * nf + 1.0).powf(-1.0 / 6.0),
            1 => z - 1.14 * nf.powf(0.426) / z,
            2 => 1.86 * z - 0.86 * x[0],
            3 => 1.91 * z - 0.91 * x[1],
            _ => 2.0 * z - x[i - 2],
        };
        let mut pp = 1.0;
        for _ in 0..100 {
            let (mut p1, mut p2) = (pim4, 0.0);
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                let jf = j as f64;
                p1 = z * (2.0 / (jf + 1.0)).sqrt() * p2 - (jf / (jf + 1.0)).sqrt() * p3;
            }
            pp = (2.0 * nf).sqrt() * p2;
            let z1 = z;
            z = z1 - p1 / pp;
            if (z - z1).abs() <= 3e-14 {
                break;
            }
        }
        x[i] = z;
        x[n - 1 - i] = -z;
        w[i] = 2.0 / (pp * pp);
        w[n - 1 - i] = w[i];
    }
    (x, w)
}

/// Statistics of the channel's normalised early-minus-late envelope discriminator
/// `D = ((2 - d)/2) (|E| - |L|)/(|E| + |L|)` (chips) at the prompt SNR `rho = CN0 T`, spacing d:
/// `E = A(1 - d/2 + e) + n_E`, `L = A(1 - d/2 - e) + n_L` with `A^2/(2 sigma^2) = rho`, complex
/// Gaussian noise whose E and L parts correlate by `R(d) = 1 - d` (ideal triangle). Expectations
/// by 4-D Gauss-Hermite quadrature (24 nodes per dimension); slope by a central difference in
/// `e`. At high SNR `var(D) -> d/(4 rho)`, slope 1, so that a loop of noise bandwidth Bn gives
/// the coherent `Bn d/(2 CN0)`.
pub fn envelope_dll_stats(cn0_dbhz: f64, t_s: f64, d: f64) -> DiscriminatorStats {
    let rho = lin(cn0_dbhz) * t_s;
    let amp = (2.0 * rho).sqrt();
    let r = 1.0 - d;
    let (a, b) = (((1.0 + r) / 2.0).sqrt(), ((1.0 - r) / 2.0).max(0.0).sqrt());
    let (x, w) = gauss_hermite(24);
    let nodes: Vec<(f64, f64)> = x
        .iter()
        .zip(&w)
        .map(|(x, w)| (std::f64::consts::SQRT_2 * x, w / PI.sqrt()))
        .collect();
    let moments = |e: f64| {
        let (me, ml) = (amp * (1.0 - d / 2.0 + e), amp * (1.0 - d / 2.0 - e));
        let (mut m1, mut m2) = (0.0, 0.0);
        for &(sr, wsr) in &nodes {
            for &(si, wsi) in &nodes {
                for &(tr, wtr) in &nodes {
                    for &(ti, wti) in &nodes {
                        let wt = wsr * wsi * wtr * wti;
                        let ee = (me + a * sr + b * tr).hypot(a * si + b * ti);
                        let ll = (ml + a * sr - b * tr).hypot(a * si - b * ti);
                        let dd = 0.5 * (2.0 - d) * (ee - ll) / (ee + ll);
                        m1 += wt * dd;
                        m2 += wt * dd * dd;
                    }
                }
            }
        }
        (m1, m2)
    };
    let h = 1e-3;
    let (_, v0) = moments(0.0);
    let (mp, _) = moments(h);
    let (mm, _) = moments(-h);
    DiscriminatorStats {
        slope: (mp - mm) / (2.0 * h),
        noise_var: v0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discriminator_statistics_have_the_right_limits() {
        // The phase density integrates to 1.
        for rho in [0.0, 0.3, 3.0, 300.0] {
            let s = simpson(|x| carrier_phase_pdf(x, rho), -PI, PI, 1 << 14);
            assert!((s - 1.0).abs() < 1e-5, "rho {rho}: {s}");
        }
        // High SNR: atan(Q/I) variance -> 1/(2 rho) rad^2, slope 1 (50 dB-Hz, 20 ms: rho 2000).
        let st = costas_atan_stats(50.0, 20e-3);
        let rho = 10f64.powf(5.0) * 0.02;
        assert!((st.noise_var * 4.0 * PI * PI * 2.0 * rho - 1.0).abs() < 0.01);
        assert!((st.slope - 1.0).abs() < 1e-9);
        // rho -> 0: uniform over (-pi/2, pi/2]: pi^2/12 rad^2, slope 0.
        let st = costas_atan_stats(-60.0, 1e-3);
        assert!((st.noise_var * 4.0 * PI * PI - PI * PI / 12.0).abs() < 1e-3);
        assert!(st.slope < 1e-6);
        // Gauss-Hermite: sum w = sqrt(pi), E[X^2] = 1/2 for weight exp(-x^2).
        let (x, w) = gauss_hermite(24);
        assert!((w.iter().sum::<f64>() - PI.sqrt()).abs() < 1e-10);
        let m2: f64 = x.iter().zip(&w).map(|(x, w)| w * x * x).sum::<f64>() / PI.sqrt();
        assert!((m2 - 0.5).abs() < 1e-10);
        // Envelope DLL at high SNR (45 dB-Hz, 20 ms): slope 1, var d/(4 rho), d = 1.
        let st = envelope_dll_stats(45.0, 20e-3, 1.0);
        let rho = 10f64.powf(4.5) * 0.02;
        assert!((st.slope - 1.0).abs() < 0.01, "{st:?}");
        assert!((st.noise_var * 4.0 * rho - 1.0).abs() < 0.02, "{st:?}");
    }
}
