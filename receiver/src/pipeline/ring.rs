//! A window of recent samples, addressed by absolute sample index, shared read-only by all
//! channels while they correlate and refilled from the source between rounds — or during
//! them: [`SampleWindow::fill_during`] reads the next block into spare room behind the
//! samples held while the channels work on those.
//!
//! Memory is bounded: samples older than the slowest channel's next integration are dropped.
//! Nothing is allocated or zeroed per block in the steady state: the buffer keeps its size and
//! the live samples are moved to its front only when the dropped prefix is as long as they
//! are.

use gpsrx_samples::{SampleError, SampleSource};
use num_complex::Complex32;

/// Samples processed per block, as a fraction of a second (10 ms). 40 ms blocks measured no
/// faster on 2 cores, with more memory.
const BLOCK_S: f64 = 0.01;

/// Samples per processing block (10 ms of signal) at `fs_hz`: the unit in which the window is
/// filled and the channels work.
pub fn block_samples(fs_hz: f64) -> usize {
    ((fs_hz * BLOCK_S).ceil() as usize).max(1)
}

/// Recent samples `[start, start + len)` of a stream.
#[derive(Debug, Default)]
pub struct SampleWindow {
    start: u64,
    /// `data[head..tail]` are the live samples; `data[tail..]` is room for the next reads
    /// (initialised once, when the buffer grows).
    data: Vec<Complex32>,
    head: usize,
    tail: usize,
    end_of_stream: bool,
}

/// A read-only view of the samples a [`SampleWindow`] holds.
#[derive(Debug, Clone, Copy)]
pub struct SampleView<'a> {
    start: u64,
    data: &'a [Complex32],
}

impl<'a> SampleView<'a> {
    /// Absolute index of the first sample held.
    pub fn start(&self) -> u64 {
        self.start
    }

    /// Absolute index one past the last sample held.
    pub fn end(&self) -> u64 {
        self.start + self.data.len() as u64
    }

    /// The samples before `limit` only (none when `limit` is at or before the start).
    pub fn until(self, limit: u64) -> SampleView<'a> {
        let n = limit.saturating_sub(self.start).min(self.data.len() as u64) as usize;
        SampleView {
            start: self.start,
            data: &self.data[..n],
        }
    }

    /// Samples `[from, from + len)` if all are held.
    pub fn get(&self, from: u64, len: usize) -> Option<&'a [Complex32]> {
        if from < self.start || from + len as u64 > self.end() {
            return None;
        }
        let a = (from - self.start) as usize;
        Some(&self.data[a..a + len])
    }
}

