//! Detection of a discontinuity of the sample stream (samples lost by the front end) from a
//! carrier-phase jump common to the satellites.
//!
//! When whole milliseconds of samples are lost, every channel's code stays aligned (a C/A code
//! period is 1 ms) and its loops keep lock, but the carrier phase of satellite `i` jumps by
//! `g f_D,i` cycles (`g` the lost time, `f_D,i` its Doppler), a different fraction of a cycle
//! for each satellite, all at the same sample. Receiver time and every SV time then run `g`
//! late together, so pseudoranges do not show it: only the time at which the satellites'
//! positions are computed is wrong, by `g` (`g` times a range rate of up to 800 m/s: 25 m for
//! 31 ms). Noise and cycle slips are independent across satellites; a jump at the same instant
//! in several of them is not.
//!
//! Per satellite, the residual carrier phase of the prompt, `phi = atan(Q / I)` (Costas: modulo
//! half a cycle), is averaged over the last [`WINDOW`] reports and compared with the
//! [`WINDOW`] before them (circular means of `2 phi`). With the per-report phase noise
//! `sigma = 1 / sqrt(2 C/N0 T)` rad, the difference of two means has
//! `sigma_d = sigma sqrt(2 / WINDOW)`. The normalised steps of all satellites at the same
//! instant are summed and tested ([`DiscontinuityMonitor::evaluate`]); a satellite whose prompt
//! power collapsed is not counted (a blockage, not lost samples).

use gpsrx_tracking::{ChannelEpoch, ChannelState};
use num_complex::Complex64;
use std::collections::{BTreeMap, VecDeque};

/// Reports averaged on each side of a step.
pub const WINDOW: usize = 4;
/// Floor of the step's standard deviation, rad (the loop's own transients).
const MIN_SIGMA_RAD: f64 = 0.06;
/// Threshold of the summed normalised steps: per satellite watched, and in all.
const MIN_SUM_PER_SAT: f64 = 8.0;
const MIN_SUM: f64 = 60.0;
/// Satellites that must jump together.
pub const MIN_SATELLITES: usize = 3;
/// Jumps this close in time are one event, s.
const CLUSTER_S: f64 = 0.006;
/// Reports in lock before a satellite is watched.
const STEADY_REPORTS: u32 = 50;
/// Weakest C/N0 watched, dB-Hz (below it the phase noise hides the jumps).
const MIN_CN0_DBHZ: f64 = 30.0;
/// Longest integration watched, s (a 20 ms integration smears a jump over a bit).
const MAX_T_COH_S: f64 = 0.005;

/// A discontinuity found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Discontinuity {
    /// Sample index of the earliest jump.
    pub sample: u64,
    /// Satellites whose carrier phase jumped.
    pub jumped: usize,
    /// Satellites watched at the time.
    pub watched: usize,
}

#[derive(Debug, Default)]
struct Watch {
    /// `(sample index, e^{i 2 phi}, |P|^2)` of the latest reports.
    recent: VecDeque<(u64, Complex64, f64)>,
    steady: u32,
    /// Sample index of the last report.
    last_sample: u64,
    /// Mean prompt power before the window, exponentially averaged (0: none yet).
    ref_power: f64,
}

/// Watches every satellite's carrier phase for a common jump.
#[derive(Debug)]
pub struct DiscontinuityMonitor {
    fs_hz: f64,
    watches: BTreeMap<u8, Watch>,
    /// Normalised phase steps not yet judged: `(sample index, PRN, (step / sigma_d)^2)`.
    steps: Vec<(u64, u8, f64)>,
}

impl DiscontinuityMonitor {
    /// A monitor for samples at `fs_hz`.
    pub fn new(fs_hz: f64) -> Self {
        Self {
            fs_hz,
            watches: BTreeMap::new(),
            steps: Vec::new(),
        }
    }

