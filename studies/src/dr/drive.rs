//! The vehicle truth: `samples/scenarios/urban-drive.toml` (embedded) or seed 002's hilly road
//! ([`super::hilly`]) tabulated by the simulator's own motion model and sampled as
//! [`VehicleTruth`], the input of the sensor models.

use super::params::{TABLE_STEP_S, TRUTH_RATE_HZ};
use anyhow::Context;
use gpsrx_ins_aiding::VehicleTruth;
use gpsrx_samples::sim::scenario::{Scenario, URBAN_DRIVE_TOML};
use gpsrx_samples::sim::trajectory::MotionTable;

/// The drive: truth at [`TRUTH_RATE_HZ`] from 0 to the scenario's `duration_s`.
#[derive(Debug, Clone)]
pub struct Drive {
    /// Truth states, in time order.
    pub truth: Vec<VehicleTruth>,
    /// Length, s.
    pub duration_s: f64,
    /// Scenario description.
    pub description: String,
}

impl Drive {
    /// The urban drive, or its first `limit_s` seconds.
    pub fn urban(limit_s: Option<f64>) -> anyhow::Result<Drive> {
        Self::from_toml(URBAN_DRIVE_TOML, limit_s).context("urban-drive.toml")
    }

    /// Seed 002's hilly road ([`super::hilly::HILLY_TOML`]).
    pub fn hilly() -> anyhow::Result<Drive> {
        Self::from_toml(super::hilly::HILLY_TOML, None).context("the hilly speed profile")
    }

    /// A `kind = "motion"` scenario's drive, or its first `limit_s` seconds.
    pub fn from_toml(text: &str, limit_s: Option<f64>) -> anyhow::Result<Drive> {
        let sc = Scenario::from_toml(text)?;
        let duration_s = limit_s.map_or(sc.duration_s, |l| l.min(sc.duration_s));
        let table = MotionTable::from_config(&sc.receiver, duration_s, TABLE_STEP_S)?;
        let n = (duration_s * TRUTH_RATE_HZ).round() as usize;
        let truth = (0..=n)
            .map(|k| table.vehicle_state(k as f64 / TRUTH_RATE_HZ))
            .collect();
        Ok(Drive {
            truth,
            duration_s,
            description: sc.description,
        })
    }

    /// The truth at `t_s` (nearest state of the evenly spaced truth; the GNSS epochs fall on
    /// truth states).
    pub fn at(&self, t_s: f64) -> &VehicleTruth {
        let dt = match self.truth.get(1) {
            Some(s) => s.t_s - self.truth[0].t_s,
            None => 1.0 / TRUTH_RATE_HZ,
        };
        let k = ((t_s - self.truth[0].t_s) / dt).round().max(0.0) as usize;
        &self.truth[k.min(self.truth.len() - 1)]
    }

    /// Path length, m (trapezoid of the speed).
    pub fn distance_m(&self) -> f64 {
        self.truth
            .windows(2)
            .map(|w| 0.5 * (w[0].speed_mps + w[1].speed_mps) * (w[1].t_s - w[0].t_s))
            .sum()
    }
}
