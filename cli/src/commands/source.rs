//! The recording a command reads: a file, a FIFO or standard input (`-`), read once, front to
//! back, and ended cleanly by Ctrl-C.
//!
//! After the first Ctrl-C (SIGINT) the source reports the end of the stream, so the receiver
//! finishes as at the end of a file and every output is completed and closed; a second Ctrl-C
//! exits at once (status 130).

use anyhow::Context;
use gpsrx_samples::{open_source, SampleError, SampleFormat, SampleSource, SourceConfig};
use num_complex::Complex32;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

/// Set by the first Ctrl-C.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Installs the Ctrl-C handler (once per process).
fn catch_interrupt() {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        let installed = ctrlc::set_handler(|| {
            if INTERRUPTED.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
            eprintln!("interrupted: finishing the outputs (Ctrl-C again to stop at once)");
        });
        if let Err(e) = installed {
            tracing::debug!("no Ctrl-C handler: {e}");
        }
    });
}

/// A source that ends at the first Ctrl-C.
struct Interruptible {
    inner: Box<dyn SampleSource>,
    next_index: u64,
}

impl SampleSource for Interruptible {
    fn fs_hz(&self) -> f64 {
        self.inner.fs_hz()
    }

    fn format(&self) -> &SampleFormat {
        self.inner.format()
    }

    fn total_samples(&self) -> Option<u64> {
        self.inner.total_samples()
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Ok((self.next_index, 0));
        }
        let (first, n) = self.inner.read(out)?;
        self.next_index = first + n as u64;
        Ok((first, n))
    }

    fn warnings(&self) -> Vec<String> {
        self.inner.warnings()
    }
}

/// Opens the recording of `cfg` (`-` is standard input) so that Ctrl-C ends it cleanly.
pub fn open_interruptible(cfg: &SourceConfig) -> anyhow::Result<Box<dyn SampleSource>> {
    let inner = open_source(cfg).with_context(|| format!("cannot read {}", cfg.path.display()))?;
    catch_interrupt();
    Ok(Box::new(Interruptible {
        inner,
        next_index: 0,
    }))
}
