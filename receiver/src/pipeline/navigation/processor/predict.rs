//! What the last fix (or the approximate position and time) predicts of a satellite for the
//! acquisition scheduler: above the horizon or not, and its Doppler with an uncertainty.

use super::{
    NavigationProcessor, APPROX_DOPPLER_HZ, BELOW_HORIZON_DEG, PENDING_FOR_S, PREDICTED_DOPPLER_HZ,
    PREDICTED_DOPPLER_RATE_HZ_S,
};
use crate::pipeline::aiding::{FixPoint, OutageBridge};
use crate::pipeline::channels::search_schedule::Visibility;
use gpsrx_core::constants::{F_L1_HZ, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::ephemeris::HealthPolicy;
use gpsrx_nav::pvt::PvtSolution;
use gpsrx_nav::Vector3;

/// How long the valid fixes are kept for the outage bridge, s.
pub(super) const RECENT_FIXES_S: f64 = 1.0;

impl NavigationProcessor {
    /// What is predicted of `prn` at stream time `t_stream_s` for the acquisition scheduler:
    /// with a valid fix (position, velocity, acceleration, clock drift; kept across gaps) and
    /// the satellite's ephemeris (decoded or from `--nav`), whether it is above the horizon and
    /// its Doppler within the uncertainty of `PredictionAnchor::at`
    /// (`crate::pipeline::channels::visibility`); else nothing.
    pub fn visibility(&self, prn: u8, t_stream_s: f64) -> Visibility {
        let Some((rx, t, drift, half_width_hz)) = self.prediction_origin(t_stream_s) else {
            // With ephemerides from `--nav`, the first fix (a few seconds away) will tell.
            let soon = self.nav_assist.is_some() && t_stream_s < PENDING_FOR_S;
            return if soon {
                Visibility::Pending
            } else {
                Visibility::Unknown
            };
        };
        let decoded = self.decoders.get(&prn).and_then(|d| d.ephemeris.as_ref());
        let eph = decoded.or_else(|| {
            self.nav_assist
                .as_ref()
                .and_then(|n| n.select_with(prn, t, HealthPolicy::PreferHealthy))
        });
        // An ephemeris within 4 h, else the decoded almanac (a few hertz worse: margin enough).
        let seen = match eph.filter(|e| e.is_within_s(t, 4.0 * 3600.0)) {
            Some(e) => e.at_reception(t, &rx.pos_m, 0.075, 3),
            None => match self.almanac.almanac(prn) {
                Some(a) => a.at_reception(t, &rx.pos_m),
                None => return Visibility::Unknown,
            },
        };
        match crate::pipeline::channels::visibility::predict_seen(&seen, &rx, drift) {
            Some(p) if p.elevation_deg < BELOW_HORIZON_DEG => Visibility::Below,
            Some(p) => Visibility::Visible {
                doppler_hz: p.doppler_hz,
                half_width_hz,
            },
            None => Visibility::Unknown,
        }
    }

    /// Where, when and with which clock drift (s/s) the receiver is at stream time
    /// `t_stream_s`, and the Doppler uncertainty of a prediction from that: the last valid fix
    /// ([`PredictionAnchor::at`]), else `--approx-llh` and `--time` (the receiver clock drift
    /// unknown: [`APPROX_DOPPLER_HZ`]).
    pub(super) fn prediction_origin(
        &self,
        t_stream_s: f64,
    ) -> Option<(gpsrx_core::PosVel, gpsrx_nav::time::GpsTime, f64, f64)> {
        if let Some(anchor) = &self.anchor {
            return Some(anchor.at(t_stream_s));
        }
        let ([lat, lon, h], t0) = (self.settings.approx_llh?, self.settings.approx_time?);
        let rx = gpsrx_core::PosVel {
            pos_m: gpsrx_nav::Llh::from_degrees(lat, lon, h).to_ecef(),
            vel_mps: gpsrx_nav::Vector3::zeros(),
        };
        Some((rx, t0.add_seconds(t_stream_s), 0.0, APPROX_DOPPLER_HZ))
    }
}

impl NavigationProcessor {
    /// Keeps the valid fix `sol` at stream time `t_stream_s` for the outage bridge (with its
    /// velocity; the last [`RECENT_FIXES_S`] of them).
    pub(super) fn remember_fix(&mut self, sol: &PvtSolution, t_stream_s: f64) {
        let Some(vel_mps) = sol.vel_ecef_mps else {
            return;
        };
        self.recent_fixes.push_back(FixPoint {
            t_stream_s,
            time: sol.time,
            pos_m: sol.pos_ecef_m,
            vel_mps,
            drift_s_s: sol.clock_drift_mps.unwrap_or(0.0) / SPEED_OF_LIGHT_MPS,
        });
        while self
            .recent_fixes
            .front()
            .is_some_and(|f| t_stream_s - f.t_stream_s > RECENT_FIXES_S)
        {
            self.recent_fixes.pop_front();
        }
    }

    /// The bridge over an outage whose common collapse of the prompt power was at stream time
    /// `collapse_s` ([`OutageBridge::arm`]): the recent valid fixes and every satellite's
    /// ephemeris (decoded, else from `--nav`, as the fixes take them). None when it is not
    /// armed.
    pub fn outage_bridge(&self, collapse_s: f64) -> Option<OutageBridge> {
        let t = self.recent_fixes.back()?.time;
        let policy = if self.settings.allow_unhealthy {
            HealthPolicy::PreferHealthy
        } else {
            HealthPolicy::HealthyOnly
        };
        let ephemerides = (1..=32u8)
            .filter_map(|prn| {
                let decoded = self.decoders.get(&prn).and_then(|d| d.ephemeris.as_ref());
                let eph = decoded.or_else(|| {
                    self.nav_assist
                        .as_ref()
                        .and_then(|n| n.select_with(prn, t, policy))
                })?;
                Some((prn, eph.clone()))
            })
            .collect();
        let fixes: Vec<FixPoint> = self.recent_fixes.iter().copied().collect();
        OutageBridge::arm(collapse_s, &fixes, ephemerides)
    }

    /// Stream time of the last valid fix, s.
    pub fn last_valid_fix_s(&self) -> Option<f64> {
        self.recent_fixes.back().map(|f| f.t_stream_s)
    }

    /// Signal lost in all the gaps measured so far, s.
    pub fn lost_total_s(&self) -> f64 {
        self.lost_total_s
    }
}

/// The last valid fix, kept for the acquisition scheduler's predictions across gaps and
/// outages (a Doppler prediction needs the time to a second, not to the millisecond the
/// receiver time is re-established to), with the receiver's acceleration from the two last
/// fixes' velocities.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PredictionAnchor {
    /// GPS time of the fix.
    time: gpsrx_nav::time::GpsTime,
    /// Its stream time, s.
    t_stream_s: f64,
    /// ECEF position, m, and velocity, m/s (zero when the fix had none).
    pos_m: Vector3<f64>,
    vel_mps: Option<Vector3<f64>>,
    /// Receiver clock drift, s/s.
    drift_s_s: f64,
    /// ECEF acceleration, m/s^2 (zero until two fixes with velocities within
    /// [`ACCEL_FROM_FIXES_WITHIN_S`]).
    accel_mps2: Vector3<f64>,
}

