//! Atmospheric delay models for a single-frequency L1 user:
//! the broadcast Klobuchar ionosphere (IS-GPS-200 20.3.3.5.2.5, Figure 20-4) and the
//! Saastamoinen troposphere with a standard atmosphere.

use crate::constants::GPS_PI;
use crate::frames::Llh;
pub use crate::utc::UtcParams;

/// Klobuchar ionospheric coefficients as broadcast in subframe 4 page 18
/// (IS-GPS-200 20.3.3.5.1.7, Table 20-X), in the ICD's semicircle-based units.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KlobucharParams {
    /// alpha_0..alpha_3: amplitude polynomial, s, s/semicircle, s/semicircle^2, s/semicircle^3.
    pub alpha: [f64; 4],
    /// beta_0..beta_3: period polynomial, s, s/semicircle, s/semicircle^2, s/semicircle^3.
    pub beta: [f64; 4],
}

impl KlobucharParams {
    /// Coefficients to use until the broadcast ones are decoded (subframe 4 page 18 comes only
    /// once every 12.5 min): a typical broadcast set (2004-01-01; the fallback RTKLIB uses too).
    /// It removes a good part of the delay on most days, where no correction would leave all
    /// of it (about 2-10 m at the zenith by day).
    pub const FALLBACK: KlobucharParams = KlobucharParams {
        alpha: [0.1118e-07, -0.7451e-08, -0.5961e-07, 0.1192e-06],
        beta: [0.1167e+06, -0.2294e+06, -0.1311e+06, 0.1049e+07],
    };
}

/// Night-time constant delay DC of the Klobuchar model, s (Figure 20-4).
pub const KLOBUCHAR_NIGHT_DELAY_S: f64 = 5.0e-9;

/// L1 ionospheric group delay from the broadcast Klobuchar model, s
/// (IS-GPS-200 20.3.3.5.2.5 and Figure 20-4).
///
/// `tow_s` is the GPS time of week of the measurement (any value: it is reduced modulo one
/// day), `rx` the receiver position, `az_rad`/`el_rad` the satellite direction. Inside, angles
/// are converted to semicircles as the ICD specifies. Returns 0 for satellites at or below
/// the horizon and for non-finite inputs.
pub fn klobuchar_delay_s(
    p: &KlobucharParams,
    tow_s: f64,
    rx: &Llh,
    az_rad: f64,
    el_rad: f64,
) -> f64 {
    if el_rad.is_nan() || el_rad <= 0.0 || !tow_s.is_finite() || !az_rad.is_finite() {
        return 0.0;
    }
    let el_sc = el_rad / GPS_PI;
    let phi_u = rx.lat_rad / GPS_PI;
    let lam_u = rx.lon_rad / GPS_PI;
    // Earth-centred angle between user and ionospheric pierce point, semicircles.
    let psi = 0.0137 / (el_sc + 0.11) - 0.022;
    // Geodetic latitude of the pierce point, clamped to +-0.416 semicircles.
    let phi_i = (phi_u + psi * az_rad.cos()).clamp(-0.416, 0.416);
    // Geodetic longitude of the pierce point.
    let lam_i = lam_u + psi * az_rad.sin() / (phi_i * GPS_PI).cos();
    // Geomagnetic latitude of the pierce point.
    let phi_m = phi_i + 0.064 * ((lam_i - 1.617) * GPS_PI).cos();
    // Local time at the pierce point, s, in [0, 86400).
    let t = (4.32e4 * lam_i + tow_s).rem_euclid(86_400.0);
    // Obliquity factor.
    let f = 1.0 + 16.0 * (0.53 - el_sc).powi(3);
    let poly = |c: &[f64; 4]| c[0] + phi_m * (c[1] + phi_m * (c[2] + phi_m * c[3]));
    let per = poly(&p.beta).max(72_000.0);
    let amp = poly(&p.alpha).max(0.0);
    let x = 2.0 * GPS_PI * (t - 50_400.0) / per;
    if x.abs() < 1.57 {
        let x2 = x * x;
        f * (KLOBUCHAR_NIGHT_DELAY_S + amp * (1.0 - x2 / 2.0 + x2 * x2 / 24.0))
    } else {
        f * KLOBUCHAR_NIGHT_DELAY_S
    }
}

