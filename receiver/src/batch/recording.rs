//! One recording of a batch: its configuration, source and assistance from a
//! [`RecordingSpec`], and a run of the [`Receiver`] over it.

use super::manifest::RecordingSpec;
use super::options::config_with_options;
use crate::config::{ConfigError, ReceiverConfig};
use crate::output::{FileSink, OutputError};
use crate::pipeline::{Assistance, AssistanceError, AssistanceFiles, Receiver, ReceiverError};
use crate::pipeline::{RunSummary, Sink};
use gpsrx_samples::sim::scenario::{BUILTIN_NAV, BUILTIN_NAV_TEXT};
use gpsrx_samples::{SampleError, SampleSource, SourceConfig};
use std::path::Path;

/// Why a recording could not be processed. The message names the recording's problem as
/// `gpsrx run` would.
#[derive(Debug, thiserror::Error)]
pub enum RecordingError {
    /// The options or configuration file.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The recording cannot be read.
    #[error("cannot read {path}: {source}")]
    Source {
        /// The recording.
        path: String,
        /// Why.
        #[source]
        source: SampleError,
    },
    /// An assistance file.
    #[error(transparent)]
    Assistance(#[from] AssistanceError),
    /// The built-in navigation data.
    #[error("the built-in navigation data: {0}")]
    BuiltinNav(gpsrx_nav::rinex_nav::RinexError),
    /// The receiver stopped.
    #[error(transparent)]
    Receiver(#[from] ReceiverError),
    /// The output directory.
    #[error(transparent)]
    Output(#[from] OutputError),
}

impl RecordingSpec {
    /// The receiver configuration: defaults, then the `config` file, then the options;
    /// validated.
    pub fn receiver_config(&self) -> Result<ReceiverConfig, ConfigError> {
        let text = match &self.config {
            Some(p) => Some((
                std::fs::read_to_string(p).map_err(|source| ConfigError::Read {
                    path: p.display().to_string(),
                    source,
                })?,
                p.display().to_string(),
            )),
            None => None,
        };
        config_with_options(
            text.as_ref().map(|(t, p)| (t.as_str(), p.as_str())),
            &self.options,
        )
    }

    /// How to read the recording.
    pub fn source_config(&self) -> Result<SourceConfig, RecordingError> {
        let format = match &self.format {
            Some(f) => Some(f.parse().map_err(|source| self.source_error(source))?),
            None => None,
        };
        Ok(SourceConfig {
            path: self.path.clone(),
            format,
            fs_hz: self.fs_hz,
            if_hz: self.if_hz,
            invert_q: self.invert_q,
            skip_s: self.skip_s,
            duration_s: self.duration_s,
        })
    }

    /// The navigation file (or the built-in one) as assistance, with the recording's start
    /// time from its SigMF metadata.
    pub fn assistance(&self, source: &SourceConfig) -> Result<Assistance, RecordingError> {
        let mut assistance = match self.nav.as_deref() {
            Some(BUILTIN_NAV) => Assistance {
                nav: Some(
                    gpsrx_nav::rinex_nav::parse_rinex_nav(BUILTIN_NAV_TEXT)
                        .map_err(RecordingError::BuiltinNav)?,
                ),
                ..Assistance::default()
            },
            nav => Assistance::read(&AssistanceFiles {
                nav: nav.map(Path::new),
                ..AssistanceFiles::default()
            })?,
        };
        assistance.recording_start = recording_start(source);
        Ok(assistance)
    }

    fn source_error(&self, source: SampleError) -> RecordingError {
        RecordingError::Source {
            path: self.path.display().to_string(),
            source,
        }
    }

    /// Opens the recording.
    pub fn open(&self) -> Result<(SourceConfig, Box<dyn SampleSource>), RecordingError> {
        let cfg = self.source_config()?;
        // Samples the SigMF captures say were lost come back as zeros.
        let src = gpsrx_samples::capture_gaps::open_filling_capture_gaps(&cfg)
            .map_err(|e| self.source_error(e))?;
        Ok((cfg, src))
    }
}

/// When the recording's first processed sample was taken (SigMF `core:datetime`, moved by the
/// skip); a date that cannot be read is a warning.
fn recording_start(cfg: &SourceConfig) -> Option<gpsrx_samples::sigmf::RecordingStart> {
    match gpsrx_samples::sigmf::recording_start(&cfg.path) {
        Ok(start) => start.map(|mut s| {
            s.time = s.time.add_seconds(cfg.skip_s);
            s
        }),
        Err(e) => {
            tracing::warn!("{e}: the recording's date is ignored");
            None
        }
    }
}

/// Runs the receiver over the recording of `spec` into `sink`, as `gpsrx run` does (without
/// the DR fusion and INS inputs); returns the summary and the source's warnings.
pub fn run_recording(
    spec: &RecordingSpec,
    sink: &mut dyn Sink,
) -> Result<(RunSummary, Vec<String>), RecordingError> {
    let config = spec.receiver_config()?;
    let (cfg, mut src) = spec.open()?;
    let assistance = spec.assistance(&cfg)?;
    let mut receiver = Receiver::new(&config, src.fs_hz(), assistance)?;
    let summary = receiver.run(src.as_mut(), sink)?;
    Ok((summary, src.warnings()))
}

/// Runs the recording of `spec` with the standard files written to `out_dir`.
pub fn run_recording_to(
    spec: &RecordingSpec,
    out_dir: &Path,
) -> Result<(RunSummary, Vec<String>), RecordingError> {
    let config = spec.receiver_config()?;
    let mut files = FileSink::create(out_dir, config.run.rate_hz)?.with_plots(config.run.plots);
    run_recording(spec, &mut files)
}
