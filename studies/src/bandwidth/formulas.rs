//! The thermal-noise formulas of oracles.md (PLL, DLL, FLL).

use std::f64::consts::PI;

pub(super) fn lin(cn0_dbhz: f64) -> f64 {
    10f64.powf(cn0_dbhz / 10.0)
}

/// PLL thermal jitter of a Costas loop, degrees (oracles.md; Kaplan eq. 5.6):
/// `sigma = (360/(2 pi)) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))`, Bn in Hz, CN0 = 10^(C/N0 / 10) Hz,
/// T in s.
pub fn pll_jitter_deg(bn_hz: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let cn0 = lin(cn0_dbhz);
    (360.0 / (2.0 * PI)) * (bn_hz / cn0 * (1.0 + 1.0 / (2.0 * t_s * cn0))).sqrt()
}

/// DLL thermal jitter of a non-coherent early-minus-late power discriminator with E-L spacing
/// `d_chips`, chips (oracles.md): `sigma = sqrt((Bn d/(2 CN0))(1 + 2/(T CN0 (2 - d))))`.
pub fn dll_jitter_chips(bn_hz: f64, d_chips: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let cn0 = lin(cn0_dbhz);
    (bn_hz * d_chips / (2.0 * cn0) * (1.0 + 2.0 / (t_s * cn0 * (2.0 - d_chips)))).sqrt()
}

/// FLL thermal jitter, Hz (oracles.md): `sigma = (1/(2 pi T)) sqrt((4 F Bn/CN0)(1 + 1/(T CN0)))`,
/// `F` = 1 at high C/N0 and 2 near threshold.
pub fn fll_jitter_hz(bn_hz: f64, cn0_dbhz: f64, t_s: f64, f: f64) -> f64 {
    let cn0 = lin(cn0_dbhz);
    (4.0 * f * bn_hz / cn0 * (1.0 + 1.0 / (t_s * cn0))).sqrt() / (2.0 * PI * t_s)
}

/// Variance (cycles^2) per update of the Costas discriminator noise that the PLL formula
/// implies: `s^2 = (1/(2 T CN0))(1 + 1/(2 T CN0)) / (2 pi)^2`, so that an analog loop of noise
/// bandwidth Bn gives `2 Bn T s^2 = sigma^2` ([`pll_jitter_deg`] in cycles).
pub fn costas_formula_noise_var_cycles2(cn0_dbhz: f64, t_s: f64) -> f64 {
    let x = 2.0 * t_s * lin(cn0_dbhz);
    (1.0 / x) * (1.0 + 1.0 / x) / (4.0 * PI * PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formulas_reproduce_the_oracle_examples() {
        // oracles.md: T = 1 ms: Bn 2 Hz at 45 dB-Hz 0.46 deg; Bn 10 Hz at 35 dB-Hz 3.47 deg;
        // Bn 18 Hz at 30 dB-Hz 9.41 deg. DLL d = 1, Bn 0.5 Hz, 45 dB-Hz: 0.0029 chip.
        assert!((pll_jitter_deg(2.0, 45.0, 1e-3) - 0.46).abs() < 0.005);
        assert!((pll_jitter_deg(10.0, 35.0, 1e-3) - 3.47).abs() < 0.005);
        assert!((pll_jitter_deg(18.0, 30.0, 1e-3) - 9.41).abs() < 0.005);
        assert!((dll_jitter_chips(0.5, 1.0, 45.0, 1e-3) - 0.0029).abs() < 0.00005);
        // FLL: 1/(2 pi T) sqrt(4 Bn/CN0 (1 + 1/(T CN0))) at 10 Hz, 45 dB-Hz, 1 ms, F = 1.
        let cn0 = 10f64.powf(4.5);
        let want = (4.0 * 10.0 / cn0 * (1.0 + 1.0 / (1e-3 * cn0))).sqrt() / (2.0 * PI * 1e-3);
        assert!((fll_jitter_hz(10.0, 45.0, 1e-3, 1.0) - want).abs() < 1e-12);
    }
}