/// Height above which [`saastamoinen_delay_m`] is 0, m (the stratopause: 1 mm of delay at
/// the zenith left, 1 cm at 5 degrees).
pub const TROPO_TOP_M: f64 = 50_000.0;
/// Height of the tropopause of the standard atmosphere, m: the temperature falls at 6.5 K/km
/// up to it and is constant above ([`saastamoinen_delay_m`]).
pub const TROPOPAUSE_M: f64 = 11_000.0;
/// Pressure scale height of the isothermal layer above [`TROPOPAUSE_M`], m:
/// `R T / g = 287.053 J/(kg K) x 216.66 K / 9.80665 m/s^2`.
pub const STRATOSPHERE_SCALE_HEIGHT_M: f64 = 287.053 * 216.66 / 9.80665;

/// Pressure (hPa) and temperature (K) of the standard atmosphere at height `h_m` (>= 0):
/// `P = 1013.25 (1 - 2.2557e-5 h)^5.2568`, `T = 288.16 - 6.5e-3 h` up to [`TROPOPAUSE_M`];
/// above, `T` stays and `P` falls by `exp(-(h - 11 km) / H)` (continuous at 11 km).
fn standard_atmosphere(h_m: f64) -> (f64, f64) {
    let lapse = |h: f64| {
        (
            1013.25 * (1.0 - 2.2557e-5 * h).powf(5.2568),
            15.0 - 6.5e-3 * h + 273.16,
        )
    };
    if h_m <= TROPOPAUSE_M {
        return lapse(h_m);
    }
    let (p11, t11) = lapse(TROPOPAUSE_M);
    (
        p11 * (-(h_m - TROPOPAUSE_M) / STRATOSPHERE_SCALE_HEIGHT_M).exp(),
        t11,
    )
}

/// Relative humidity assumed by [`saastamoinen_delay_m`].
pub const STANDARD_RELATIVE_HUMIDITY: f64 = 0.7;

/// Slant tropospheric delay, m, from the Saastamoinen model with a standard atmosphere
/// (Saastamoinen 1972; the standard-atmosphere conventions are those of RTKLIB's `tropmodel`):
///
/// - P = 1013.25 (1 - 2.2557e-5 h)^5.2568 hPa, T = 15 - 6.5e-3 h + 273.16 K, with h the
///   receiver height (m, clamped at 0), relative humidity 0.7 and water-vapour pressure
///   e = 6.108 RH exp((17.15 T - 4684) / (T - 38.45)) hPa;
/// - dry = 0.0022768 P / (1 - 0.00266 cos(2 lat) - 0.00028 h_km) / cos(z),
///   wet = 0.002277 (1255 / T + 0.05) e / cos(z), z = pi/2 - el.
///
/// The zenith dry delay is about 2.3 m at sea level. Returns 0 for `el_rad <= 0`, below
/// -100 m and above [`TROPO_TOP_M`] (50 km: a millimetre at the zenith is left there, and
/// the formula's height term would divide by zero at 3570 km).
///
/// Above the tropopause ([`TROPOPAUSE_M`], 11 km) the standard atmosphere is taken isothermal
/// (U.S. Standard Atmosphere 1976 up to 20 km: T = 216.66 K, P = 226.3 hPa at 11 km falling as
/// `exp(-(h - 11 km) / H)`, `H = R T / g =` [`STRATOSPHERE_SCALE_HEIGHT_M`]; 5 % under its
/// pressure at 30 km, where it warms again: a millimetre of delay), and the formulas
/// above take that pressure and temperature: the dry term is the hydrostatic delay of the
/// column above the receiver at any height (0.55 m at 11 km, 0.12 m at 20 km, zenith). RTKLIB's
/// `tropmodel` (which this matches to 1e-9 m up to 10 km) returns 0 above 10 km instead: a
/// step of 0.65 m at the zenith and 2-7 m at low elevations when an aircraft climbs through
/// 10 km, which the receiver took for lost samples (every carrier phase jumped at once) and
/// a simulated signal carried as a real jump.
pub fn saastamoinen_delay_m(rx: &Llh, el_rad: f64) -> f64 {
    if el_rad.is_nan() || el_rad <= 0.0 || !(-100.0..=TROPO_TOP_M).contains(&rx.h_m) {
        return 0.0;
    }
    let h_m = rx.h_m.max(0.0);
    let (pressure_hpa, temp_k) = standard_atmosphere(h_m);
    let e_hpa =
        6.108 * STANDARD_RELATIVE_HUMIDITY * ((17.15 * temp_k - 4684.0) / (temp_k - 38.45)).exp();
    let cos_z = (std::f64::consts::FRAC_PI_2 - el_rad).cos();
    let dry_m = 0.0022768 * pressure_hpa
        / (1.0 - 0.00266 * (2.0 * rx.lat_rad).cos() - 0.00028 * h_m / 1e3)
        / cos_z;
    let wet_m = 0.002277 * (1255.0 / temp_k + 0.05) * e_hpa / cos_z;
    dry_m + wet_m
}
