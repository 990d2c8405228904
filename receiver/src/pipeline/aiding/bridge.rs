//! The outage bridge: without an INS, the receiver's own motion, fitted from its last fixes,
//! fed forward into every channel while the signal is gone and while the loops take it back.
//!
//! When the prompt power of every tracked satellite collapses at once (a blockage, zeros, lost
//! samples: `crate::pipeline::timing::code_jump`), an unaided channel coasts on its loop's
//! memory: its Doppler and, in a 3rd-order loop, its Doppler rate. That holds a constant
//! acceleration, not a turn: in a 10 g turn at 250 m/s the acceleration turns at 0.39 rad/s,
//! and after 1 s the frequency the loop coasts on is up to 100 Hz from the signal's (the
//! jerk `a w` over `t^2 / 2`), far outside any pull-in; the channels are lost and searched
//! again, and the searches then pull in under 500 Hz/s.
//!
//! The bridge is the INS's stand-in: at the collapse the receiver's motion is fitted from its
//! valid fixes of the last [`FIT_WINDOW_S`] ([`TurnMotion::fit`]: velocity and acceleration at
//! the window's mean time) and carried on as a turn at constant rate and constant speed change
//! (the coordinated-turn model of target tracking: the acceleration across the velocity turns
//! the velocity at `w = v x a_n / |v|^2`, the part along it changes the speed); each channel's
//! carrier NCO is fed the Doppler this motion predicts for its satellite (from the ephemeris,
//! [`crate::pipeline::channels::visibility::predict`]) through the aiding port, exactly as an
//! INS's, until the first valid fix after the signal's return, or [`MAX_BRIDGE_S`].
//!
//! The aid's level does not matter: a channel keeps its NCO frequency when an aid comes or
//! goes (`gpsrx_tracking::Channel::set_aid`), so only the predicted *change* of each Doppler
//! reaches the NCO, and the receiver clock drift (constant over seconds) drops out.
//!
//! It is armed only when the fixes show an acceleration of at least [`ARM_ACCEL_MPS2`] (a
//! receiver without one coasts as well on its loops' memories, and its results stay those of
//! the loops alone) that is steady ([`MAX_ACCEL_CHANGE`]: not the onset or the end of a
//! manoeuvre, which the model cannot foresee).

use crate::pipeline::channels::visibility::predict;
use gpsrx_core::{Polynomial, PosVel};
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::DopplerAid;
use nalgebra::Vector3;
use std::collections::BTreeMap;

/// The fixes of this many seconds before the collapse give the motion, s.
pub const FIT_WINDOW_S: f64 = 0.5;
/// Fewest fixes with a velocity in the window.
pub const MIN_FIT_FIXES: usize = 3;
/// Fewest fixes for a quadratic through the velocities (else a line), [`TurnMotion::fit`].
pub const QUADRATIC_FIT_FIXES: usize = 5;
/// The last fix must be at most this long before the collapse, s.
pub const MAX_FIX_AGE_S: f64 = 0.5;
/// Acceleration from which the bridge is armed, m/s^2 (a Doppler rate of 8 Hz/s: where the
/// receiver counts as under dynamics, `crate::pipeline::channels::dynamics`).
pub const ARM_ACCEL_MPS2: f64 = 1.5;
/// Largest change of the acceleration's magnitude from the fit window's middle to its end, as
/// a fraction of it, for which the bridge is armed: the turn model holds a steady manoeuvre;
/// at the onset or the end of one (the simulator's 1 s ramp to 10 g changes it by 30 % over
/// the last 0.25 s) the loops' own memories are fresher than fixes 0.1-0.2 s old (measured:
/// 1 s of zeros at the end of a 10 g onset, bridged: worst fix 14.8 m; coasting: 9.0 m).
pub const MAX_ACCEL_CHANGE: f64 = 0.2;
/// Longest bridge from the collapse, s: a turn does not last for ever, and after the
/// signal's return the loops hold the residual of a wrong prediction no worse than the
/// dynamics themselves.
pub const MAX_BRIDGE_S: f64 = 3.0;
/// Below this speed the turn rate is not defined: constant acceleration, m/s.
pub const MIN_TURN_SPEED_MPS: f64 = 5.0;
/// Step of the Doppler rate, s.
const RATE_STEP_S: f64 = 0.01;

