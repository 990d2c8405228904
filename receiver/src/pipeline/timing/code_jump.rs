//! Detection of a code jump common to the satellites (samples lost by a fraction of a code
//! period), and the check that the satellites found again moved together.
//!
//! When the front end loses `g` seconds of samples and `g` is not a whole number of
//! milliseconds, the code of every satellite jumps by `g` modulo 1 ms: all channels' prompt
//! power collapses to the noise floor at the same sample, while the carrier frequency each
//! held is still right. A long gap (tenths of a second) moves the code of each satellite by a
//! different part of a chip (`g f_D / f_L1`), and collapses those moved most.
//! [`CollapseMonitor`] watches every strong 1 ms channel's prompt power against its own level
//! and reports a collapse of [`MIN_SATELLITES`] or more satellites within [`CLUSTER_S`]: the
//! channel manager then searches every tracked satellite's code at its Doppler
//! ([`crate::pipeline::channels::channel_manager`]). A blockage collapses the power too; the search then
//! finds nothing (or the code where it was) and nothing is moved.
//!
//! Per satellite, the mean prompt power of the last [`POWER_REPORTS`] reports is compared with
//! the reference level `S` (signal plus noise, averaged while the signal is there). The noise
//! floor is `S / (1 + C/N0 T)`; the threshold is their geometric mean `S / sqrt(1 + C/N0 T)`,
//! so that both sides have a margin of `sqrt(1 + C/N0 T)` (2.2 at [`MIN_CN0_DBHZ`], 1 ms).

use crate::pipeline::timing::modulo::nearest_remainder;
use gpsrx_tracking::{ChannelEpoch, ChannelState, CodeShift};
use std::collections::{BTreeMap, VecDeque};

/// Reports whose mean power is tested.
pub const POWER_REPORTS: usize = 8;
/// Reports with signal before a satellite is watched.
pub const ARM_REPORTS: u32 = 100;
/// Weakest C/N0 watched, dB-Hz.
pub const MIN_CN0_DBHZ: f64 = 34.0;
/// Collapses this close in time are one event, s.
pub const CLUSTER_S: f64 = 0.012;
/// Satellites that must collapse together.
pub const MIN_SATELLITES: usize = 3;
/// Reports of NCO frequency fitted for the Doppler and its rate before a collapse.
pub const FIT_REPORTS: usize = 200;

/// A satellite whose prompt collapsed, with the carrier it held before.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollapsedSat {
    /// PRN.
    pub prn: u8,
    /// Carrier Doppler before the collapse, Hz, at stream time `t_s`.
    pub doppler_hz: f64,
    /// Its rate, Hz/s.
    pub doppler_rate_hz_s: f64,
    /// Stream time the Doppler refers to, s.
    pub t_s: f64,
    /// C/N0 before the collapse, dB-Hz.
    pub cn0_dbhz: f64,
}

impl CollapsedSat {
    /// The Doppler extrapolated to stream time `t_s`, Hz.
    pub fn doppler_at(&self, t_s: f64) -> f64 {
        self.doppler_hz + self.doppler_rate_hz_s * (t_s - self.t_s)
    }
}

/// Prompt power collapsed on several satellites at once.
#[derive(Debug, Clone, PartialEq)]
pub struct Collapse {
    /// Sample index of the collapse (the median onset).
    pub sample: u64,
    /// The satellites that collapsed.
    pub satellites: Vec<CollapsedSat>,
    /// Satellites watched at the time.
    pub watched: usize,
}

#[derive(Debug, Default)]
struct Watch {
    /// Reports with signal in a row.
    steady: u32,
    /// Reference power (signal plus noise), exponentially averaged.
    ref_power: f64,
    cn0_dbhz: f64,
    /// `(sample index, |P|^2)` of the latest reports.
    recent: VecDeque<(u64, f64)>,
    /// `(stream time s, NCO frequency Hz)` of the latest reports with signal.
    freq: VecDeque<(f64, f64)>,
}

/// Watches every satellite's prompt power for a collapse common to several.
#[derive(Debug, Default)]
pub struct CollapseMonitor {
    watches: BTreeMap<u8, Watch>,
    /// Collapses not yet judged: `(onset sample, satellite)`.
    pending: Vec<(u64, CollapsedSat)>,
}

