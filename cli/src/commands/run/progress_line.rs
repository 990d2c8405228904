//! The progress of `gpsrx run` as a log line, for a standard error that is not a terminal
//! (a log file, a batch system, CI): where the terminal gets a progress bar, a pipe gets one
//! line every [`LINE_EVERY`] of wall time.

use gpsrx_receiver::pipeline::Progress;
use std::time::{Duration, Instant};

/// Wall time between two progress lines.
pub const LINE_EVERY: Duration = Duration::from_secs(5);

/// Writes a progress line at most every [`LINE_EVERY`].
#[derive(Debug)]
pub struct ProgressLine {
    fs_hz: f64,
    total_samples: Option<u64>,
    start: Instant,
    last: Instant,
}

impl ProgressLine {
    /// A line for a recording at `fs_hz` of `total_samples` (unknown for a stream).
    pub fn new(fs_hz: f64, total_samples: Option<u64>) -> Self {
        let now = Instant::now();
        Self {
            fs_hz,
            total_samples,
            start: now,
            last: now,
        }
    }

    /// Logs `p` when the last line is [`LINE_EVERY`] old: percent (of a file), seconds of
    /// signal, real-time factor, fixes and satellites.
    pub fn update(&mut self, p: &Progress) {
        if self.last.elapsed() < LINE_EVERY {
            return;
        }
        self.last = Instant::now();
        let signal_s = p.sample_index as f64 / self.fs_hz;
        let wall_s = self.start.elapsed().as_secs_f64().max(1e-9);
        let percent = self
            .total_samples
            .filter(|&n| n > 0)
            .map(|n| format!("{:.0} %, ", 100.0 * p.sample_index as f64 / n as f64))
            .unwrap_or_default();
        tracing::info!(
            "progress: {percent}{signal_s:.1} s of signal, {:.1}x real time, {} fixes, {} satellites ({} with ephemeris)",
            signal_s / wall_s,
            p.fixes,
            p.satellites,
            p.with_ephemeris
        );
    }
}