/// A receiver's motion fitted from its fixes and carried on as a turn at a constant rate
/// with a constant change of speed (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurnMotion {
    /// GPS time of the fit's reference epoch (the fixes' mean time).
    pub time: GpsTime,
    /// Stream time of the reference epoch, s.
    pub t_stream_s: f64,
    /// ECEF position, velocity and acceleration at the reference epoch.
    pub pos_m: Vector3<f64>,
    /// ECEF velocity, m/s.
    pub vel_mps: Vector3<f64>,
    /// ECEF acceleration, m/s^2.
    pub accel_mps2: Vector3<f64>,
    /// Receiver clock drift, s/s.
    pub drift_s_s: f64,
    /// The change of the acceleration's magnitude over the fit window's second half, as a
    /// fraction of its magnitude at the end (0 with too few fixes to tell): how steady the
    /// manoeuvre was ([`MAX_ACCEL_CHANGE`]).
    pub accel_change: f64,
}

/// One valid fix as the fit takes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixPoint {
    /// Stream time, s.
    pub t_stream_s: f64,
    /// GPS time of reception.
    pub time: GpsTime,
    /// ECEF position, m.
    pub pos_m: Vector3<f64>,
    /// ECEF velocity, m/s.
    pub vel_mps: Vector3<f64>,
    /// Receiver clock drift, s/s.
    pub drift_s_s: f64,
}

impl TurnMotion {
    /// The least-squares line through the velocities of `fixes` (in time order): velocity
    /// `v_c` (the mean's direction with the mean speed: the mean velocity on a turn's arc is a
    /// chord) and acceleration `a = sum (t - t_c)(v - v_mean) / sum (t - t_c)^2` at their mean
    /// time `t_c`, the mean position; and how steady the manoeuvre was: per axis the
    /// least-squares quadratic through the velocities (`gpsrx_core::Polynomial`, with at least
    /// [`QUADRATIC_FIT_FIXES`]), whose slopes at the window's middle and end give the change of
    /// the acceleration's magnitude over its second half. (The line at the mean time, not the
    /// quadratic at the end, carries the turn: on a steady 10 g turn it is 0.16 m/s off after
    /// 1 s, the quadratic's slope at the end 0.35 m/s, and 1 s of zeros in the turn left a fix
    /// 5.2 m off with it.) None with fewer than [`MIN_FIT_FIXES`] or spanning less than 0.1 s.
    pub fn fit(fixes: &[FixPoint]) -> Option<Self> {
        let n = fixes.len();
        let (first, last) = (fixes.first()?, fixes.last()?);
        if n < MIN_FIT_FIXES || last.t_stream_s - first.t_stream_s < 0.1 {
            return None;
        }
        let nf = n as f64;
        let t_c = fixes.iter().map(|f| f.t_stream_s).sum::<f64>() / nf;
        let v_mean = fixes.iter().map(|f| f.vel_mps).sum::<Vector3<f64>>() / nf;
        let speed = fixes.iter().map(|f| f.vel_mps.norm()).sum::<f64>() / nf;
        let v_c = v_mean.try_normalize(1e-9).map_or(v_mean, |d| d * speed);
        let p_c = fixes.iter().map(|f| f.pos_m).sum::<Vector3<f64>>() / nf;
        let stt: f64 = fixes.iter().map(|f| (f.t_stream_s - t_c).powi(2)).sum();
        let stv: Vector3<f64> = fixes
            .iter()
            .map(|f| (f.vel_mps - v_mean) * (f.t_stream_s - t_c))
            .sum();
        let m = Self {
            time: last.time.add_seconds(t_c - last.t_stream_s),
            t_stream_s: t_c,
            pos_m: p_c,
            vel_mps: v_c,
            accel_mps2: stv / stt,
            drift_s_s: last.drift_s_s,
            accel_change: accel_change(fixes)?,
        };
        (m.vel_mps
            .iter()
            .chain(m.accel_mps2.iter())
            .all(|x| x.is_finite()))
        .then_some(m)
    }

