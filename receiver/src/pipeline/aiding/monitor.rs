//! The integrity monitor of the INS aiding (`gpsrx run --ins`): the feed-forward is checked
//! against the Doppler the tracking loops measure, and an INS that disagrees is dropped (the
//! loops run unaided) until it agrees again. Never a silent wrong aid.
//!
//! # The residual
//!
//! Per satellite `i` and per window of [`WINDOW_S`] (0.1 s) of receive time, from the reports of
//! a channel in phase lock:
//!
//! - aided epochs: `r_i = f_NCO - f_ff`, the loop filter's own correction (seed 004 Fig. 4:
//!   `f_NCO = f_ff + F(e)`), which a correct feed-forward keeps near zero;
//! - unaided epochs (before the aid is admitted, or after it was dropped): `r_i = mean(f_NCO) -
//!   f_ff(t_mean)`, the tracked Doppler against the feed-forward the INS *would* give
//!   ([`crate::pipeline::aiding::InsFeedForward::predicted_doppler_hz`]) at the mean time of
//!   the epochs (exact for a Doppler varying linearly over the window).
//!
//! The epochs are weighted by their integration time.
//!
//! # What a wrong INS looks like
//!
//! With a correct INS `r_i = c + n_i`: `c = -f_L1 d_ref` is common to all satellites (the
//! tracked Doppler holds the whole receiver clock drift, the feed-forward only its change since
//! the first fix, see `pipeline::aiding`; before the first fix `c = -f_L1 d_rx`, unknown) and
//! `n_i` is loop noise (about 1 Hz over 0.1 s). An INS velocity error `dv` adds
//! `dv . u_i / lambda` (5.3 Hz per m/s along the line of sight `u_i`): different on every
//! satellite, since the `u_i` point all over the sky. A time-base error `dt` acts as a velocity
//! error `a dt` (nothing on a static antenna; 49 m/s for 1 s in a 5 g turn). So per window:
//!
//! - the common part `c_hat = median_i(r_i)` (robust to one bad channel);
//! - the spread `s = sqrt(mean_i((r_i - c_hat)^2))` over the satellites (the largest
//!   deviation left out when there are 5 or more, so that one bad channel alone does not
//!   condemn the INS); a clock drift does not enter it, a velocity error does (a 50 m/s error
//!   gives 100-200 Hz);
//! - once the clock drift is known from the fixes, the common part too:
//!   `e_c = c_hat - (-f_L1 d_ref)` (a velocity error along the mean line of sight, mostly
//!   vertical, shows there and not in the spread);
//! - per satellite, its deviation `d_i = r_i - c_hat`.
//!
//! # Decisions (with hysteresis)
//!
//! Global state: *probation* (at the start: the aid is withheld until it is verified),
//! *admitted*, *rejected*. A window with 3 or more satellites is *bad* when
//! `s > `[`REJECT_SPREAD_HZ`] or `|e_c| > `[`REJECT_COMMON_HZ`], *good* when
//! `s < `[`ADMIT_SPREAD_HZ`] and `|e_c| < `[`ADMIT_COMMON_HZ`] (or `e_c` unknown).
//!
//! - [`REJECT_WINDOWS`] bad windows in a row reject the INS (WARN log), from probation or
//!   admitted; the loops then run unaided;
//! - good windows for [`ADMIT_S`] admit it from probation, for [`READMIT_S`] re-admit it after a
//!   rejection (INFO log); any window that is not good restarts the count. Windows with fewer
//!   than 3 satellites decide nothing.
//!
//! A satellite gets the aid only while the INS is admitted *and* its own deviation has been
//! below [`SAT_ADMIT_HZ`] for [`SAT_ADMIT_WINDOWS`] windows since its channel started (so a
//! re-acquired channel pulls in unaided and is checked before the aid is applied); a deviation
//! above [`SAT_REJECT_HZ`] for [`REJECT_WINDOWS`] windows while the INS as a whole agrees
//! withholds the aid from that satellite alone.

use gpsrx_dsp::Prn;
use gpsrx_tracking::{AidingPort, ChannelEpoch, ChannelState, DopplerAid};
use std::collections::BTreeMap;

