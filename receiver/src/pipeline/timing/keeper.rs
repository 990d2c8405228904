//! [`TimeKeeper`]: the one type navigation asks about time across gaps and outages.
//!
//! It holds what receiver and SV time need to survive lost samples and losses of the signal:
//! the satellites' SV times ([`SvTimeKeeper`]), the two gap detectors (a carrier-phase jump
//! common to the satellites, [`DiscontinuityMonitor`]; a common collapse of the prompt power,
//! [`CollapseMonitor`]), the carrier-phase steps awaited after a code realignment, the clock
//! of the last valid fix (to measure a gap from the clock bias once the time is back,
//! [`GapRecovery::length_from_bias_ms`]) and the recovery from a gap too long to measure
//! ([`LongGapRecovery`]). Navigation tells it what it sees (reports, fixes, clock steps,
//! refused carried times) and asks it what to do; it never edits its state.

use crate::pipeline::navigation::navdata::NavDecoder;
use crate::pipeline::timing::bit_edge::BitEdgeMonitor;
use crate::pipeline::timing::carrier_step::PhaseStep;
use crate::pipeline::timing::coarse_fix::CoarseOutcome;
use crate::pipeline::timing::code_jump::{Collapse, CollapseMonitor};
use crate::pipeline::timing::discontinuity::{Discontinuity, DiscontinuityMonitor, FoundBy};
use crate::pipeline::timing::long_gap::{LongGapRecovery, LongGapStart};
use crate::pipeline::timing::sv_time::{CarryNote, EdgeOffsets, GapRecovery, SvTimeKeeper};
use gpsrx_nav::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::time::GpsTime;
use gpsrx_nav::Llh;
use gpsrx_tracking::ChannelEpoch;

/// What the end of a block found in the reports.
#[derive(Debug, Clone, PartialEq)]
pub enum BlockEvent {
    /// Samples lost by whole milliseconds: the carrier phase jumped on every satellite; the
    /// channels must find their bit edges again.
    PhaseJump(Discontinuity),
    /// The prompt power collapsed on several satellites at once: their code must be searched
    /// again (samples lost by a fraction of a millisecond, or a blockage).
    Collapse(Collapse),
}

/// Receiver and SV time across gaps and outages (see the module documentation).
#[derive(Debug)]
pub struct TimeKeeper {
    /// Sampling rate, Hz.
    fs_hz: f64,
    /// The satellites' SV times kept over losses and gaps.
    sv: SvTimeKeeper,
    /// Watches for lost samples: carrier-phase jumps.
    monitor: DiscontinuityMonitor,
    /// Watches for lost samples: the data-bit edges moving together.
    edges: BitEdgeMonitor,
    /// Watches for lost samples: prompt power collapsing on several satellites at once.
    collapse: CollapseMonitor,
    /// After a code realignment: the jump's sample, the satellites moved and the sample from
    /// which their carrier phase is locked again, for the phase steps over the jump.
    pending_steps: Option<(u64, Vec<u8>, u64)>,
    /// The last valid fix: stream time (s), clock bias after any clock step (m), clock drift
    /// (m/s).
    last_clock: Option<(f64, f64, f64)>,
    /// The receiver time re-established after samples of unknown length were lost.
    long_gap: LongGapRecovery,
}

impl TimeKeeper {
    /// A keeper for samples at `fs_hz`, knowing no time yet.
    pub fn new(fs_hz: f64) -> Self {
        Self {
            fs_hz,
            sv: SvTimeKeeper::default(),
            monitor: DiscontinuityMonitor::new(fs_hz),
            edges: BitEdgeMonitor::new(),
            collapse: CollapseMonitor::new(),
            pending_steps: None,
            last_clock: None,
            long_gap: LongGapRecovery::default(),
        }
    }

    /// A channel report, to the gap detectors.
    pub fn push(&mut self, e: &ChannelEpoch) {
        self.monitor.push(e);
        self.edges.push(e);
        self.collapse.push(e);
    }

