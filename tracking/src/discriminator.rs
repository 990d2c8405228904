//! Carrier (PLL, FLL) and code (DLL) discriminators on correlator outputs (Kaplan Tables 5.2,
//! 5.4 and 5.5).
//!
//! Conventions. A prompt `P = I + jQ = A d exp(j 2 pi e)` with data bit `d = +-1` and phase error
//! `e = theta_signal - phi_replica` in cycles. Code errors are `e = (code phase of the signal) -
//! (code phase of the replica)` in chips, positive when the replica lags and must speed up; the
//! early replica runs `d/2` chip ahead in code phase, the late one `d/2` behind. Every
//! discriminator returns 0 for a zero or non-finite input instead of NaN.

use num_complex::Complex64;
use std::f64::consts::PI;

fn usable(z: Complex64) -> bool {
    z.re.is_finite() && z.im.is_finite() && (z.re != 0.0 || z.im != 0.0)
}

/// Costas two-quadrant arctangent `atan(Q/I) / (2 pi)`, cycles, in `[-1/4, 1/4]`.
///
/// Insensitive to the data bit (`d = -1` leaves `Q/I` unchanged); unit slope; its output is the
/// phase error wrapped to +-1/4 cycle, so a Costas loop has a 180 deg ambiguity (Kaplan
/// Table 5.2, "ATAN(Q/I)", the maximum-likelihood estimator at high SNR).
pub fn costas_atan(p: Complex64) -> f64 {
    if !usable(p) {
        return 0.0;
    }
    if p.re == 0.0 {
        return 0.25 * p.im.signum();
    }
    (p.im / p.re).atan() / (2.0 * PI)
}

/// Four-quadrant arctangent `atan2(Q, I) / (2 pi)`, cycles, in `(-1/2, 1/2]`: for a data-free
/// (pilot) signal; a data bit flip appears as a half-cycle jump.
pub fn pll_atan2(p: Complex64) -> f64 {
    if !usable(p) {
        return 0.0;
    }
    p.im.atan2(p.re) / (2.0 * PI)
}

/// FLL `atan2(cross, dot) / (2 pi dt)`, Hz, in `(-1/(2 dt), 1/(2 dt)]`, on consecutive prompts
/// whose centres are `dt_s` apart (`dt = T` for back-to-back intervals).
///
/// `cross = I1 Q2 - I2 Q1`, `dot = I1 I2 + Q1 Q2`, i.e. `arg(P2 P1*)` (Kaplan Table 5.4,
/// ATAN2(dot, cross)). A data-bit flip between the prompts adds a half cycle: use
/// [`fll_data_insensitive`] unless the two prompts are known to carry the same bit.
pub fn fll_atan2(prev: Complex64, cur: Complex64, dt_s: f64) -> f64 {
    if !(usable(prev) && usable(cur) && dt_s.is_finite() && dt_s > 0.0) {
        return 0.0;
    }
    let x = cur * prev.conj();
    x.im.atan2(x.re) / (2.0 * PI * dt_s)
}

/// Data-insensitive FLL `atan2(cross * sign(dot), |dot|) / (2 pi dt)`, Hz, in
/// `[-1/(4 dt), 1/(4 dt)]`: the phase change is folded into +-1/4 cycle, so a bit flip between
/// the prompts (which negates both cross and dot) does not change the output (Kaplan Table 5.4,
/// the sign-of-dot form). The pull-in range is therefore +-1/(4T).
pub fn fll_data_insensitive(prev: Complex64, cur: Complex64, dt_s: f64) -> f64 {
    if !(usable(prev) && usable(cur) && dt_s.is_finite() && dt_s > 0.0) {
        return 0.0;
    }
    let x = cur * prev.conj();
    let s = if x.re < 0.0 { -1.0 } else { 1.0 };
    (x.im * s).atan2(x.re.abs()) / (2.0 * PI * dt_s)
}

/// Normalised early-minus-late envelope, chips:
/// `D = (2 - d)/2 * (|E| - |L|) / (|E| + |L|)` for early-late spacing `d` chips (0 < d <= 1).
///
/// Normalisation: for the ideal (infinite-bandwidth) triangle `R(x) = 1 - |x|` and a code error
/// `|e| <= d/2`, `|E| = A(1 - d/2 + e)`, `|L| = A(1 - d/2 - e)`, so `(|E|-|L|)/(|E|+|L|) =
/// 2e/(2 - d)` and `D = e` exactly: unit slope in chips, independent of the amplitude A (Kaplan
/// Table 5.5, normalised E-L envelope; for d = 1 the familiar `0.5 (E-L)/(E+L)`). Beyond `d/2`
/// the output flattens and it returns to 0 at `|e| = 1 + d/2`.
pub fn dll_normalized_envelope(early: Complex64, late: Complex64, spacing_chips: f64) -> f64 {
    let (e, l) = (early.norm(), late.norm());
    let sum = e + l;
    if !(sum.is_finite() && sum > 0.0 && spacing_chips.is_finite()) {
        return 0.0;
    }
    0.5 * (2.0 - spacing_chips) * (e - l) / sum
}

