//! DR mechanization (seed 000 eqs. 1-3): speed from odometer pulses, heading from the integrated
//! gyro voltage, east/north position from both; and the sensor parameters it uses.
//!
//! For a row covering `dt` seconds with mean gyro voltage `V_g` and `N` pulses:
//! - speed (eq. 2): `s = Sf_N N / dt`;
//! - heading (eq. 3): `psi_k = psi_{k-1} + dpsi`, `dpsi = Sf_G (V_g - V_nom) dt` (deg -> rad);
//! - position (eq. 1 integrated over the row as an arc of constant speed and turn rate, exact for
//!   a constant-rate circle): `p_k = p_{k-1} + s dt sinc(dpsi/2) (sin psi_m, cos psi_m)`,
//!   `psi_m = psi_{k-1} + dpsi/2`, `sinc(x) = sin(x)/x`;
//! - velocity output (eq. 1): `v_k = s (sin psi_k, cos psi_k)` (east, north).
//!
//! Heading is clockwise from north. The DR is planar: on a slope the odometer's path length
//! exceeds the horizontal distance by `1/cos(pitch)` (0.1 % at 4.5 % grade), which a calibrating
//! filter absorbs in `Sf_N`. Rows in engineering units are turned into the equivalent raw outputs
//! with the *initial* (nominal) parameters, `V_g = V_nom0 + yaw_rate_dps / Sf_G0`,
//! `N = speed_mps dt / Sf_N0`, so calibrated parameters act on them the same way.

use crate::dr_error::DrError;
use crate::dr_log::{DrReading, DrSample};
use crate::vehicle::wrap_pi;
use std::path::Path;

/// The DR sensor parameters of seed 000: the configuration's nominal values, or a filter's
/// calibration, saved and loaded as TOML (seed 000: reusing a calibration avoids the ~900 s
/// convergence of the gyro scale factor).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrParams {
    /// Gyro scale factor `Sf_G`, deg/s/V.
    pub sf_g_dps_per_v: f64,
    /// Gyro zero-rate (bias) voltage `V_nom`, V.
    pub v_nom_v: f64,
    /// Odometer scale factor `Sf_N`, m/pulse.
    pub sf_n_m_per_pulse: f64,
}

impl Default for DrParams {
    /// Seed 000's gyro (45.045 deg/s/V) with a 2.5 V zero-rate voltage and a 0.1 m/pulse odometer.
    fn default() -> Self {
        Self {
            sf_g_dps_per_v: crate::dr_sensors::SEED000_SF_G_DPS_PER_V,
            v_nom_v: 2.5,
            sf_n_m_per_pulse: 0.1,
        }
    }
}

impl DrParams {
    /// Checks: finite values, positive scale factors.
    pub fn validate(&self) -> Result<(), DrError> {
        if !(self.sf_g_dps_per_v.is_finite() && self.sf_g_dps_per_v > 0.0) {
            return Err(DrError::Config(format!(
                "DR parameters: sf_g_dps_per_v = {} must be positive (deg/s/V; seed 000: 45.045)",
                self.sf_g_dps_per_v
            )));
        }
        if !self.v_nom_v.is_finite() {
            return Err(DrError::Config(
                "DR parameters: v_nom_v must be a finite voltage".into(),
            ));
        }
        if !(self.sf_n_m_per_pulse.is_finite() && self.sf_n_m_per_pulse > 0.0) {
            return Err(DrError::Config(format!(
                "DR parameters: sf_n_m_per_pulse = {} must be positive (m/pulse)",
                self.sf_n_m_per_pulse
            )));
        }
        Ok(())
    }

