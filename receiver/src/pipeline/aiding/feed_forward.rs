//! The INS-velocity Doppler feed-forward that drives the tracking channels' aiding port
//! (seed 004, Fig. 4).
//!
//! For satellite `k` at receive time `t` (seconds from the first IF sample):
//!
//! 1. receive time in GPS time: `t_gps = t0 + t`, with `t0` the GPS time of the first sample
//!    (from the first decoded time of week, or from the INS file's `gps_tow_s` column);
//! 2. satellite position, velocity and clock drift from the ephemeris (the decoded one or one
//!    from `--nav`, whichever valid one has the toe nearest to `t_gps`,
//!    [`gpsrx_nav::select_ephemeris`]) at the transmit time `t_gps - tau`, rotated by the
//!    Earth's rotation during the flight `OmegaE tau` into the frame of reception, with the
//!    light time `tau` iterated twice from 75 ms ([`gpsrx_nav::light_time`], IS-GPS-200
//!    20.3.3.4.3.3.2);
//! 3. receiver position: the INS position before the first fix; after it, the fix propagated
//!    by the INS displacement since the fix (the INS position may carry a bias, its velocity is
//!    what matters); receiver velocity from the INS, for aided loops of order 1-2 less its
//!    error followed from the fixes' velocities ([`InsVelocityCalibration`]: offset and drift,
//!    so an accelerometer bias does not become a Doppler ramp in the loops;
//!    [`InsFeedForward::with_velocity_calibration`]);
//! 4. Doppler, seed 004 eq. 6 written with the unit vector `u` from receiver to satellite
//!    ([`gpsrx_core::los_doppler_hz`]):
//!    `f = -((v_sv - v_rx) . u) / lambda + f_L1 d_sv - f_L1 (d_rx - d_ref)`, with `d_sv` the
//!    satellite clock drift and `d_rx` the receiver clock drift (s/s) from the fixes, smoothed
//!    with a 1 s time constant (`pseudorange rate = range rate + c d_rx - c d_sv`,
//!    `f = -pseudorange rate / lambda`). Only the *change* of the receiver clock drift since
//!    its first estimate `d_ref` is fed forward: a channel keeps its NCO frequency when the aid
//!    comes on (the loop's base frequency takes up the difference, see
//!    `gpsrx_tracking::Channel::set_aid`), so the drift at that moment is already in the loop,
//!    whereas putting the whole drift in when the first fix arrives would step every NCO by
//!    `f_L1 d_rx` (63 Hz for 4e-8) and throw narrow aided loops out of lock;
//! 5. optionally the band limiter `alpha / (s + alpha)` (seed 004 eq. 8) on each satellite's
//!    feed-forward, so that the effect of an INS of limited dynamic range can be reproduced on
//!    real recordings;
//! 6. the Doppler rate over the next interval from the same computation 10 ms later (or, with
//!    the band limiter, its output slope `alpha (f - y)`).
//!
//! Until a satellite's ephemeris and the GPS time are known it gets no feed-forward (logged
//! once per satellite), and outside the INS file's time span no satellite does.
//!
//! # Time
//!
//! The receiver counts samples, so after a front end drops `g` seconds of samples its stream
//! time lags the time elapsed since the first sample by `g`. The INS file's `t_s` and the GPS
//! time `t0 + t` are elapsed time: once the receiver has measured a gap
//! ([`InsFeedForward::note_samples_lost`]) every stream time is taken as `t_s + lost` here
//! (fixes, aids, predictions), and a time origin given after it is moved back by `lost`.

use crate::pipeline::navigation::fix_output::passes_integrity;
use gpsrx_core::{los_doppler_hz, PosVel};
use gpsrx_dsp::constants::{F_L1_HZ, SPEED_OF_LIGHT_MPS};
use gpsrx_ins_aiding::{BandLimiter, InsTrack, InsVelocityCalibration};
use gpsrx_nav::ephemeris::{select_ephemeris, Ephemeris, HealthPolicy};
use gpsrx_nav::pvt::{PvtSolution, RaimStatus};
use gpsrx_nav::rinex_nav::NavData;
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::DopplerAid;
use nalgebra::Vector3;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Mutex, RwLock};

/// Step used for the Doppler rate, s.
const RATE_STEP_S: f64 = 0.01;
/// A band limiter that has not been stepped for this long restarts from its input, s.
const LIMITER_RESTART_S: f64 = 1.0;
/// Time constant of the receiver clock drift smoothing, s.
pub const DRIFT_SMOOTHING_S: f64 = 30.0;

