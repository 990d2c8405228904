//! Carrier smoothing of the pseudoranges (Hatch filter), carried over outages and gaps.
//!
//! `P_s(k) = P(k) / M + (M - 1) / M (P_s(k-1) + lambda (L(k) - L(k-1)))`, with `M` growing to
//! the filter length: the code's noise (metres at 2.6 MHz) is averaged down while the carrier
//! carries the range change. A loss of lock breaks the carrier, and a new filter would start
//! from the raw code again: the first fixes after an outage or a sample gap would carry the
//! raw noise, several times the smoothed error.
//!
//! When the satellite's pseudorange is continuous over the break (its SV time was carried
//! over the outage, or over lost samples whose length is known), the filter bridges it instead
//! of restarting: the range change over the break comes from the carrier phase *before* it,
//! a quadratic in time fitted to the last [`HISTORY`] epochs (phase, Doppler and Doppler rate,
//! extrapolated over at most [`MAX_BRIDGE_S`], and only when the quadratic follows the phase
//! to [`MAX_FIT_RMS_CYCLES`]: not under a manoeuvre's jerk), so that
//!
//! `lambda dL = lambda (L_fit(t_prev + T) - L_fit(t_prev)) - c g + c dsteps`,
//!
//! with `T` the signal time elapsed (stream time plus the lost time `g`), `-c g` the receiver
//! clock falling behind by the lost samples and `c dsteps` the receiver clock steps since.
//! A bridge whose prediction misses the new code by more than [`MAX_INNOVATION_M`] (a carried
//! time that was wrong) restarts the filter.
//!
//! # Under a manoeuvre, and after a re-lock (issue 26)
//!
//! No quadratic follows 3 s of phase through a 10 g turn (the turning acceleration changes
//! at 40 m/s^3), but the break to be bridged is often short: the lost samples and the 0.2-0.4
//! s until the loops hold the signal again. From then on the channel's own carrier phase is
//! continuous (an [`CarrierAnchor`], its first locked report after the gap settled), so only
//! the stretch from the last epoch to the anchor is extrapolated:
//!
//! `lambda dL = lambda (L_fit(t_a + g - t_prev) - L_fit(0)) + lambda (L(now) - L(t_a)) - c g + c dsteps`.
//!
//! When the whole history does not fit a quadratic, a cubic (the jerk) through its last
//! [`SHORT_WINDOWS_S`] is tried, and taken only when its extrapolation error, predicted from
//! its own residuals as if they were all a snap's (`snap_error_per_rms`: a 10 g turn at 250
//! m/s has a snap of up to 15 m/s^4, 3 cm over 0.4 s), is within [`MAX_EXTRAPOLATION_ERROR_M`].

use crate::pipeline::timing::carrier_step::Quadratic;
use gpsrx_core::Polynomial;
use gpsrx_dsp::constants::{F_L1_HZ, SPEED_OF_LIGHT_MPS};
use std::collections::VecDeque;

/// Epochs of carrier phase kept for a bridge.
pub const HISTORY: usize = 30;
/// Longest break bridged, s: the quadratic's extrapolation error grows with the cube of it
/// (a Doppler acceleration of 0.01 Hz/s^2 gives 0.05 m over 3 s).
pub const MAX_BRIDGE_S: f64 = 3.0;
/// Largest difference between the bridged prediction and the new code accepted, m.
pub const MAX_INNOVATION_M: f64 = 30.0;
/// Largest RMS of the carrier phase about its quadratic fit that is bridged, cycles (a steady
/// signal leaves millimetres; a 10 g manoeuvre's jerk leaves metres over the fit's 3 s).
pub const MAX_FIT_RMS_CYCLES: f64 = 0.1;
/// Shorter windows of the carrier history (the latest epochs, s) tried, with a cubic, when the
/// whole history does not fit a quadratic.
pub const SHORT_WINDOWS_S: [f64; 2] = [2.0, 1.0];
/// Largest predicted extrapolation error of a short window's cubic, m (a restarted filter
/// starts from the raw code: metres of noise under a manoeuvre's geometry).
pub const MAX_EXTRAPOLATION_ERROR_M: f64 = 0.5;

/// A range change over a break known from outside the carrier's history (m, carrier sign,
/// without the clock terms), and the longest break it is good for, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GivenChange {
    /// The range change, m.
    pub change_m: f64,
    /// The longest break over which it is taken, s.
    pub max_s: f64,
}

