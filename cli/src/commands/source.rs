//! The recording a command reads: a file, a FIFO or standard input (`-`), read once, front to
//! back, and ended cleanly by Ctrl-C.
//!
//! After the first Ctrl-C (SIGINT) the source reports the end of the stream, so the receiver
//! finishes as at the end of a file and every output is completed and closed; a second Ctrl-C
//! exits at once (status 130).
//!
//! A stream (standard input, a named pipe, a device) is read on a thread of its own, and the
//! command waits for its blocks a tenth of a second at a time, checking for Ctrl-C in between:
//! so Ctrl-C also ends a stream that sends nothing (an idle pipe), where a read would block
//! for ever. (Opening a named pipe waits for a writer before the handler is installed: Ctrl-C
//! then stops the command at once, as there is nothing to finish.)

use anyhow::Context;
use gpsrx_samples::capture_gaps::open_filling_capture_gaps;
use gpsrx_samples::stream_source::is_stdin_path;
use gpsrx_samples::{
    IntegerFormat, IntegerSamplesMut, SampleError, SampleFormat, SampleSource, SourceConfig,
};
use num_complex::Complex32;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError};
use std::sync::{Arc, Mutex, Once};
use std::time::Duration;

/// How often a wait for a stream's samples checks for Ctrl-C.
const INTERRUPT_POLL: Duration = Duration::from_millis(100);
/// Samples per block read by a stream's reader thread.
const STREAM_BLOCK: usize = 1 << 16;

/// Set by the first Ctrl-C.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether Ctrl-C ended the recording early.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

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

    fn integer_format(&self) -> Option<IntegerFormat> {
        self.inner.integer_format()
    }

    fn read_integer(&mut self, out: IntegerSamplesMut<'_>) -> Result<(u64, usize), SampleError> {
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Ok((self.next_index, 0));
        }
        let (first, n) = self.inner.read_integer(out)?;
        self.next_index = first + n as u64;
        Ok((first, n))
    }

    fn integer_gain(&self) -> f32 {
        self.inner.integer_gain()
    }

    fn warnings(&self) -> Vec<String> {
        self.inner.warnings()
    }
}

/// A block from a stream's reader thread: its first index and samples, or the error.
type Block = Result<(u64, Vec<Complex32>), SampleError>;

/// A stream read on a thread of its own, so that waiting for it can be interrupted.
struct Threaded {
    fs_hz: f64,
    format: SampleFormat,
    total: Option<u64>,
    blocks: Receiver<Block>,
    /// The block being handed out and how much of it is gone.
    current: Option<(u64, Vec<Complex32>, usize)>,
    /// The source's warnings, as of its latest read.
    warnings: Arc<Mutex<Vec<String>>>,
    ended: bool,
    next_index: u64,
}

impl Threaded {
    fn new(mut inner: Box<dyn SampleSource>) -> Threaded {
        let (fs_hz, format, total) = (inner.fs_hz(), inner.format().clone(), inner.total_samples());
        let (tx, blocks) = sync_channel::<Block>(4);
        let warnings = Arc::new(Mutex::new(Vec::new()));
        let shared = Arc::clone(&warnings);
        std::thread::spawn(move || loop {
            let mut buf = vec![Complex32::new(0.0, 0.0); STREAM_BLOCK];
            let block = inner.read(&mut buf).map(|(first, n)| {
                buf.truncate(n);
                (first, buf)
            });
            if let Ok(mut w) = shared.lock() {
                *w = inner.warnings();
            }
            let last = !matches!(&block, Ok((_, b)) if !b.is_empty());
            // The command has stopped listening (Ctrl-C, an error): so does the thread.
            if tx.send(block).is_err() || last {
                return;
            }
        });
        Threaded {
            fs_hz,
            format,
            total,
            blocks,
            current: None,
            warnings,
            ended: false,
            next_index: 0,
        }
    }
}

impl SampleSource for Threaded {
    fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    fn format(&self) -> &SampleFormat {
        &self.format
    }

    fn total_samples(&self) -> Option<u64> {
        self.total
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        while self.current.is_none() && !self.ended {
            if INTERRUPTED.load(Ordering::SeqCst) {
                return Ok((self.next_index, 0));
            }
            match self.blocks.recv_timeout(INTERRUPT_POLL) {
                Ok(Ok((first, b))) if !b.is_empty() => self.current = Some((first, b, 0)),
                Ok(Ok(_)) | Err(RecvTimeoutError::Disconnected) => self.ended = true,
                Ok(Err(e)) => {
                    self.ended = true;
                    return Err(e);
                }
                Err(RecvTimeoutError::Timeout) => {}
            }
        }
        let Some((first, block, used)) = &mut self.current else {
            return Ok((self.next_index, 0));
        };
        let n = out.len().min(block.len() - *used);
        out[..n].copy_from_slice(&block[*used..*used + n]);
        let index = *first + *used as u64;
        *used += n;
        if *used == block.len() {
            self.current = None;
        }
        self.next_index = index + n as u64;
        Ok((index, n))
    }

    fn warnings(&self) -> Vec<String> {
        self.warnings.lock().map(|w| w.clone()).unwrap_or_default()
    }
}

/// Whether `cfg` names a stream (standard input, a named pipe, a device), not a file.
fn is_stream(cfg: &SourceConfig) -> bool {
    is_stdin_path(&cfg.path)
        || std::fs::metadata(&cfg.path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Opens the recording of `cfg` (`-` is standard input) so that Ctrl-C ends it cleanly, also
/// while a stream sends nothing.
pub fn open_interruptible(cfg: &SourceConfig) -> anyhow::Result<Box<dyn SampleSource>> {
    // Samples the SigMF captures say were lost come back as zeros (the receiver's time runs on).
    let inner = open_filling_capture_gaps(cfg)
        .with_context(|| format!("cannot read {}", cfg.path.display()))?;
    catch_interrupt();
    let inner: Box<dyn SampleSource> = if is_stream(cfg) {
        Box::new(Threaded::new(inner))
    } else {
        inner
    };
    Ok(Box::new(Interruptible {
        inner,
        next_index: 0,
    }))
}
