//! Simulated DR sensors (yaw-rate gyro, odometer) and a longitudinal accelerometer, made from a
//! [`VehicleTruth`] trajectory with the error sources of seeds 000 and 002.
//!
//! **DR** ([`simulate_dr`]): rows at `t_k = t_0 + k / rate_hz` while `t_k <= t_end` (`t_0`, `t_end`:
//! first and last truth times). Row `k >= 1` covers `(t_{k-1}, t_k]` (`dt = 1 / rate_hz`), with the
//! truth integrated over it: heading change `dpsi` (unwrapped heading, linear between truth
//! states) and path length `dd` (trapezoid of `speed_mps`). With the configured *nominal*
//! parameters `Sf_G` (`sf_g_dps_per_v`), `V_nom` (`v_nom_v`), `Sf_N` (`sf_n_m_per_pulse`):
//! - gyro (seed 000 eq. 3 inverted): `gyro_v = V_nom + b + cos(theta) (dpsi/dt in deg/s) / Sf_G + n`,
//!   `b` = `gyro_bias_offset_v`, `theta` = `gyro_tilt_deg` (a gyro tilted by `theta` about a
//!   horizontal axis senses `cos(theta)` of the yaw rate), `n ~ N(0, gyro_noise_v^2)` per row;
//! - odometer (eq. 2 inverted): `(1 + e) dd / Sf_N` pulses, `e` = `odo_scale_error` (the tyre is
//!   smaller than nominal when `e > 0`), quantised to whole pulses with the fractional remainder
//!   carried to the next row (so the count never loses distance).
//!
//! The sensors are therefore exactly described by the *true* parameters of
//! [`DrSensorConfig::true_params`]: `Sf_G / cos(theta)`, `V_nom + b`, `Sf_N / (1 + e)`. With
//! `raw = false` the rows are in engineering units computed with the nominal parameters:
//! `yaw_rate_dps = Sf_G (gyro_v - V_nom)` and `speed_mps = (1 + e) dd / dt` (not quantised).
//! Row 0 has no interval: zero pulses (speed 0) and the gyro output of the instantaneous yaw rate.
//!
//! **Accelerometer** ([`simulate_accel`], seed 002): at `t_k = t_0 + k / rate_hz`,
//! `a_long_mps2 = a_long + g sin(pitch) + bias + w`, `g` = [`GRAVITY_MPS2`], `w ~ N(0,
//! vibration_noise_mps2^2)` white (vibration and road shocks), truth interpolated linearly.
//! Both models draw from xoshiro256++ seeded with `seed`: the same seed gives the same log.

use crate::accel_log::AccelSample;
use crate::dr_error::DrError;
use crate::dr_log::{DrReading, DrSample};
use crate::dr_mechanization::DrParams;
use crate::vehicle::{interpolate_truth, validate_truth, TruthIntegrals, VehicleTruth};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Standard gravity, m/s^2.
pub const GRAVITY_MPS2: f64 = 9.80665;

/// Highest sensor rate accepted, Hz (a bound on memory).
pub const MAX_SENSOR_RATE_HZ: f64 = 1000.0;

/// Seed 000's gyro scale factor, deg/s/V.
pub const SEED000_SF_G_DPS_PER_V: f64 = 45.045;

fn d_rate() -> f64 {
    10.0
}
fn d_true() -> bool {
    true
}
fn d_sf_g() -> f64 {
    SEED000_SF_G_DPS_PER_V
}
fn d_v_nom() -> f64 {
    2.5
}
fn d_sf_n() -> f64 {
    0.1
}
fn d_accel_rate() -> f64 {
    50.0
}

/// The DR sensors of a simulated vehicle (the simulator's `[dr]` table); see the module
/// documentation for the equations.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrSensorConfig {
    /// Output rate, Hz (default 10).
    #[serde(default = "d_rate")]
    pub rate_hz: f64,
    /// true: `gyro_v`/`odo_pulses` rows; false: `yaw_rate_dps`/`speed_mps` (default true).
    #[serde(default = "d_true")]
    pub raw: bool,
    /// Nominal gyro scale factor `Sf_G`, deg/s/V (default 45.045, seed 000).
    #[serde(default = "d_sf_g")]
    pub sf_g_dps_per_v: f64,
    /// Nominal gyro zero-rate voltage `V_nom`, V (default 2.5).
    #[serde(default = "d_v_nom")]
    pub v_nom_v: f64,
    /// Gyro bias: offset of the true zero-rate voltage from `V_nom`, V (default 0).
    #[serde(default)]
    pub gyro_bias_offset_v: f64,
    /// Gyro mounting tilt from vertical, deg (default 0; seed 000 case 3: 20).
    #[serde(default)]
    pub gyro_tilt_deg: f64,
    /// White noise on each row's mean gyro voltage, V (default 0).
    #[serde(default)]
    pub gyro_noise_v: f64,
    /// Nominal odometer scale factor `Sf_N`, m/pulse (default 0.1).
    #[serde(default = "d_sf_n")]
    pub sf_n_m_per_pulse: f64,
    /// Relative odometer scale error `e`: `(1 + e)` times the nominal pulse count (default 0).
    #[serde(default)]
    pub odo_scale_error: f64,
    /// Noise seed (default 0).
    #[serde(default)]
    pub seed: u64,
}

