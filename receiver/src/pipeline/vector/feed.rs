//! The filter's Doppler prediction fed forward into every channel's carrier NCO through the
//! aiding port (`gpsrx_tracking::AidingPort`): a VDFLL-style feed-forward, the channel's own
//! PLL (or FLL) tracking the residual on top (`f_NCO = f_ff + F(e)`, seed 004 Fig. 4).
//!
//! For satellite `k` at stream time `t` (seconds from the first sample), from the filter's
//! state at its last update (stream time `t_u`, GPS time `T_u`):
//!
//! 1. the receiver `dt = t - t_u` later: `r = r_u + v dt`, `v`, clock drift `d` (the
//!    constant-velocity model of the filter); with an INS, the filter's state moved by the
//!    INS's motion since the update: `v = v_u + (v_ins(t) - v_ins(t_u))`,
//!    `r = r_u + (v_u - v_ins(t_u)) dt + (r_ins(t) - r_ins(t_u))` (its position error and
//!    velocity error held), so the aid follows a manoeuvre between updates;
//! 2. the satellite seen from `r` at GPS time `T_u + dt` (its ephemeris at the transmit time,
//!    rotated by the Earth's rotation during the flight: `Ephemeris::at_reception`);
//! 3. the Doppler `f = -((v_sv - v_rx) . u) / lambda + f_L1 (d_sv - d / c)`
//!    ([`gpsrx_core::los_doppler_hz`], seed 004 eq. 6 with the clock drifts), and its rate
//!    from the same computation [`RATE_STEP_S`] later.
//!
//! The whole receiver clock drift is fed forward: the aid comes on when the filter starts,
//! with its drift already estimated, and the channel keeps its NCO frequency when an aid comes
//! or goes (its loop's base frequency takes up the difference, `Channel::set_aid`).
//! Every satellite with an ephemeris gets the aid, its channel locked or not: the filter's
//! prediction is what holds a channel whose own loop is losing a weak signal. Predictions
//! more than the filter's coast limit (`[vector] max_coast_s`) from the last update give no
//! aid.
//!
//! **Through an outage.** The aid of a satellite the filter admitted a measurement of within
//! that limit carries [`DopplerAid::coast`]: when its signal is blocked the channel coasts on
//! the prediction (its loops hold their memories, its C/N0 test waits) instead of being
//! released and searched again, so it is there with its code, bits and SV time the moment
//! the signal returns. The code follows the carrier aid, so the predicted range rate steers
//! it: the code drifts by the range-rate error over the outage only (a static receiver:
//! nothing the filter's clock-drift error does not cover; 1 m/s^2 of unmodelled acceleration
//! over 3 s: 4.5 m, 0.015 chip).
//!
//! **Before a satellite's first measurement.** A weak satellite's channel gives observables
//! only after its bits and frame are synchronised (10-20 s at 24 dB-Hz), and under the
//! scalar loss threshold (25 dB-Hz) it is released long before: the filter never sees it, so
//! it is never checked. Its code phase can be checked at once: the prediction gives the SV
//! time at the channel's sample, `t_sv = T - tau + dt_sv` (`T` the GPS time of the sample,
//! `tau` the flight time, `dt_sv` the SV clock), so the code phase modulo one period,
//! `1.023e6 (t_sv mod 1 ms)` chips ([`code_phase_chips`]). A channel within
//! [`super::vouch::VOUCH_CHIPS`] of it tracks that satellite's signal: a cross-correlation
//! peak or a false acquisition sits anywhere in the 1023 chips (1 in 1000 to fall within
//! half a chip). Such a channel counts as checked ([`Snapshot::checked`]) until the filter
//! excludes one of its measurements (`super::vouch`).

use super::ekf::{State, BIAS, DRIFT};
use crate::pipeline::aiding::InsFeedForward;
use gpsrx_core::constants::{
    CA_CHIP_RATE_HZ, CA_CODE_LENGTH, CA_CODE_PERIOD_S, SPEED_OF_LIGHT_MPS,
};
use gpsrx_core::{los_doppler_hz, PosVel};
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::DopplerAid;
use nalgebra::Vector3;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Step of the Doppler rate, s.
pub const RATE_STEP_S: f64 = 0.01;
/// How recent the filter's last admitted measurement of a satellite must be for its channel
/// to count as checked ([`DopplerAid::checked`]), s: a few epochs (a channel the innovation
/// test starts excluding falls back to the scalar loss threshold within a second).
pub const CHECKED_S: f64 = 1.0;