    /// Takes one channel report.
    pub fn push(&mut self, e: &ChannelEpoch) {
        let w = self.watches.entry(e.prn).or_default();
        let gap = e.sample_index.saturating_sub(w.last_sample) as f64 / self.fs_hz;
        w.last_sample = e.sample_index;
        let watched = e.state == ChannelState::Track
            && e.pll_lock
            && e.t_coh_s <= MAX_T_COH_S
            && e.cn0_dbhz >= MIN_CN0_DBHZ
            && e.prompt.norm_sqr() > 0.0
            && gap <= 2.5 * e.t_coh_s;
        if !watched {
            *w = Watch {
                last_sample: e.sample_index,
                ..Watch::default()
            };
            return;
        }
        let p = e.prompt / e.prompt.norm();
        w.recent
            .push_back((e.sample_index, p * p, e.prompt.norm_sqr()));
        if w.recent.len() > 2 * WINDOW {
            if let Some((_, _, old)) = w.recent.pop_front() {
                w.ref_power = if w.ref_power > 0.0 {
                    0.95 * w.ref_power + 0.05 * old
                } else {
                    old
                };
            }
        }
        w.steady += 1;
        if w.steady < STEADY_REPORTS || w.recent.len() < 2 * WINDOW {
            return;
        }
        let old: Complex64 = w.recent.iter().take(WINDOW).map(|x| x.1).sum();
        let new: Complex64 = w.recent.iter().skip(WINDOW).map(|x| x.1).sum();
        // The first new report may straddle the jump (partly cancelled): power from the rest.
        let new_power =
            w.recent.iter().skip(WINDOW + 1).map(|x| x.2).sum::<f64>() / (WINDOW - 1) as f64;
        // The signal is still there: a blockage or a code-phase jump collapses the power and
        // randomises the phase (a loss of signal, which the channel handles).
        if new_power < 0.5 * w.ref_power {
            return;
        }
        // Half the angle between the two means of e^{i 2 phi}: the step of phi.
        let step = 0.5 * (new * old.conj()).arg();
        let cn0 = 10f64.powf(e.cn0_dbhz / 10.0);
        let sigma = (1.0 / (2.0 * cn0 * e.t_coh_s)).sqrt();
        let sigma_d = (sigma * (2.0 / WINDOW as f64).sqrt()).max(MIN_SIGMA_RAD);
        self.steps
            .push((w.recent[WINDOW].0, e.prn, (step / sigma_d).powi(2)));
    }

    /// After all channels have reported up to sample `end`: the discontinuity among the steps
    /// old enough to be complete, if any. At each step's time `t`, every satellite's largest
    /// normalised step within [`CLUSTER_S`] after it is summed: `S = sum_i max z_i^2`. Without
    /// a jump `S` is a sum of maxima of a few `chi^2_1` (about 3 per satellite); a common jump
    /// uniform in +-90 deg adds `(pi/2)^2 / 3 / sigma_d^2` per satellite (about 50 at 45
    /// dB-Hz). A discontinuity needs `S > MIN_SUM_PER_SAT n + MIN_SUM` over the `n` satellites
    /// watched and [`MIN_SATELLITES`] of them with `z^2 > 25`.
    pub fn evaluate(&mut self, end: u64) -> Option<Discontinuity> {
        let settle = (0.02 * self.fs_hz) as u64;
        let cluster = (CLUSTER_S * self.fs_hz) as u64;
        let ready = end.saturating_sub(settle);
        self.steps.sort_unstable_by_key(|s| s.0);
        let mut found = None;
        for (i, &(t0, _, _)) in self.steps.iter().enumerate() {
            if t0 + cluster > ready {
                break;
            }
            let mut best: BTreeMap<u8, f64> = BTreeMap::new();
            for &(_, prn, z2) in self.steps[i..].iter().take_while(|s| s.0 < t0 + cluster) {
                let b = best.entry(prn).or_insert(0.0);
                *b = b.max(z2);
            }
            let n = best.len();
            let sum: f64 = best.values().sum();
            let strong = best.values().filter(|&&z2| z2 > 25.0).count();
            if n >= MIN_SATELLITES
                && strong >= MIN_SATELLITES
                && sum > MIN_SUM_PER_SAT * n as f64 + MIN_SUM
            {
                tracing::debug!("carrier phase steps at sample {t0}: {best:?}");
                found = Some(Discontinuity {
                    sample: t0,
                    jumped: strong,
                    watched: n,
                });
                break;
            }
        }
        self.steps.retain(|s| s.0 + cluster > ready);
        if found.is_some() {
            self.steps.clear();
            for w in self.watches.values_mut() {
                w.steady = 0;
                w.recent.clear();
            }
        }
        found
    }
}