impl SampleWindow {
    /// An empty window at sample 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// The samples held.
    pub fn view(&self) -> SampleView<'_> {
        SampleView {
            start: self.start,
            data: &self.data[self.head..self.tail],
        }
    }

    /// Absolute index of the first sample held.
    pub fn start(&self) -> u64 {
        self.start
    }

    /// Absolute index one past the last sample held.
    pub fn end(&self) -> u64 {
        self.start + (self.tail - self.head) as u64
    }

    /// Whether the source is exhausted.
    pub fn end_of_stream(&self) -> bool {
        self.end_of_stream
    }

    /// Samples `[from, from + len)` if all are held.
    pub fn get(&self, from: u64, len: usize) -> Option<&[Complex32]> {
        self.view().get(from, len)
    }

    /// Drops samples before `index`.
    pub fn discard_before(&mut self, index: u64) {
        let index = index.min(self.end());
        if index <= self.start {
            return;
        }
        self.head += (index - self.start) as usize;
        self.start = index;
        // Compact when the dropped prefix is as long as the live samples: at most one copy per
        // sample dropped, and the buffer stays within twice the live span plus one block (the
        // background search holds up to half a second: 32 MB at 4 MHz, not 80).
        if self.head >= self.tail - self.head {
            self.data.copy_within(self.head..self.tail, 0);
            self.tail -= self.head;
            self.head = 0;
        }
    }

    /// Appends samples that follow the ones held (a stream pushed block by block).
    pub fn push(&mut self, samples: &[Complex32]) {
        if self.data.len() < self.tail + samples.len() {
            self.data
                .resize(self.tail + samples.len(), Complex32::new(0.0, 0.0));
        }
        self.data[self.tail..self.tail + samples.len()].copy_from_slice(samples);
        self.tail += samples.len();
    }

    /// Reads up to `n` more samples from `src`; returns how many arrived (0 at the end).
    /// A source whose first sample index is not contiguous with the window (a gap) restarts
    /// the window at the new index.
    pub fn fill(&mut self, src: &mut dyn SampleSource, n: usize) -> Result<usize, SampleError> {
        Ok(self.fill_during(src, n, |_| ())?.0)
    }

    /// [`SampleWindow::fill`] while `work` runs on the samples held before it (concurrently,
    /// rayon `join`); returns the samples read and `work`'s result. `work` runs even when the
    /// read fails or the source has ended.
    pub fn fill_during<R: Send>(
        &mut self,
        src: &mut dyn SampleSource,
        n: usize,
        work: impl FnOnce(SampleView<'_>) -> R + Send,
    ) -> Result<(usize, R), SampleError> {
        if self.end_of_stream {
            return Ok((0, work(self.view())));
        }
        if self.data.len() < self.tail + n {
            self.data.resize(self.tail + n, Complex32::new(0.0, 0.0));
        }
        let (held, room) = self.data.split_at_mut(self.tail);
        let view = SampleView {
            start: self.start,
            data: &held[self.head..],
        };
        let room = &mut room[..n];
        let (read, r) = rayon::join(|| src.read(room), || work(view));
        let (first, got) = read?;
        if got == 0 {
            self.end_of_stream = true;
            return Ok((0, r));
        }
        if self.tail == self.head {
            // First read, or the window was empty: adopt the source's index.
            self.start = first;
        } else if first != self.end() {
            // A gap in the stream: keep only the new samples.
            self.head = self.tail;
            self.start = first;
        }
        self.tail += got;
        Ok((got, r))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn get_and_discard_by_absolute_index() {
        let mut w = SampleWindow::new();
        w.start = 100;
        w.data = (0..10).map(|i| Complex32::new(i as f32, 0.0)).collect();
        w.tail = 10;
        assert_eq!(w.end(), 110);
        assert_eq!(w.get(103, 2).map(|s| s[0].re), Some(3.0));
        assert!(w.get(99, 2).is_none());
        assert!(w.get(109, 2).is_none());
        w.discard_before(106);
        assert_eq!(w.start(), 106);
        assert_eq!(w.get(106, 4).map(|s| s[3].re), Some(9.0));
        assert!(w.get(105, 1).is_none());
    }

    /// A source counting up from `first`: sample k is k + 0j.
    struct Counter {
        next: u64,
        end: u64,
    }

    impl SampleSource for Counter {
        fn fs_hz(&self) -> f64 {
            1e3
        }
        fn format(&self) -> &gpsrx_samples::SampleFormat {
            &gpsrx_samples::SampleFormat::Cf32Le
        }
        fn total_samples(&self) -> Option<u64> {
            None
        }
        fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
            let first = self.next;
            let n = (out.len() as u64).min(self.end - self.next) as usize;
            for (k, o) in out[..n].iter_mut().enumerate() {
                *o = Complex32::new((first + k as u64) as f32, 0.0);
            }
            self.next += n as u64;
            Ok((first, n))
        }
        fn warnings(&self) -> Vec<String> {
            Vec::new()
        }
    }

    #[test]
    fn fill_during_shows_the_held_samples_and_appends_the_read_ones() {
        let mut src = Counter {
            next: 50,
            end: 2000,
        };
        let mut w = SampleWindow::new();
        let mut seen_ends = Vec::new();
        for round in 0..40u64 {
            let (got, seen) = w
                .fill_during(&mut src, 30, |v| {
                    // The work sees exactly what was held before this read, values = indices.
                    let ok = (v.start()..v.end())
                        .all(|i| v.get(i, 1).map(|s| s[0].re) == Some(i as f32));
                    (v.end(), ok)
                })
                .unwrap_or_else(|e| panic!("{e}"));
            assert!(seen.1, "round {round}: view holds wrong samples");
            seen_ends.push(seen.0);
            assert_eq!(got, 30);
            assert_eq!(w.end(), 50 + 30 * (round + 1));
            // Keep the last 45 samples, as a slow channel would.
            w.discard_before(w.end().saturating_sub(45));
            assert!(
                w.data.len() <= 2 * 45 + 30 + 30,
                "buffer {} grew",
                w.data.len()
            );
        }
        // Each round's work saw the window as it was before the round's read.
        assert_eq!(seen_ends[0], 0);
        assert!(seen_ends[1..]
            .iter()
            .enumerate()
            .all(|(k, &e)| e == 50 + 30 * (k as u64 + 1)));
        // Every held sample is still its own index after the compactions.
        let v = w.view();
        assert!((v.start()..v.end()).all(|i| v.get(i, 1).map(|s| s[0].re) == Some(i as f32)));
    }
}
