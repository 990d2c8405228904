//! The Cramer-Rao bound of a snapshot's code delay: how well any unbiased estimator can
//! measure a satellite's code phase from `T` seconds of signal at a given C/N0 through a front
//! end of two-sided band `+-B`.
//!
//! # Equations
//!
//! For a known waveform in white noise (Kay, *Fundamentals of Statistical Signal Processing*
//! vol. I, eq. 3.37; Betz & Kolodziejski 2009 for GNSS), the delay's variance is bounded by
//!
//! ```text
//! var(tau) >= 1 / (8 pi^2 beta^2 (C/N0) T)
//! ```
//!
//! with the Gabor (RMS) bandwidth of the band-limited C/A code spectrum
//! `S(f) = Tc sinc^2(f Tc)`, `Tc = 1 / 1.023 MHz`:
//!
//! ```text
//! beta^2 = int_{-B}^{B} f^2 S(f) df / int_{-B}^{B} S(f) df
//!        = (B - sin(2 pi B Tc) / (2 pi Tc)) / (pi^2 Tc^2 int_{-B}^{B} sinc^2(f Tc) df / Tc)
//! ```
//!
//! (the numerator in closed form, the denominator by Simpson's rule). The carrier phase and
//! the data bits of each 1 ms block being unknown (non-coherent sums), the bound grows by the
//! squaring loss `1 + 1 / (2 (C/N0) T_c)` with `T_c` the coherent time of a block; at 40 dB-Hz
//! and 1 ms that is 1.05 (0.2 dB). The C/N0 is the one measured on the quantised samples, so a
//! 1-bit front end's loss (2/pi, -1.96 dB) is in it already.

use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use std::f64::consts::PI;

const SPEED_OF_LIGHT_MPS: f64 = 299_792_458.0;

/// The Gabor bandwidth `beta` of the C/A code limited to `+-band_hz`, Hz (module docs).
/// NaN for a band that is not positive and finite.
pub fn gabor_bandwidth_hz(band_hz: f64) -> f64 {
    if !(band_hz.is_finite() && band_hz > 0.0) {
        return f64::NAN;
    }
    let tc = 1.0 / CA_CHIP_RATE_HZ;
    // int_{-B}^{B} f^2 Tc sinc^2(f Tc) df = (B - sin(2 pi B Tc) / (2 pi Tc)) / (pi^2 Tc).
    let num = (band_hz - (2.0 * PI * band_hz * tc).sin() / (2.0 * PI * tc)) / (PI * PI * tc);
    // int_{-B}^{B} Tc sinc^2(f Tc) df by Simpson's rule (even in f).
    let n = 2000;
    let h = band_hz / n as f64;
    let s = |f: f64| {
        let x = PI * f * tc;
        if x == 0.0 {
            tc
        } else {
            tc * (x.sin() / x).powi(2)
        }
    };
    let mut sum = s(0.0) + s(band_hz);
    for i in 1..n {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * s(i as f64 * h);
    }
    let den = 2.0 * sum * h / 3.0;
    (num / den).sqrt()
}

/// The bound on the code delay's standard deviation, m, for C/N0 `cn0_dbhz`, `total_s` of
/// signal summed non-coherently in blocks of `coherent_s`, front-end band `+-band_hz`
/// (module docs).
pub fn code_delay_crlb_m(cn0_dbhz: f64, total_s: f64, coherent_s: f64, band_hz: f64) -> f64 {
    let cn0 = 10f64.powf(cn0_dbhz / 10.0);
    let beta = gabor_bandwidth_hz(band_hz);
    let squaring = 1.0 + 1.0 / (2.0 * cn0 * coherent_s);
    let var_s2 = squaring / (8.0 * PI * PI * beta * beta * cn0 * total_s);
    SPEED_OF_LIGHT_MPS * var_s2.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gabor_bandwidth_agrees_with_a_direct_integration() {
        // Both integrals by the midpoint rule on a fine grid.
        let tc = 1.0 / CA_CHIP_RATE_HZ;
        for band in [0.5e6, 1.023e6, 1.75e6, 4e6] {
            let n = 200_000;
            let (mut num, mut den) = (0.0, 0.0);
            for i in 0..n {
                let f = -band + (i as f64 + 0.5) * 2.0 * band / n as f64;
                let x = PI * f * tc;
                let s = (x.sin() / x).powi(2);
                num += f * f * s;
                den += s;
            }
            let direct = (num / den).sqrt();
            let b = gabor_bandwidth_hz(band);
            assert!((b / direct - 1.0).abs() < 1e-4, "{band}: {b} vs {direct}");
        }
        // A narrow band: the spectrum is flat, beta^2 = B^2 / 3.
        let b = gabor_bandwidth_hz(1e3);
        assert!((b / (1e3 / 3f64.sqrt()) - 1.0).abs() < 1e-5, "{b}");
        assert!(gabor_bandwidth_hz(0.0).is_nan());
    }

    #[test]
    fn the_bound_scales_as_one_over_root_cn0_t() {
        let a = code_delay_crlb_m(40.0, 12e-3, 1e-3, 1.75e6);
        // 457 kHz of Gabor bandwidth, 1e4 Hz x 12 ms: 6.7 m (times the squaring loss 1.05).
        assert!((a / 1.05f64.sqrt() - 6.73).abs() < 0.02, "{a}");
        let b = code_delay_crlb_m(46.0, 12e-3, 12e-3, 1.75e6);
        let c = code_delay_crlb_m(40.0, 48e-3, 48e-3, 1.75e6);
        // 6 dB more C/N0 or 4 times the time halve it (squaring loss aside).
        assert!((b / c - 1.0).abs() < 0.01, "{b} {c}");
    }
}
