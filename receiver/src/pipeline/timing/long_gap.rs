//! Receiver time re-established after samples of unknown length were lost (a long gap).
//!
//! The monitors measure lost samples up to about a second: the carrier-phase steps, the new
//! bit edges and the code ([`crate::pipeline::timing::gap_length`], [`crate::pipeline::timing::code_jump`],
//! whose fit reaches [`crate::pipeline::timing::code_jump::MAX_GAP_S`]). After a longer gap (a front
//! end dropping seconds, a file joined from two captures) the receiver, which counts samples,
//! runs late by the unknown length `g`: an SV time carried over it is off by `g` (whole data
//! bits, which the bit edges cannot show: `g (1 + f_D / f_L1)` falls within a few
//! microseconds of a 20 ms multiple for any whole-bit `g`), and a satellite computed at the
//! receiver's time is `g` too early along its orbit (about 5 km of error for 5 s). So every
//! SV time is forgotten, and the time comes back from the signal:
//!
//! - with ephemerides known (a navigation file, or decoded before the gap): from the
//!   coarse-time solver ([`crate::pipeline::timing::coarse_fix`], `gpsrx_nav::pvt::coarse_time`, van
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
//!   [`crate::pipeline::timing::quick_sync`]), which the navigation processor then uses to step the
//!   clock near GPS time.
//!
//! This module is part of the receiver's time keeping (with `sv_time`, `gap_length`,
//! `discontinuity`, `code_jump`, `carrier_step`, `quick_sync`, `coarse_fix` and `dating`): a
//! `timing/` wing behind one type that navigation asks would hold it.

use crate::pipeline::timing::coarse_fix::{CoarseFixer, CoarseOutcome};
use crate::pipeline::timing::sv_time::GapRecovery;
use gpsrx_nav::frames::Llh;
use gpsrx_nav::time::GpsTime;

/// Bound on the lost time the coarse-time solver may find, s.
pub const TIME_UNCERTAINTY_S: f64 = 150.0;
/// Smallest time correction accepted after lost samples, s: the receiver time is late by the
/// gap, never early (the clock bias is kept within 0.5 ms; 10 ms covers the solver's
/// millisecond-level time precision).
pub const MIN_CORRECTION_S: f64 = -0.010;

/// How the time comes back after a long gap ([`LongGapRecovery::begin`]).
#[derive(Debug)]
pub struct LongGapStart {
    /// The coarse-time fixer (a-priori: the last fix and the receiver time), when ephemerides
    /// and a fix before the gap are known.
    pub coarse: Option<CoarseFixer>,
    /// Frame sync from a TLM and HOW confirmed across satellites
    /// ([`crate::pipeline::timing::quick_sync`]): with ephemerides known a fix follows at once.
    pub quick_sync: bool,
}

/// After a long gap found by the code moves, no fix before this long after the channels were
/// moved onto the new code, s: the search places them within a few hundredths of a chip (up
/// to 10 m of range each), which the tracking DLL (0.5 Hz) pulls in over a second or more.
/// Measured on the shared GPS-SDR-SIM recording (8 satellites, `--allow-unhealthy`, 5 s cut):
/// fixes 1.0-1.2 s after the return were 10-12 m off (one beyond its stated 3-sigma), from
/// 1.5 s on at most 7.4 m, within it.
pub const CODE_SETTLE_S: f64 = 1.5;

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

    /// Once the length of the gap being recovered from (`gap`) cannot be measured (samples of
    /// unknown length lost, [`GapRecovery::unresolved`]) and it is not recovered from yet:
    /// how the time comes back (samples at `fs_hz`; `rx_origin` the receiver time of sample
    /// 0; `ephemerides_known` from a navigation file, or decoded for enough satellites).
    pub fn begin(
        &mut self,
        gap: Option<&GapRecovery>,
        fs_hz: f64,
        rx_origin: Option<GpsTime>,
        ephemerides_known: bool,
    ) -> Option<LongGapStart> {
        let t_s = gap
            .filter(|g| g.unresolved && g.length_ms.is_none())
            .map(|g| g.t_s)
            .filter(|&t| self.recovering != Some(t))?;
        self.recovering = Some(t_s);
        let coarse = match (self.last_fix, rx_origin, ephemerides_known) {
            (Some(llh), Some(t0), true) => Some(
                CoarseFixer::new(fs_hz, t0, llh)
                    .with_time_window(MIN_CORRECTION_S, TIME_UNCERTAINTY_S),
            ),
            _ => None,
        };
        tracing::info!(
            "the receiver time lost at {t_s:.3} s comes back from {}",
            if coarse.is_some() {
                "the coarse-time solver (ephemerides known) or the next time of week"
            } else {
                "the next time of week"
            }
        );
        Some(LongGapStart {
            coarse,
            quick_sync: ephemerides_known,
        })
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
    fn a_long_gap_is_recovered_from_once_and_the_clock_stepped_by_the_whole_milliseconds_lost() {
        let llh = Llh::from_degrees(37.5, 127.0, 40.0);
        let t0 = GpsTime::new(2190, 538_198.0);
        let mut r = LongGapRecovery::default();
        let gap = |t_s: f64, unresolved: bool| GapRecovery {
            unresolved,
            ..GapRecovery::new(t_s, None, Vec::new(), Some(t_s))
        };
        // A gap whose length is being measured: nothing to do.
        assert!(r
            .begin(Some(&gap(16.0, false)), 2.048e6, Some(t0), true)
            .is_none());
        // No fix before the gap: no a-priori position, the time of week gives the time.
        let s = r.begin(Some(&gap(16.0, true)), 2.048e6, Some(t0), true);
        assert!(s.is_some_and(|s| s.coarse.is_none() && s.quick_sync));
        // Once per gap.
        assert!(r
            .begin(Some(&gap(16.0, true)), 2.048e6, Some(t0), true)
            .is_none());
        r.note_fix(llh);
        // No ephemerides: the time of week (normal frame sync).
        let s = r.begin(Some(&gap(17.0, true)), 2.048e6, Some(t0), false);
        assert!(s.is_some_and(|s| s.coarse.is_none() && !s.quick_sync));
        let s = r.begin(Some(&gap(18.0, true)), 2.048e6, Some(t0), true);
        assert!(s.is_some_and(|s| s.coarse.is_some()));
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