    /// Position and velocity `dt_s` after the reference epoch. Velocity: the speed
    /// `s = |v_c| + a_t dt` (`a_t = a . v_c / |v_c|`) along the direction of `v_c` turned by
    /// `|w| dt` about `w = v_c x a_n / |v_c|^2` (`a_n = a - a_t v_c / |v_c|`; Rodrigues'
    /// rotation); below [`MIN_TURN_SPEED_MPS`], `v_c + a dt`. Position: `p_c + v_c dt +
    /// a dt^2 / 2` (the turn's own curvature of the path, `|a| |w| dt^3 / 6`, is 6 m after
    /// 1 s of a 10 g turn at 250 m/s: nothing for a line of sight to a satellite).
    pub fn at(&self, dt_s: f64) -> PosVel {
        let (v, a) = (self.vel_mps, self.accel_mps2);
        let pos_m = self.pos_m + v * dt_s + a * (0.5 * dt_s * dt_s);
        let speed = v.norm();
        let straight = v + a * dt_s;
        let vel_mps = if speed < MIN_TURN_SPEED_MPS {
            straight
        } else {
            let dir = v / speed;
            let a_t = a.dot(&dir);
            let a_n = a - dir * a_t;
            let w = dir.cross(&a_n) / speed;
            let rate = w.norm();
            let s = (speed + a_t * dt_s).max(0.0);
            if rate < 1e-9 {
                dir * s
            } else {
                let k = w / rate;
                let th = rate * dt_s;
                let turned =
                    dir * th.cos() + k.cross(&dir) * th.sin() + k * k.dot(&dir) * (1.0 - th.cos());
                turned * s
            }
        };
        PosVel { pos_m, vel_mps }
    }
}

/// The bridge over one outage: the motion, the ephemerides, and when it aids (module docs).
#[derive(Debug, Clone)]
pub struct OutageBridge {
    motion: TurnMotion,
    ephemerides: BTreeMap<u8, Ephemeris>,
    /// Stream time of the collapse, s.
    from_s: f64,
    /// Stream time after which it no longer aids, s.
    until_s: f64,
    /// Signal lost in gaps measured since the fit, s: stream time plus this is elapsed time.
    lost_s: f64,
}

impl OutageBridge {
    /// A bridge from the collapse at stream time `collapse_s`, with the valid fixes before it
    /// (`fixes`, in time order: the last [`FIT_WINDOW_S`] of them are fitted) and the
    /// ephemerides of the satellites. None (the loops coast alone) when the fixes are too few
    /// or too old, or show less than [`ARM_ACCEL_MPS2`].
    pub fn arm(
        collapse_s: f64,
        fixes: &[FixPoint],
        ephemerides: BTreeMap<u8, Ephemeris>,
    ) -> Option<Self> {
        let last = fixes.iter().rev().find(|f| f.t_stream_s <= collapse_s)?;
        if collapse_s - last.t_stream_s > MAX_FIX_AGE_S {
            return None;
        }
        let window: Vec<FixPoint> = fixes
            .iter()
            .filter(|f| {
                f.t_stream_s <= last.t_stream_s && last.t_stream_s - f.t_stream_s <= FIT_WINDOW_S
            })
            .copied()
            .collect();
        let motion = TurnMotion::fit(&window)?;
        let accel = motion.accel_mps2.norm();
        if accel < ARM_ACCEL_MPS2 || ephemerides.is_empty() {
            return None;
        }
        if motion.accel_change.abs() > MAX_ACCEL_CHANGE {
            tracing::info!(
                "{collapse_s:.3} s: every signal gone while the acceleration ({accel:.1} m/s^2) changes by {:.0} % over {:.2} s: no steady manoeuvre to carry on, the channels coast on their loops",
                100.0 * motion.accel_change,
                0.5 * FIT_WINDOW_S
            );
            return None;
        }
        tracing::info!(
            "{collapse_s:.3} s: every signal gone under {accel:.1} m/s^2 ({:.0} m/s): the channels are aided by the motion of the last fixes (a turn at {:.2} rad/s) until a fix after the return, at most {MAX_BRIDGE_S} s",
            motion.vel_mps.norm(),
            turn_rate_rad_s(&motion),
        );
        Some(Self {
            motion,
            ephemerides,
            from_s: collapse_s,
            until_s: collapse_s + MAX_BRIDGE_S,
            lost_s: 0.0,
        })
    }

