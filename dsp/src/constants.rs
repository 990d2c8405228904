//! GPS L1 C/A signal constants (IS-GPS-200 section 3.3).

/// L1 carrier frequency, Hz (IS-GPS-200 3.3.1.1: 154 x 10.23 MHz).
pub const F_L1_HZ: f64 = 1_575.42e6;
/// C/A code chipping rate, chips per second (IS-GPS-200 3.3.2.3: 10.23 MHz / 10).
pub const CA_CHIP_RATE_HZ: f64 = 1.023e6;
/// C/A code length in chips.
pub const CA_CODE_LENGTH: usize = 1023;
/// C/A code period, seconds.
pub const CA_CODE_PERIOD_S: f64 = 1.0e-3;
/// Navigation data bit period, seconds (50 bit/s).
pub const NAV_BIT_PERIOD_S: f64 = 20.0e-3;
/// Speed of light in vacuum, m/s (IS-GPS-200 20.3.4.3).
pub const SPEED_OF_LIGHT_MPS: f64 = 299_792_458.0;
/// L1 wavelength, m.
pub const LAMBDA_L1_M: f64 = SPEED_OF_LIGHT_MPS / F_L1_HZ;
/// Carrier cycles per code chip (1575.42 / 1.023 = 1540).
pub const CARRIER_CYCLES_PER_CHIP: f64 = F_L1_HZ / CA_CHIP_RATE_HZ;