impl Default for DrSensorConfig {
    /// Perfect sensors with seed 000's nominal parameters, raw outputs at 10 Hz.
    fn default() -> Self {
        Self {
            rate_hz: d_rate(),
            raw: true,
            sf_g_dps_per_v: d_sf_g(),
            v_nom_v: d_v_nom(),
            gyro_bias_offset_v: 0.0,
            gyro_tilt_deg: 0.0,
            gyro_noise_v: 0.0,
            sf_n_m_per_pulse: d_sf_n(),
            odo_scale_error: 0.0,
            seed: 0,
        }
    }
}

fn check_rate(name: &str, rate_hz: f64) -> Result<(), DrError> {
    if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= MAX_SENSOR_RATE_HZ) {
        return Err(DrError::Config(format!(
            "{name}.rate_hz = {rate_hz} must be in (0, {MAX_SENSOR_RATE_HZ}] Hz"
        )));
    }
    Ok(())
}

impl DrSensorConfig {
    /// Checks what the types cannot: rate in (0, 1000] Hz, scale factors positive, finite
    /// voltages, tilt within +-80 deg, noise `>= 0`, `odo_scale_error > -1`.
    pub fn validate(&self) -> Result<(), DrError> {
        let bad = |m: String| Err(DrError::Config(format!("dr: {m}")));
        check_rate("dr", self.rate_hz)?;
        if !(self.sf_g_dps_per_v.is_finite() && self.sf_g_dps_per_v > 0.0) {
            return bad(format!(
                "sf_g_dps_per_v = {} must be positive (seed 000: 45.045 deg/s/V)",
                self.sf_g_dps_per_v
            ));
        }
        if !(self.v_nom_v.is_finite() && self.gyro_bias_offset_v.is_finite()) {
            return bad("v_nom_v and gyro_bias_offset_v must be finite (volts)".into());
        }
        if !(self.gyro_tilt_deg.is_finite() && self.gyro_tilt_deg.abs() <= 80.0) {
            return bad(format!(
                "gyro_tilt_deg = {} must be within +-80 deg",
                self.gyro_tilt_deg
            ));
        }
        if !(self.gyro_noise_v.is_finite() && self.gyro_noise_v >= 0.0) {
            return bad(format!("gyro_noise_v = {} must be >= 0", self.gyro_noise_v));
        }
        if !(self.sf_n_m_per_pulse.is_finite() && self.sf_n_m_per_pulse > 0.0) {
            return bad(format!(
                "sf_n_m_per_pulse = {} must be positive (e.g. 0.1 m/pulse)",
                self.sf_n_m_per_pulse
            ));
        }
        if !(self.odo_scale_error.is_finite() && self.odo_scale_error > -1.0) {
            return bad(format!(
                "odo_scale_error = {} must be above -1 (a relative error, e.g. 0.02)",
                self.odo_scale_error
            ));
        }
        Ok(())
    }

    /// The nominal parameters (what a user would put in the configuration).
    pub fn nominal_params(&self) -> DrParams {
        DrParams {
            sf_g_dps_per_v: self.sf_g_dps_per_v,
            v_nom_v: self.v_nom_v,
            sf_n_m_per_pulse: self.sf_n_m_per_pulse,
        }
    }

    /// The parameters that describe the simulated sensors exactly: `Sf_G / cos(theta)`,
    /// `V_nom + b`, `Sf_N / (1 + e)` (what a calibrating filter should converge to).
    pub fn true_params(&self) -> DrParams {
        DrParams {
            sf_g_dps_per_v: self.sf_g_dps_per_v / self.gyro_tilt_deg.to_radians().cos(),
            v_nom_v: self.v_nom_v + self.gyro_bias_offset_v,
            sf_n_m_per_pulse: self.sf_n_m_per_pulse / (1.0 + self.odo_scale_error),
        }
    }
}