    /// Reads a parameter file written by [`DrParams::save`] (TOML with the three keys) and
    /// validates it.
    pub fn load(path: &Path) -> Result<DrParams, DrError> {
        let p = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| DrError::Io {
            what: "DR parameter",
            path: p.clone(),
            message: e.to_string(),
        })?;
        let params: DrParams = toml::from_str(&text).map_err(|e| DrError::Config(format!(
            "DR parameter file {p}: {e}: it must hold sf_g_dps_per_v, v_nom_v and sf_n_m_per_pulse (as written by a previous run)"
        )))?;
        params.validate()?;
        Ok(params)
    }

    /// Writes the parameters as TOML.
    pub fn save(&self, path: &Path) -> Result<(), DrError> {
        let werr = |message: String| DrError::Write {
            what: "DR parameter",
            path: path.display().to_string(),
            message,
        };
        let text = toml::to_string(self).map_err(|e| werr(e.to_string()))?;
        let text = format!("# gpsrx DR sensor calibration (seed 000 parameters)\n{text}");
        std::fs::write(path, text).map_err(|e| werr(e.to_string()))
    }
}

/// The DR solution at the last processed row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrState {
    /// Time of the last row, s (None before the first row).
    pub t_s: Option<f64>,
    /// East position, m.
    pub east_m: f64,
    /// North position, m.
    pub north_m: f64,
    /// Heading, clockwise from north, rad, in (-pi, pi].
    pub heading_rad: f64,
    /// Speed over the last row, m/s.
    pub speed_mps: f64,
    /// Heading rate over the last row, rad/s.
    pub yaw_rate_rad_s: f64,
    /// East velocity output, m/s.
    pub vel_east_mps: f64,
    /// North velocity output, m/s.
    pub vel_north_mps: f64,
}

/// One mechanization step (module equations), as a pure function of the heading before the row,
/// the parameters and the raw row values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrStep {
    /// Position increment (east, north), m.
    pub dpos_m: [f64; 2],
    /// Heading after the row (not wrapped), rad.
    pub heading_rad: f64,
    /// Speed `s`, m/s.
    pub speed_mps: f64,
    /// Heading rate, rad/s.
    pub yaw_rate_rad_s: f64,
    /// Velocity output (east, north), m/s.
    pub vel_mps: [f64; 2],
}

/// `sin(x)/x`, with its series near 0.
pub(crate) fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// The mechanization of one row of `dt` seconds (`dt > 0`), mean gyro voltage `gyro_v`, `pulses`.
pub fn dr_step(params: &DrParams, heading_rad: f64, gyro_v: f64, pulses: f64, dt: f64) -> DrStep {
    let yaw_rate = (params.sf_g_dps_per_v * (gyro_v - params.v_nom_v)).to_radians();
    let dpsi = yaw_rate * dt;
    let s = params.sf_n_m_per_pulse * pulses / dt;
    let psi_m = heading_rad + 0.5 * dpsi;
    let arc = s * dt * sinc(0.5 * dpsi);
    let psi = heading_rad + dpsi;
    DrStep {
        dpos_m: [arc * psi_m.sin(), arc * psi_m.cos()],
        heading_rad: psi,
        speed_mps: s,
        yaw_rate_rad_s: yaw_rate,
        vel_mps: [s * psi.sin(), s * psi.cos()],
    }
}

/// Dead reckoning from a start position and heading, row by row.
#[derive(Debug, Clone)]
pub struct DrMechanization {
    params: DrParams,
    nominal: DrParams,
    state: DrState,
}

impl DrMechanization {
    /// Starts at (`east_m`, `north_m`) with `heading_rad` (clockwise from north); `params` are
    /// also the nominal parameters that convert engineering-unit rows.
    pub fn new(
        params: DrParams,
        east_m: f64,
        north_m: f64,
        heading_rad: f64,
    ) -> Result<DrMechanization, DrError> {
        params.validate()?;
        if !(east_m.is_finite() && north_m.is_finite() && heading_rad.is_finite()) {
            return Err(DrError::Input(
                "the DR start position and heading must be finite".into(),
            ));
        }
        Ok(DrMechanization {
            params,
            nominal: params,
            state: DrState {
                t_s: None,
                east_m,
                north_m,
                heading_rad: wrap_pi(heading_rad),
                speed_mps: 0.0,
                yaw_rate_rad_s: 0.0,
                vel_east_mps: 0.0,
                vel_north_mps: 0.0,
            },
        })
    }

