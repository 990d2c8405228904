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

use crate::pipeline::timing::carrier_step::{phase_step, NcoPoint, PhaseStep};
use crate::pipeline::timing::modulo::nearest_remainder;
use gpsrx_tracking::{ChannelEpoch, ChannelState};
use num_complex::Complex64;
use std::collections::{BTreeMap, VecDeque};

/// Reports averaged on each side of a step.
pub const WINDOW: usize = 4;
/// Floor of the step's standard deviation, rad (the loop's own transients).
pub const MIN_SIGMA_RAD: f64 = 0.06;
/// Threshold of the summed normalised steps: per satellite watched, and in all.
pub const MIN_SUM_PER_SAT: f64 = 8.0;
/// See [`MIN_SUM_PER_SAT`].
pub const MIN_SUM: f64 = 60.0;
/// Normalised squared step `(step / sigma_d)^2` of a satellite that shows a jump clearly
/// (a 5 sigma step).
pub const STRONG_Z2: f64 = 25.0;
/// Satellites that must jump together.
pub const MIN_SATELLITES: usize = 3;
/// Jumps this close in time are one event, s.
pub const CLUSTER_S: f64 = 0.006;
/// Reports in lock before a satellite is watched.
pub const STEADY_REPORTS: u32 = 50;
/// Weakest C/N0 watched, dB-Hz (below it the phase noise hides the jumps).
pub const MIN_CN0_DBHZ: f64 = 30.0;
/// Reports before a jump that give the carrier's phase, frequency and rate there
/// ([`crate::pipeline::timing::carrier_step`]: up to a second).
pub const PRE_REPORTS: usize = 1000;
/// Reports after a jump over which its step is averaged.
pub const POST_REPORTS: usize = 32;
/// Reports left out on each side of a jump when its step is measured.
pub const GUARD: usize = 5;
/// Reports of carrier NCO history kept per satellite: enough for the steps over a code jump,
/// measured once the channels moved onto the new code hold the phase again.
pub const NCO_HISTORY: usize = PRE_REPORTS + 500;
/// Longest integration watched, s (a 20 ms integration smears a jump over a bit).
pub const MAX_T_COH_S: f64 = 0.005;

/// A discontinuity found.
#[derive(Debug, Clone, PartialEq)]
pub struct Discontinuity {
    /// Sample index of the jump (the median of the satellites that show it clearly).
    pub sample: u64,
    /// Satellites whose carrier phase jumped.
    pub jumped: usize,
    /// Satellites watched at the time.
    pub watched: usize,
    /// Per satellite: the step of its carrier phase over the jump
    /// ([`crate::pipeline::timing::carrier_step`]).
    pub steps: Vec<PhaseStep>,
    /// What showed it.
    pub found_by: FoundBy,
}

/// What showed a discontinuity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FoundBy {
    /// The carrier phases jumped together at `sample` (this monitor).
    CarrierPhase,
    /// The data-bit edges moved together by `offset_ms` somewhere between `sample` and
    /// `after_sample` (the timing wing's `bit_edge` monitor).
    BitEdges {
        /// The move, ms in 1..20.
        offset_ms: u64,
        /// The first sample known to follow the jump.
        after_sample: u64,
    },
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
    /// The carrier NCO of the latest reports.
    nco: VecDeque<NcoPoint>,
}

/// Watches every satellite's carrier phase for a common jump.
#[derive(Debug)]
pub struct DiscontinuityMonitor {
    fs_hz: f64,
    /// Steps before this sample are not judged (channels just moved onto a new code).
    hold_until: u64,
    watches: BTreeMap<u8, Watch>,
    /// Normalised phase steps not yet judged: `(sample index, PRN, (step / sigma_d)^2)`.
    steps: Vec<(u64, u8, f64)>,
}

