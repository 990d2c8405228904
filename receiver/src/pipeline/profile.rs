//! Where a run's time goes, stage by stage: wall-clock seconds measured with
//! [`std::time::Instant`] around each stage of [`crate::Receiver`] (a few readings per 40 ms
//! block, nothing measurable), reported in [`crate::RunSummary::profile`] (`gpsrx run
//! --profile` prints them).
//!
//! The stages follow the receiver's loop. Serial, on the calling thread, one after the other:
//! the cold start's search, the parallel rounds, the navigation and the completion of the
//! outputs at the end. Within a round the channels and a due search run side by side on the
//! rayon pool ([`crate::pipeline::channels::channel_manager::ChannelManager::work`]). Without
//! an INS or vector tracking, the navigation of a round runs on the calling thread while the
//! pool works the next round and reads the block after it (`Receiver::run`: a round is worked
//! again when the navigation's end of block asks for something else); its time then counts as
//! navigation and the rest of the round's as the round. Otherwise the navigation runs between
//! the rounds, the next block read beside it
//! ([`crate::pipeline::channels::ring::SampleWindow::read_during`]). Before the cold start, and
//! when the receiver is pushed samples, nothing overlaps. Each part is timed from its start to
//! its end on its own, so parts that overlap can add up to more than their stage, and each
//! includes the time its own parallel parts waited for a thread.

use std::time::{Duration, Instant};

/// Wall-clock seconds per stage of a run (see the module documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct StageTimes {
    /// The cold start's search of every wanted PRN, s.
    pub cold_start_s: f64,
    /// The parallel rounds (the channels and a due search side by side), s.
    pub rounds_s: f64,
    /// Within the rounds: the channels' correlations and loops, from start to end of each
    /// round's channel work, s.
    pub tracking_s: f64,
    /// Within the rounds: the background searches (and code realignments), each from its
    /// start to its end, s.
    pub search_s: f64,
    /// Searches run in the rounds.
    pub searches: usize,
    /// Reading the source (and converting it): beside the navigation, s.
    pub read_s: f64,
    /// The channels' reports to the navigation processor (observables, fixes, rows written to
    /// the sink), beside the next round or, between the rounds, while the next block is read;
    /// the channels started by a search, the samples dropped, s.
    pub navigation_s: f64,
    /// Rounds worked while the navigation processor took the reports of the round before.
    pub overlapped_rounds: usize,
    /// Of those, rounds worked again because the navigation's end of block asked for
    /// something else (an event, another search).
    pub redone_rounds: usize,
    /// At the end: the sink completing its outputs (plots, files), s.
    pub finish_s: f64,
}

impl StageTimes {
    /// The serial stages' sum: cold start, rounds, navigation and finish, s (the rest of a
    /// run's wall time is its setup: opening files, planning the FFTs).
    pub fn accounted_s(&self) -> f64 {
        self.cold_start_s + self.rounds_s + self.navigation_s + self.finish_s
    }
}

/// Runs `f` and returns its result with its wall time.
pub fn timed<R>(f: impl FnOnce() -> R) -> (R, Duration) {
    let t0 = Instant::now();
    let r = f();
    (r, t0.elapsed())
}

/// Runs `f` and adds its wall time, s, to `total`.
pub fn add_timed<R>(total: &mut f64, f: impl FnOnce() -> R) -> R {
    let (r, d) = timed(f);
    *total += d.as_secs_f64();
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timed_stages_add_up_and_the_serial_ones_are_accounted() {
        let mut t = StageTimes::default();
        let sleep = || std::thread::sleep(Duration::from_millis(20));
        add_timed(&mut t.rounds_s, sleep);
        add_timed(&mut t.rounds_s, sleep);
        add_timed(&mut t.navigation_s, sleep);
        let (v, d) = timed(|| 7);
        assert_eq!(v, 7);
        assert!(d < Duration::from_millis(20));
        // Sleeping never returns early; the slack covers a loaded machine.
        assert!((0.04..0.5).contains(&t.rounds_s), "{t:?}");
        assert!((0.02..0.5).contains(&t.navigation_s), "{t:?}");
        t.tracking_s = 5.0;
        assert_eq!(t.accounted_s(), t.rounds_s + t.navigation_s);
    }
}