/// Two fixes further apart than this give no acceleration, s.
const ACCEL_FROM_FIXES_WITHIN_S: f64 = 2.0;

impl PredictionAnchor {
    /// The anchor after the valid fix `sol` at stream time `t_stream_s`, following `prev`.
    pub(super) fn new(sol: &PvtSolution, t_stream_s: f64, prev: Option<&Self>) -> Self {
        let drift_s_s = sol.clock_drift_mps.unwrap_or(0.0) / SPEED_OF_LIGHT_MPS;
        Self::from_fix(
            sol.time,
            t_stream_s,
            sol.pos_ecef_m,
            sol.vel_ecef_mps,
            drift_s_s,
        )
        .after(prev)
    }

    fn from_fix(
        time: gpsrx_nav::time::GpsTime,
        t_stream_s: f64,
        pos_m: Vector3<f64>,
        vel_mps: Option<Vector3<f64>>,
        drift_s_s: f64,
    ) -> Self {
        Self {
            time,
            t_stream_s,
            pos_m,
            vel_mps,
            drift_s_s,
            accel_mps2: Vector3::zeros(),
        }
    }

    /// With the acceleration from the previous anchor's velocity.
    fn after(mut self, prev: Option<&Self>) -> Self {
        self.accel_mps2 = prev
            .and_then(|p| {
                let dt = self.t_stream_s - p.t_stream_s;
                let (v1, v0) = (self.vel_mps?, p.vel_mps?);
                (dt > 0.0 && dt <= ACCEL_FROM_FIXES_WITHIN_S).then(|| (v1 - v0) / dt)
            })
            .filter(|a| a.iter().all(|x| x.is_finite()))
            .unwrap_or_else(Vector3::zeros);
        self
    }