    /// The raw equivalent (`gyro_v`, `pulses`) of a reading over `dt` seconds.
    pub fn raw_equivalent(&self, reading: &DrReading, dt: f64) -> (f64, f64) {
        match *reading {
            DrReading::Raw { gyro_v, odo_pulses } => (gyro_v, odo_pulses),
            DrReading::Engineering {
                yaw_rate_dps,
                speed_mps,
            } => (
                self.nominal.v_nom_v + yaw_rate_dps / self.nominal.sf_g_dps_per_v,
                speed_mps * dt / self.nominal.sf_n_m_per_pulse,
            ),
        }
    }

    /// Processes one row; returns the step (None for the first row, which only sets the time,
    /// and for a row not after the previous one, which is refused).
    pub fn propagate(&mut self, sample: &DrSample) -> Result<Option<DrStep>, DrError> {
        if !sample.t_s.is_finite() {
            return Err(DrError::Input(format!(
                "DR row time {} is not finite",
                sample.t_s
            )));
        }
        let Some(t_prev) = self.state.t_s else {
            self.state.t_s = Some(sample.t_s);
            return Ok(None);
        };
        let dt = sample.t_s - t_prev;
        if dt <= 0.0 {
            return Err(DrError::Input(format!(
                "DR row at t = {} s is not after the previous one ({t_prev} s)",
                sample.t_s
            )));
        }
        let (gyro_v, pulses) = self.raw_equivalent(&sample.reading, dt);
        if !(gyro_v.is_finite() && pulses.is_finite()) {
            return Err(DrError::Input(format!(
                "DR row at t = {} s has a non-finite value",
                sample.t_s
            )));
        }
        let step = dr_step(&self.params, self.state.heading_rad, gyro_v, pulses, dt);
        let s = &mut self.state;
        s.t_s = Some(sample.t_s);
        s.east_m += step.dpos_m[0];
        s.north_m += step.dpos_m[1];
        s.heading_rad = wrap_pi(step.heading_rad);
        s.speed_mps = step.speed_mps;
        s.yaw_rate_rad_s = step.yaw_rate_rad_s;
        s.vel_east_mps = step.vel_mps[0];
        s.vel_north_mps = step.vel_mps[1];
        Ok(Some(step))
    }

    /// The current solution.
    pub fn state(&self) -> &DrState {
        &self.state
    }

    /// The current sensor parameters.
    pub fn params(&self) -> &DrParams {
        &self.params
    }

    /// The nominal parameters (engineering-unit conversion).
    pub fn nominal_params(&self) -> &DrParams {
        &self.nominal
    }