impl CollapseMonitor {
    /// A monitor with no history.
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes one channel report.
    pub fn push(&mut self, e: &ChannelEpoch) {
        let w = self.watches.entry(e.prn).or_default();
        let p2 = e.prompt.norm_sqr();
        if e.state != ChannelState::Track || e.t_coh_s > 1.5e-3 || !p2.is_finite() {
            *w = Watch::default();
            return;
        }
        let armed = w.steady >= ARM_REPORTS && w.cn0_dbhz >= MIN_CN0_DBHZ;
        w.recent.push_back((e.sample_index, p2));
        if w.recent.len() > POWER_REPORTS {
            w.recent.pop_front();
        }
        let mean = w.recent.iter().map(|r| r.1).sum::<f64>() / w.recent.len() as f64;
        let snr = 10f64.powf(w.cn0_dbhz / 10.0) * e.t_coh_s;
        if armed && w.recent.len() == POWER_REPORTS && mean < w.ref_power / (1.0 + snr).sqrt() {
            let onset = w.recent.front().map_or(e.sample_index, |r| r.0);
            if let Some((f, rate, t)) = fit_line(&w.freq) {
                self.pending.push((
                    onset,
                    CollapsedSat {
                        prn: e.prn,
                        doppler_hz: f,
                        doppler_rate_hz_s: rate,
                        t_s: t,
                        cn0_dbhz: w.cn0_dbhz,
                    },
                ));
            }
            *w = Watch::default();
            return;
        }
        if !e.pll_lock || !e.cn0_dbhz.is_finite() {
            w.steady = 0;
            return;
        }
        w.steady += 1;
        w.cn0_dbhz = e.cn0_dbhz;
        w.ref_power = if w.ref_power > 0.0 {
            w.ref_power + 0.02 * (p2 - w.ref_power)
        } else {
            p2
        };
        w.freq.push_back((e.t_rx_s, e.doppler_hz));
        if w.freq.len() > FIT_REPORTS {
            w.freq.pop_front();
        }
    }

    /// After all channels have reported up to sample `end` (samples at `fs_hz`): the common
    /// collapse among those old enough to be complete, if any.
    pub fn evaluate(&mut self, end: u64, fs_hz: f64) -> Option<Collapse> {
        let cluster = (CLUSTER_S * fs_hz) as u64;
        let ready = end.saturating_sub(cluster);
        self.pending.sort_by_key(|p| p.0);
        let watched = self
            .watches
            .values()
            .filter(|w| w.steady >= ARM_REPORTS && w.cn0_dbhz >= MIN_CN0_DBHZ)
            .count();
        let mut found = None;
        for (i, &(t0, _)) in self.pending.iter().enumerate() {
            if t0 + cluster > ready {
                break;
            }
            let group: Vec<(u64, CollapsedSat)> = self.pending[i..]
                .iter()
                .take_while(|p| p.0 < t0 + cluster)
                .copied()
                .collect();
            let n = group.len();
            if n >= MIN_SATELLITES {
                let mut onsets: Vec<u64> = group.iter().map(|g| g.0).collect();
                onsets.sort_unstable();
                found = Some(Collapse {
                    sample: onsets[n / 2],
                    satellites: group.iter().map(|g| g.1).collect(),
                    watched: n + watched,
                });
                break;
            }
        }
        if found.is_some() {
            self.pending.clear();
        } else {
            self.pending.retain(|p| p.0 + cluster > ready);
        }
        found
    }
}

/// The least-squares line through `(t, f)`: the frequency at the last point, the slope and
/// that point's time; `None` with fewer than 20 points.
fn fit_line(pts: &VecDeque<(f64, f64)>) -> Option<(f64, f64, f64)> {
    if pts.len() < 20 {
        return None;
    }
    let (t_last, _) = *pts.back()?;
    let n = pts.len() as f64;
    let (st, sf, stt, stf) = pts.iter().fold((0.0, 0.0, 0.0, 0.0), |a, &(t, f)| {
        let t = t - t_last;
        (a.0 + t, a.1 + f, a.2 + t * t, a.3 + t * f)
    });
    let den = n * stt - st * st;
    if den <= 0.0 {
        return Some((sf / n, 0.0, t_last));
    }
    let b = (n * stf - st * sf) / den;
    let a = (sf - b * st) / n;
    Some((a, b, t_last))
}

