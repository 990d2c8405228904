//! GPS/accelerometer speed estimation (seed 002): two Kalman filters in series, and the
//! hold-the-last-speed baseline it is compared with.
//!
//! - **KF1** ([`AccelSmoother`], seed 002 eqs. 8-11): state `a` (longitudinal acceleration),
//!   `A = C = 1`; process noise `q = jerk_psd * dt` ((m/s^3)^2 s: how fast the true acceleration
//!   wanders), measurement noise the vibration variance. It removes vibration and road shocks.
//! - **KF2** ([`SpeedFilter`], eqs. 12-16): state `[v, a, r]` (speed, accelerometer output,
//!   accelerometer reference: bias plus `g sin(pitch)` on a slope, eq. 14),
//!   `A = [[1, dt, -dt], [0, 1, 0], [0, 0, 1]]`, `C = [1 0 0]` (GPS speed). Each prediction
//!   first sets `a` to the smoothed accelerometer (KF1's output, the series connection of
//!   seed 002 Fig. 1) with variance `accel_sigma^2` and no correlation, then
//!   `x = A x`, `P = A P A^T + Q`, `Q = diag(speed_psd dt, 0, ref_psd dt)`. GPS speed updates
//!   make `r` observable (speed change versus integrated acceleration); through GPS gaps the
//!   filter predicts only, integrating `a - r` with the last `r`.
//! - [`HoldLastSpeed`]: the baseline of seed 002 Fig. 6, the last GPS speed held through gaps.

use crate::dr_error::DrError;
use nalgebra::{Matrix3, Vector3};

fn check(name: &str, v: f64, positive: bool) -> Result<(), DrError> {
    let ok = v.is_finite() && if positive { v > 0.0 } else { v >= 0.0 };
    if ok {
        Ok(())
    } else {
        Err(DrError::Config(format!(
            "speed filter: {name} = {v} must be {}",
            if positive { "positive" } else { ">= 0" }
        )))
    }
}

/// KF1 of seed 002: a scalar random-walk filter smoothing the accelerometer.
#[derive(Debug, Clone)]
pub struct AccelSmoother {
    jerk_psd: f64,
    vibration_var: f64,
    a: Option<f64>,
    p: f64,
}

impl AccelSmoother {
    /// `jerk_psd` in (m/s^3)^2 s (e.g. 0.5), `vibration_sigma_mps2` the accelerometer noise
    /// (e.g. 0.3).
    pub fn new(jerk_psd: f64, vibration_sigma_mps2: f64) -> Result<AccelSmoother, DrError> {
        check("jerk_psd", jerk_psd, false)?;
        check("vibration_sigma_mps2", vibration_sigma_mps2, true)?;
        Ok(AccelSmoother {
            jerk_psd,
            vibration_var: vibration_sigma_mps2 * vibration_sigma_mps2,
            a: None,
            p: 0.0,
        })
    }

    /// Predicts over `dt` seconds and updates with the raw reading; returns the smoothed
    /// acceleration (the first reading initialises the filter).
    pub fn filter(&mut self, a_raw_mps2: f64, dt: f64) -> f64 {
        match self.a {
            None => {
                self.a = Some(a_raw_mps2);
                self.p = self.vibration_var;
                a_raw_mps2
            }
            Some(a) => {
                let p = self.p + self.jerk_psd * dt.max(0.0);
                let k = p / (p + self.vibration_var);
                let a = a + k * (a_raw_mps2 - a);
                self.p = (1.0 - k) * p;
                self.a = Some(a);
                a
            }
        }
    }

    /// The smoothed acceleration (None before the first reading).
    pub fn accel_mps2(&self) -> Option<f64> {
        self.a
    }

    /// Its variance, (m/s^2)^2.
    pub fn variance(&self) -> f64 {
        self.p
    }
}