/// What the receiver has learned that the feed-forward needs; updated as the run goes.
#[derive(Debug, Clone, Default)]
struct Knowledge {
    /// GPS time of the first IF sample.
    t0: Option<GpsTime>,
    /// Decoded ephemerides, per PRN.
    ephemerides: BTreeMap<u8, Ephemeris>,
    /// Latest fix: receive time (s from the first sample), ECEF position.
    fix: Option<(f64, Vector3<f64>)>,
    /// Receiver clock drift from the fixes, smoothed, s/s.
    rx_clock_drift_s_s: Option<f64>,
    /// The first receiver clock drift estimate, s/s, and the time of the latest, s.
    rx_clock_drift_ref: Option<(f64, f64)>,
    /// The INS velocity error followed from the fixes (step 3 of the module docs).
    calibration: InsVelocityCalibration,
    /// Signal lost in the gaps measured so far, s: stream time plus this is the time elapsed
    /// since the first sample (module docs, "Time").
    lost_s: f64,
}

/// The INS feed-forward for all satellites (`gpsrx run --ins`). Shared by the tracking threads
/// (reads) and the navigation thread (updates).
#[derive(Debug)]
pub struct InsFeedForward {
    ins: InsTrack,
    /// The `--nav` ephemerides, per PRN, in file order.
    nav: BTreeMap<u8, Vec<Ephemeris>>,
    band_limit_alpha_rad_s: Option<f64>,
    allow_unhealthy: bool,
    know: RwLock<Knowledge>,
    limiters: Mutex<BTreeMap<u8, (BandLimiter, f64)>>,
    logged: Mutex<BTreeSet<(u8, &'static str)>>,
    calibrate: bool,
    /// The INS file's time of week at its stream time (s, s), waiting for the GPS week when it
    /// was not known at the start: the first decoded time of week gives it.
    ins_first_tow_s: Option<(f64, f64)>,
}

impl InsFeedForward {
    /// A feed-forward from an INS track, optional `--nav` ephemerides (used until a satellite's
    /// own are decoded), the GPS week to place the INS file's `gps_tow_s` in (`None`: not known
    /// yet; the week of the first decoded time of week is taken, see
    /// [`InsFeedForward::set_time_origin`]), and an optional band limiter corner (rad/s).
    pub fn new(
        ins: InsTrack,
        nav: Option<NavData>,
        reference_week: Option<u32>,
        band_limit_alpha_rad_s: Option<f64>,
    ) -> Self {
        // A file with `t_s` and `gps_tow_s` tells the GPS time of the first IF sample (once the
        // week is known); a file in the GPS time base (no `t_s`) needs the receiver's own time.
        let first_tow_s = ins
            .gps_time_base_tow_s()
            .is_none()
            .then(|| ins.gps_tow_at(ins.span_s().0))
            .flatten()
            .map(|tow| (tow, ins.span_s().0));
        let t0 = first_tow_s.zip(reference_week).map(|((tow, at_s), week)| {
            let t = GpsTime::new(week, tow).add_seconds(-at_s);
            tracing::info!(
                "INS aiding: GPS time from the INS file (first sample at TOW {:.3} s)",
                t.tow_s
            );
            t
        });
        let mut by_prn: BTreeMap<u8, Vec<Ephemeris>> = BTreeMap::new();
        for e in nav.into_iter().flat_map(|n| n.ephemerides) {
            by_prn.entry(e.prn).or_default().push(e);
        }
        Self {
            ins,
            nav: by_prn,
            band_limit_alpha_rad_s,
            allow_unhealthy: false,
            know: RwLock::new(Knowledge {
                t0,
                ..Knowledge::default()
            }),
            ins_first_tow_s: first_tow_s.filter(|_| t0.is_none()),
            limiters: Mutex::new(BTreeMap::new()),
            logged: Mutex::new(BTreeSet::new()),
            calibrate: false,
        }
    }

    /// Follows the INS velocity error from the fixes and takes it out of the feed-forward
    /// ([`InsVelocityCalibration`]). For aided loops of order 1 and 2, which have no
    /// Doppler-rate integrator of their own: an accelerometer bias would leave them a static
    /// phase offset (order 2) or an unbounded one (order 1). Not for order 3: its own rate
    /// integrator follows the drift without steady error, and two integrators of the same
    /// ramp at similar bandwidths fight (measured on the 10 g turn with a 1 mg INS, 3rd order
    /// at 0.4 Hz: 5 of 8 satellites held with the calibration, 8 of 8 without).
    pub fn with_velocity_calibration(mut self, on: bool) -> Self {
        self.calibrate = on;
        self
    }