    /// Stream time of the collapse, s.
    pub fn from_s(&self) -> f64 {
        self.from_s
    }

    /// Ends the bridge at stream time `t_s` (a valid fix after the return).
    pub fn end_at(&mut self, t_s: f64) {
        self.until_s = self.until_s.min(t_s);
    }

    /// Whether it aids at no stream time after `t_s`.
    pub fn over_at(&self, t_s: f64) -> bool {
        t_s >= self.until_s
    }

    /// Records the signal lost in the gaps measured since the bridge was armed, s (stream time
    /// then lags the motion by it).
    pub fn set_lost_s(&mut self, lost_s: f64) {
        if lost_s.is_finite() && lost_s >= 0.0 {
            self.lost_s = lost_s;
        }
    }

    /// The predicted Doppler of `prn` at stream time `t_s`, Hz.
    fn doppler_hz(&self, prn: u8, t_s: f64) -> Option<f64> {
        let eph = self.ephemerides.get(&prn)?;
        let dt = t_s + self.lost_s - self.motion.t_stream_s;
        let rx = self.motion.at(dt);
        let t = self.motion.time.add_seconds(dt);
        predict(eph, &rx, t, self.motion.drift_s_s).map(|p| p.doppler_hz)
    }
}

impl gpsrx_tracking::AidingPort for OutageBridge {
    fn doppler_aid(&self, prn: gpsrx_dsp::Prn, t_s: f64) -> Option<DopplerAid> {
        if !(self.from_s..self.until_s).contains(&t_s) {
            return None;
        }
        let f = self.doppler_hz(prn.get(), t_s)?;
        let f2 = self.doppler_hz(prn.get(), t_s + RATE_STEP_S).unwrap_or(f);
        Some(DopplerAid {
            doppler_hz: f,
            doppler_rate_hz_s: (f2 - f) / RATE_STEP_S,
            coast: false,
            checked: false,
            source: gpsrx_tracking::AidSource::Bridge,
        })
    }
}

/// `(|a(t_end)| - |a(t_mid)|) / |a(t_end)|` from per-axis quadratics through the velocities
/// of `fixes` ([`TurnMotion::accel_change`]); 0 with fewer than [`QUADRATIC_FIT_FIXES`]. None
/// when a fit fails.
fn accel_change(fixes: &[FixPoint]) -> Option<f64> {
    let (first, last) = (fixes.first()?, fixes.last()?);
    if fixes.len() < QUADRATIC_FIT_FIXES {
        return Some(0.0);
    }
    let t_mid = 0.5 * (first.t_stream_s + last.t_stream_s);
    let (mut end, mut mid) = (Vector3::zeros(), Vector3::<f64>::zeros());
    for axis in 0..3 {
        let pts: Vec<(f64, f64)> = fixes
            .iter()
            .map(|f| (f.t_stream_s, f.vel_mps[axis]))
            .collect();
        let p = Polynomial::fit(&pts, 2)?;
        end[axis] = p.slope_at(last.t_stream_s);
        mid[axis] = p.slope_at(t_mid);
    }
    let e = end.norm();
    Some(if e > 0.0 { (e - mid.norm()) / e } else { 0.0 })
}