/// Longest gap whose code shifts are fitted, s.
pub const MAX_GAP_S: f64 = 1.0;

/// What the code shifts of the satellites found again after a collapse say.
#[derive(Debug, Clone, PartialEq)]
pub struct CodeGap {
    /// The shortest gap consistent with the shifts, s (the length is known only modulo a few
    /// milliseconds from the code: the bit edges and the carrier phase resolve it).
    pub shortest_s: f64,
    /// The satellites whose shift it explains.
    pub prns: Vec<u8>,
}

/// The gap that explains the code shifts of the satellites searched after a collapse.
///
/// Lost samples move every code epoch after them `g fs` samples earlier, so the forward
/// shift of satellite `i`'s replica onto its signal is `s_i = -g fs` modulo its code period
/// `P_i = 1023 fs / R_i` (`R_i` the code rate): a common fraction of a period, plus
/// `g fs f_D,i / f_L1` that differs between satellites (2.6 samples for 0.5 s at 3 kHz of
/// Doppler and 2.6 MHz). The candidates `g = (k P_ref - s_ref) / fs` of each reference
/// satellite are tried up to [`MAX_GAP_S`]; the one that explains the most shifts within
/// `tol_samples` wins (the shortest among equals). `None` when fewer than
/// [`MIN_SATELLITES`] agree, or when no code moved (every shift within `tol_samples` of zero:
/// the power came back after a fade or a blockage; a short whole-millisecond gap moves no
/// code either, and is found by its carrier-phase steps).
pub fn fit_code_gap(shifts: &[(u8, CodeShift)], fs_hz: f64, tol_samples: f64) -> Option<CodeGap> {
    if shifts
        .iter()
        .all(|(_, s)| nearest_remainder(s.shift_samples, s.period_samples).abs() <= tol_samples)
    {
        return None;
    }
    let explained = |g: f64| -> Vec<u8> {
        shifts
            .iter()
            .filter(|(_, s)| {
                nearest_remainder(-g * fs_hz - s.shift_samples, s.period_samples).abs()
                    <= tol_samples
            })
            .map(|(p, _)| *p)
            .collect()
    };
    let mut best: Option<(f64, Vec<u8>)> = None;
    for (_, r) in shifts {
        let k_max = (MAX_GAP_S * fs_hz / r.period_samples).ceil() as u64;
        for k in 1..=k_max {
            let g = (k as f64 * r.period_samples - r.shift_samples) / fs_hz;
            if g <= 0.0 {
                continue;
            }
            let prns = explained(g);
            let better = match &best {
                None => true,
                Some((g0, p0)) => prns.len() > p0.len() || (prns.len() == p0.len() && g < *g0),
            };
            if better {
                best = Some((g, prns));
            }
        }
    }
    let (g, prns) = best?;
    (prns.len() >= MIN_SATELLITES).then_some(CodeGap {
        shortest_s: g,
        prns,
    })
}

/// What to do with the channels after a code realignment search: the decision on the gap its
/// code shifts show, made here and carried out by the channel manager
/// ([`crate::pipeline::channels::ChannelManager::realign`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RealignPlan {
    /// The shortest gap the code shifts allow, s.
    pub shortest_gap_s: f64,
    /// The satellites whose channels move onto the code found.
    pub prns: Vec<u8>,
    /// The code moved by more than a gap of up to [`MAX_GAP_S`] explains (on at least
    /// [`MIN_SATELLITES`] satellites): samples of an unknown, longer length were lost; the
    /// channels take the Doppler the search found (the one held before may have drifted).
    pub length_unknown: bool,
}