    /// Also aids satellites whose `--nav` ephemeris is flagged unhealthy (as `run
    /// --allow-unhealthy` uses them); decoded ephemerides are used whatever their flag.
    pub fn allow_unhealthy(mut self, allow: bool) -> Self {
        self.allow_unhealthy = allow;
        self
    }

    /// Sets the GPS time of the first sample (from the first decoded time of week), unless it is
    /// already known. An INS file with its own time of week waiting for the week
    /// ([`InsFeedForward::new`] without one) takes the week from `t0` (the one putting the
    /// file's time of week nearest to it) and keeps its own time of week.
    pub fn set_time_origin(&self, t0: GpsTime) {
        if self.know.read().is_ok_and(|k| k.t0.is_some()) {
            return;
        }
        if let Ok(mut k) = self.know.write() {
            if k.t0.is_none() {
                // `t0` maps stream time to GPS time; the aid works in elapsed time.
                let decoded = t0.add_seconds(-k.lost_s);
                let t0 = match self.ins_first_tow_s {
                    Some((tow, at_s)) => {
                        let t = nearest_week(decoded, tow).add_seconds(-at_s);
                        tracing::info!(
                            "INS aiding: GPS time from the INS file (first sample at TOW {:.3} s), \
                             the week from the navigation message",
                            t.tow_s
                        );
                        t
                    }
                    None => {
                        tracing::info!(
                            "INS aiding: GPS time known (TOW {:.3} s at the first sample)",
                            decoded.tow_s
                        );
                        decoded
                    }
                };
                k.t0 = Some(t0);
            }
        }
    }

    /// Records `len_s` of signal lost in a gap the receiver has measured: from now on stream
    /// time `t_s` stands for the elapsed time `t_s + lost`, at which the INS and the satellites
    /// are looked up (module docs, "Time"). Without it, after a cut of `g` s the aid would use
    /// the INS and the satellites `g` s late (in a 10 g turn a 31 ms cut is 3 m/s).
    pub fn note_samples_lost(&self, len_s: f64) {
        if !(len_s.is_finite() && len_s > 0.0) {
            return;
        }
        if let Ok(mut k) = self.know.write() {
            k.lost_s += len_s;
            tracing::info!(
                "INS aiding: {:.3} s of signal lost, the INS and the satellites are looked up that much later from now on",
                len_s
            );
        }
    }

    /// The INS position and velocity (ECEF m, m/s) at stream time `t_s` (seconds from the
    /// first sample; samples lost are added, module docs "Time"), None outside the INS file
    /// or, for a file in the GPS time base, before the GPS time is known. Vector tracking
    /// with an INS propagates its filter with it (`crate::pipeline::vector`).
    pub fn motion_at(&self, t_s: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let (t0, lost_s) = {
            let k = self.know.read().ok()?;
            (k.t0, k.lost_s)
        };
        let t_s = t_s + lost_s;
        match t0 {
            Some(t0) => self.ins_at(t0, t_s),
            None if self.ins.gps_time_base_tow_s().is_none() => self.ins.at(t_s),
            None => None,
        }
    }

    /// The elapsed time since the first sample for stream time `t_s`.
    fn elapsed_s(&self, t_s: f64) -> f64 {
        t_s + self.know.read().map_or(0.0, |k| k.lost_s)
    }

    /// Uses a decoded ephemeris from now on.
    pub fn set_ephemeris(&self, eph: &Ephemeris) {
        if let Ok(mut k) = self.know.write() {
            k.ephemerides.insert(eph.prn, eph.clone());
        }
    }

