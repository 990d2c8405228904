//! How `gpsrx` ends: its exit status, the one-line error message on standard error, and standard
//! output written through a writer whose errors are reported instead of panicking.
//!
//! | status | meaning |
//! |---|---|
//! | 0 | done (also when standard output was closed early, e.g. `gpsrx ... \| head -1`) |
//! | 1 | an error: bad input, a file that cannot be read or written (the message says which) |
//! | 2 | `gpsrx run` (or `gpsrx demo`) processed the recording but made no valid fix (the summary says why) |
//! | 130 | a second Ctrl-C |

use gpsrx_receiver::config::ConfigError;
use gpsrx_receiver::snapshot::SnapshotError;
use gpsrx_samples::SampleError;
use std::io::{self, Write};

/// The exit status of `gpsrx run` when it ran to the end without a valid fix.
pub const EXIT_NO_VALID_FIX: u8 = 2;

/// How a command that did not fail ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Completion {
    /// It did its job (exit status 0).
    Done,
    /// `gpsrx run` ran to the end but made no valid fix (exit status [`EXIT_NO_VALID_FIX`]).
    NoValidFix,
}

impl Completion {
    /// The process exit status.
    pub fn exit_status(self) -> u8 {
        match self {
            Completion::Done => 0,
            Completion::NoValidFix => EXIT_NO_VALID_FIX,
        }
    }
}

/// Whether the error comes from writing to a closed pipe (`gpsrx ... | head`): by the Unix
/// convention the program then ends quietly with status 0.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<io::Error>()
            .is_some_and(|io| io.kind() == io::ErrorKind::BrokenPipe)
    })
}

/// The error and its causes on one line, `outer: cause: root`, each text once
/// ([`gpsrx_receiver::error_message`]), followed by the command-line option that gives what
/// the library says is missing or wrong ([`option_hint`]).
pub fn error_message(e: &anyhow::Error) -> String {
    let text = gpsrx_receiver::error_message(e.as_ref());
    match option_hint(e) {
        Some(option) => format!("{text} (option {option})"),
        None => text,
    }
}

/// The command-line option behind an error, from the variant of the first cause that has one:
/// the library's messages describe the input ("no sampling rate known", "no navigation data
/// were given"), not the flag that gives it.
pub fn option_hint(e: &anyhow::Error) -> Option<&'static str> {
    e.chain().find_map(option_for)
}

/// See [`option_hint`].
fn option_for(cause: &(dyn std::error::Error + 'static)) -> Option<&'static str> {
    if let Some(e) = cause.downcast_ref::<SampleError>() {
        return match e {
            SampleError::FormatUnknown { .. } => Some("--format"),
            SampleError::SampleRateUnknown { .. } | SampleError::BadSampleRate { .. } => {
                Some("--fs HZ")
            }
            SampleError::StreamNeedsFormatAndRate {
                format_missing,
                rate_missing,
                ..
            } => match (format_missing, rate_missing) {
                (true, true) => Some("--format and --fs HZ"),
                (true, false) => Some("--format"),
                _ => Some("--fs HZ"),
            },
            SampleError::IfOutOfRange { .. } => Some("--if HZ (and --fs HZ)"),
            SampleError::IfConflict { .. } => Some("--if HZ: leave it out to use the metadata"),
            SampleError::SkipBeyondEnd { .. } => Some("--skip S"),
            _ => None,
        };
    }
    if let Some(ConfigError::Setting { key, .. }) = cause.downcast_ref::<ConfigError>() {
        return match *key {
            "[run] week" => Some("--week WEEK"),
            "[run] approx_time" => Some("--time WEEK:TOW"),
            "[run] approx_llh" => Some("--approx-llh LAT,LON,H"),
            _ => None,
        };
    }
    if let Some(SnapshotError::NoEphemerides) = cause.downcast_ref::<SnapshotError>() {
        return Some("--nav FILE");
    }
    None
}

/// Standard output for the commands' results: a write error says it was standard output
/// (`cannot write to standard output: No space left on device`) and keeps its kind, so a
/// closed pipe is recognised by [`is_broken_pipe`].
pub fn stdout() -> Stdout {
    Stdout(io::stdout().lock())
}

/// See [`stdout`].
#[derive(Debug)]
pub struct Stdout(io::StdoutLock<'static>);

/// The message of a failed write to standard output.
fn stdout_error(e: io::Error) -> io::Error {
    io::Error::new(e.kind(), StdoutError(e))
}

/// A write to standard output failed (the operating system's error in the text, not as a
/// source, so the message carries it once).
#[derive(Debug)]
struct StdoutError(io::Error);

impl std::fmt::Display for StdoutError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot write to standard output: {}", self.0)
    }
}

impl std::error::Error for StdoutError {}

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf).map_err(stdout_error)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.0.write_all(buf).map_err(stdout_error)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.0.flush().map_err(stdout_error)
    }
}
