//! Narrowing the carrier loop in steps: the hand-over to a narrow (aided) loop without a
//! transient.
//!
//! A loop switched at once from the pull-in or tracking bandwidth (15-18 Hz) to a narrow aided
//! one (0.4 Hz) inherits the wide loop's frequency noise as its initial error. A frequency error
//! `df` in a loop of natural frequency `w0` rings with a phase excursion of about `df / w0`
//! cycles (`w0 = Bn / 0.7845` rad/s at 3rd order): 0.5 Hz against 0.51 rad/s is a cycle, enough
//! to slip and to make the lock detector drop the channel before a manoeuvre has even begun.
//! Halving the bandwidth at a time ([`NARROW_RATIO`]), each stage held for [`STAGE_BN_S`] / Bn
//! seconds (a few time constants), starts every stage with the errors of a loop only twice as
//! wide; the stage states carry over bumplessly ([`CarrierLoop::retuned`]: frequency and
//! Doppler-rate memory). 18 Hz to 0.4 Hz takes six stages and about 8 s.
//!
//! # The frequency and rate a stage starts from (issue 25)
//!
//! The memories of the running loop are not good enough for a 3rd-order loop: its lightly
//! damped pole pair (`(-0.149 +- 0.673 j) w0`, [`crate::phase_fit`]) keeps about 70 % of a
//! rate error over a stage of `2 / Bn`, while the next stage tolerates four times less
//! (`dr / w0^2` cycles). Measured on the simulator (static, perfect clock, 36 dB-Hz): the
//! hand-over left G29's rate memory at -1.82 Hz/s against a true -0.637 Hz/s, the stages
//! carried -0.83 Hz/s into the 0.94 Hz stage and -0.75 Hz/s into the 0.47 Hz one, whose phase
//! then ran to a quarter cycle: the Costas loop slipped and stayed 0.3-0.7 Hz off.
//!
//! So every stage (and the hand-over from pull-in) starts from the open-loop least-squares fit
//! of the carrier phase tracked since the phase locked
//! ([`crate::phase_fit::QuadraticPhaseFit`]): its frequency when its 1-sigma error costs the
//! new loop less than [`FIT_TOLERANCE_CYCLES`] (`sigma_f / w0`), its rate likewise
//! (`sigma_r / w0^2`), provided its latest samples show no slip
//! ([`MAX_END_RESIDUAL_CYCLES`]); otherwise (a short or disturbed window) from the running
//! loop's memories as before.

use super::{Channel, ChannelState};
use crate::carrier_loop::CarrierLoop;
use crate::config::LoopConfig;
use crate::loop_filter::omega0;

/// Bandwidth ratio between consecutive stages; a target narrower than the running loop by more
/// than this is reached in stages.
pub const NARROW_RATIO: f64 = 2.0;
/// Length of a stage in units of its own `1 / Bn`: `Bn t` (2: about 2.5 time constants
/// `1 / w0` of a 3rd-order loop).
pub const STAGE_BN_S: f64 = 2.0;
/// Largest phase excursion (cycles) the 1-sigma errors of the phase fit may cost a loop
/// started from it (`sigma_f / w0` and `sigma_r / w0^2`, each): 3 sigma within 1/8 cycle (45 deg, the
/// rule of thumb for a Costas PLL whose discriminator folds at 90 deg).
pub const FIT_TOLERANCE_CYCLES: f64 = 0.125 / 3.0;
/// Largest mean residual of the phase fit's latest samples, cycles: a Costas slip in the
/// middle of the window leaves them 0.12 cycle off ([`crate::phase_fit`]), a later one more;
/// the noise of 64 samples is below 0.015 cycle rms down to 30 dB-Hz at 1 ms (4 sigma).
pub const MAX_END_RESIDUAL_CYCLES: f64 = 0.06;
/// Longest window of the phase fit, s: a static receiver's Doppler rate changes by about
/// 1e-4 Hz/s^2, so a quadratic phase holds for far longer; under dynamics the residuals grow
/// and the fit is not used anyway.
pub const MAX_FIT_WINDOW_S: f64 = 30.0;

/// Where a channel's stepwise narrowing stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Narrowing {
    /// The loops being narrowed to.
    target: LoopConfig,
    /// The current stage ends at this `ms_count`.
    until_ms: u64,
}