/// The plan for the code `shifts` `(PRN, shift)` a realignment search found at `fs_hz`: move
/// the channels whose shift one gap explains ([`fit_code_gap`]), or, when at least
/// [`MIN_SATELLITES`] moved by more than any gap up to [`MAX_GAP_S`] explains, every channel
/// whose code moved (the length is then unknown). `None`: no gap explains the shifts, nothing
/// moves.
pub fn plan_realignment(shifts: &[(u8, CodeShift)], fs_hz: f64) -> Option<RealignPlan> {
    // Two samples, or a twentieth of a chip at high rates: the search's code resolution.
    let tol = (0.05 * fs_hz / gpsrx_dsp::constants::CA_CHIP_RATE_HZ).max(2.0);
    let fit = fit_code_gap(shifts, fs_hz, tol);
    let unexplained = unexplained_moves(shifts, fit.as_ref(), tol);
    let length_unknown = unexplained.len() >= MIN_SATELLITES;
    let (shortest_gap_s, prns) = match fit {
        _ if length_unknown => {
            tracing::debug!(
                "code realignment: the code of {unexplained:?} moved by more than a gap of up to {} s explains: {shifts:?}",
                MAX_GAP_S
            );
            let moved = shifts.iter().filter(|(_, s)| code_moved(s, tol));
            (MAX_GAP_S, moved.map(|(p, _)| *p).collect())
        }
        Some(gap) => (gap.shortest_s, gap.prns),
        None => {
            tracing::debug!("code realignment: no gap explains the shifts {shifts:?}");
            return None;
        }
    };
    Some(RealignPlan {
        shortest_gap_s,
        prns,
        length_unknown,
    })
}

/// Whether a code shift moved the code (by more than `tol_samples`, modulo its period).
fn code_moved(s: &CodeShift, tol_samples: f64) -> bool {
    nearest_remainder(s.shift_samples, s.period_samples).abs() > tol_samples
}

/// The satellites whose code moved but which the fitted gap (if any) does not explain.
fn unexplained_moves(
    shifts: &[(u8, CodeShift)],
    fit: Option<&CodeGap>,
    tol_samples: f64,
) -> Vec<u8> {
    shifts
        .iter()
        .filter(|(p, s)| code_moved(s, tol_samples) && fit.is_none_or(|g| !g.prns.contains(p)))
        .map(|(p, _)| *p)
        .collect()
}