/// Dot-product discriminator, chips: `D = Re((E - L) P*) / (2 |P|^2)`
/// `= ((I_E - I_L) I_P + (Q_E - Q_L) Q_P) / (2 (I_P^2 + Q_P^2))`.
///
/// Normalisation: for `|e| <= d/2` the triangle gives `E - L = 2 e c` and `P = (1 - |e|) c` (c the
/// complex amplitude, data bit included), so `D = e/(1 - |e|) = e + O(e^2)` chips for any spacing
/// d (Kaplan Table 5.5, dot product power, normalised by the prompt power so that it is
/// amplitude-free). Data bits cancel (both E-L and P carry them). Uses the prompt, so it assumes
/// the carrier is tracked well enough that P is not near zero.
pub fn dll_dot_product(early: Complex64, prompt: Complex64, late: Complex64) -> f64 {
    let p2 = prompt.norm_sqr();
    if !(p2.is_finite() && p2 > 0.0) {
        return 0.0;
    }
    let v = ((early - late) * prompt.conj()).re / (2.0 * p2);
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(x: f64) -> f64 {
        (1.0 - x.abs()).max(0.0)
    }

    #[test]
    fn carrier_discriminators_are_unit_slope_and_wrap_as_stated() {
        for k in -20..=20 {
            let e = k as f64 * 0.01; // +-0.2 cycle
            for d in [1.0, -1.0] {
                let p = Complex64::from_polar(3.0 * d, 2.0 * PI * e);
                assert!((costas_atan(p) - e).abs() < 1e-12);
            }
            assert!((pll_atan2(Complex64::from_polar(2.0, 2.0 * PI * e)) - e).abs() < 1e-12);
        }
        // Costas wraps at +-1/4: 0.3 cycle reads as -0.2.
        let p = Complex64::from_polar(1.0, 2.0 * PI * 0.3);
        assert!((costas_atan(p) + 0.2).abs() < 1e-12);
        assert_eq!(costas_atan(Complex64::new(0.0, -1.0)), -0.25);
        assert_eq!(costas_atan(Complex64::new(0.0, 0.0)), 0.0);
        assert_eq!(costas_atan(Complex64::new(f64::NAN, 0.0)), 0.0);
    }

    #[test]
    fn fll_discriminators() {
        let t = 1e-3;
        for f in [-240.0, -100.0, -3.0, 0.0, 7.0, 200.0, 249.0] {
            let p1 = Complex64::from_polar(2.0, 0.4);
            let p2 = p1 * Complex64::from_polar(1.0, 2.0 * PI * f * t);
            assert!((fll_atan2(p1, p2, t) - f).abs() < 1e-9);
            assert!((fll_data_insensitive(p1, p2, t) - f).abs() < 1e-9);
            // A bit flip between the prompts: the data-insensitive form does not see it.
            assert!((fll_data_insensitive(p1, -p2, t) - f).abs() < 1e-9);
        }
        // 300 Hz at T = 1 ms is beyond +-250 Hz: folds to 300 - 500 = -200 Hz.
        let p1 = Complex64::new(1.0, 0.0);
        let p2 = Complex64::from_polar(1.0, 2.0 * PI * 0.3);
        assert!((fll_data_insensitive(p1, p2, t) + 200.0).abs() < 1e-9);
        assert_eq!(fll_atan2(p1, p2, 0.0), 0.0);
    }

    #[test]
    fn dll_discriminators_read_chips_for_any_spacing() {
        let c = Complex64::from_polar(-5.0, 1.1); // arbitrary carrier phase and data bit
        for d in [0.1, 0.2, 0.5, 1.0] {
            for k in -10..=10 {
                let e = k as f64 * 0.05 * d; // within +-d/2
                let early = c * tri(e - d / 2.0);
                let late = c * tri(e + d / 2.0);
                let prompt = c * tri(e);
                assert!((dll_normalized_envelope(early, late, d) - e).abs() < 1e-12);
                assert!((dll_dot_product(early, prompt, late) - e / (1.0 - e.abs())).abs() < 1e-12);
            }
        }
        let z = Complex64::new(0.0, 0.0);
        assert_eq!(dll_normalized_envelope(z, z, 1.0), 0.0);
        assert_eq!(dll_dot_product(z, z, z), 0.0);
    }

    proptest::proptest! {
        /// Any amplitude, data bit and carrier phase: the Costas output is the phase error, the
        /// E-L envelope output is the code error (within +-d/2) for any spacing.
        #[test]
        fn unit_slope_whatever_the_amplitude(
            a in 1e-3f64..1e4,
            neg in proptest::bool::ANY,
            e in -0.2499f64..0.2499,
            phase in -PI..PI,
            d in 0.1f64..=1.0,
            frac in -0.999f64..0.999,
        ) {
            let bit = if neg { -1.0 } else { 1.0 };
            let p = Complex64::from_polar(a * bit, 2.0 * PI * e);
            proptest::prop_assert!((costas_atan(p) - e).abs() < 1e-9);
            let c = Complex64::from_polar(a * bit, phase);
            let x = frac * d / 2.0;
            let (early, late) = (c * tri(x - d / 2.0), c * tri(x + d / 2.0));
            proptest::prop_assert!((dll_normalized_envelope(early, late, d) - x).abs() < 1e-9);
        }
    }
}