/// The stage that follows a loop of `bw_hz` on the way to `target`: the target itself when it
/// is within [`NARROW_RATIO`] (`None` narrowing), else the target's settings at `bw_hz /`
/// [`NARROW_RATIO`] (limited by the target's `Bn T`), held from `now_ms` for [`STAGE_BN_S`] /
/// Bn.
pub(super) fn next_stage(
    bw_hz: f64,
    target: &LoopConfig,
    now_ms: u64,
) -> (LoopConfig, Option<Narrowing>) {
    if !(bw_hz.is_finite() && target.pll_order > 0 && target.pll_bw_hz * NARROW_RATIO < bw_hz) {
        return (*target, None);
    }
    let max_bw = crate::config::MAX_BN_T / target.t_coh_s;
    let stage_bw = (bw_hz / NARROW_RATIO).min(max_bw);
    let stage = LoopConfig {
        pll_bw_hz: stage_bw,
        ..*target
    };
    let stage_ms = (STAGE_BN_S / stage_bw * 1e3).ceil() as u64;
    (
        stage,
        Some(Narrowing {
            target: *target,
            until_ms: now_ms + stage_ms,
        }),
    )
}

impl Channel {
    /// The carrier loop for `target` loops from the running one: the first narrowing stage
    /// when `target` is much narrower (and the narrowing started), else `target`, with the
    /// running loop's frequency and rate memory.
    ///
    /// Also returns whether the new loop starts from the phase fit ([`Channel::retune`]).
    pub(super) fn carrier_toward(&mut self, target: &LoopConfig) -> Option<(CarrierLoop, bool)> {
        let running = self.carrier.config();
        let bw = if running.pll_order > 0 {
            running.pll_bw_hz
        } else {
            running.fll_bw_hz
        };
        let (stage, narrowing) = next_stage(bw, target, self.ms_count);
        let next = self.retune(&stage)?;
        self.narrowing = narrowing;
        Some(next)
    }

    /// The running carrier loop with the settings `stage`, starting from the phase fit's
    /// frequency and Doppler rate (evaluated at the middle of the next interval) when the fit
    /// is good enough for it ([`FIT_TOLERANCE_CYCLES`]), else from the running loop's memories
    /// ([`CarrierLoop::retuned`]). The flag says which.
    fn retune(&self, stage: &LoopConfig) -> Option<(CarrierLoop, bool)> {
        let mut next = self.carrier.retuned(stage).ok()?;
        let (freq, rate) = self.usable_fit(stage);
        if let Some(f) = freq {
            next.shift_base_hz(f - next.frequency_memory_hz());
        }
        if let Some(r) = rate {
            next.preset_doppler_rate(r);
        }
        Some((next, rate.is_some()))
    }

    /// The phase fit's frequency and rate at the middle of the next interval, each if a loop
    /// `stage` may start from it: its 1-sigma error costs that loop at most
    /// [`FIT_TOLERANCE_CYCLES`] (`sigma_f / w0`, `sigma_r / w0^2`), and the latest samples
    /// show no slip ([`MAX_END_RESIDUAL_CYCLES`]). The two are judged apart: a short window
    /// gives a usable frequency long before a usable rate.
    fn usable_fit(&self, stage: &LoopConfig) -> (Option<f64>, Option<f64>) {
        if stage.pll_order == 0 {
            return (None, None);
        }
        let t_s = self.next_sample as f64 / self.fs_hz + 0.5 * stage.t_coh_s;
        let w0 = omega0(stage.pll_order, stage.pll_bw_hz);
        let Some(fit) = self
            .phase_fit
            .estimate(t_s)
            .filter(|fit| fit.end_residual_cycles.abs() <= MAX_END_RESIDUAL_CYCLES)
        else {
            return (None, None);
        };
        let freq = (fit.freq_sigma_hz / w0 <= FIT_TOLERANCE_CYCLES).then_some(fit.freq_hz);
        let rate =
            (fit.rate_sigma_hz_s / (w0 * w0) <= FIT_TOLERANCE_CYCLES).then_some(fit.rate_hz_s);
        (freq, rate)
    }

    /// Whether the phase fit has samples (the phase has been locked since its last reset):
    /// the pull-in's NCO-frequency rate fit is then not used, usable fit or not (it spans the
    /// unlocked part of the pull-in too: +8.4 Hz/s against a true -0.09 Hz/s at 34 dB-Hz,
    /// measured, which a 7.5 Hz stage turned into a 1.4 Hz frequency error).
    pub(super) fn phase_fit_started(&self) -> bool {
        !self.phase_fit.is_empty()
    }