    /// Records a fix: receive time (s from the first sample), ECEF position, the receiver
    /// clock drift (m/s, as the velocity solution gives it) and the fix's velocity with its
    /// largest per-axis sigma (ECEF, m/s). The drift is smoothed by a first-order filter of
    /// time constant [`DRIFT_SMOOTHING_S`]; the velocity calibrates the INS
    /// ([`InsVelocityCalibration`]; a fix whose RAIM failed should pass no velocity).
    pub fn set_fix(
        &self,
        t_s: f64,
        pos_m: Vector3<f64>,
        clock_drift_mps: Option<f64>,
        velocity: Option<(Vector3<f64>, f64)>,
    ) {
        let t_s = self.elapsed_s(t_s);
        // The INS velocity at the fix and its acceleration (over +-RATE_STEP_S).
        let ins = self.know.read().ok().and_then(|k| k.t0).and_then(|t0| {
            let (_, v) = self.ins_at(t0, t_s)?;
            let (_, v1) = self.ins_at(t0, t_s + RATE_STEP_S)?;
            let (_, v0) = self.ins_at(t0, t_s - RATE_STEP_S)?;
            Some((v, (v1 - v0).norm() / (2.0 * RATE_STEP_S)))
        });
        if let Ok(mut k) = self.know.write() {
            if let (true, Some((v_ins, accel)), Some((v_fix, sigma))) =
                (self.calibrate, ins, velocity)
            {
                let before = k.calibration.updates();
                let used = k.calibration.update(t_s, v_ins - v_fix, sigma, accel);
                if used && before == 0 {
                    tracing::info!(
                        "INS aiding: velocity calibrated from the fixes from {t_s:.2} s"
                    );
                }
            }
            k.fix = Some((t_s, pos_m));
            if let Some(d) = clock_drift_mps.filter(|d| d.is_finite()) {
                let d = d / SPEED_OF_LIGHT_MPS;
                match (k.rx_clock_drift_s_s, k.rx_clock_drift_ref) {
                    (Some(prev), Some((d_ref, t_prev))) => {
                        let g = 1.0 - (-(t_s - t_prev).max(0.0) / DRIFT_SMOOTHING_S).exp();
                        k.rx_clock_drift_s_s = Some(prev + g * (d - prev));
                        k.rx_clock_drift_ref = Some((d_ref, t_s));
                    }
                    _ => {
                        k.rx_clock_drift_s_s = Some(d);
                        k.rx_clock_drift_ref = Some((d, t_s));
                    }
                }
            }
        }
    }

    /// [`Self::set_fix`] from a solution: its position, clock drift and velocity (the velocity
    /// only when it has a covariance and it passed an integrity test that could run: a fix of
    /// 4 satellites, which RAIM cannot check, does not calibrate the INS).
    pub fn set_fix_from(&self, t_s: f64, sol: &PvtSolution) {
        let raim_ok = passes_integrity(sol) && !matches!(sol.raim, RaimStatus::Unavailable);
        let velocity = sol
            .vel_ecef_mps
            .filter(|_| raim_ok)
            .zip(sol.vel_covariance)
            .map(|(v, cov)| {
                let var = cov[(0, 0)].max(cov[(1, 1)]).max(cov[(2, 2)]);
                (v, var.max(0.0).sqrt())
            });
        self.set_fix(t_s, sol.pos_ecef_m, sol.clock_drift_mps, velocity);
    }

    /// The receiver clock drift fed forward now: its change since the first estimate, s/s.
    pub fn clock_drift_fed_forward_s_s(&self) -> f64 {
        self.know
            .read()
            .ok()
            .and_then(|k| Some(k.rx_clock_drift_s_s? - k.rx_clock_drift_ref?.0))
            .unwrap_or(0.0)
    }

    /// The Doppler the loops should measure in common on every satellite if the feed-forward
    /// were perfect, Hz: the tracked Doppler holds the whole receiver clock drift
    /// (`-f_L1 d_rx`), the feed-forward only its change since the first estimate
    /// (`-f_L1 (d_rx - d_ref)`), so `tracked - fed forward = -f_L1 d_ref`. None before the
    /// first fix with a clock drift.
    pub fn expected_common_residual_hz(&self) -> Option<f64> {
        let k = self.know.read().ok()?;
        let (d_ref, _) = k.rx_clock_drift_ref?;
        Some(-F_L1_HZ * d_ref)
    }

    /// The change of the carrier phase the loops track for `prn` over the `span_s` seconds of
    /// signal that end at receive time `t_s` (cycles, in the sense of the Doppler: its
    /// integral), from the INS: the feed-forward Doppler plus the part of the receiver clock
    /// drift it leaves to the loops ([`Self::expected_common_residual_hz`]), integrated by
    /// Simpson's rule over 8 intervals; with the signal lost so far (s) by which receive times
    /// are moved to signal times. `None` when a Doppler cannot be computed or the clock drift
    /// is not known yet.
    pub fn carrier_change_cycles(&self, prn: u8, t_s: f64, span_s: f64) -> Option<(f64, f64)> {
        const INTERVALS: usize = 8;
        if !(span_s.is_finite() && span_s > 0.0 && t_s.is_finite()) {
            return None;
        }
        let common = self.expected_common_residual_hz()?;
        let lost_s = self.know.read().ok()?.lost_s;
        let h = span_s / INTERVALS as f64;
        let mut sum = 0.0;
        for i in 0..=INTERVALS {
            let f = self.predicted_doppler_hz(prn, t_s - span_s + i as f64 * h)? + common;
            let w = match i {
                0 | INTERVALS => 1.0,
                i if i % 2 == 1 => 4.0,
                _ => 2.0,
            };
            sum += w * f;
        }
        Some((sum * h / 3.0, lost_s))
    }