/// The turn rate of the fitted motion, rad/s (0 below [`MIN_TURN_SPEED_MPS`]).
fn turn_rate_rad_s(m: &TurnMotion) -> f64 {
    let speed = m.vel_mps.norm();
    if speed < MIN_TURN_SPEED_MPS {
        return 0.0;
    }
    let dir = m.vel_mps / speed;
    (m.accel_mps2 - dir * m.accel_mps2.dot(&dir)).norm() / speed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level circular turn: speed `s`, normal acceleration `g_n`, in the local east-north
    /// plane of a point on the Earth (ECEF axes rotated so the circle is exact): position and
    /// velocity at time `t` from the turn's start.
    fn circle(t: f64, s: f64, g_n: f64) -> (Vector3<f64>, Vector3<f64>) {
        let w = g_n / s;
        let r = s / w;
        let (e, n) = (Vector3::new(0.0, 1.0, 0.0), Vector3::new(-0.6, 0.0, 0.8));
        let base = Vector3::new(3.0e6, 0.0, 4.0e6) * (6.371e6 / 5.0e6);
        let pos = base + e * (r * (w * t).sin()) + n * (r * (1.0 - (w * t).cos()));
        let vel = e * (s * (w * t).cos()) + n * (s * (w * t).sin());
        (pos, vel)
    }

    fn fixes_of(times: &[f64], s: f64, g_n: f64) -> Vec<FixPoint> {
        let t0 = GpsTime::new(2190, 538_000.0);
        times
            .iter()
            .map(|&t| {
                let (p, v) = circle(t, s, g_n);
                FixPoint {
                    t_stream_s: 40.0 + t,
                    time: t0.add_seconds(t),
                    pos_m: p,
                    vel_mps: v,
                    drift_s_s: 0.0,
                }
            })
            .collect()
    }

    /// The 10 g turn at 250 m/s fitted from 0.5 s of fixes at 10 Hz and carried 1 s past the
    /// last: the velocity within 0.3 m/s of the circle's (0.16 m/s, 0.8 Hz), where
    /// constant acceleration from the same fit is 25 m/s off and the velocity held 98 m/s.
    #[test]
    fn a_turn_is_carried_round_its_circle() {
        let g = 9.80665;
        let times: Vec<f64> = (0..=5).map(|i| 1.0 + 0.1 * i as f64).collect();
        let m = TurnMotion::fit(&fixes_of(&times, 250.0, 10.0 * g)).expect("fit");
        assert!((m.t_stream_s - 41.25).abs() < 1e-9);
        let t_end = 2.5; // 1 s after the last fix
        let (_, v_true) = circle(t_end, 250.0, 10.0 * g);
        let dt = 40.0 + t_end - m.t_stream_s;
        let v = m.at(dt).vel_mps;
        assert!(
            (v - v_true).norm() < 0.3,
            "turn model {:.3} m/s off",
            (v - v_true).norm()
        );
        let straight = m.vel_mps + m.accel_mps2 * dt;
        assert!(
            (straight - v_true).norm() > 20.0,
            "constant acceleration {:.1}",
            (straight - v_true).norm()
        );
        assert!((turn_rate_rad_s(&m) - 10.0 * g / 250.0).abs() < 1e-3);
        assert!(
            m.accel_change.abs() < 0.01,
            "a steady turn: {}",
            m.accel_change
        );
    }

    /// The onset of a turn: the normal acceleration ramps from 0 to 10 g over 1 s (the
    /// simulator's jerk-limited transition), the fixes of its last 0.5 s fitted. The turn
    /// carried on from the window's middle (three quarters of the final rate) would be 25 m/s
    /// off after a second of the full turn; the fit sees the acceleration grow by a quarter
    /// over the window's second half, and the bridge is not armed.
    #[test]
    fn a_turn_fitted_in_its_onset_is_not_bridged() {
        let (s, w_max) = (250.0, 10.0 * 9.80665 / 250.0);
        // Heading: w(t) = w_max t for t in [0, 1], then w_max.
        let heading = |t: f64| {
            if t <= 1.0 {
                0.5 * w_max * t * t
            } else {
                0.5 * w_max + w_max * (t - 1.0)
            }
        };
        let (e, n) = (Vector3::new(0.0, 1.0, 0.0), Vector3::new(-0.6, 0.0, 0.8));
        let vel = |t: f64| (e * heading(t).cos() + n * heading(t).sin()) * s;
        let t0 = GpsTime::new(2190, 538_000.0);
        let fixes: Vec<FixPoint> = (0..=5)
            .map(|i| {
                let t = 0.5 + 0.1 * i as f64;
                FixPoint {
                    t_stream_s: t,
                    time: t0.add_seconds(t),
                    pos_m: Vector3::new(3.822e6, 0.0, 5.096e6),
                    vel_mps: vel(t),
                    drift_s_s: 0.0,
                }
            })
            .collect();
        let m = TurnMotion::fit(&fixes).expect("fit");
        let off = (m.at(2.0 - m.t_stream_s).vel_mps - vel(2.0)).norm();
        assert!(off > 20.0, "{off:.2} m/s off after 1 s");
        assert!((m.accel_change - 0.25).abs() < 0.05, "{}", m.accel_change);
        let nav = gpsrx_nav::rinex_nav::parse_rinex_nav(include_str!(
            "../../../../samples/data/brdc0010.22n"
        ))
        .expect("nav");
        let ephs: BTreeMap<u8, Ephemeris> =
            nav.ephemerides.iter().map(|e| (e.prn, e.clone())).collect();
        assert!(OutageBridge::arm(1.05, &fixes, ephs).is_none());
    }

    /// Speeding up along a straight line: the speed grows by `a_t dt`, the direction holds.
    #[test]
    fn a_straight_acceleration_changes_the_speed_only() {
        let t0 = GpsTime::new(2190, 1000.0);
        let dir = Vector3::new(0.6, 0.0, 0.8);
        let fixes: Vec<FixPoint> = (0..5)
            .map(|i| {
                let t = 0.1 * i as f64;
                FixPoint {
                    t_stream_s: t,
                    time: t0.add_seconds(t),
                    pos_m: Vector3::new(6.4e6, 0.0, 0.0) + dir * (100.0 * t + 20.0 * t * t),
                    vel_mps: dir * (100.0 + 40.0 * t),
                    drift_s_s: 0.0,
                }
            })
            .collect();
        let m = TurnMotion::fit(&fixes).expect("fit");
        let v = m.at(1.0).vel_mps;
        let want = dir * (100.0 + 40.0 * 1.2);
        assert!((v - want).norm() < 1e-6, "{v} vs {want}");
    }

    /// It aids only from the collapse to its end, and only when the fixes accelerate; too
    /// few or too old fixes arm nothing.
    #[test]
    fn it_aids_between_the_collapse_and_its_end_only_under_dynamics() {
        let g = 9.80665;
        let times: Vec<f64> = (0..=5).map(|i| 1.0 + 0.1 * i as f64).collect();
        let fixes = fixes_of(&times, 250.0, 10.0 * g);
        let nav = gpsrx_nav::rinex_nav::parse_rinex_nav(include_str!(
            "../../../../samples/data/brdc0010.22n"
        ))
        .expect("nav");
        let ephs: BTreeMap<u8, Ephemeris> =
            nav.ephemerides.iter().map(|e| (e.prn, e.clone())).collect();
        let prn = gpsrx_dsp::Prn::new(*ephs.keys().next().expect("a prn")).expect("prn");
        use gpsrx_tracking::AidingPort;
        let mut b = OutageBridge::arm(41.55, &fixes, ephs.clone()).expect("armed");
        assert!(b.doppler_aid(prn, 41.5).is_none(), "before the collapse");
        assert!(b.doppler_aid(prn, 42.0).is_some());
        b.end_at(42.2);
        assert!(b.doppler_aid(prn, 42.3).is_none(), "after its end");
        assert!(b.over_at(42.2));
        assert!(
            OutageBridge::arm(41.55, &fixes[..2], ephs.clone()).is_none(),
            "two fixes"
        );
        assert!(
            OutageBridge::arm(42.5, &fixes, ephs.clone()).is_none(),
            "a fix 1 s old"
        );
        let straight = fixes_of(&times, 250.0, 0.01);
        assert!(
            OutageBridge::arm(41.55, &straight, ephs).is_none(),
            "no acceleration"
        );
    }
}
