//! What the last fix (or the approximate position and time) predicts of a satellite for the
//! acquisition scheduler: above the horizon or not, and its Doppler with an uncertainty.

use super::{
    NavigationProcessor, APPROX_DOPPLER_HZ, BELOW_HORIZON_DEG, PENDING_FOR_S, PREDICTED_DOPPLER_HZ,
    PREDICTED_DOPPLER_RATE_HZ_S,
};
use crate::pipeline::channels::search_schedule::Visibility;
use gpsrx_nav::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::ephemeris::HealthPolicy;

impl NavigationProcessor {
    /// What is predicted of `prn` at stream time `t_stream_s` for the acquisition scheduler:
    /// with a fix (position, velocity, clock bias and drift) and the satellite's ephemeris
    /// (decoded or from `--nav`), whether it is above the horizon and its Doppler within
    /// [`PREDICTED_DOPPLER_HZ`] plus [`PREDICTED_DOPPLER_RATE_HZ_S`] per second since the fix
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
    /// `t_stream_s`, and the Doppler uncertainty of a prediction from that: the last fix
    /// (position, velocity, clock bias and drift; [`PREDICTED_DOPPLER_HZ`] growing by
    /// [`PREDICTED_DOPPLER_RATE_HZ_S`] with its age), else `--approx-llh` and `--time` (the
    /// receiver clock drift unknown: [`APPROX_DOPPLER_HZ`]).
    pub(super) fn prediction_origin(
        &self,
        t_stream_s: f64,
    ) -> Option<(gpsrx_core::PosVel, gpsrx_nav::time::GpsTime, f64, f64)> {
        if let (Some(fix), Some(t0)) = (self.prior.as_ref(), self.builder.rx_time_origin()) {
            // GPS time: receiver time less the clock bias of the fix.
            let t = t0.add_seconds(t_stream_s - fix.clock_bias_m / SPEED_OF_LIGHT_MPS);
            let rx = gpsrx_core::PosVel {
                pos_m: fix.pos_ecef_m,
                vel_mps: fix.vel_ecef_mps.unwrap_or_default(),
            };
            let drift = fix.clock_drift_mps.unwrap_or(0.0) / SPEED_OF_LIGHT_MPS;
            let age_s = (t.tow_s - fix.time.tow_s).abs();
            let width = PREDICTED_DOPPLER_HZ + PREDICTED_DOPPLER_RATE_HZ_S * age_s;
            return Some((rx, t, drift, width));
        }
        let ([lat, lon, h], t0) = (self.settings.approx_llh?, self.settings.approx_time?);
        let rx = gpsrx_core::PosVel {
            pos_m: gpsrx_nav::Llh::from_degrees(lat, lon, h).to_ecef(),
            vel_mps: gpsrx_nav::Vector3::zeros(),
        };
        Some((rx, t0.add_seconds(t_stream_s), 0.0, APPROX_DOPPLER_HZ))
    }
}