/// Settings of [`SpeedFilter`] (KF2).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedFilterConfig {
    /// Sigma of the smoothed acceleration put into `a` at each prediction, m/s^2 (default 0.05).
    #[serde(default = "d_accel_sigma")]
    pub accel_sigma_mps2: f64,
    /// Speed process noise PSD, (m/s)^2/s (default 0.01).
    #[serde(default = "d_speed_psd")]
    pub speed_psd: f64,
    /// Reference (slope/bias) random-walk PSD, (m/s^2)^2/s (default 1e-3: a grade change of a few
    /// percent over tens of seconds).
    #[serde(default = "d_ref_psd")]
    pub ref_psd: f64,
    /// Initial reference sigma, m/s^2 (default 0.5).
    #[serde(default = "d_ref_sigma")]
    pub init_ref_sigma_mps2: f64,
}

fn d_accel_sigma() -> f64 {
    0.05
}
fn d_speed_psd() -> f64 {
    0.01
}
fn d_ref_psd() -> f64 {
    1e-3
}
fn d_ref_sigma() -> f64 {
    0.5
}

impl Default for SpeedFilterConfig {
    fn default() -> Self {
        Self {
            accel_sigma_mps2: d_accel_sigma(),
            speed_psd: d_speed_psd(),
            ref_psd: d_ref_psd(),
            init_ref_sigma_mps2: d_ref_sigma(),
        }
    }
}

impl SpeedFilterConfig {
    /// Checks: sigmas positive, PSDs `>= 0`, all finite.
    pub fn validate(&self) -> Result<(), DrError> {
        check("accel_sigma_mps2", self.accel_sigma_mps2, true)?;
        check("speed_psd", self.speed_psd, false)?;
        check("ref_psd", self.ref_psd, false)?;
        check("init_ref_sigma_mps2", self.init_ref_sigma_mps2, true)
    }
}

/// KF2 of seed 002: speed from the smoothed accelerometer, calibrated by GPS speed.
#[derive(Debug, Clone)]
pub struct SpeedFilter {
    config: SpeedFilterConfig,
    x: Vector3<f64>,
    p: Matrix3<f64>,
}

impl SpeedFilter {
    /// Starts at `initial_speed_mps` (sigma `initial_sigma_mps`), reference 0.
    pub fn new(
        initial_speed_mps: f64,
        initial_sigma_mps: f64,
        config: SpeedFilterConfig,
    ) -> Result<SpeedFilter, DrError> {
        config.validate()?;
        check("initial_speed_mps", initial_speed_mps.abs(), false)?;
        check("initial_sigma_mps", initial_sigma_mps, true)?;
        let p = Matrix3::from_diagonal(&Vector3::new(
            initial_sigma_mps * initial_sigma_mps,
            config.accel_sigma_mps2 * config.accel_sigma_mps2,
            config.init_ref_sigma_mps2 * config.init_ref_sigma_mps2,
        ));
        Ok(SpeedFilter {
            config,
            x: Vector3::new(initial_speed_mps, 0.0, 0.0),
            p,
        })
    }

