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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dr_mechanization::dr_step;

    /// A clockwise circle at `v` m/s and `w` rad/s from the origin heading north, at 100 Hz, on a
    /// constant `pitch`.
    fn circle(v: f64, w: f64, pitch: f64, secs: f64) -> Vec<VehicleTruth> {
        let n = (secs * 100.0) as usize;
        (0..=n)
            .map(|k| {
                let t = k as f64 / 100.0;
                let r = v / w;
                VehicleTruth {
                    t_s: t,
                    east_m: r * (1.0 - (w * t).cos()),
                    north_m: r * (w * t).sin(),
                    up_m: v * pitch.sin() * t,
                    speed_mps: v,
                    heading_rad: crate::vehicle::wrap_pi(w * t),
                    yaw_rate_rad_s: w,
                    a_long_mps2: 0.0,
                    pitch_rad: pitch,
                }
            })
            .collect()
    }

    fn rows(truth: &[VehicleTruth], cfg: &DrSensorConfig) -> Vec<DrSample> {
        simulate_dr(truth, cfg).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn tilted_gyro_senses_cos_theta_of_the_yaw_rate() {
        let truth = circle(12.0, 0.15, 0.0, 30.0);
        let cfg = DrSensorConfig {
            gyro_tilt_deg: 20.0,
            gyro_bias_offset_v: 0.01,
            ..DrSensorConfig::default()
        };
        let nominal = cfg.nominal_params();
        let exact = cfg.true_params();
        assert!((exact.sf_g_dps_per_v - 47.936).abs() < 5e-4);
        for s in &rows(&truth, &cfg)[1..] {
            let DrReading::Raw { gyro_v, .. } = s.reading else {
                panic!("raw expected")
            };
            let sensed = nominal.sf_g_dps_per_v * (gyro_v - exact.v_nom_v);
            assert!((sensed - 20f64.to_radians().cos() * 0.15f64.to_degrees()).abs() < 1e-9);
            let rate = exact.sf_g_dps_per_v * (gyro_v - exact.v_nom_v);
            assert!((rate - 0.15f64.to_degrees()).abs() < 1e-9);
        }
    }

    #[test]
    fn odometer_pulses_are_whole_and_integrate_to_distance_over_sf_n() {
        let truth = circle(13.7, 0.05, 0.0, 60.0);
        let cfg = DrSensorConfig {
            odo_scale_error: 0.03,
            sf_n_m_per_pulse: 0.37,
            ..DrSensorConfig::default()
        };
        let mut total = 0.0;
        for s in rows(&truth, &cfg) {
            let DrReading::Raw { odo_pulses, .. } = s.reading else {
                panic!("raw expected")
            };
            assert_eq!(odo_pulses, odo_pulses.round());
            total += odo_pulses;
        }
        let exact = 1.03 * 13.7 * 60.0 / 0.37;
        assert!(
            total <= exact + 1e-6 && total > exact - 1.0,
            "{total} vs {exact}"
        );
        // With the true Sf_N the distance comes back to within one pulse.
        assert!((total * cfg.true_params().sf_n_m_per_pulse - 13.7 * 60.0).abs() < 0.37);
    }

    #[test]
    fn true_parameters_dead_reckon_the_truth() {
        let truth = circle(10.0, 0.1, 0.0, 40.0);
        let cfg = DrSensorConfig {
            gyro_tilt_deg: 15.0,
            gyro_bias_offset_v: -0.02,
            odo_scale_error: -0.04,
            raw: false,
            ..DrSensorConfig::default()
        };
        let log = rows(&truth, &cfg);
        let mut m = crate::DrMechanization::new(cfg.nominal_params(), 0.0, 0.0, 0.0)
            .unwrap_or_else(|e| panic!("{e}"));
        m.set_params(cfg.true_params())
            .unwrap_or_else(|e| panic!("{e}"));
        for s in &log {
            m.propagate(s).unwrap_or_else(|e| panic!("{e}"));
        }
        let end = truth[truth.len() - 1];
        let s = m.state();
        assert!(
            (s.east_m - end.east_m).hypot(s.north_m - end.north_m) < 1e-6,
            "{s:?}"
        );
        // The nominal parameters do not.
        let mut n = crate::DrMechanization::new(cfg.nominal_params(), 0.0, 0.0, 0.0)
            .unwrap_or_else(|e| panic!("{e}"));
        for s in &log {
            n.propagate(s).unwrap_or_else(|e| panic!("{e}"));
        }
        assert!((n.state().east_m - end.east_m).hypot(n.state().north_m - end.north_m) > 10.0);
        let _ = dr_step;
    }

    #[test]
    fn accelerometer_senses_the_slope() {
        let pitch = 0.06;
        let truth = circle(10.0, 0.1, pitch, 10.0);
        let cfg = AccelSensorConfig {
            bias_mps2: 0.02,
            ..AccelSensorConfig::default()
        };
        let a = simulate_accel(&truth, &cfg).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(a.len(), 501);
        for s in &a {
            assert!((s.a_long_mps2 - (GRAVITY_MPS2 * pitch.sin() + 0.02)).abs() < 1e-12);
        }
    }

    #[test]
    fn noise_is_seeded_and_has_the_configured_sigma() {
        let truth = circle(10.0, 0.1, 0.0, 200.0);
        let cfg = AccelSensorConfig {
            vibration_noise_mps2: 0.3,
            seed: 7,
            ..AccelSensorConfig::default()
        };
        let a = simulate_accel(&truth, &cfg).unwrap_or_else(|e| panic!("{e}"));
        let b = simulate_accel(&truth, &cfg).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(a, b);
        let c = simulate_accel(
            &truth,
            &AccelSensorConfig {
                seed: 8,
                ..cfg.clone()
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_ne!(a, c);
        let n = a.len() as f64;
        let rms = (a.iter().map(|s| s.a_long_mps2.powi(2)).sum::<f64>() / n).sqrt();
        // 10001 samples: the sample sigma is within 3 % of 0.3 with overwhelming probability.
        assert!((rms - 0.3).abs() < 0.009, "{rms}");
    }

    #[test]
    fn configs_are_validated() {
        let ok = DrSensorConfig::default();
        assert!(ok.validate().is_ok());
        for bad in [
            DrSensorConfig {
                rate_hz: 0.0,
                ..ok.clone()
            },
            DrSensorConfig {
                sf_g_dps_per_v: -1.0,
                ..ok.clone()
            },
            DrSensorConfig {
                gyro_tilt_deg: 90.0,
                ..ok.clone()
            },
            DrSensorConfig {
                gyro_noise_v: f64::NAN,
                ..ok.clone()
            },
            DrSensorConfig {
                sf_n_m_per_pulse: 0.0,
                ..ok.clone()
            },
            DrSensorConfig {
                odo_scale_error: -1.0,
                ..ok.clone()
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(AccelSensorConfig {
            vibration_noise_mps2: -0.1,
            ..AccelSensorConfig::default()
        }
        .validate()
        .is_err());
        let parsed: DrSensorConfig =
            toml::from_str("gyro_tilt_deg = 20.0\nseed = 3\n").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(parsed.rate_hz, 10.0);
        assert_eq!(parsed.sf_g_dps_per_v, 45.045);
        assert!(toml::from_str::<DrSensorConfig>("tilt = 20.0\n").is_err());
        assert!(simulate_dr(&circle(1.0, 0.1, 0.0, 1.0)[..1], &ok).is_err());
    }
}