impl DiscontinuityMonitor {
    /// A monitor for samples at `fs_hz`.
    pub fn new(fs_hz: f64) -> Self {
        Self {
            fs_hz,
            hold_until: 0,
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
        // The NCO history is kept whatever the lock (a jump unlocks the phase detector).
        w.nco.push_back(NcoPoint::of(e));
        if w.nco.len() > NCO_HISTORY {
            w.nco.pop_front();
        }
        if !watched {
            let nco = std::mem::take(&mut w.nco);
            *w = Watch {
                last_sample: e.sample_index,
                nco,
                ..Watch::default()
            };
            return;
        }
        let p = e.prompt / e.prompt.norm();
        w.recent
            .push_back((e.sample_index, p * p, e.prompt.norm_sqr()));
        if w.recent.len() > 2 * WINDOW {
            if let Some((_, _, old)) = w.recent.pop_front() {
                // The reference follows slow changes of the signal level, never a collapse
                // (a blockage must not become the new level).
                if w.ref_power <= 0.0 {
                    w.ref_power = old;
                } else if old > 0.3 * w.ref_power {
                    w.ref_power = 0.95 * w.ref_power + 0.05 * old;
                }
            }
        }
        w.steady += 1;
        if e.sample_index < self.hold_until {
            w.steady = 0;
        }
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

    /// No step before sample `sample` is judged (the phase loops of channels just moved onto
    /// a new code are pulling in).
    pub fn hold_until(&mut self, sample: u64) {
        self.hold_until = sample;
    }

    /// Per satellite of `prns`: the carrier-phase step over the jump at sample `jump` (the
    /// same instant for every satellite), from up to [`PRE_REPORTS`] reports before it to
    /// [`POST_REPORTS`] after it, leaving out [`GUARD`] reports on each side (the instant is
    /// known to a few reports: at 37-44 dB-Hz the best splits of the satellites scatter by
    /// +-2 ms), or, with `post_from`, the reports from that sample on (after a code jump the
    /// phase loop holds the signal again only later).
    pub fn phase_steps(&self, prns: &[u8], jump: u64, post_from: Option<u64>) -> Vec<PhaseStep> {
        prns.iter()
            .filter_map(|&prn| {
                let w = self.watches.get(&prn)?;
                let pts: Vec<NcoPoint> = w.nco.iter().copied().collect();
                // The first report that starts after the jump; the one before straddles it.
                let k = pts.iter().position(|p| p.sample > jump)?;
                let pre = &pts[k.saturating_sub(PRE_REPORTS + GUARD)..k.saturating_sub(GUARD)];
                let k_post = match post_from {
                    Some(from) => pts.iter().position(|p| p.sample >= from)?,
                    None => k + GUARD,
                };
                let post = &pts[k_post.min(pts.len())..(k_post + POST_REPORTS).min(pts.len())];
                let step = phase_step(prn, pre, post, self.fs_hz)?;
                // The two halves of `post` must agree (a loop slipping right after the jump
                // gives no clean step): within 0.3 rad, modulo pi.
                let half = post.len() / 2;
                let a = phase_step(prn, pre, &post[..half], self.fs_hz)?;
                let b = phase_step(prn, pre, &post[half..], self.fs_hz)?;
                let d = nearest_remainder(a.step_rad - b.step_rad, std::f64::consts::PI);
                (d.abs() < 0.3).then_some(step)
            })
            .collect()
    }

    /// After all channels have reported up to sample `end`: the discontinuity among the steps
    /// old enough to be complete, if any. At each strong step's time `t`, every satellite's largest
    /// normalised step within [`CLUSTER_S`] after it is summed: `S = sum_i max z_i^2`. Without
    /// a jump `S` is a sum of maxima of a few `chi^2_1` (about 3 per satellite); a common jump
    /// uniform in +-90 deg adds `(pi/2)^2 / 3 / sigma_d^2` per satellite (about 50 at 45
    /// dB-Hz). A discontinuity needs `S > MIN_SUM_PER_SAT n + MIN_SUM` over the `n` satellites
    /// watched and [`MIN_SATELLITES`] of them with `z^2 >` [`STRONG_Z2`].
    pub fn evaluate(&mut self, end: u64) -> Option<Discontinuity> {
        let settle = (0.02 * self.fs_hz) as u64;
        let cluster = (CLUSTER_S * self.fs_hz) as u64;
        let ready = end.saturating_sub(settle);
        self.steps.sort_unstable_by_key(|s| s.0);
        let mut found = None;
        // A discontinuity needs strong steps, so windows start only at those (the others
        // cannot open one that passes): linear in the steps, not quadratic.
        for (i, &(t0, _, z2)) in self.steps.iter().enumerate() {
            if t0 + cluster > ready {
                break;
            }
            if z2 <= STRONG_Z2 {
                continue;
            }
            // Per PRN: the largest normalised step, and where.
            let mut best: Vec<(u8, f64, u64)> = Vec::with_capacity(16);
            for &(at, prn, z2) in self.steps[i..].iter().take_while(|s| s.0 < t0 + cluster) {
                match best.iter_mut().find(|b| b.0 == prn) {
                    Some(b) if z2 > b.1 => *b = (prn, z2, at),
                    Some(_) => {}
                    None => best.push((prn, z2, at)),
                }
            }
            let n = best.len();
            let sum: f64 = best.iter().map(|b| b.1).sum();
            let strong: Vec<u64> = best
                .iter()
                .filter(|b| b.1 > STRONG_Z2)
                .map(|b| b.2)
                .collect();
            if n >= MIN_SATELLITES
                && strong.len() >= MIN_SATELLITES
                && sum > MIN_SUM_PER_SAT * n as f64 + MIN_SUM
            {
                tracing::debug!("carrier phase steps at sample {t0}: {best:?}");
                // The jump's instant: the median split of the satellites that show it clearly.
                let mut ats = strong;
                ats.sort_unstable();
                let jump = ats.get(ats.len() / 2).copied().unwrap_or(t0);
                let prns: Vec<u8> = best.iter().map(|b| b.0).collect();
                let steps = self.phase_steps(&prns, jump, None);
                found = Some(Discontinuity {
                    sample: jump,
                    jumped: ats.len(),
                    watched: n,
                    steps,
                    found_by: FoundBy::CarrierPhase,
                });
                break;
            }
        }
        self.steps.retain(|s| s.0 + cluster > ready);
        if found.is_some() {
            self.reset();
        }
        found
    }

    /// Forgets the steps and the carrier histories (a discontinuity was found, here or by
    /// another monitor).
    pub fn reset(&mut self) {
        self.steps.clear();
        for w in self.watches.values_mut() {
            w.steady = 0;
            w.recent.clear();
            w.nco.clear();
        }
    }

    /// Per satellite with a carrier history: the carrier-phase step over a jump known only
    /// to lie between samples `before` and `after` (the bit edges' move,
    /// `bit_edge`): measured from the reports before the one and after
    /// the other, so that neither side holds the jump.
    pub fn steps_between(&self, before: u64, after: u64) -> Vec<PhaseStep> {
        let prns: Vec<u8> = self.watches.keys().copied().collect();
        self.phase_steps(&prns, before, Some(after))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    const FS: f64 = 2.048e6;
    const FREQS: [f64; 8] = [
        -3120.4, -1877.9, -640.2, 199.1, 874.6, 1502.3, 2280.8, 3411.7,
    ];

    use crate::pipeline::test_support::Noise;

    /// A 1 ms report of satellite `i` at 45 dB-Hz whose signal phase is `2 pi f t + jump`
    /// against an NCO at `2 pi f t` (the loop has not reacted yet), with unit noise per arm
    /// and `power` times the nominal signal power.
    fn report(i: usize, k: u64, jump_rad: f64, power: f64, noise: &mut Noise) -> ChannelEpoch {
        let f = FREQS[i];
        let t = k as f64 * 1e-3;
        let amp = (2.0 * 10f64.powf(4.5) * 1e-3 * power).sqrt();
        let prompt =
            Complex64::from_polar(amp, jump_rad) + Complex64::new(noise.normal(), noise.normal());
        crate::pipeline::test_support::report(i as u8 + 1, k, prompt, f, f * t, 45.0)
    }

    /// Runs 8 satellites for 400 ms; from `at_ms` satellite `i` gets `jump(i)` and `power(i)`.
    fn run(
        at_ms: u64,
        jump: impl Fn(usize) -> f64,
        power: impl Fn(usize) -> f64,
    ) -> Option<Discontinuity> {
        let mut m = DiscontinuityMonitor::new(FS);
        let mut noise = Noise(0x9E37_79B9_7F4A_7C15);
        let mut found = None;
        for block in 0..40u64 {
            for i in 0..8 {
                for k in block * 10..(block + 1) * 10 {
                    let (j, p) = if k >= at_ms {
                        (jump(i), power(i))
                    } else {
                        (0.0, 1.0)
                    };
                    m.push(&report(i, k, j, p, &mut noise));
                }
            }
            if let Some(d) = m.evaluate(((block + 1) as f64 * 0.01 * FS) as u64) {
                found.get_or_insert(d);
            }
        }
        found
    }

    #[test]
    fn a_common_phase_jump_is_found_at_its_sample_with_its_steps() {
        // 31 ms lost: each carrier steps by 2 pi f g (modulo pi).
        let g = 0.031;
        let step = |i: usize| {
            let x = TAU * FREQS[i] * g;
            nearest_remainder(x, PI)
        };
        let d = run(200, step, |_| 1.0).expect("found");
        assert!(
            (d.sample as f64 / FS - 0.2).abs() < 0.004,
            "at {}",
            d.sample as f64 / FS
        );
        assert!(d.jumped >= MIN_SATELLITES);
        assert!(d.steps.len() >= 6, "{:?}", d.steps);
        for &PhaseStep {
            prn,
            step_rad: s,
            freq_hz: f,
            ..
        } in &d.steps
        {
            let i = usize::from(prn) - 1;
            let err = s - step(i);
            let err = nearest_remainder(err, PI);
            assert!(
                err.abs() < 0.15,
                "G{prn}: step {s:.3} against {:.3}",
                step(i)
            );
            assert!((f - FREQS[i]).abs() < 1.0, "G{prn}: {f} Hz");
        }
    }

    #[test]
    fn noise_a_lone_slip_and_a_blockage_are_not_lost_samples() {
        assert_eq!(run(200, |_| 0.0, |_| 1.0), None);
        // One satellite slips a quarter cycle.
        assert_eq!(
            run(200, |i| if i == 3 { PI / 2.0 } else { 0.0 }, |_| 1.0),
            None
        );
        // Every signal blocked: the power collapses, the phases are noise.
        assert_eq!(run(200, |i| i as f64 * 0.4, |_| 0.0), None);
    }
}