/// The filter's state at one update, as the channels need it.
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// Stream time of the update, s.
    pub t_stream_s: f64,
    /// GPS time of the update (the receiver time less the clock bias).
    pub gps_time: GpsTime,
    /// The state.
    pub x: State,
    /// The ephemerides of the satellites the filter uses.
    pub ephemerides: Arc<BTreeMap<u8, Ephemeris>>,
    /// Stream time of each satellite's last admitted measurement, s.
    pub admitted_s: Arc<BTreeMap<u8, f64>>,
    /// Stream time at which each satellite's channel last agreed with the predicted code
    /// phase, s (`super::vouch`; none while the filter excludes its measurements).
    pub vouched_s: Arc<BTreeMap<u8, f64>>,
    /// Longest prediction (from the update, and from a satellite's last admitted
    /// measurement for its [`DopplerAid::coast`]), s: `[vector] max_coast_s`.
    pub max_coast_s: f64,
    /// With an INS: its motion at the update, which the prediction follows from there.
    pub ins: Option<InsAnchor>,
}

/// The INS whose motion a [`Snapshot`]'s prediction follows, and its state at the update.
#[derive(Debug, Clone)]
pub struct InsAnchor {
    /// The INS (its positions and velocities at stream times).
    pub ins: Arc<InsFeedForward>,
    /// Its position at the update, ECEF m.
    pub pos_m: Vector3<f64>,
    /// Its velocity at the update, ECEF m/s.
    pub vel_mps: Vector3<f64>,
}

impl InsAnchor {
    /// The anchor at stream time `t_s` (None outside the INS file).
    pub fn at(ins: &Arc<InsFeedForward>, t_s: f64) -> Option<Self> {
        let (pos_m, vel_mps) = ins.motion_at(t_s)?;
        Some(Self {
            ins: Arc::clone(ins),
            pos_m,
            vel_mps,
        })
    }
}

impl Snapshot {
    /// The predicted Doppler (Hz) of `prn` at stream time `t_s` (module docs), None without
    /// its ephemeris, beyond [`Snapshot::max_coast_s`] or when the geometry is degenerate.
    pub fn doppler_hz(&self, prn: u8, t_s: f64) -> Option<f64> {
        let (eph, dt) = self.ephemeris_within_reach(prn, t_s)?;
        let (pos, vel) = self.motion(t_s, dt);
        let drift_mps = self.x[DRIFT];
        let seen = eph.at_reception(self.gps_time.add_seconds(dt), &pos, 0.075, 2);
        let sv = PosVel {
            pos_m: seen.sv.pos_m,
            vel_mps: seen.sv.vel_mps,
        };
        let rx = PosVel {
            pos_m: pos,
            vel_mps: vel,
        };
        let f = los_doppler_hz(
            &sv,
            &rx,
            seen.sv.clock_drift_s_s,
            drift_mps / SPEED_OF_LIGHT_MPS,
        )?;
        f.is_finite().then_some(f)
    }

    /// The ephemeris of `prn` and the time from the update to stream time `t_s`, s, when
    /// the prediction reaches that far ([`Snapshot::max_coast_s`]).
    fn ephemeris_within_reach(&self, prn: u8, t_s: f64) -> Option<(&Ephemeris, f64)> {
        let dt = t_s - self.t_stream_s;
        if !(dt.is_finite() && dt.abs() <= self.max_coast_s) {
            return None;
        }
        Some((self.ephemerides.get(&prn)?, dt))
    }

    /// The receiver's predicted position and velocity (ECEF m, m/s) at stream time `t_s`,
    /// `dt` after the update: the filter's velocity held, or with an INS the filter's state
    /// moved by the INS's motion since the update (module docs).
    fn motion(&self, t_s: f64, dt: f64) -> (Vector3<f64>, Vector3<f64>) {
        let vel = Vector3::new(self.x[3], self.x[4], self.x[5]);
        let pos = Vector3::new(self.x[0], self.x[1], self.x[2]);
        let by_ins = self.ins.as_ref().and_then(|a| {
            let (p, v) = a.ins.motion_at(t_s)?;
            Some((
                pos + (vel - a.vel_mps) * dt + (p - a.pos_m),
                vel + (v - a.vel_mps),
            ))
        });
        by_ins.unwrap_or((pos + vel * dt, vel))
    }

    /// The receiver's predicted position at stream time `t_s`, ECEF m (module docs).
    pub fn position_at(&self, t_s: f64) -> Vector3<f64> {
        self.motion(t_s, t_s - self.t_stream_s).0
    }

    /// Whether the channel of `prn` may coast on the prediction at stream time `t_s` through
    /// an outage of its signal: the filter admitted a measurement of it within
    /// [`Snapshot::max_coast_s`] (module docs).
    pub fn coasts(&self, prn: u8, t_s: f64) -> bool {
        self.admitted_s
            .get(&prn)
            .is_some_and(|t| t_s - t <= self.max_coast_s)
    }