/// The first locked report of a satellite's channel after a break: its stream time (s) and
/// carrier phase (cycles, RINEX sign, without the clock steps). The channel's carrier phase
/// is continuous from it to the current epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarrierAnchor {
    /// Stream time, s.
    pub t_stream_s: f64,
    /// Carrier phase, cycles.
    pub signal_cycles: f64,
}

/// One epoch's measurements of a satellite for its Hatch filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HatchEpoch {
    /// Epoch index.
    pub epoch: i64,
    /// Carrier phase, cycles (RINEX sign, with the clock steps).
    pub carrier_cycles: f64,
    /// Raw pseudorange, m.
    pub pseudorange_m: f64,
    /// Receiver clock steps so far, ms.
    pub steps_ms: i64,
    /// Stream time of the epoch, s.
    pub t_stream_s: f64,
}

/// One satellite's Hatch filter.
#[derive(Debug, Clone)]
pub struct Hatch {
    /// Epoch index of the last update.
    pub epoch: i64,
    /// Carrier phase at it, cycles (RINEX sign, with the clock steps).
    pub carrier_cycles: f64,
    /// Smoothed pseudorange, m.
    pub smoothed_m: f64,
    /// Epochs averaged.
    pub m: u32,
    /// Receiver clock steps so far at it, ms.
    pub steps_ms: i64,
    /// Stream time of the epoch (receiver time less the origin), s.
    pub t_stream_s: f64,
    /// `(stream time s, carrier phase cycles without the clock steps)` of the last epochs in
    /// lock.
    history: VecDeque<(f64, f64)>,
    /// The filter after each of its last [`SNAPSHOTS`] epochs (to go back to before lost
    /// samples found a few epochs late).
    snapshots: VecDeque<Snapshot>,
}

/// What [`Hatch::rewind`] restores.
#[derive(Debug, Clone, Copy)]
struct Snapshot {
    epoch: i64,
    carrier_cycles: f64,
    smoothed_m: f64,
    m: u32,
    steps_ms: i64,
    t_stream_s: f64,
}

/// Epochs of the filter kept to rewind it.
const SNAPSHOTS: usize = 16;

impl Hatch {
    /// A filter started at epoch `e` from the raw pseudorange.
    pub fn start(e: &HatchEpoch) -> Self {
        let mut h = Self {
            epoch: e.epoch,
            carrier_cycles: e.carrier_cycles,
            smoothed_m: e.pseudorange_m,
            m: 1,
            steps_ms: e.steps_ms,
            t_stream_s: e.t_stream_s,
            history: VecDeque::new(),
            snapshots: VecDeque::new(),
        };
        h.remember();
        h
    }

    /// The filter as it was before stream time `t_s` (samples were lost then and found a few
    /// epochs later: the epochs since were measured on a shifted time scale); false when it
    /// has no epoch before (the caller drops it).
    pub fn rewind(&mut self, t_s: f64) -> bool {
        while self.snapshots.back().is_some_and(|s| s.t_stream_s >= t_s) {
            self.snapshots.pop_back();
        }
        while self.history.back().is_some_and(|h| h.0 >= t_s) {
            self.history.pop_back();
        }
        let Some(s) = self.snapshots.back().copied() else {
            return false;
        };
        self.epoch = s.epoch;
        self.carrier_cycles = s.carrier_cycles;
        self.smoothed_m = s.smoothed_m;
        self.m = s.m;
        self.steps_ms = s.steps_ms;
        self.t_stream_s = s.t_stream_s;
        true
    }

    /// The carrier phase of this epoch without the receiver clock steps, cycles.
    fn signal_cycles(&self) -> f64 {
        self.carrier_cycles - self.steps_ms as f64 * 1e-3 * F_L1_HZ
    }

    fn remember(&mut self) {
        let p = (self.t_stream_s, self.signal_cycles());
        self.history.push_back(p);
        if self.history.len() > HISTORY {
            self.history.pop_front();
        }
        self.snapshots.push_back(Snapshot {
            epoch: self.epoch,
            carrier_cycles: self.carrier_cycles,
            smoothed_m: self.smoothed_m,
            m: self.m,
            steps_ms: self.steps_ms,
            t_stream_s: self.t_stream_s,
        });
        if self.snapshots.len() > SNAPSHOTS {
            self.snapshots.pop_front();
        }
    }

