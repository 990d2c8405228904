//! Receiver time re-established after samples of unknown length were lost (a long gap).
//!
//! The monitors measure lost samples up to about a second: the carrier-phase steps, the new
//! bit edges and the code ([`crate::pipeline::gap_length`], [`crate::pipeline::code_jump`],
//! whose fit reaches [`crate::pipeline::code_jump::MAX_GAP_S`]). After a longer gap (a front
//! end dropping seconds, a file joined from two captures) the receiver, which counts samples,
//! runs late by the unknown length `g`: an SV time carried over it is off by `g` (whole data
//! bits, which the bit edges cannot show: `g (1 + f_D / f_L1)` falls within a few
//! microseconds of a 20 ms multiple for any whole-bit `g`), and a satellite computed at the
//! receiver's time is `g` too early along its orbit (about 5 km of error for 5 s). So every
//! SV time is forgotten, and the time comes back from the signal:
//!
//! - with ephemerides known (a navigation file, or decoded before the gap): from the
//!   coarse-time solver ([`crate::pipeline::coarse_fix`], `gpsrx_nav::pvt::coarse_time`, van
//!   Diggelen ch. 4) once five or six satellites are tracked again with their bit edges, about
//!   a second after the signal returns. Its a-priori position is the last fix, its a-priori
//!   time the receiver's own at the common sample `k`, `T_rx(k) = T_0 + k / f_s`, which lies
//!   `g` before the true time and never after it: corrections below [`MIN_CORRECTION_S`] are
//!   refused, and the solver's bound is [`TIME_UNCERTAINTY_S`] (the solver is measured right
//!   for time errors alone up to 190-230 s). The receiver clock is then stepped by the
//!   correction's whole milliseconds, `round((T - T_rx(k)) / 1 ms)`, and every satellite's SV
//!   time is set; the first HOW of each confirms it, RAIM checks every fix.
//! - else (or when the solver refuses): from the first time of week decoded after the gap
//!   (frame sync, or a TLM and HOW confirmed across satellites,
//!   [`crate::pipeline::quick_sync`]), which the navigation processor then uses to step the
//!   clock near GPS time.
//!
//! This module is part of the receiver's time keeping (with `sv_time`, `gap_length`,
//! `discontinuity`, `code_jump`, `carrier_step`, `quick_sync`, `coarse_fix` and `dating`): a
//! `timing/` wing behind one type that navigation asks would hold it.

use crate::pipeline::coarse_fix::{CoarseFixer, CoarseOutcome};
use gpsrx_nav::frames::Llh;
use gpsrx_nav::time::GpsTime;

/// Bound on the lost time the coarse-time solver may find, s.
pub const TIME_UNCERTAINTY_S: f64 = 150.0;
/// Smallest time correction accepted after lost samples, s: the receiver time is late by the
/// gap, never early (the clock bias is kept within 0.5 ms; 10 ms covers the solver's
/// millisecond-level time precision).
pub const MIN_CORRECTION_S: f64 = -0.010;

/// The receiver time lost with samples of unknown length, re-established from the signal.
#[derive(Debug, Default)]
pub struct LongGapRecovery {
    /// Where the last valid fix was.
    last_fix: Option<Llh>,
    /// Stream time of the gap being recovered from, s.
    recovering: Option<f64>,
}

impl LongGapRecovery {
    /// A valid fix at `llh`: the a-priori position after a later gap.
    pub fn note_fix(&mut self, llh: Llh) {
        self.last_fix = Some(llh);
    }

    /// Whether the gap at stream time `t_s` is being recovered from already.
    pub fn recovering_from(&self, t_s: f64) -> bool {
        self.recovering == Some(t_s)
    }

    /// Samples of unknown length were lost at stream time `t_s` (samples at `fs_hz`; the
    /// receiver time of sample 0 is `rx_origin`): the coarse-time fixer that re-establishes
    /// the time, when `ephemerides_known` and a fix came before (else `None`: the time of week
    /// decoded after the gap gives it).
    pub fn start(
        &mut self,
        t_s: f64,
        fs_hz: f64,
        rx_origin: Option<GpsTime>,
        ephemerides_known: bool,
    ) -> Option<CoarseFixer> {
        self.recovering = Some(t_s);
        let (Some(llh), Some(t0), true) = (self.last_fix, rx_origin, ephemerides_known) else {
            return None;
        };
        Some(
            CoarseFixer::new(fs_hz, t0, llh).with_time_window(MIN_CORRECTION_S, TIME_UNCERTAINTY_S),
        )
    }

    /// The receiver clock step (ms) that puts the receiver time on the time of a coarse-time
    /// `outcome` while a gap is recovered from (`rx_origin`: the receiver time of sample 0):
    /// `round((T - T_rx(k)) / 1 ms)` at the outcome's stream time `k / f_s`.
    pub fn clock_step_ms(
        &self,
        outcome: &CoarseOutcome,
        rx_origin: Option<GpsTime>,
    ) -> Option<i64> {
        self.recovering?;
        let t_rx = rx_origin?.add_seconds(outcome.t_s);
        let lost_s = outcome.time.diff_s(t_rx);
        Some((lost_s * 1e3).round() as i64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(t_s: f64, time: GpsTime) -> CoarseOutcome {
        CoarseOutcome {
            t_s,
            time,
            time_correction_s: 0.0,
            position_shift_m: 0.0,
            sv_times: Vec::new(),
            check: String::new(),
        }
    }

    #[test]
    fn the_clock_is_stepped_by_the_whole_milliseconds_of_the_lost_time() {
        let llh = Llh::from_degrees(37.5, 127.0, 40.0);
        let t0 = GpsTime::new(2190, 538_198.0);
        let mut r = LongGapRecovery::default();
        // No fix before the gap: no a-priori position, the HOW gives the time.
        assert!(r.start(16.0, 2.048e6, Some(t0), true).is_none());
        r.note_fix(llh);
        // No ephemerides: the HOW gives the time.
        assert!(r.start(16.0, 2.048e6, Some(t0), false).is_none());
        assert!(r.start(16.0, 2.048e6, Some(t0), true).is_some());
        assert!(r.recovering_from(16.0) && !r.recovering_from(17.0));
        // 60.0123 s lost: at stream time 17 s the true time is t0 + 77.0123 s.
        let out = outcome(17.0, t0.add_seconds(77.0123));
        assert_eq!(r.clock_step_ms(&out, Some(t0)), Some(60_012));
        // Across the end of the week.
        let t0 = GpsTime::new(2190, 604_790.0);
        let out = outcome(5.0, GpsTime::new(2191, 0.0004));
        assert_eq!(r.clock_step_ms(&out, Some(t0)), Some(5_000));
        // Nothing to step without a receiver time.
        assert_eq!(r.clock_step_ms(&out, None), None);
    }
}