/// Length of one monitoring window, s.
pub const WINDOW_S: f64 = 0.1;
/// A window ends this long before the end of the samples processed before it is evaluated
/// (every channel has reported it: its longest integration is 20 ms), s.
pub const WINDOW_LAG_S: f64 = 0.05;
/// Fewest satellites that make a decision.
pub const MIN_SATELLITES: usize = 3;
/// Spread (rms over the satellites, Hz) above which a window is bad: about 4 m/s of velocity
/// error on the lines of sight.
pub const REJECT_SPREAD_HZ: f64 = 20.0;
/// Spread (Hz) below which a window is good.
pub const ADMIT_SPREAD_HZ: f64 = 8.0;
/// Error of the common part against the clock drift (Hz) above which a window is bad.
pub const REJECT_COMMON_HZ: f64 = 40.0;
/// Error of the common part (Hz) below which a window is good.
pub const ADMIT_COMMON_HZ: f64 = 20.0;
/// Consecutive bad windows that reject the INS (or a satellite's aid).
pub const REJECT_WINDOWS: u32 = 2;
/// Good time that admits the INS at the start, s.
pub const ADMIT_S: f64 = 1.0;
/// Good time that re-admits the INS after a rejection, s.
pub const READMIT_S: f64 = 5.0;
/// Deviation of one satellite (Hz) below which its window counts for its admission.
pub const SAT_ADMIT_HZ: f64 = 12.0;
/// Deviation of one satellite (Hz) above which its aid is withheld.
pub const SAT_REJECT_HZ: f64 = 30.0;
/// Windows of agreement that admit a satellite's aid.
pub const SAT_ADMIT_WINDOWS: u32 = 3;

/// Where the INS stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum InsState {
    /// Not verified yet: the aid is withheld. `good_s`: agreement time so far; `bad`:
    /// consecutive bad windows.
    Probation { good_s: f64, bad: u32 },
    /// The aid is applied. `bad`: consecutive bad windows.
    Admitted { bad: u32 },
    /// Dropped: the loops run unaided. `good_s`: agreement time so far.
    Rejected { good_s: f64 },
}

/// Which satellites may get the aid now: a copy handed to the channels for one round.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AidPermission {
    /// Bit `prn - 1` set: the satellite gets the aid.
    prns: u32,
}

impl AidPermission {
    /// Whether satellite `prn` gets the aid.
    pub fn allows(&self, prn: u8) -> bool {
        (1..=32).contains(&prn) && self.prns & (1 << (prn - 1)) != 0
    }
}

/// The aiding port the channels get: the feed-forward of `port` for the satellites `permission`
/// allows, nothing for the others (their loops run unaided).
#[derive(Debug, Clone, Copy)]
pub struct GatedAid<'a, P: AidingPort + ?Sized> {
    /// The feed-forward.
    pub port: &'a P,
    /// Who gets it.
    pub permission: AidPermission,
}

impl<P: AidingPort + ?Sized> AidingPort for GatedAid<'_, P> {
    fn doppler_aid(&self, prn: Prn, t_s: f64) -> Option<DopplerAid> {
        if self.permission.allows(prn.get()) {
            self.port.doppler_aid(prn, t_s)
        } else {
            None
        }
    }
}

/// One satellite's sums over the current window.
#[derive(Debug, Clone, Copy, Default)]
struct WindowSums {
    /// Window index (`floor(t / WINDOW_S)`).
    k: i64,
    /// Aided epochs: sum of weights and of weighted `f_NCO - f_ff`.
    w_aided: f64,
    sum_resid: f64,
    /// Unaided epochs: sum of weights, of weighted `f_NCO` and of weighted times.
    w_unaided: f64,
    sum_nco: f64,
    sum_t: f64,
}

/// One satellite's monitor.
#[derive(Debug, Clone, Default)]
struct SatMonitor {
    /// The channel (index in the channel manager) reporting for it.
    channel: usize,
    sums: Option<WindowSums>,
    admitted: bool,
    good: u32,
    bad: u32,
}

/// A residual of one satellite in one window: `(prn, r_i)`, Hz.
type Residual = (u8, f64);