    /// Whether the filter checked and admitted a measurement of `prn` within [`CHECKED_S`]
    /// of stream time `t_s`, or its channel's code agreed with the prediction then (module
    /// docs, "Before a satellite's first measurement"): its channel's loss threshold is then
    /// `[tracking] vector_cn0_lost_dbhz` ([`DopplerAid::checked`]).
    pub fn checked(&self, prn: u8, t_s: f64) -> bool {
        let recent = |m: &BTreeMap<u8, f64>| m.get(&prn).is_some_and(|t| t_s - t <= CHECKED_S);
        recent(&self.admitted_s) || recent(&self.vouched_s)
    }

    /// The predicted SV time of `prn` at stream time `t_s`: the time of week (s) its signal
    /// arriving then left it by its own clock, `t_sv = T - tau + dt_sv` (module docs).
    /// Without the ionosphere and troposphere (2-50 m, 7-170 ns; the filter's clock bias
    /// holds their mean). None as [`Snapshot::doppler_hz`].
    pub fn sv_tow_s(&self, prn: u8, t_s: f64) -> Option<f64> {
        let (eph, dt) = self.ephemeris_within_reach(prn, t_s)?;
        let (pos, _) = self.motion(t_s, dt);
        // The receiver clock runs on between updates: GPS time advances by dt less its drift.
        let t_gps = self
            .gps_time
            .add_seconds(dt * (1.0 - self.x[DRIFT] / SPEED_OF_LIGHT_MPS));
        let seen = eph.at_reception(t_gps, &pos, 0.075, 2);
        let tow = t_gps.tow_s - seen.flight_time_s + seen.sv.clock_bias_s;
        tow.is_finite().then_some(tow)
    }

    /// The receiver clock bias at the update, m.
    pub fn clock_bias_m(&self) -> f64 {
        self.x[BIAS]
    }
}

/// The aiding port of vector tracking: the latest [`Snapshot`] while the filter holds the
/// channels, nothing otherwise (the channels run scalar).
#[derive(Debug, Clone, Default)]
pub struct VectorPort {
    /// The filter's latest state (None: scalar tracking).
    pub snapshot: Option<Snapshot>,
}

impl gpsrx_tracking::AidingPort for VectorPort {
    fn doppler_aid(&self, prn: gpsrx_dsp::Prn, t_s: f64) -> Option<DopplerAid> {
        let snap = self.snapshot.as_ref()?;
        let f = snap.doppler_hz(prn.get(), t_s)?;
        let f2 = snap.doppler_hz(prn.get(), t_s + RATE_STEP_S).unwrap_or(f);
        Some(DopplerAid {
            doppler_hz: f,
            doppler_rate_hz_s: (f2 - f) / RATE_STEP_S,
            coast: snap.coasts(prn.get(), t_s),
            checked: snap.checked(prn.get(), t_s),
            source: gpsrx_tracking::AidSource::Vector,
        })
    }
}

/// The C/A code phase at SV time `sv_tow_s` (s), chips in `[0, 1023)`: `1.023e6 (t_sv mod
/// 1 ms)` (the code starts with every millisecond of SV time, IS-GPS-200 3.3.2.3).
pub fn code_phase_chips(sv_tow_s: f64) -> f64 {
    (sv_tow_s.rem_euclid(CA_CODE_PERIOD_S) * CA_CHIP_RATE_HZ) % CA_CODE_LENGTH as f64
}

/// A prediction for the unit tests: a static receiver at Seoul (37.5665, 126.978, 40 m) with
/// a perfect clock at GPS week 2190, TOW 538200 s, at stream time 10 s, with the broadcast
/// ephemerides of the simulator's built-in navigation file.
#[cfg(test)]
pub(crate) fn test_snapshot() -> Snapshot {
    use gpsrx_nav::ephemeris::HealthPolicy;
    let nav = gpsrx_nav::rinex_nav::parse_rinex_nav(gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT)
        .unwrap_or_else(|e| panic!("{e}"));
    let t = GpsTime::new(2190, 538_200.0);
    let ephemerides = (1..=32u8)
        .filter_map(|p| Some((p, nav.select_with(p, t, HealthPolicy::Ignore)?.clone())))
        .collect();
    let mut x = State::zeros();
    let pos = gpsrx_core::frames::Llh::from_degrees(37.5665, 126.978, 40.0).to_ecef();
    x.fixed_rows_mut::<3>(0).copy_from(&pos);
    Snapshot {
        t_stream_s: 10.0,
        gps_time: t,
        x,
        ephemerides: Arc::new(ephemerides),
        admitted_s: Arc::new(BTreeMap::new()),
        vouched_s: Arc::new(BTreeMap::new()),
        max_coast_s: 5.0,
        ins: None,
    }
}