    /// The unfiltered feed-forward Doppler (Hz) of `prn` at receive time `t_s`, without
    /// logging and without the band limiter: what the integrity monitor compares with the
    /// Doppler of a channel that runs unaided ([`crate::pipeline::aiding::AidMonitor`]). None when
    /// the aid cannot be computed (no GPS time, no ephemeris, outside the INS file).
    pub fn predicted_doppler_hz(&self, prn: u8, t_s: f64) -> Option<f64> {
        let (t0, know) = {
            let k = self.know.read().ok()?;
            (k.t0?, k.clone_light())
        };
        let t_s = t_s + know.lost_s;
        let eph = self.ephemeris(prn, t0.add_seconds(t_s))?;
        self.doppler_hz(&eph, &know, t0, t_s)
    }

    /// Logs `msg` the first time `(prn, what)` happens: why a satellite has no feed-forward at
    /// info level, the start of a feed-forward at debug level (`-v`).
    fn log_once(&self, prn: u8, what: &'static str, msg: impl FnOnce() -> String) {
        if let Ok(mut l) = self.logged.lock() {
            if l.insert((prn, what)) {
                if what == "on" {
                    tracing::debug!("{}", msg());
                } else {
                    tracing::info!("{}", msg());
                }
            }
        }
    }

    /// The ephemeris for `prn` at `t`: among the decoded one (whatever its health flag) and
    /// those from `--nav` (healthy ones, or all with [`Self::allow_unhealthy`]), the valid one
    /// with the toe nearest to `t` ([`select_ephemeris`]; the decoded one wins a tie).
    fn ephemeris(&self, prn: u8, t: GpsTime) -> Option<Ephemeris> {
        let k = self.know.read().ok()?;
        let nav = self
            .nav
            .get(&prn)
            .into_iter()
            .flatten()
            .filter(|e| self.allow_unhealthy || e.sv_health == 0);
        let candidates = k.ephemerides.get(&prn).into_iter().chain(nav);
        select_ephemeris(candidates, prn, t, HealthPolicy::Ignore).cloned()
    }

    /// The INS state at receive time `t_s` (seconds from the first IF sample), through the GPS
    /// time when the INS file is in the GPS time base.
    fn ins_at(&self, t0: GpsTime, t_s: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let t_ins = match self.ins.gps_time_base_tow_s() {
            Some(_) => self.ins.t_s_from_tow(t0.add_seconds(t_s).tow_s)?,
            None => t_s,
        };
        self.ins.at(t_ins)
    }

    /// The unfiltered feed-forward Doppler (Hz) of `prn` at receive time `t_s`.
    fn doppler_hz(&self, eph: &Ephemeris, k: &Knowledge, t0: GpsTime, t_s: f64) -> Option<f64> {
        let (ins_pos, ins_vel) = self.ins_at(t0, t_s)?;
        let rx_pos = match k.fix {
            Some((t_fix, p_fix)) => {
                let (p_then, _) = self.ins_at(t0, t_fix).unwrap_or((ins_pos, ins_vel));
                p_fix + (ins_pos - p_then)
            }
            None => ins_pos,
        };
        let seen = eph.at_reception(t0.add_seconds(t_s), &rx_pos, 0.075, 2);
        let sv = PosVel {
            pos_m: seen.sv.pos_m,
            vel_mps: seen.sv.vel_mps,
        };
        let rx = PosVel {
            pos_m: rx_pos,
            vel_mps: ins_vel - k.calibration.correction_mps(t_s),
        };
        let rx_drift = match (k.rx_clock_drift_s_s, k.rx_clock_drift_ref) {
            (Some(d), Some((d_ref, _))) => d - d_ref,
            _ => 0.0,
        };
        let f = los_doppler_hz(&sv, &rx, seen.sv.clock_drift_s_s, rx_drift)?;
        f.is_finite().then_some(f)
    }