/// The code shifts after `g_s` of lost samples at 2.6 MHz for satellites at `dopplers` (Hz),
/// PRNs 1, 2, ... (test support).
#[cfg(test)]
pub(crate) fn shifts_after(g_s: f64, dopplers: &[f64]) -> Vec<(u8, gpsrx_tracking::CodeShift)> {
    dopplers
        .iter()
        .enumerate()
        .map(|(i, &f)| {
            let period = 2600.0 / (1.0 + f / 1.57542e9);
            let shift = (-g_s * 2.6e6).rem_euclid(period);
            let s = gpsrx_tracking::CodeShift {
                shift_samples: shift,
                period_samples: period,
            };
            (i as u8 + 1, s)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    fn report(prn: u8, k: u64, amplitude: f64, noise: f64) -> ChannelEpoch {
        let doppler = 1000.0 + f64::from(prn) + 0.5 * k as f64 * 1e-3;
        let prompt = Complex64::new(amplitude + noise, noise);
        let mut e = crate::pipeline::test_support::report(prn, k, prompt, doppler, 0.0, 42.0);
        (e.early, e.late) = (Complex64::new(0.0, 0.0), Complex64::new(0.0, 0.0));
        e
    }

    /// Deterministic noise in [-0.5, 0.5).
    fn noise(i: u64) -> f64 {
        ((i.wrapping_mul(6_364_136_223_846_793_005) >> 33) as f64 / (1u64 << 31) as f64) - 0.5
    }

    fn run(collapse_at: &[(u8, u64)], prns: &[u8]) -> Option<Collapse> {
        let mut m = CollapseMonitor::new();
        let mut found = None;
        for k in 0..600u64 {
            for &p in prns {
                let gone = collapse_at.iter().any(|&(q, at)| q == p && k >= at);
                let amp = if gone { 0.0 } else { 10.0 };
                m.push(&report(p, k, amp, noise(k * 37 + u64::from(p))));
            }
            if k % 10 == 9 {
                found = found.or(m.evaluate((k + 1) * 2048, 2.048e6));
            }
        }
        found
    }

    #[test]
    fn a_common_collapse_is_found_at_its_sample_with_the_doppler_held_before() {
        let prns = [3, 7, 11, 19, 23];
        let c = run(&prns.map(|p| (p, 400)), &prns).expect("collapse");
        let onset_ms = c.sample as f64 / 2048.0;
        assert!((onset_ms - 400.0).abs() <= 2.0, "onset {onset_ms} ms");
        assert_eq!(c.satellites.len(), 5);
        for s in &c.satellites {
            // The NCO frequency was 1000 + prn + 0.5 Hz/s t.
            let f = s.doppler_at(0.4);
            assert!(
                (f - (1000.0 + f64::from(s.prn) + 0.2)).abs() < 0.01,
                "{s:?}"
            );
            assert!((s.doppler_rate_hz_s - 0.5).abs() < 0.01, "{s:?}");
        }
    }

    #[test]
    fn one_or_two_satellites_fading_or_collapses_far_apart_are_not_a_jump() {
        let prns = [3, 7, 11, 19, 23];
        assert_eq!(run(&[(3, 300), (7, 300)], &prns), None);
        assert_eq!(run(&[(3, 200), (7, 300), (11, 400)], &prns), None);
        assert_eq!(run(&[], &prns), None);
    }

    #[test]
    fn the_code_shifts_of_a_fractional_or_a_long_gap_are_explained_by_one_length() {
        let dopplers = [-3186.0, 1963.0, -1888.0, 637.0, -565.0, 193.0];
        for g in [1.25e-3, 0.2004, 0.5, 0.7317] {
            let gap = fit_code_gap(&shifts_after(g, &dopplers), 2.6e6, 2.0).expect("a gap");
            assert_eq!(gap.prns.len(), 6, "{g}: {gap:?}");
            // Its length modulo 1 ms is exact; the code alone leaves a few ms open.
            let ms_apart = (gap.shortest_s - g) * 1e3;
            assert!(
                nearest_remainder(ms_apart, 1.0).abs() < 0.01,
                "{g}: {gap:?}"
            );
            assert!(gap.shortest_s <= g + 1e-9, "{g}: {gap:?}");
        }
    }

    #[test]
    fn shifts_that_no_gap_explains_or_no_shift_at_all_are_not_a_gap() {
        let s = |shift: f64| CodeShift {
            shift_samples: shift,
            period_samples: 2600.0,
        };
        // Nothing moved (a blockage that ended), including around the wrap of the period.
        let still = [(1, s(0.4)), (2, s(2599.5)), (3, s(1.1))];
        assert_eq!(fit_code_gap(&still, 2.6e6, 2.0), None);
        // Two satellites moved alike, the third elsewhere: no three agree.
        let odd = [(1, s(650.0)), (2, s(650.4)), (3, s(1300.0))];
        assert_eq!(fit_code_gap(&odd, 2.6e6, 2.0), None);
        // A false detection among four is left out.
        let mut four = shifts_after(1.25e-3, &[100.0, 2000.0, -1500.0]);
        four.push((9, s(90.0)));
        let gap = fit_code_gap(&four, 2.6e6, 2.0).expect("gap");
        assert_eq!(gap.prns, vec![1, 2, 3]);
    }

    #[test]
    fn code_moves_of_a_gap_longer_than_the_fit_reaches_are_left_unexplained() {
        let dopplers = [
            -3186.0, 1963.0, -1888.0, 637.0, -565.0, 2480.0, -2710.0, 1210.0,
        ];
        let unexplained = |g: f64| {
            let s = shifts_after(g, &dopplers);
            unexplained_moves(&s, fit_code_gap(&s, 2.6e6, 2.0).as_ref(), 2.0)
        };
        // Up to the fit's reach, one length explains every move.
        for g in [1.25e-3, 0.5, 0.7317] {
            assert!(unexplained(g).is_empty(), "{g} s: {:?}", unexplained(g));
        }
        // Beyond, the moves g f_D / f_L1 (26 samples for 5 s at 3 kHz) differ between satellites by
        // more than any one gap of up to a second explains (a few may agree by chance).
        for g in [5.0, 5.37, 60.0] {
            let u = unexplained(g);
            assert!(u.len() >= 6, "{g} s: {u:?}");
        }
        // Nothing moved (a blockage that ended): no gap.
        let still: Vec<(u8, CodeShift)> = shifts_after(0.0, &dopplers);
        assert!(unexplained_moves(&still, None, 2.0).is_empty());
    }
}