    /// The next epoch in lock: the usual update, up to `max_m` epochs averaged.
    pub fn update(&mut self, e: &HatchEpoch, max_m: u32) {
        let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
        let dl = e.carrier_cycles - self.carrier_cycles;
        self.advance(e, lambda * dl, max_m);
        self.remember();
    }

    /// The range change (m, carrier sign, with the clock terms) from the last epoch to one
    /// `elapsed_s` of signal later, across `lost_s` of lost samples and `dsteps_ms` of clock
    /// steps; `None` without enough history or beyond [`MAX_BRIDGE_S`].
    fn bridge_change_m(
        &self,
        e: &HatchEpoch,
        lost_s: f64,
        given: Option<GivenChange>,
        anchor: Option<CarrierAnchor>,
    ) -> Option<f64> {
        let elapsed_s = e.t_stream_s - self.t_stream_s + lost_s;
        let dsteps_ms = e.steps_ms - self.steps_ms;
        let clock_m = -SPEED_OF_LIGHT_MPS * lost_s + SPEED_OF_LIGHT_MPS * dsteps_ms as f64 * 1e-3;
        // The stretch to the anchor extrapolated, the channel's own carrier after it.
        let anchored = anchor
            .filter(|a| a.t_stream_s > self.t_stream_s && a.t_stream_s <= e.t_stream_s)
            .and_then(|a| {
                let to_anchor_s = a.t_stream_s - self.t_stream_s + lost_s;
                let now_cycles = e.carrier_cycles - e.steps_ms as f64 * 1e-3 * F_L1_HZ;
                let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
                (0.0..=MAX_BRIDGE_S)
                    .contains(&to_anchor_s)
                    .then(|| self.quadratic_change_m(to_anchor_s))?
                    .map(|c| c + lambda * (now_cycles - a.signal_cycles))
            });
        if let Some(change) = anchored {
            return Some(change + clock_m);
        }
        // The carrier's own quadratic when it follows the phase (it holds a steady
        // acceleration to millimetres), else the change given from outside.
        let quadratic = (0.0..=MAX_BRIDGE_S)
            .contains(&elapsed_s)
            .then(|| self.quadratic_change_m(elapsed_s))
            .flatten();
        let given = given
            .filter(|g| g.change_m.is_finite() && (0.0..=g.max_s).contains(&elapsed_s))
            .map(|g| g.change_m);
        quadratic.or(given).map(|change| change + clock_m)
    }

    /// The range change (m, carrier sign, without the clock terms) over `elapsed_s` of signal
    /// after the last epoch, by the quadratic through the carrier history; `None` when the
    /// history is short or no quadratic follows it.
    fn quadratic_change_m(&self, elapsed_s: f64) -> Option<f64> {
        if self.history.len() < 5 {
            return None;
        }
        let (t_last, l_last) = *self.history.back()?;
        let (t_first, _) = *self.history.front()?;
        if t_last - t_first < 0.3 {
            return None;
        }
        let pts: Vec<(f64, f64)> = self
            .history
            .iter()
            .map(|&(t, l)| (t - t_last, l - l_last))
            .collect();
        let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
        let (q, rms) = fit_with_rms(&pts)?;
        if rms <= MAX_FIT_RMS_CYCLES {
            return Some(lambda * (q.at(elapsed_s) - q.at(0.0)));
        }
        // Under dynamics (a manoeuvre's jerk) no quadratic follows the whole history: a cubic
        // through the latest epochs, if its predicted error over the break is small.
        SHORT_WINDOWS_S.iter().find_map(|&w| {
            let tail: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 >= -w).collect();
            if tail.len() < 8 || -tail[0].0 < 0.5 * w {
                return None;
            }
            let c = Polynomial::fit(&tail, 3)?;
            let error_m = lambda * c.rms(&tail) * snap_error_per_rms(&tail, elapsed_s)?;
            (error_m <= MAX_EXTRAPOLATION_ERROR_M).then(|| lambda * (c.at(elapsed_s) - c.at(0.0)))
        })
    }

    /// Continues the filter over a break in lock (the pseudorange being continuous) to epoch
    /// `e`, `lost_s` of samples lost since the last epoch. The range change over the break
    /// (m, carrier sign, without the clock terms) is, with an `anchor` (the channel's first
    /// settled locked report since), the extrapolation up to it plus the carrier after it;
    /// else the extrapolated quadratic when it follows the phase, else the change `given` from
    /// outside (an INS, [`crate::pipeline::aiding::InsFeedForward::carrier_change_cycles`]: it
    /// follows a manoeuvre's jerk; the channel's own carrier coasted on an aid) over a break
    /// within its [`GivenChange::max_s`]. Returns false (the caller restarts the filter) when
    /// the break cannot be bridged or the bridged prediction misses the new code.
    pub fn bridge(
        &mut self,
        e: &HatchEpoch,
        lost_s: f64,
        max_m: u32,
        given: Option<GivenChange>,
        anchor: Option<CarrierAnchor>,
    ) -> bool {
        let Some(change) = self.bridge_change_m(e, lost_s, given, anchor) else {
            return false;
        };
        if (self.smoothed_m + change - e.pseudorange_m).abs() > MAX_INNOVATION_M {
            return false;
        }
        self.advance(e, change, max_m);
        // A new lock period: its carrier starts a new history.
        self.history.clear();
        self.remember();
        true
    }

    /// The filter moved to epoch `e` with the range change `change_m` since the last one.
    fn advance(&mut self, e: &HatchEpoch, change_m: f64, max_m: u32) {
        self.m = (self.m + 1).min(max_m);
        let mf = f64::from(self.m);
        self.smoothed_m = e.pseudorange_m / mf + (mf - 1.0) / mf * (self.smoothed_m + change_m);
        self.epoch = e.epoch;
        self.carrier_cycles = e.carrier_cycles;
        self.steps_ms = e.steps_ms;
        self.t_stream_s = e.t_stream_s;
    }
}