/// What one window showed across the satellites.
#[derive(Debug, Clone, Copy)]
struct WindowVerdict {
    /// Satellites with a residual.
    n: usize,
    /// The spread `s`, Hz.
    spread_hz: f64,
    /// The common part `c_hat`, Hz.
    common_hz: f64,
    /// Its error against the clock drift `e_c`, Hz, when the drift is known.
    common_err_hz: Option<f64>,
}

impl WindowVerdict {
    fn bad(&self) -> bool {
        self.spread_hz > REJECT_SPREAD_HZ
            || self
                .common_err_hz
                .is_some_and(|e| e.abs() > REJECT_COMMON_HZ)
    }

    fn good(&self) -> bool {
        self.spread_hz < ADMIT_SPREAD_HZ
            && self.common_err_hz.is_none_or(|e| e.abs() < ADMIT_COMMON_HZ)
    }

    /// Words for the log: what disagrees, by how much.
    fn describe(&self) -> String {
        let mut s = format!(
            "feed-forward disagrees with the tracked Doppler by {:.0} Hz rms over {} satellites",
            self.spread_hz, self.n
        );
        if let Some(e) = self.common_err_hz.filter(|e| e.abs() > REJECT_COMMON_HZ) {
            s.push_str(&format!(
                ", and by {e:.0} Hz in common beyond the receiver clock drift"
            ));
        }
        s
    }
}

/// What the monitor did over a run, for the summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct AidingStats {
    /// Seconds of the recording in which the feed-forward reached the loops (windows of
    /// `WINDOW_S` with an aided channel).
    pub aided_s: f64,
    /// Seconds of the recording the monitor went through.
    pub monitored_s: f64,
    /// Times the INS was rejected.
    pub rejections: usize,
    /// Times it was admitted (the first admission included).
    pub admissions: usize,
}

/// The INS integrity monitor (see the module documentation).
#[derive(Debug, Clone)]
pub struct AidMonitor {
    state: InsState,
    sats: BTreeMap<u8, SatMonitor>,
    /// Finished windows waiting for evaluation: window index -> residuals.
    pending: BTreeMap<i64, Vec<Residual>>,
    /// Windows in which some channel ran with the feed-forward (not yet evaluated).
    aided_windows: std::collections::BTreeSet<i64>,
    /// The next window to evaluate (None before the first evaluation).
    next_k: Option<i64>,
    stats: AidingStats,
}

impl Default for AidMonitor {
    fn default() -> Self {
        Self::new()
    }
}

impl AidMonitor {
    /// A monitor in probation: no satellite gets the aid until it is verified.
    pub fn new() -> Self {
        Self {
            state: InsState::Probation {
                good_s: 0.0,
                bad: 0,
            },
            sats: BTreeMap::new(),
            pending: BTreeMap::new(),
            aided_windows: std::collections::BTreeSet::new(),
            next_k: None,
            stats: AidingStats::default(),
        }
    }

    /// Which satellites get the aid now.
    pub fn permission(&self) -> AidPermission {
        if !matches!(self.state, InsState::Admitted { .. }) {
            return AidPermission::default();
        }
        let prns = self
            .sats
            .iter()
            .filter(|(&p, s)| s.admitted && (1..=32).contains(&p))
            .fold(0u32, |m, (&p, _)| m | 1 << (p - 1));
        AidPermission { prns }
    }

    /// Whether the INS is admitted now.
    pub fn admitted(&self) -> bool {
        matches!(self.state, InsState::Admitted { .. })
    }

    /// The run so far.
    pub fn stats(&self) -> AidingStats {
        self.stats
    }

