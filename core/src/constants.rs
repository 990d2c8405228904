//! Physical and GPS system constants, exactly as IS-GPS-200 specifies them (section 3.3 for the
//! L1 C/A signal, Table 20-IV and 20.3.3.3.3.1 for the navigation user algorithms) and WGS-84
//! (NIMA TR8350.2 Table 3.1, the frame of IS-GPS-200 20.3.3.4.3). Use these, not more precise
//! modern values, so that satellite positions agree with what the control segment computed.
//!
//! `gpsrx_dsp::constants` and `gpsrx_nav::constants` re-export this module.

/// L1 carrier frequency, Hz (IS-GPS-200 3.3.1.1: 154 x 10.23 MHz).
pub const F_L1_HZ: f64 = 1_575.42e6;
/// C/A code chipping rate, chips per second (IS-GPS-200 3.3.2.3: 10.23 MHz / 10).
pub const CA_CHIP_RATE_HZ: f64 = 1.023e6;
/// C/A code length in chips (IS-GPS-200 3.3.2.3: a 1023-chip Gold code).
pub const CA_CODE_LENGTH: usize = 1023;
/// C/A code period, seconds (IS-GPS-200 3.3.2.3: 1023 chips at 1.023 MHz, 1 ms).
pub const CA_CODE_PERIOD_S: f64 = 1.0e-3;
/// Navigation data bit period, seconds (IS-GPS-200 3.3.3 and 20.3.2: 50 bit/s).
pub const NAV_BIT_PERIOD_S: f64 = 20.0e-3;
/// Speed of light in vacuum, m/s (IS-GPS-200 20.3.4.3 and 20.3.3.3.3.1).
pub const SPEED_OF_LIGHT_MPS: f64 = 299_792_458.0;
/// L1 wavelength `c / f_L1`, m (IS-GPS-200 3.3.1.1 and 20.3.4.3; 0.190294 m).
pub const LAMBDA_L1_M: f64 = SPEED_OF_LIGHT_MPS / F_L1_HZ;
/// Carrier cycles per code chip, `f_L1 / f_chip` = 1575.42 / 1.023 = 1540 (IS-GPS-200 3.3.1.1:
/// both are coherently derived from 10.23 MHz).
pub const CARRIER_CYCLES_PER_CHIP: f64 = F_L1_HZ / CA_CHIP_RATE_HZ;

/// WGS-84 value of the Earth's gravitational constant for GPS users, m^3/s^2 (IS-GPS-200
/// Table 20-IV).
pub const MU_M3_S2: f64 = 3.986005e14;
/// WGS-84 value of the Earth's rotation rate, rad/s (IS-GPS-200 Table 20-IV).
pub const OMEGA_E_DOT_RAD_S: f64 = 7.2921151467e-5;
/// The value of pi used by the interface specification for semicircle conversion (IS-GPS-200
/// 20.3.3.3.3.1 and the Table 20-IV note).
#[allow(clippy::approx_constant)] // the ICD value, deliberately not f64::consts::PI
pub const GPS_PI: f64 = 3.1415926535898;
/// Relativistic clock correction constant F = -2 sqrt(mu) / c^2, s/sqrt(m) (IS-GPS-200
/// 20.3.3.3.3.1).
pub const F_REL_S_PER_SQRT_M: f64 = -4.442807633e-10;
/// Seconds in one GPS week (IS-GPS-200 Table 20-IV, the 604800 s of the t_k rule).
pub const SECONDS_PER_WEEK: f64 = 604_800.0;
/// Seconds in one day (IS-GPS-200 20.3.3.5.2.4, the UTC day).
pub const SECONDS_PER_DAY: f64 = 86_400.0;

/// WGS-84 semi-major axis, m (NIMA TR8350.2 Table 3.1; the frame of IS-GPS-200 20.3.3.4.3).
pub const WGS84_A_M: f64 = 6_378_137.0;
/// WGS-84 flattening 1/298.257223563 (NIMA TR8350.2 Table 3.1).
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS-84 first eccentricity squared `e^2 = f (2 - f)` (NIMA TR8350.2 Table 3.3:
/// 6.69437999014e-3).
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_values_match_the_published_ones() {
        assert!((LAMBDA_L1_M - 0.190_293_672_798).abs() < 1e-12);
        assert_eq!(CARRIER_CYCLES_PER_CHIP, 1540.0);
        assert!((WGS84_E2 - 6.694_379_990_14e-3).abs() < 1e-14);
    }
}