    /// Prediction over `dt` seconds with the smoothed accelerometer output `a_long_mps2`
    /// (module documentation). Non-finite inputs or `dt <= 0` leave the filter unchanged.
    pub fn predict(&mut self, a_long_mps2: f64, dt: f64) {
        if !(a_long_mps2.is_finite() && dt.is_finite() && dt > 0.0) {
            return;
        }
        let sa2 = self.config.accel_sigma_mps2 * self.config.accel_sigma_mps2;
        self.x[1] = a_long_mps2;
        for i in 0..3 {
            self.p[(1, i)] = 0.0;
            self.p[(i, 1)] = 0.0;
        }
        self.p[(1, 1)] = sa2;
        let a = Matrix3::new(1.0, dt, -dt, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let q = Matrix3::from_diagonal(&Vector3::new(
            self.config.speed_psd * dt,
            0.0,
            self.config.ref_psd * dt,
        ));
        self.x = a * self.x;
        self.p = a * self.p * a.transpose() + q;
    }

    /// GPS speed update (`C = [1 0 0]`) with standard deviation `sigma_mps`; returns the
    /// normalised innovation squared. Non-finite values or `sigma_mps <= 0` are refused.
    pub fn update_speed(&mut self, v_mps: f64, sigma_mps: f64) -> Result<f64, DrError> {
        if !(v_mps.is_finite() && sigma_mps.is_finite() && sigma_mps > 0.0) {
            return Err(DrError::Input(format!(
                "GPS speed {v_mps} m/s with sigma {sigma_mps}: both must be finite, sigma positive"
            )));
        }
        let s = self.p[(0, 0)] + sigma_mps * sigma_mps;
        let y = v_mps - self.x[0];
        let k = self.p.column(0) / s;
        self.x += k * y;
        let ikh = Matrix3::identity() - k * Vector3::new(1.0, 0.0, 0.0).transpose();
        self.p = ikh * self.p * ikh.transpose() + k * k.transpose() * (sigma_mps * sigma_mps);
        Ok(y * y / s)
    }

    /// The estimated speed, m/s.
    pub fn speed_mps(&self) -> f64 {
        self.x[0]
    }

    /// The estimated accelerometer reference `r` (bias plus `g sin(pitch)`), m/s^2.
    pub fn reference_mps2(&self) -> f64 {
        self.x[2]
    }

    /// The state covariance (`v`, `a`, `r`).
    pub fn covariance(&self) -> &Matrix3<f64> {
        &self.p
    }
}

/// The baseline: the last GPS speed, held through gaps.
#[derive(Debug, Clone, Default)]
pub struct HoldLastSpeed {
    last: Option<f64>,
}

impl HoldLastSpeed {
    /// No speed yet.
    pub fn new() -> HoldLastSpeed {
        HoldLastSpeed { last: None }
    }

    /// Records a GPS speed (non-finite values are ignored).
    pub fn update_speed(&mut self, v_mps: f64) {
        if v_mps.is_finite() {
            self.last = Some(v_mps);
        }
    }

    /// The last GPS speed (0 before the first).
    pub fn speed_mps(&self) -> f64 {
        self.last.unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoother_converges_to_the_steady_state_gain() {
        // Random-walk state, white measurement: steady-state prior variance p solves
        // p = (p R / (p + R)) + q, i.e. p = (q + sqrt(q^2 + 4 q R)) / 2.
        let (q_psd, sigma, dt) = (0.5, 0.3, 0.02);
        let mut s = AccelSmoother::new(q_psd, sigma).unwrap_or_else(|e| panic!("{e}"));
        for _ in 0..5000 {
            s.filter(1.0, dt);
        }
        let (q, r) = (q_psd * dt, sigma * sigma);
        let prior = 0.5 * (q + (q * q + 4.0 * q * r).sqrt());
        assert!((s.variance() - prior * r / (prior + r)).abs() < 1e-12);
        assert!((s.accel_mps2().unwrap_or(f64::NAN) - 1.0).abs() < 1e-12);
        assert!(AccelSmoother::new(0.5, 0.0).is_err());
    }

    #[test]
    fn speed_filter_learns_the_slope_reference_and_predicts_through_a_gap() {
        // True speed 10 + 0.5 t; accelerometer reads 0.5 + g sin(0.03) (uphill).
        let r_true = crate::GRAVITY_MPS2 * 0.03f64.sin();
        let mut f = SpeedFilter::new(10.0, 1.0, SpeedFilterConfig::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let dt = 0.02;
        for k in 1..=3000 {
            let t = f64::from(k) * dt;
            f.predict(0.5 + r_true, dt);
            if k % 50 == 0 && t <= 40.0 {
                f.update_speed(10.0 + 0.5 * t, 0.1)
                    .unwrap_or_else(|e| panic!("{e}"));
            }
        }
        assert!(
            (f.reference_mps2() - r_true).abs() < 0.01,
            "{}",
            f.reference_mps2()
        );
        // 20 s of prediction: error below 0.01 * 20 + the residual at the gap start.
        assert!((f.speed_mps() - 40.0).abs() < 0.3, "{}", f.speed_mps());
        assert!(f.update_speed(f64::NAN, 0.1).is_err());
        let mut hold = HoldLastSpeed::new();
        assert_eq!(hold.speed_mps(), 0.0);
        hold.update_speed(12.0);
        hold.update_speed(f64::NAN);
        assert_eq!(hold.speed_mps(), 12.0);
    }
}