    /// Takes one report of channel `channel`. `predict(prn, t)`: the feed-forward Doppler the
    /// INS gives for `prn` at receive time `t` (for the unaided epochs).
    pub fn observe(
        &mut self,
        channel: usize,
        e: &ChannelEpoch,
        predict: &dyn Fn(u8, f64) -> Option<f64>,
    ) {
        let sat = self.sats.entry(e.prn).or_default();
        if sat.channel != channel {
            // Another channel for this satellite (re-acquired): checked again before its aid.
            *sat = SatMonitor {
                channel,
                ..SatMonitor::default()
            };
        }
        let usable = e.pll_lock
            && e.state != ChannelState::Lost
            && e.doppler_hz.is_finite()
            && e.t_coh_s > 0.0;
        if !usable {
            return;
        }
        let t = e.t_rx_s + 0.5 * e.t_coh_s;
        let k = (t / WINDOW_S).floor() as i64;
        if sat.sums.is_some_and(|s| s.k != k) {
            Self::close(e.prn, sat, &mut self.pending, predict);
        }
        let sums = sat.sums.get_or_insert(WindowSums {
            k,
            ..WindowSums::default()
        });
        let w = e.t_coh_s;
        match e.feedforward_hz.filter(|f| f.is_finite()) {
            Some(ff) => {
                self.aided_windows.insert(k);
                sums.w_aided += w;
                sums.sum_resid += w * (e.doppler_hz - ff);
            }
            None => {
                sums.w_unaided += w;
                sums.sum_nco += w * e.doppler_hz;
                sums.sum_t += w * t;
            }
        }
    }

    /// Closes a satellite's window: its residual goes to `pending`.
    fn close(
        prn: u8,
        sat: &mut SatMonitor,
        pending: &mut BTreeMap<i64, Vec<Residual>>,
        predict: &dyn Fn(u8, f64) -> Option<f64>,
    ) {
        let Some(s) = sat.sums.take() else {
            return;
        };
        let mut w = s.w_aided;
        let mut sum = s.sum_resid;
        if s.w_unaided > 0.0 {
            let t_mean = s.sum_t / s.w_unaided;
            if let Some(ff) = predict(prn, t_mean).filter(|f| f.is_finite()) {
                sum += s.sum_nco - s.w_unaided * ff;
                w += s.w_unaided;
            }
        }
        if w > 0.0 {
            pending.entry(s.k).or_default().push((prn, sum / w));
        }
    }

    /// Evaluates every window that ends at least `WINDOW_LAG_S` before `t_processed_s` (the
    /// receive time up to which the channels have processed the samples), in order, from the
    /// one holding `t_first_s` (the stream's first sample). `expected_common_hz`: the common
    /// residual a correct INS gives (`-f_L1 d_ref`), when the clock drift is known.
    pub fn evaluate(
        &mut self,
        t_first_s: f64,
        t_processed_s: f64,
        expected_common_hz: Option<f64>,
        predict: &dyn Fn(u8, f64) -> Option<f64>,
    ) {
        if !(t_processed_s.is_finite() && t_first_s.is_finite()) {
            return;
        }
        let last = ((t_processed_s - WINDOW_LAG_S) / WINDOW_S).floor() as i64 - 1;
        let first = (t_first_s / WINDOW_S).floor() as i64;
        while *self.next_k.get_or_insert(first) <= last {
            let k = self.next_k.unwrap_or(first);
            // Satellites that have stopped reporting: their last window is finished too.
            for (&prn, sat) in self.sats.iter_mut() {
                if sat.sums.is_some_and(|s| s.k <= k) {
                    Self::close(prn, sat, &mut self.pending, predict);
                }
            }
            let residuals = self.pending.remove(&k).unwrap_or_default();
            self.decide(k, &residuals, expected_common_hz);
            self.next_k = Some(k + 1);
        }
        // Nothing is kept for windows already decided (a report later than its window's
        // evaluation cannot count any more).
        if let Some(next) = self.next_k {
            self.pending = self.pending.split_off(&next);
            self.aided_windows = self.aided_windows.split_off(&next);
        }
    }