    /// After every channel has reported up to sample `end`: the carrier-phase steps awaited
    /// over a code jump (handed to the gap being recovered from), then a common collapse of
    /// the prompt power, else a carrier-phase jump common to the satellites, else their
    /// data-bit edges moved together (the carrier-phase steps then measured between the last
    /// flip at an old edge and the first at the new offset).
    pub fn end_block(&mut self, end: u64) -> Option<BlockEvent> {
        self.measure_pending_steps(end);
        if let Some(c) = self.collapse.evaluate(end, self.fs_hz) {
            return Some(BlockEvent::Collapse(c));
        }
        if let Some(d) = self.monitor.evaluate(end) {
            self.edges.reset();
            return Some(BlockEvent::PhaseJump(d));
        }
        let m = self.edges.evaluate()?;
        let steps = self.monitor.steps_between(m.before_sample, m.after_sample);
        self.monitor.reset();
        Some(BlockEvent::PhaseJump(Discontinuity {
            sample: m.before_sample,
            jumped: m.prns.len(),
            watched: m.watched,
            steps,
            found_by: FoundBy::BitEdges {
                offset_ms: m.offset_ms,
                after_sample: m.after_sample,
            },
        }))
    }

    /// The channels of `prns` were moved onto a code that jumped at sample `jump`, from
    /// sample `locked_from` their phase loops hold again: the carrier-phase detector waits
    /// until then, and the phase steps over the jump are measured after it.
    pub fn code_realigned(&mut self, jump: u64, prns: Vec<u8>, locked_from: u64) {
        self.monitor.hold_until(locked_from);
        self.pending_steps = Some((jump, prns, locked_from));
    }

    /// The carrier-phase steps over a code jump, once the phase loops of the moved channels
    /// hold again (up to sample `end`): handed to the gap being recovered from.
    fn measure_pending_steps(&mut self, end: u64) {
        let Some((jump, prns, from)) = self.pending_steps.as_ref() else {
            return;
        };
        if end < from + (0.02 * self.fs_hz) as u64 {
            return;
        }
        let steps = self.monitor.phase_steps(prns, *jump, Some(*from));
        tracing::debug!("carrier-phase steps over the code jump: {steps:?}");
        self.sv.set_gap_steps(steps);
        self.pending_steps = None;
    }

    /// Keeps the satellite's SV time from a report and carries it over to a new channel
    /// (`SvTimeKeeper::observe`).
    pub fn observe(
        &mut self,
        e: &ChannelEpoch,
        dec: &mut NavDecoder,
        usable: bool,
    ) -> Option<CarryNote> {
        self.sv.observe(e, dec, self.fs_hz, usable)
    }

    /// Where the SV time of `prn` stood at its last usable report, `(sample, TOW s)`, unless
    /// it is known only roughly.
    pub fn last_known(&self, prn: u8) -> Option<(u64, f64)> {
        self.sv.last_known(prn)
    }

    /// Whether an SV time of `prn` was ever kept (roughly or not).
    pub fn ever_known(&self, prn: u8) -> bool {
        self.sv.ever_known(prn)
    }

    /// Marks the SV time of `prn` (all with `None`) as rough: samples may have been lost.
    pub fn make_rough(&mut self, prn: Option<u8>) {
        self.sv.make_rough(prn);
    }

    /// Moves every kept SV time over a gap of `length_ms` once its length is known.
    pub fn move_over_gap(&mut self, length_ms: f64) {
        self.sv.move_over_gap(length_ms);
    }

    /// Samples were lost at stream time `t_s`: the gap is kept to be measured, with the clock
    /// of the last valid fix, the carrier-phase `steps` and `code_from_s`
    /// (`SvTimeKeeper::start_gap`).
    pub fn start_gap(&mut self, t_s: f64, steps: Vec<PhaseStep>, code_from_s: Option<f64>) {
        // The channels find their bit edges again: the flips seen so far are of no use.
        self.edges.reset();
        self.sv
            .start_gap(t_s, self.fs_hz, self.last_clock, steps, code_from_s);
    }

    /// A gap at `t_s` unless one is being recovered from already
    /// (`SvTimeKeeper::ensure_gap`).
    pub fn ensure_gap(&mut self, t_s: f64) {
        self.sv.ensure_gap(t_s, self.last_clock);
    }

