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
//! wide, which settle within a fraction of a cycle; the stage states carry over bumplessly
//! ([`CarrierLoop::retuned`]: frequency and Doppler-rate memory). 18 Hz to 0.4 Hz takes six
//! stages and about 8 s.

use super::Channel;
use crate::carrier_loop::CarrierLoop;
use crate::config::LoopConfig;

/// Bandwidth ratio between consecutive stages; a target narrower than the running loop by more
/// than this is reached in stages.
pub const NARROW_RATIO: f64 = 2.0;
/// Length of a stage in units of its own `1 / Bn`: `Bn t` (2: about 2.5 time constants
/// `1 / w0` of a 3rd-order loop).
pub const STAGE_BN_S: f64 = 2.0;

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
    pub(super) fn carrier_toward(&mut self, target: &LoopConfig) -> Option<CarrierLoop> {
        let running = self.carrier.config();
        let bw = if running.pll_order > 0 {
            running.pll_bw_hz
        } else {
            running.fll_bw_hz
        };
        let (stage, narrowing) = next_stage(bw, target, self.ms_count);
        let next = self.carrier.retuned(&stage).ok()?;
        self.narrowing = narrowing;
        Some(next)
    }

    /// At a data-bit edge (integrations stay aligned), moves to the next narrowing stage once
    /// the current one has lasted its time.
    pub(super) fn maybe_narrow(&mut self, at_edge: bool) {
        let Some(n) = self.narrowing else {
            return;
        };
        if !at_edge || self.ms_count < n.until_ms {
            return;
        }
        let bw = self.carrier.config().pll_bw_hz;
        let (stage, narrowing) = next_stage(bw, &n.target, self.ms_count);
        if let Ok(next) = self.carrier.retuned(&stage) {
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