    /// One window's decisions (global, then per satellite).
    fn decide(&mut self, k: i64, residuals: &[Residual], expected_common_hz: Option<f64>) {
        self.stats.monitored_s += WINDOW_S;
        if self.aided_windows.remove(&k) {
            self.stats.aided_s += WINDOW_S;
        }
        let Some(v) = verdict(residuals, expected_common_hz) else {
            return;
        };
        let t_end = (k + 1) as f64 * WINDOW_S;
        if k % 10 == 0 {
            tracing::debug!(
                "INS check at {t_end:.1} s: {:.1} Hz rms over {} satellites, common part {:.1} Hz{}",
                v.spread_hz,
                v.n,
                v.common_hz,
                v.common_err_hz
                    .map(|e| format!(" ({e:+.1} Hz from the clock drift)"))
                    .unwrap_or_default()
            );
        }
        self.step_state(t_end, &v);
        if v.bad() {
            return; // the INS as a whole is in question: no satellite's own verdict
        }
        let admitted = self.admitted();
        for &(prn, r) in residuals {
            let Some(sat) = self.sats.get_mut(&prn) else {
                continue;
            };
            let d = (r - v.common_hz).abs();
            if d < SAT_ADMIT_HZ {
                sat.bad = 0;
                sat.good = sat.good.saturating_add(1);
                if !sat.admitted && sat.good >= SAT_ADMIT_WINDOWS {
                    sat.admitted = true;
                    tracing::debug!("G{prn:02}: INS feed-forward verified at {t_end:.1} s ({d:.1} Hz from the common part)");
                }
            } else {
                sat.good = 0;
                if d > SAT_REJECT_HZ {
                    sat.bad += 1;
                    if sat.admitted && sat.bad >= REJECT_WINDOWS {
                        sat.admitted = false;
                        if !admitted {
                            continue; // no aid anyway: checked again before it gets one
                        }
                        tracing::warn!("G{prn:02}: INS feed-forward disagrees with its tracked Doppler by {d:.0} Hz at {t_end:.1} s while the other satellites agree (ephemeris or channel wrong?); this satellite runs unaided");
                    }
                }
            }
        }
    }

    /// The global state machine for one window with a verdict.
    fn step_state(&mut self, t_end: f64, v: &WindowVerdict) {
        let (good, bad) = (v.good(), v.bad());
        self.state = match self.state {
            InsState::Admitted { bad: n } | InsState::Probation { bad: n, .. } if bad => {
                if n + 1 >= REJECT_WINDOWS {
                    self.reject(t_end, v)
                } else if self.admitted() {
                    InsState::Admitted { bad: n + 1 }
                } else {
                    InsState::Probation {
                        good_s: 0.0,
                        bad: n + 1,
                    }
                }
            }
            InsState::Admitted { .. } => InsState::Admitted { bad: 0 },
            InsState::Probation { good_s, .. } => {
                let good_s = if good { good_s + WINDOW_S } else { 0.0 };
                if good_s >= ADMIT_S - 1e-9 {
                    self.admit(t_end, v, true)
                } else {
                    InsState::Probation { good_s, bad: 0 }
                }
            }
            InsState::Rejected { good_s } => {
                let good_s = if good { good_s + WINDOW_S } else { 0.0 };
                if good_s >= READMIT_S - 1e-9 {
                    self.admit(t_end, v, false)
                } else {
                    InsState::Rejected { good_s }
                }
            }
        };
    }

    fn reject(&mut self, t_end: f64, v: &WindowVerdict) -> InsState {
        self.stats.rejections += 1;
        tracing::warn!(
            "INS aiding rejected at {t_end:.1} s: {} (INS velocity or time base wrong?); loops run unaided",
            v.describe()
        );
        InsState::Rejected { good_s: 0.0 }
    }

    fn admit(&mut self, t_end: f64, v: &WindowVerdict, first: bool) -> InsState {
        self.stats.admissions += 1;
        let what = if first { "admitted" } else { "re-admitted" };
        tracing::info!(
            "INS aiding {what} at {t_end:.1} s: feed-forward agrees with the tracked Doppler within {:.1} Hz rms over {} satellites",
            v.spread_hz,
            v.n
        );
        InsState::Admitted { bad: 0 }
    }
}