    /// The aid for `prn` at receive time `t_s` (seconds from the first sample), or None when it
    /// cannot be computed yet (no GPS time, no ephemeris, outside the INS file).
    pub fn aid(&self, prn: u8, t_s: f64) -> Option<DopplerAid> {
        let (t0, know) = {
            let k = self.know.read().ok()?;
            (k.t0, k.clone_light())
        };
        let t_s = t_s + know.lost_s;
        let Some(t0) = t0 else {
            self.log_once(0, "time", || {
                "INS aiding waits for the GPS time (the first decoded time of week, or a gps_tow_s column in the INS file)".to_string()
            });
            return None;
        };
        let Some(eph) = self.ephemeris(prn, t0.add_seconds(t_s)) else {
            self.log_once(prn, "eph", || {
                format!("G{prn:02}: no ephemeris yet (none decoded, none in the navigation data given), no INS feed-forward")
            });
            return None;
        };
        let Some(f) = self.doppler_hz(&eph, &know, t0, t_s) else {
            let (a, b) = self.ins.span_s();
            self.log_once(prn, "span", || {
                format!("G{prn:02}: {t_s:.2} s is outside the INS file ({a:.2} to {b:.2} s), no feed-forward")
            });
            return None;
        };
        self.log_once(prn, "on", || {
            format!("G{prn:02}: INS feed-forward on at {t_s:.2} s ({f:.1} Hz)")
        });
        let aid = match self.band_limit_alpha_rad_s {
            None => {
                let f2 = self
                    .doppler_hz(&eph, &know, t0, t_s + RATE_STEP_S)
                    .unwrap_or(f);
                DopplerAid {
                    doppler_hz: f,
                    doppler_rate_hz_s: (f2 - f) / RATE_STEP_S,
                    coast: false,
                    checked: false,
                    source: gpsrx_tracking::AidSource::Ins,
                }
            }
            Some(alpha) => {
                let mut l = self.limiters.lock().ok()?;
                let (lim, t_last) = l.entry(prn).or_insert((BandLimiter::new(alpha), t_s));
                let dt = t_s - *t_last;
                if !(0.0..=LIMITER_RESTART_S).contains(&dt) {
                    lim.reset(None);
                }
                let y = lim.step(f, dt.max(0.0));
                *t_last = t_s;
                DopplerAid {
                    doppler_hz: y,
                    doppler_rate_hz_s: alpha * (f - y),
                    coast: false,
                    checked: false,
                    source: gpsrx_tracking::AidSource::Ins,
                }
            }
        };
        Some(aid)
    }
}

impl Knowledge {
    /// The parts the Doppler computation needs (not the ephemeris map).
    fn clone_light(&self) -> Knowledge {
        Knowledge {
            t0: self.t0,
            ephemerides: BTreeMap::new(),
            fix: self.fix,
            rx_clock_drift_s_s: self.rx_clock_drift_s_s,
            rx_clock_drift_ref: self.rx_clock_drift_ref,
            calibration: self.calibration,
            lost_s: self.lost_s,
        }
    }
}

impl gpsrx_tracking::AidingPort for InsFeedForward {
    fn doppler_aid(&self, prn: gpsrx_dsp::Prn, t_s: f64) -> Option<DopplerAid> {
        self.aid(prn.get(), t_s)
    }
}

/// The GPS time at time of week `tow_s` in the week that puts it nearest to `near`.
fn nearest_week(near: GpsTime, tow_s: f64) -> GpsTime {
    let same = GpsTime::new(near.week, tow_s);
    let half_week_s = 302_400.0;
    match same.diff_s(near) {
        d if d > half_week_s && near.week > 0 => GpsTime::new(near.week - 1, tow_s),
        d if d < -half_week_s => GpsTime::new(near.week + 1, tow_s),
        _ => same,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_time_of_week_takes_the_week_nearest_to_the_decoded_time() {
        let near = GpsTime::new(2191, 5.0);
        assert_eq!(
            nearest_week(near, 604_795.0).week,
            2190,
            "just before the rollover"
        );
        assert_eq!(nearest_week(near, 20.0).week, 2191);
        let late = GpsTime::new(2190, 604_790.0);
        assert_eq!(
            nearest_week(late, 3.0).week,
            2191,
            "just after the rollover"
        );
        assert_eq!(nearest_week(late, 604_789.0).week, 2190);
    }
}
