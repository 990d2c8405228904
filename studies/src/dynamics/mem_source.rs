//! Simulated samples held in memory, replayed to each case like a recording.

use super::params::FS_HZ;
use gpsrx_samples::{SampleError, SampleFormat, SampleSource};
use num_complex::Complex32;

/// Complex baseband samples held in memory, read like a recording. Each scenario is generated
/// once (246 MB at 2.048 MHz for 15 s) and replayed for its 5 to 32 cases, which costs far less
/// than generating it again per case with [`if_sim::SimSource`](crate::if_sim::SimSource).
pub(super) struct MemSource<'a> {
    pub(super) data: &'a [Complex32],
    pub(super) pos: usize,
    pub(super) format: SampleFormat,
}

impl SampleSource for MemSource<'_> {
    fn fs_hz(&self) -> f64 {
        FS_HZ
    }

    fn format(&self) -> &SampleFormat {
        &self.format
    }

    fn total_samples(&self) -> Option<u64> {
        Some(self.data.len() as u64)
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let n = out.len().min(self.data.len() - self.pos);
        out[..n].copy_from_slice(&self.data[self.pos..self.pos + n]);
        let first = self.pos as u64;
        self.pos += n;
        Ok((first, n))
    }

    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}