/// The instants `t_0 + k / rate_hz` up to the last truth time.
fn sample_times(truth: &[VehicleTruth], rate_hz: f64) -> impl Iterator<Item = f64> {
    let t0 = truth[0].t_s;
    let t_end = truth[truth.len() - 1].t_s;
    let n = ((t_end - t0) * rate_hz + 1e-9).floor() as u64;
    (0..=n).map(move |k| t0 + k as f64 / rate_hz)
}

/// Simulates a DR log from the truth (see the module documentation).
pub fn simulate_dr(truth: &[VehicleTruth], cfg: &DrSensorConfig) -> Result<Vec<DrSample>, DrError> {
    cfg.validate()?;
    validate_truth(truth)?;
    let integ = TruthIntegrals::new(truth);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(cfg.seed);
    let cos_tilt = cfg.gyro_tilt_deg.to_radians().cos();
    let v_true = cfg.v_nom_v + cfg.gyro_bias_offset_v;
    let mut out = Vec::new();
    let mut prev: Option<(f64, f64, f64)> = None;
    let mut carry = 0.0;
    for t in sample_times(truth, cfg.rate_hz) {
        let (d, h) = integ.at(t);
        let (rate_dps, dd, dt) = match prev {
            None => (
                interpolate_truth(truth, t).yaw_rate_rad_s.to_degrees(),
                0.0,
                0.0,
            ),
            Some((tp, dp, hp)) => (((h - hp) / (t - tp)).to_degrees(), d - dp, t - tp),
        };
        prev = Some((t, d, h));
        let noise: f64 = rng.sample(StandardNormal);
        let gyro_v = v_true + cos_tilt * rate_dps / cfg.sf_g_dps_per_v + cfg.gyro_noise_v * noise;
        let pulses_exact = (1.0 + cfg.odo_scale_error) * dd / cfg.sf_n_m_per_pulse;
        let reading = if cfg.raw {
            carry += pulses_exact;
            let n = carry.floor().max(0.0);
            carry -= n;
            DrReading::Raw {
                gyro_v,
                odo_pulses: n,
            }
        } else {
            DrReading::Engineering {
                yaw_rate_dps: cfg.sf_g_dps_per_v * (gyro_v - cfg.v_nom_v),
                speed_mps: if dt > 0.0 {
                    (pulses_exact * cfg.sf_n_m_per_pulse / dt).max(0.0)
                } else {
                    0.0
                },
            }
        };
        out.push(DrSample { t_s: t, reading });
    }
    Ok(out)
}

/// The accelerometer of a simulated vehicle (the simulator's `[accel]` table).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccelSensorConfig {
    /// Output rate, Hz (default 50).
    #[serde(default = "d_accel_rate")]
    pub rate_hz: f64,
    /// Constant accelerometer bias, m/s^2 (default 0).
    #[serde(default)]
    pub bias_mps2: f64,
    /// White vibration noise, m/s^2 (default 0).
    #[serde(default)]
    pub vibration_noise_mps2: f64,
    /// Noise seed (default 0).
    #[serde(default)]
    pub seed: u64,
}

impl Default for AccelSensorConfig {
    /// A perfect accelerometer at 50 Hz (it still senses the slope, `g sin(pitch)`).
    fn default() -> Self {
        Self {
            rate_hz: d_accel_rate(),
            bias_mps2: 0.0,
            vibration_noise_mps2: 0.0,
            seed: 0,
        }
    }
}

impl AccelSensorConfig {
    /// Checks: rate in (0, 1000] Hz, finite bias, noise `>= 0`.
    pub fn validate(&self) -> Result<(), DrError> {
        check_rate("accel", self.rate_hz)?;
        if !self.bias_mps2.is_finite() {
            return Err(DrError::Config("accel: bias_mps2 must be finite".into()));
        }
        if !(self.vibration_noise_mps2.is_finite() && self.vibration_noise_mps2 >= 0.0) {
            return Err(DrError::Config(format!(
                "accel: vibration_noise_mps2 = {} must be >= 0",
                self.vibration_noise_mps2
            )));
        }
        Ok(())
    }
}

/// Simulates an accelerometer log from the truth (see the module documentation).
pub fn simulate_accel(
    truth: &[VehicleTruth],
    cfg: &AccelSensorConfig,
) -> Result<Vec<AccelSample>, DrError> {
    cfg.validate()?;
    validate_truth(truth)?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(cfg.seed);
    Ok(sample_times(truth, cfg.rate_hz)
        .map(|t| {
            let s = interpolate_truth(truth, t);
            let w: f64 = rng.sample(StandardNormal);
            AccelSample {
                t_s: t,
                a_long_mps2: s.a_long_mps2
                    + GRAVITY_MPS2 * s.pitch_rad.sin()
                    + cfg.bias_mps2
                    + cfg.vibration_noise_mps2 * w,
            }
        })
        .collect())
}
