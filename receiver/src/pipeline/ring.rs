//! A window of recent samples, addressed by absolute sample index, shared read-only by all
//! channels while they correlate and refilled from the source between rounds.
//!
//! Memory is bounded: samples older than the slowest channel's next integration are dropped.

use gpsrx_samples::{SampleError, SampleSource};
use num_complex::Complex32;

/// Recent samples `[start, start + len)` of a stream.
#[derive(Debug, Default)]
pub struct SampleWindow {
    start: u64,
    data: Vec<Complex32>,
    /// Offset of the first live sample in `data` (dropped samples are compacted lazily).
    head: usize,
    end_of_stream: bool,
}

impl SampleWindow {
    /// An empty window at sample 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Absolute index of the first sample held.
    pub fn start(&self) -> u64 {
        self.start
    }

    /// Absolute index one past the last sample held.
    pub fn end(&self) -> u64 {
        self.start + (self.data.len() - self.head) as u64
    }

    /// Whether the source is exhausted.
    pub fn end_of_stream(&self) -> bool {
        self.end_of_stream
    }

    /// Samples `[from, from + len)` if all are held.
    pub fn get(&self, from: u64, len: usize) -> Option<&[Complex32]> {
        if from < self.start || from + len as u64 > self.end() {
            return None;
        }
        let a = self.head + (from - self.start) as usize;
        Some(&self.data[a..a + len])
    }

    /// Drops samples before `index`.
    pub fn discard_before(&mut self, index: u64) {
        let index = index.min(self.end());
        if index <= self.start {
            return;
        }
        self.head += (index - self.start) as usize;
        self.start = index;
        if self.head > self.data.len() / 2 {
            self.data.drain(..self.head);
            self.head = 0;
        }
    }

    /// Reads up to `n` more samples from `src`; returns how many arrived (0 at the end).
    /// A source whose first sample index is not contiguous with the window (a gap) restarts
    /// the window at the new index.
    pub fn fill(&mut self, src: &mut dyn SampleSource, n: usize) -> Result<usize, SampleError> {
        if self.end_of_stream {
            return Ok(0);
        }
        let old = self.data.len();
        self.data.resize(old + n, Complex32::new(0.0, 0.0));
        let (first, got) = src.read(&mut self.data[old..])?;
        self.data.truncate(old + got);
        if got == 0 {
            self.end_of_stream = true;
            return Ok(0);
        }
        if self.data.len() == got && self.head == 0 {
            // First read, or the window was empty: adopt the source's index.
            self.start = first;
        } else if first != self.end() - got as u64 {
            // A gap in the stream: keep only the new samples.
            self.data.drain(..old);
            self.head = 0;
            self.start = first;
        }
        Ok(got)
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
        assert_eq!(w.end(), 110);
        assert_eq!(w.get(103, 2).map(|s| s[0].re), Some(3.0));
        assert!(w.get(99, 2).is_none());
        assert!(w.get(109, 2).is_none());
        w.discard_before(106);
        assert_eq!(w.start(), 106);
        assert_eq!(w.get(106, 4).map(|s| s[3].re), Some(9.0));
        assert!(w.get(105, 1).is_none());
    }
}