    /// The receiver `age` s after the fix (position and velocity carried with the fix's
    /// acceleration: `p + v age + a age^2 / 2`, `v + a age`), the GPS time, the clock drift
    /// (s/s), and the Doppler uncertainty: [`PREDICTED_DOPPLER_HZ`] plus, per second of age,
    /// [`PREDICTED_DOPPLER_RATE_HZ_S`] and the Doppler rate of the acceleration, `|a| /
    /// lambda_L1` (the acceleration may stop or double: a 10 g turn is 515 Hz/s).
    pub(super) fn at(
        &self,
        t_stream_s: f64,
    ) -> (gpsrx_core::PosVel, gpsrx_nav::time::GpsTime, f64, f64) {
        let age_s = t_stream_s - self.t_stream_s;
        let v = self.vel_mps.unwrap_or_default();
        let a = self.accel_mps2;
        let rx = gpsrx_core::PosVel {
            pos_m: self.pos_m + v * age_s + a * (0.5 * age_s * age_s),
            vel_mps: v + a * age_s,
        };
        let accel_rate_hz_s = a.norm() / (SPEED_OF_LIGHT_MPS / F_L1_HZ);
        let width =
            PREDICTED_DOPPLER_HZ + (PREDICTED_DOPPLER_RATE_HZ_S + accel_rate_hz_s) * age_s.abs();
        (rx, self.time.add_seconds(age_s), self.drift_s_s, width)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_nav::time::GpsTime;

    /// Two fixes 0.1 s apart in a 10 g turn (the velocity turned by 9.8 m/s): 1 s after the
    /// second the receiver is where constant acceleration takes it, and the Doppler window
    /// has grown by the acceleration's 515 Hz/s besides the base rate.
    #[test]
    fn a_prediction_carries_the_fixes_acceleration_and_widens_with_it() {
        let t = GpsTime::new(2190, 538_240.0);
        let p0 = Vector3::new(-3.0e6, 4.0e6, 3.9e6);
        let v0 = Vector3::new(250.0, 0.0, 0.0);
        let a = Vector3::new(0.0, 98.0665, 0.0);
        let first = PredictionAnchor::from_fix(t, 40.0, p0, Some(v0), 1e-8);
        let second = PredictionAnchor::from_fix(
            t.add_seconds(0.1),
            40.1,
            p0 + v0 * 0.1 + a * 0.005,
            Some(v0 + a * 0.1),
            1e-8,
        )
        .after(Some(&first));
        let (rx, time, drift, width) = second.at(41.1);
        let want_v = v0 + a * 1.1;
        let want_p = p0 + v0 * 1.1 + a * (0.5 * 1.1 * 1.1);
        assert!((rx.vel_mps - want_v).norm() < 1e-6, "{}", rx.vel_mps);
        assert!((rx.pos_m - want_p).norm() < 1e-6, "{}", rx.pos_m);
        assert!((time.diff_s(t) - 1.1).abs() < 1e-9);
        assert_eq!(drift, 1e-8);
        let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
        let want_w = PREDICTED_DOPPLER_HZ + PREDICTED_DOPPLER_RATE_HZ_S + 98.0665 / lambda;
        assert!((width - want_w).abs() < 1e-6, "{width} vs {want_w}");
        // Fixes too far apart tell no acceleration: the window grows at the base rate only.
        let late = PredictionAnchor::from_fix(t.add_seconds(5.0), 45.0, p0, Some(v0), 0.0)
            .after(Some(&second));
        let (_, _, _, w) = late.at(46.0);
        assert!((w - PREDICTED_DOPPLER_HZ - PREDICTED_DOPPLER_RATE_HZ_S).abs() < 1e-9);
    }
}