    /// Replaces the sensor parameters (a filter's calibration).
    pub fn set_params(&mut self, params: DrParams) -> Result<(), DrError> {
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// Mutable access to the solution (a filter's position, heading and velocity corrections).
    pub fn state_mut(&mut self) -> &mut DrState {
        &mut self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.1;

    fn raw(t_s: f64, gyro_v: f64, odo_pulses: f64) -> DrSample {
        DrSample {
            t_s,
            reading: DrReading::Raw { gyro_v, odo_pulses },
        }
    }

    fn run(mech: &mut DrMechanization, rows: impl Iterator<Item = DrSample>) {
        for s in rows {
            mech.propagate(&s).unwrap_or_else(|e| panic!("{e}"));
        }
    }

    #[test]
    fn straight_line_at_constant_speed() {
        let p = DrParams::default();
        let psi0 = 30f64.to_radians();
        let mut m = DrMechanization::new(p, 100.0, -50.0, psi0).unwrap_or_else(|e| panic!("{e}"));
        // 15 pulses of 0.1 m per 0.1 s: 15 m/s for 10 s.
        run(
            &mut m,
            (0..=100).map(|k| raw(f64::from(k) * DT, p.v_nom_v, 15.0)),
        );
        let s = m.state();
        assert!((s.east_m - (100.0 + 150.0 * psi0.sin())).abs() < 1e-9);
        assert!((s.north_m - (-50.0 + 150.0 * psi0.cos())).abs() < 1e-9);
        assert!((s.heading_rad - psi0).abs() < 1e-12);
        assert!((s.speed_mps - 15.0).abs() < 1e-12);
        assert!((s.vel_east_mps - 15.0 * psi0.sin()).abs() < 1e-9);
        assert_eq!(s.t_s, Some(10.0));
    }

    /// Closed form of a clockwise circle from the origin heading north: centre (R, 0),
    /// `east = R (1 - cos(w t))`, `north = R sin(w t)`, heading `w t`.
    #[test]
    fn constant_rate_circle_matches_the_closed_form() {
        let p = DrParams {
            sf_g_dps_per_v: 47.936,
            v_nom_v: 2.47,
            sf_n_m_per_pulse: 0.05,
        };
        let (v, w): (f64, f64) = (10.0, 0.2);
        let r = v / w;
        let gyro_v = p.v_nom_v + w.to_degrees() / p.sf_g_dps_per_v;
        let pulses = v * DT / p.sf_n_m_per_pulse;
        let rows = |eng: bool| {
            (0..=157).map(move |k| {
                let t = f64::from(k) * DT;
                if eng {
                    DrSample {
                        t_s: t,
                        reading: DrReading::Engineering {
                            yaw_rate_dps: w.to_degrees(),
                            speed_mps: v,
                        },
                    }
                } else {
                    raw(t, gyro_v, pulses)
                }
            })
        };
        for eng in [false, true] {
            let mut m = DrMechanization::new(p, 0.0, 0.0, 0.0).unwrap_or_else(|e| panic!("{e}"));
            run(&mut m, rows(eng));
            let t = 15.7;
            let s = m.state();
            assert!((s.east_m - r * (1.0 - (w * t).cos())).abs() < 1e-8, "{s:?}");
            assert!((s.north_m - r * (w * t).sin()).abs() < 1e-8, "{s:?}");
            assert!((s.heading_rad - wrap_pi(w * t)).abs() < 1e-10);
            assert!((s.yaw_rate_rad_s - w).abs() < 1e-12);
        }
    }

    #[test]
    fn rows_out_of_order_and_bad_values_are_refused() {
        let mut m = DrMechanization::new(DrParams::default(), 0.0, 0.0, 0.0)
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(m.propagate(&raw(1.0, 2.5, 0.0)).is_ok_and(|s| s.is_none()));
        assert!(m.propagate(&raw(1.0, 2.5, 3.0)).is_err());
        assert!(m.propagate(&raw(1.1, f64::NAN, 3.0)).is_err());
        assert!(m.propagate(&raw(f64::NAN, 2.5, 3.0)).is_err());
        assert!(DrMechanization::new(DrParams::default(), f64::NAN, 0.0, 0.0).is_err());
        let bad = DrParams {
            sf_n_m_per_pulse: 0.0,
            ..DrParams::default()
        };
        assert!(DrMechanization::new(bad, 0.0, 0.0, 0.0).is_err());
    }

    #[test]
    fn params_save_and_load_round_trip() {
        let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let path = dir.path().join("dr_params.toml");
        let p = DrParams {
            sf_g_dps_per_v: 47.93612345678,
            v_nom_v: 2.5123456789,
            sf_n_m_per_pulse: 0.0987654321,
        };
        p.save(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(DrParams::load(&path).unwrap_or_else(|e| panic!("{e}")), p);
        let bad = |text: &str| {
            std::fs::write(&path, text).unwrap_or_else(|e| panic!("{e}"));
            DrParams::load(&path)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        };
        assert!(bad("sf_g_dps_per_v = 45.0\nv_nom_v = 2.5\n").contains("sf_n_m_per_pulse"));
        assert!(
            bad("sf_g_dps_per_v = -45.0\nv_nom_v = 2.5\nsf_n_m_per_pulse = 0.1\n")
                .contains("must be positive")
        );
        assert!(
            bad("sf_g_dps_per_v = 45.0\nv_nom_v = 2.5\nsf_n_m_per_pulse = 0.1\nx = 1\n")
                .contains("unknown field")
        );
        let missing = DrParams::load(&dir.path().join("none.toml"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            missing.contains("cannot read DR parameter file"),
            "{missing}"
        );
    }
}