/// The spread and common part of one window's residuals (see the module documentation); None
/// with fewer than [`MIN_SATELLITES`].
fn verdict(residuals: &[Residual], expected_common_hz: Option<f64>) -> Option<WindowVerdict> {
    let n = residuals.len();
    if n < MIN_SATELLITES {
        return None;
    }
    let mut r: Vec<f64> = residuals.iter().map(|&(_, r)| r).collect();
    r.sort_by(f64::total_cmp);
    let common_hz = if n % 2 == 1 {
        r[n / 2]
    } else {
        0.5 * (r[n / 2 - 1] + r[n / 2])
    };
    let mut d2: Vec<f64> = r.iter().map(|x| (x - common_hz).powi(2)).collect();
    d2.sort_by(f64::total_cmp);
    if n >= 5 {
        d2.pop();
    }
    let spread_hz = (d2.iter().sum::<f64>() / d2.len() as f64).sqrt();
    Some(WindowVerdict {
        n,
        spread_hz,
        common_hz,
        common_err_hz: expected_common_hz.map(|c| common_hz - c),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    /// Lines of sight of 6 satellites spread over the sky (unit vectors).
    const LOS: [[f64; 3]; 6] = [
        [0.0, 0.0, 1.0],
        [0.8, 0.0, 0.6],
        [-0.7, 0.5, 0.5],
        [0.1, -0.9, 0.42],
        [0.5, 0.8, 0.33],
        [-0.6, -0.6, 0.53],
    ];
    const LAMBDA_M: f64 = 0.190_293_672_798;

    fn epoch(prn: u8, t: f64, doppler_hz: f64, feedforward_hz: Option<f64>) -> ChannelEpoch {
        let z = Complex64::new(0.0, 0.0);
        ChannelEpoch {
            prn,
            state: ChannelState::Track,
            sample_index: 0,
            t_rx_s: t,
            code_phase_chips: 0.0,
            code_rate_chips_s: 1.023e6,
            carrier_phase_cycles: 0.0,
            doppler_hz,
            cn0_dbhz: 45.0,
            cn0_lost_dbhz: 25.0,
            pll_lock: true,
            pll_lock_metric: 1.0,
            code_lock: true,
            prompt: z,
            early: z,
            late: z,
            phase_error_cycles: 0.0,
            freq_error_hz: 0.0,
            code_error_chips: 0.0,
            t_coh_s: 1e-3,
            feedforward_hz,
            coasting: false,
            ms_count: 0,
            bit_edge: false,
            bit: None,
            bit_start_ms: None,
        }
    }

    /// Runs `n_sats` satellites for `duration_s` through the monitor, with loops that track the
    /// true Doppler (plus 1 Hz of deterministic noise) and a feed-forward that is the true
    /// Doppler plus `ff_error(prn, t)`; `expected` is the common residual a correct INS gives.
    /// Returns the monitor and, per 10 ms round, whether the INS was admitted.
    fn simulate(
        n_sats: usize,
        duration_s: f64,
        ff_error: &dyn Fn(u8, f64) -> f64,
        expected: Option<f64>,
    ) -> (AidMonitor, Vec<(f64, bool)>) {
        let truth = |prn: u8, t: f64| 1000.0 * f64::from(prn) - 0.5 * t;
        let predict = |prn: u8, t: f64| Some(truth(prn, t) + ff_error(prn, t));
        let mut m = AidMonitor::new();
        let mut log = Vec::new();
        let rounds = (duration_s / 0.01).round() as usize;
        for j in 0..rounds {
            let permission = m.permission();
            for ms in 0..10 {
                let t = (j * 10 + ms) as f64 * 1e-3;
                for (i, prn) in (1..=n_sats as u8).enumerate() {
                    let noise = (t * 377.0 + f64::from(prn)).sin();
                    let nco = truth(prn, t + 0.5e-3) + noise;
                    let ff = permission
                        .allows(prn)
                        .then(|| truth(prn, t + 0.5e-3) + ff_error(prn, t + 0.5e-3));
                    m.observe(i, &epoch(prn, t, nco, ff), &predict);
                }
            }
            let done = (j + 1) as f64 * 0.01;
            m.evaluate(0.0, done, expected, &predict);
            log.push((done, m.admitted()));
        }
        (m, log)
    }

    /// The first time in `log` the admission turns to `to` after `from_s`.
    fn first_change(log: &[(f64, bool)], from_s: f64, to: bool) -> Option<f64> {
        log.iter()
            .find(|&&(t, a)| t > from_s && a == to)
            .map(|&(t, _)| t)
    }

    #[test]
    fn a_clock_drift_common_to_all_satellites_is_no_disagreement() {
        // 300 Hz on every satellite (a receiver clock drift of 1.9e-7 the feed-forward lacks).
        let (m, log) = simulate(6, 5.0, &|_, _| 300.0, None);
        let s = m.stats();
        assert_eq!(s.rejections, 0, "{s:?}");
        assert_eq!(s.admissions, 1, "{s:?}");
        let admitted = first_change(&log, 0.0, true).unwrap_or(f64::INFINITY);
        assert!((1.0..1.4).contains(&admitted), "admitted at {admitted} s");
        for prn in 1..=6 {
            assert!(m.permission().allows(prn), "G{prn:02}");
        }
        assert!(!m.permission().allows(7) && !m.permission().allows(0));
        assert!(s.aided_s > 3.4 && s.aided_s < 4.1, "{s:?}");
    }

    #[test]
    fn a_velocity_error_is_rejected_and_readmitted_with_hysteresis() {
        // 50 m/s along x from 3 s to 5 s, on top of a 60 Hz clock term; the INS has just been
        // admitted before.
        let dv = |prn: u8, t: f64| {
            let u = LOS[usize::from(prn - 1) % LOS.len()];
            let v = if (3.0..5.0).contains(&t) { 50.0 } else { 0.0 };
            60.0 + v * u[0] / LAMBDA_M
        };
        let (m, log) = simulate(6, 12.0, &dv, None);
        let s = m.stats();
        let rejected = first_change(&log, 1.5, false).unwrap_or(f64::INFINITY);
        assert!((3.0..3.4).contains(&rejected), "rejected at {rejected} s");
        // Agreement again from 5 s: re-admitted after 5 s of it, not before.
        let back = first_change(&log, rejected, true).unwrap_or(f64::INFINITY);
        assert!((10.0..10.4).contains(&back), "re-admitted at {back} s");
        assert_eq!((s.rejections, s.admissions), (1, 2), "{s:?}");
    }

    #[test]
    fn an_error_flickering_about_the_thresholds_does_not_flap() {
        // 50 m/s for 0.1 s every 0.5 s: never 5 s of agreement once rejected.
        let dv = |prn: u8, t: f64| {
            let u = LOS[usize::from(prn - 1) % LOS.len()];
            let v = if t > 2.0 && (t % 0.5) < 0.1 {
                50.0
            } else {
                0.0
            };
            v * u[0] / LAMBDA_M
        };
        let (m, _) = simulate(6, 12.0, &dv, None);
        let s = m.stats();
        assert!(s.rejections <= 1 && s.admissions <= 1, "{s:?}");
    }

    #[test]
    fn one_satellite_off_loses_its_own_aid_only() {
        let err = |prn: u8, _t: f64| if prn == 4 { 100.0 } else { 0.0 };
        let (m, _) = simulate(6, 4.0, &err, None);
        assert_eq!(m.stats().rejections, 0, "{:?}", m.stats());
        assert!(m.admitted());
        assert!(!m.permission().allows(4));
        for prn in [1, 2, 3, 5, 6] {
            assert!(m.permission().allows(prn), "G{prn:02}");
        }
    }

    #[test]
    fn the_common_part_is_checked_once_the_clock_drift_is_known() {
        // Every satellite 60 Hz off, where the clock drift says 0: a vertical velocity error.
        let (m, _) = simulate(6, 3.0, &|_, _| 60.0, Some(0.0));
        assert!(!m.admitted());
        assert_eq!(m.stats().rejections, 1);
        // The same with the drift explaining it (tracked - fed forward = -60 Hz): admitted.
        let (m, _) = simulate(6, 3.0, &|_, _| 60.0, Some(-60.0));
        assert!(m.admitted());
    }

    #[test]
    fn two_satellites_decide_nothing() {
        let (m, _) = simulate(2, 3.0, &|prn, _| 100.0 * f64::from(prn), None);
        let s = m.stats();
        assert_eq!((s.rejections, s.admissions), (0, 0), "{s:?}");
        assert!(!m.permission().allows(1));
    }
}
