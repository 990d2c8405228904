//! Physical and system constants exactly as IS-GPS-200 specifies them (Table 20-IV and
//! 20.3.3.3.3.1). Use these, not more precise modern values, so that satellite positions
//! agree with what the control segment computed.

/// WGS-84 value of the Earth's gravitational constant for GPS users, m^3/s^2 (Table 20-IV).
pub const MU_M3_S2: f64 = 3.986005e14;
/// WGS-84 value of the Earth's rotation rate, rad/s (Table 20-IV).
pub const OMEGA_E_DOT_RAD_S: f64 = 7.2921151467e-5;
/// Speed of light in vacuum, m/s (20.3.3.3.3.1).
pub const SPEED_OF_LIGHT_MPS: f64 = 299_792_458.0;
/// The value of pi used by the interface specification for semicircle conversion (20.3.3.3.3.1
/// and Table 20-IV note).
#[allow(clippy::approx_constant)] // the ICD value, deliberately not f64::consts::PI
pub const GPS_PI: f64 = 3.1415926535898;
/// Relativistic clock correction constant F = -2 sqrt(mu) / c^2, s/sqrt(m) (20.3.3.3.3.1).
pub const F_REL_S_PER_SQRT_M: f64 = -4.442807633e-10;
/// Seconds in one GPS week.
pub const SECONDS_PER_WEEK: f64 = 604_800.0;
/// Seconds in one day.
pub const SECONDS_PER_DAY: f64 = 86_400.0;
/// L1 carrier frequency, Hz (IS-GPS-200 3.3.1.1).
pub const L1_FREQ_HZ: f64 = 1_575.42e6;
/// WGS-84 semi-major axis, m (NIMA TR8350.2 Table 3.1).
pub const WGS84_A_M: f64 = 6_378_137.0;
/// WGS-84 flattening (NIMA TR8350.2 Table 3.1).
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
