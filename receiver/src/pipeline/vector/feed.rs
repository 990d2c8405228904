//! The filter's Doppler prediction fed forward into every channel's carrier NCO through the
//! aiding port (`gpsrx_tracking::AidingPort`): a VDFLL-style feed-forward, the channel's own
//! PLL (or FLL) tracking the residual on top (`f_NCO = f_ff + F(e)`, seed 004 Fig. 4).
//!
//! For satellite `k` at stream time `t` (seconds from the first sample), from the filter's
//! state at its last update (stream time `t_u`, GPS time `T_u`):
//!
//! 1. the receiver `dt = t - t_u` later: `r = r_u + v dt`, `v`, clock drift `d` (the
//!    constant-velocity model of the filter);
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
//! more than [`MAX_COAST_S`] from the last update give no aid.

use super::ekf::{State, BIAS, DRIFT};
use gpsrx_core::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_core::{los_doppler_hz, PosVel};
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::DopplerAid;
use nalgebra::Vector3;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Step of the Doppler rate, s.
pub const RATE_STEP_S: f64 = 0.01;
/// Longest prediction from the last update that still aids the channels, s; also the longest
/// time without an admitted measurement before the filter gives the channels back
/// (`super::tracker`). After a blockage of every signal the channels are found again by the
/// search, and the first fixes after it (4-5 satellites, a velocity good to metres per second)
/// are no base for a feed-forward: a filter that had coasted 3 s and took the returning
/// channels in from them threw one out of lock again (35 m fixes on 4 satellites). Taking
/// channels in from the filter's prediction without a search is a later part.
pub const MAX_COAST_S: f64 = 1.0;

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
}

impl Snapshot {
    /// The predicted Doppler (Hz) of `prn` at stream time `t_s` (module docs), None without
    /// its ephemeris, beyond [`MAX_COAST_S`] or when the geometry is degenerate.
    pub fn doppler_hz(&self, prn: u8, t_s: f64) -> Option<f64> {
        let dt = t_s - self.t_stream_s;
        if !(dt.is_finite() && dt.abs() <= MAX_COAST_S) {
            return None;
        }
        let eph = self.ephemerides.get(&prn)?;
        let vel = Vector3::new(self.x[3], self.x[4], self.x[5]);
        let pos = Vector3::new(self.x[0], self.x[1], self.x[2]) + vel * dt;
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
        })
    }
}