    /// Whether a recovering channel may hand over to `target` loops: at once for loops without
    /// a rate memory, else once the phase fit is good enough for the first stage toward them
    /// (the pull-in loop's rate memory after the kick that lost the lock is no start for a
    /// narrow 3rd-order loop; measured: a 1 Hz loop slipped again 0.5 s after every such
    /// hand-over). The recovery's time limit bounds the wait.
    pub(super) fn recovery_ready(&self, target: &LoopConfig) -> bool {
        if target.pll_order < 3 {
            return true;
        }
        let running = self.carrier.config();
        let bw = if running.pll_order > 0 {
            running.pll_bw_hz
        } else {
            running.fll_bw_hz
        };
        let (stage, _) = next_stage(bw, target, self.ms_count);
        let (freq, rate) = self.usable_fit(&stage);
        freq.is_some() && rate.is_some()
    }

    /// Adds the interval just closed to the phase fit: at its middle time, the NCO's mean
    /// phase over it less the feed-forward's, plus the discriminator output
    /// `phase_error_cycles`. Fed while the phase-lock indicator says locked (in pull-in,
    /// recovery and tracking; not in a weak pull-in's frequency stage, whose sums are not
    /// aligned); the fit starts again when the lock indicator is out (a slip would corrupt
    /// it) and after [`MAX_FIT_WINDOW_S`]; when the aid comes or goes its samples are moved
    /// onto the new reference ([`crate::phase_fit::QuadraticPhaseFit::subtract_trajectory`]).
    pub(super) fn feed_phase_fit(&mut self, phase_error_cycles: f64) {
        let (s0, _, ph0, _) = self.acc_start;
        let dur_s = (self.next_sample.saturating_sub(s0)) as f64 / self.fs_hz;
        let ff = self.acc_feedforward_hz.unwrap_or(0.0);
        let ff_mid = self.ff_phase_cycles + 0.5 * ff * dur_s;
        self.ff_phase_cycles += ff * dur_s;
        let t_mid = (s0 as f64 / self.fs_hz) + 0.5 * dur_s;
        let feeding = self.state != ChannelState::Lost
            && self.pll_lock.locked()
            && !self.weak_frequency_stage()
            && !self.coasting_on_aid();
        if !feeding || self.phase_fit.span_s(t_mid) > MAX_FIT_WINDOW_S {
            self.phase_fit.reset();
        }
        if feeding {
            let y = 0.5 * (ph0 + self.carrier_phase_cycles) - ff_mid + phase_error_cycles;
            self.phase_fit.push(
                t_mid,
                y,
                self.carrier_freq_hz - self.ff_applied_hz.unwrap_or(0.0),
            );
        }
        if let Some((t_c, f, rate)) = self.aid_switched.take() {
            self.phase_fit.subtract_trajectory(t_c, f, rate);
        }
    }

    /// At a data-bit edge (integrations stay aligned), moves to the next narrowing stage once
    /// the current one has lasted its time.
    pub(super) fn maybe_narrow(&mut self, at_edge: bool) {
        let Some(n) = self.narrowing else {
            return;
        };
        if !at_edge || self.ms_count < n.until_ms || self.coasting_on_aid() {
            return;
        }
        let bw = self.carrier.config().pll_bw_hz;
        let (stage, narrowing) = next_stage(bw, &n.target, self.ms_count);
        if let Some((next, _)) = self.retune(&stage) {
            self.carrier = next;
        }
        self.narrowing = narrowing;
    }

    /// Whether the carrier loop is on its way down to a narrower bandwidth.
    pub fn narrowing(&self) -> bool {
        self.narrowing.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_narrow_target_is_reached_by_halving_and_a_near_one_at_once() {
        let target = LoopConfig {
            pll_order: 3,
            pll_bw_hz: 0.4,
            fll_order: 0,
            fll_bw_hz: 0.0,
            ..LoopConfig::default()
        };
        let (mut bw, mut now, mut stages, mut total_ms) = (18.0, 0u64, Vec::new(), 0u64);
        loop {
            let (stage, n) = next_stage(bw, &target, now);
            stages.push(stage.pll_bw_hz);
            let Some(n) = n else { break };
            assert_eq!(stage.pll_order, 3);
            total_ms += n.until_ms - now;
            now = n.until_ms;
            bw = stage.pll_bw_hz;
        }
        assert_eq!(stages, vec![9.0, 4.5, 2.25, 1.125, 0.5625, 0.4]);
        // Each stage 2 / Bn: 0.22 + 0.44 + 0.89 + 1.78 + 3.56 s.
        assert!((6_800..7_000).contains(&total_ms), "{total_ms} ms");
        let (stage, n) = next_stage(0.7, &target, 0);
        assert_eq!((stage.pll_bw_hz, n), (0.4, None));
    }
}