/// The least-squares quadratic through `pts` and the RMS of its residuals.
fn fit_with_rms(pts: &[(f64, f64)]) -> Option<(Quadratic, f64)> {
    let q = Quadratic::fit(pts)?;
    let ss: f64 = pts.iter().map(|&(t, l)| (l - q.at(t)).powi(2)).sum();
    Some((q, (ss / pts.len() as f64).sqrt()))
}

/// The error of a cubic fitted at the times of `pts` (the last at 0) and extrapolated to
/// `t_s`, per unit of its residual RMS, when what it leaves out is a snap (a quartic `t^4`:
/// a turning acceleration `a` seen along a line of sight has a snap of up to `a w^2`):
/// `|(p(t_s) - p(0)) - t_s^4| / rms(t^4 - p)` for the cubic `p` through `t^4` at those times.
/// Exact for a constant snap; noise read as snap only overstates it.
fn snap_error_per_rms(pts: &[(f64, f64)], t_s: f64) -> Option<f64> {
    let quartic: Vec<(f64, f64)> = pts.iter().map(|&(t, _)| (t, t.powi(4))).collect();
    let c = Polynomial::fit(&quartic, 3)?;
    let rms4 = c.rms(&quartic);
    let error = (c.at(t_s) - c.at(0.0) - t_s.powi(4)).abs();
    (rms4 > 0.0).then_some(error / rms4)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A satellite whose range is `r0 + v t + a t^2 / 2` (m) seen by a receiver whose clock
    /// stands still over `lost_s` lost at `t_gap` (samples lost), epochs every 0.1 s of stream.
    struct Truth {
        r0: f64,
        v: f64,
        a: f64,
    }

    impl Truth {
        fn range(&self, t_true: f64) -> f64 {
            self.r0 + self.v * t_true + 0.5 * self.a * t_true * t_true
        }
    }

    #[test]
    fn a_bridge_over_lost_samples_continues_the_smoothed_range() {
        let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
        let s = Truth {
            r0: 21_000_000.0,
            v: -600.0,
            a: 0.12,
        };
        let (t_gap, lost) = (3.0, 0.5);
        // Code noise of +-3 m (deterministic), no clock steps before the gap; after it the
        // receiver is stepped by the whole 500 ms, and the pseudorange falls by c (g - 0.5 s).
        let noise = |k: i64| 3.0 * ((k as f64 * 12.9898).sin() * 43_758.545).fract();
        let mut h: Option<Hatch> = None;
        let mut last_err = f64::NAN;
        for k in 0..60i64 {
            let t_stream = k as f64 * 0.1;
            let after = t_stream >= t_gap;
            let t_true = t_stream + if after { lost } else { 0.0 };
            let steps = if after { 500 } else { 0 };
            let clock_m = if after {
                SPEED_OF_LIGHT_MPS * (0.5 - lost)
            } else {
                0.0
            };
            let p = s.range(t_true) + clock_m + noise(k);
            // The carrier follows the range; after the gap the new channel's phase starts
            // anywhere (here 12345.25 cycles), with the steps term.
            let l_sig = if after {
                12_345.25 + s.range(t_true) / lambda
            } else {
                s.range(t_true) / lambda
            };
            let l = l_sig + steps as f64 * 1e-3 * F_L1_HZ;
            let e = HatchEpoch {
                epoch: k,
                carrier_cycles: l,
                pseudorange_m: p,
                steps_ms: steps,
                t_stream_s: t_stream,
            };
            match h.as_mut() {
                None => h = Some(Hatch::start(&e)),
                Some(f) if (t_stream - t_gap).abs() < 1e-9 => {
                    assert!(f.bridge(&e, lost, 100, None, None), "bridged");
                }
                Some(f) => f.update(&e, 100),
            }
            if let Some(f) = &h {
                last_err = f.smoothed_m - s.range(t_true) - clock_m;
                if after {
                    // Smoothed across the gap: well below the raw +-3 m.
                    assert!(last_err.abs() < 1.0, "k {k}: {last_err}");
                }
            }
        }
        assert!(last_err.abs() < 0.5, "{last_err}");
    }

    #[test]
    fn a_bridge_that_misses_the_new_code_or_is_too_long_is_refused() {
        let at = |k: i64, l: f64, p: f64, t: f64| HatchEpoch {
            epoch: k,
            carrier_cycles: l,
            pseudorange_m: p,
            steps_ms: 0,
            t_stream_s: t,
        };
        let mut h = Hatch::start(&at(0, 0.0, 20e6, 0.0));
        for k in 1..10 {
            let kf = k as f64;
            h.update(&at(k, -kf * 100.0, 20e6 - kf * 19.0, kf * 0.1), 100);
        }
        // A carried time 1 ms wrong: 300 km off the prediction.
        let mut wrong = h.clone();
        assert!(!wrong.bridge(&at(20, 0.0, 20e6 - 300_000.0, 2.0), 0.0, 100, None, None));
        // Too long a break.
        assert!(!h.bridge(&at(60, 0.0, 20e6 - 1000.0, 6.0), 0.0, 100, None, None));
    }

    #[test]
    fn a_given_range_change_bridges_as_long_a_break_as_it_is_good_for() {
        // 5 s without carrier (a channel coasted on vector tracking's prediction, whose own
        // carrier over the coast is the range change: -190 m/s here).
        let at = |k: i64, p: f64, t: f64| HatchEpoch {
            epoch: k,
            carrier_cycles: 0.0,
            pseudorange_m: p,
            steps_ms: 0,
            t_stream_s: t,
        };
        let mut h = Hatch::start(&at(0, 20e6, 0.0));
        for k in 1..10 {
            let kf = k as f64;
            let mut e = at(k, 20e6 - kf * 19.0, kf * 0.1);
            e.carrier_cycles = -kf * 19.0 * F_L1_HZ / SPEED_OF_LIGHT_MPS;
            h.update(&e, 100);
        }
        let after = at(59, 20e6 - 59.0 * 19.0 + 2.0, 5.9);
        let given = |max_s| {
            Some(GivenChange {
                change_m: -5.0 * 190.0,
                max_s,
            })
        };
        // Beyond the quadratic's 3 s: only a change good for 5 s or more bridges.
        assert!(!h
            .clone()
            .bridge(&after, 0.0, 100, given(MAX_BRIDGE_S), None));
        let mut bridged = h.clone();
        assert!(bridged.bridge(&after, 0.0, 100, given(f64::INFINITY), None));
        // The smoothed range carries the change (the new code's 2 m weighs 1/10).
        let expected = 20e6 - 59.0 * 19.0;
        assert!(
            (bridged.smoothed_m - expected).abs() < 0.3,
            "{}",
            bridged.smoothed_m - expected
        );
        // A change that is not finite does not.
        let nan = Some(GivenChange {
            change_m: f64::NAN,
            max_s: f64::INFINITY,
        });
        assert!(!h.bridge(&after, 0.0, 100, nan, None));
    }

    /// A 10 g turn at 250 m/s (radius 637 m, 0.385 rad/s) seen by a satellite on the
    /// horizon: the range's acceleration turns with the aircraft (jerk up to 38 m/s^3, snap
    /// 15 m/s^4). Epochs every 0.1 s of stream; `lost` s of samples lost at stream `t_gap`
    /// (the receiver clock falls behind by it); code noise +-3 m. Returns the epoch and the
    /// true pseudorange; the carrier after the gap is a new channel's (`offset` cycles off).
    fn turn_epoch(k: i64, t_gap: f64, lost: f64, offset: f64) -> (HatchEpoch, f64) {
        let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
        let (radius, w) = (637.0, 98.0_f64 / 250.0);
        let range = |t: f64| 21e6 - 300.0 * t - radius * (w * t + 0.3).cos();
        let noise = |k: i64| 3.0 * ((k as f64 * 12.9898).sin() * 43_758.545).fract();
        let t_stream = k as f64 * 0.1;
        let after = t_stream >= t_gap;
        let t_true = t_stream + if after { lost } else { 0.0 };
        let clock_m = if after {
            -SPEED_OF_LIGHT_MPS * lost
        } else {
            0.0
        };
        let truth = range(t_true) + clock_m;
        let e = HatchEpoch {
            epoch: k,
            carrier_cycles: truth / lambda + if after { offset } else { 0.0 },
            pseudorange_m: truth + noise(k),
            steps_ms: 0,
            t_stream_s: t_stream,
        };
        (e, truth)
    }

    /// The filter after the epochs before `t_gap` (stream s) of [`turn_epoch`].
    fn turn_filter(t_gap: f64) -> Hatch {
        let mut h = Hatch::start(&turn_epoch(0, t_gap, 0.0, 0.0).0);
        for k in 1..(t_gap * 10.0).round() as i64 {
            h.update(&turn_epoch(k, t_gap, 0.0, 0.0).0, 100);
        }
        h
    }

    #[test]
    fn in_a_turn_a_short_break_is_bridged_by_the_cubic_of_the_latest_epochs() {
        // 31 ms lost at 3.0 s, the next epoch at 3.0 s of stream: 0.131 s of signal after
        // the last epoch. No quadratic follows the 3 s of history (the turning acceleration),
        // the cubic through its last 2 s does.
        let (t_gap, lost) = (3.0, 0.031);
        let mut h = turn_filter(t_gap);
        let (e, truth) = turn_epoch(30, t_gap, lost, 0.0);
        assert!(h.bridge(&e, lost, 100, None, None), "refused");
        assert!(
            (h.smoothed_m - truth).abs() < 1.0,
            "{}",
            h.smoothed_m - truth
        );
    }

    #[test]
    fn in_a_turn_a_long_break_is_bridged_from_the_carrier_after_the_re_lock() {
        // 31 ms lost at 3.0 s; the channel holds the signal again from 3.4 s of stream (its
        // carrier 12345.25 cycles off), the time comes back at 4.5 s. The cubic would have
        // to carry 1.5 s of the turn: refused; from the anchor only 0.43 s is extrapolated.
        let (t_gap, lost, offset) = (3.0, 0.031, 12_345.25);
        let h = turn_filter(t_gap);
        let (e, truth) = turn_epoch(45, t_gap, lost, offset);
        let (at_anchor, _) = turn_epoch(34, t_gap, lost, offset);
        let anchor = CarrierAnchor {
            t_stream_s: at_anchor.t_stream_s,
            signal_cycles: at_anchor.carrier_cycles,
        };
        assert!(
            !h.clone().bridge(&e, lost, 100, None, None),
            "a polynomial carried 1.5 s of a turn"
        );
        let mut anchored = h.clone();
        assert!(
            anchored.bridge(&e, lost, 100, None, Some(anchor)),
            "refused"
        );
        assert!(
            (anchored.smoothed_m - truth).abs() < 1.0,
            "{}",
            anchored.smoothed_m - truth
        );
        // A range change from outside (an INS) bridges it too.
        let lambda = SPEED_OF_LIGHT_MPS / F_L1_HZ;
        let (last, _) = turn_epoch(29, t_gap, 0.0, 0.0);
        let change =
            (e.carrier_cycles - offset - last.carrier_cycles) * lambda + SPEED_OF_LIGHT_MPS * lost;
        let mut by_ins = h;
        assert!(
            by_ins.bridge(
                &e,
                lost,
                100,
                Some(GivenChange {
                    change_m: change,
                    max_s: MAX_BRIDGE_S
                }),
                None
            ),
            "refused"
        );
        assert!((by_ins.smoothed_m - truth).abs() < 1.0);
    }
}