    /// The gap being recovered from, if any.
    pub fn gap(&self) -> Option<&GapRecovery> {
        self.sv.gap()
    }

    /// The gap being recovered from, taken at the first valid fix after it, if its length
    /// was not resolved on the way.
    pub fn take_unmeasured_gap(&mut self) -> Option<GapRecovery> {
        self.sv.take_unmeasured_gap()
    }

    /// A carried SV time refused at the new bit edge (`SvTimeKeeper::note_refusal`).
    pub fn note_refusal(&mut self, t_s: f64, prn: u8, off_ms: f64) -> Option<(usize, EdgeOffsets)> {
        self.sv.note_refusal(t_s, prn, off_ms)
    }

    /// Offsets of refused carried times for the gap (`SvTimeKeeper::add_edge_offsets`).
    pub fn add_edge_offsets(&mut self, offsets: EdgeOffsets, t_s: f64) -> Option<f64> {
        self.sv.add_edge_offsets(offsets, t_s)
    }

    /// A receiver clock step of `step_ms` made while a gap is recovered from.
    pub fn note_clock_step(&mut self, step_ms: i64) {
        self.sv.note_clock_step(step_ms);
    }

    /// The receiver clock was stepped by `step_ms` over lost samples: the clock of the last
    /// fix is put on the stepped time scale.
    pub fn step_last_clock(&mut self, step_ms: i64) {
        if let Some((t, b, d)) = self.last_clock {
            self.last_clock = Some((t, b + step_ms as f64 * 1e-3 * SPEED_OF_LIGHT_MPS, d));
        }
    }

    /// A valid fix at stream time `t_s` at `llh`, with the clock bias after any clock step
    /// (m) and drift (m/s): the clock a later gap is measured against, and the a-priori
    /// position after a long gap.
    pub fn note_fix(&mut self, t_s: f64, bias_after_m: f64, drift_mps: f64, llh: Llh) {
        self.last_clock = Some((t_s, bias_after_m, drift_mps));
        self.long_gap.note_fix(llh);
    }

    /// The clock of the last valid fix, if any.
    pub fn last_clock(&self) -> Option<(f64, f64, f64)> {
        self.last_clock
    }

    /// Once the length of the gap being recovered from cannot be measured: how the time comes
    /// back (`LongGapRecovery::begin`).
    pub fn begin_long_gap(
        &mut self,
        rx_origin: Option<GpsTime>,
        ephemerides_known: bool,
    ) -> Option<LongGapStart> {
        let gap = self.sv.gap();
        self.long_gap
            .begin(gap, self.fs_hz, rx_origin, ephemerides_known)
    }

    /// The receiver clock step to a coarse-time outcome while a long gap is recovered from
    /// (`LongGapRecovery::clock_step_ms`).
    pub fn coarse_clock_step_ms(
        &self,
        outcome: &CoarseOutcome,
        rx_origin: Option<GpsTime>,
    ) -> Option<i64> {
        self.long_gap.clock_step_ms(outcome, rx_origin)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gap_is_measured_against_the_last_fix_on_the_stepped_time_scale() {
        let mut k = TimeKeeper::new(2.6e6);
        assert!(k.last_clock().is_none());
        k.note_fix(5.0, 300.0, 0.0, Llh::from_degrees(37.5, 127.0, 40.0));
        // The receiver clock stepped by 31 ms over a measured gap: the last fix's bias moves by
        // c 31 ms on the new time scale.
        k.step_last_clock(31);
        let (t, b, d) = k.last_clock().expect("a clock");
        assert_eq!((t, d), (5.0, 0.0));
        assert!(
            (b - (300.0 + 0.031 * SPEED_OF_LIGHT_MPS)).abs() < 1e-6,
            "{b}"
        );
        // A later gap keeps that clock; a second call does not replace the gap.
        k.ensure_gap(8.0);
        k.ensure_gap(9.0);
        let gap = k.gap().expect("a gap");
        assert_eq!(gap.t_s, 8.0);
        assert_eq!(gap.before, Some((t, b, d)));
    }
}
