//! Working out how to read a recording: which file holds the data, its format, sampling rate, IF
//! and Q sign, from the configuration first, then SigMF metadata, then a WAV header.
//!
//! Metadata lookup for a path `P`:
//! - `P` ends in `.sigmf-meta`: the data is the file its `core:dataset` names beside it, else
//!   `P` with `.sigmf-data` (an error if missing);
//! - otherwise the metadata is `P` with its extension replaced by `.sigmf-meta` (what
//!   [`crate::sigmf::write_sigmf_meta`] writes), or else `P` + `.sigmf-meta`, if either exists;
//! - without metadata, a file starting with a RIFF/WAVE header is read as WAV.
//!
//! Precedence: `--format` and `--fs` win over metadata (a disagreement is a warning); the IF is
//! the configuration's when non-zero, else the metadata's (`gpsrx:if_hz`, else `L1 -
//! core:frequency`: [`crate::sigmf::SigmfMeta::described_if_hz`]), and a non-zero IF in both
//! that disagrees is an error; Q is inverted when the configuration or the metadata asks for
//! it.

use std::path::{Path, PathBuf};

use crate::error::SampleError;
use crate::format::SampleFormat;
use crate::sigmf::read_sigmf_meta;
use crate::source::SourceConfig;
use crate::wav::{looks_like_wav, read_wav_layout};

/// Lowest complex sampling rate that holds the C/A main lobe (±1.023 MHz), in Hz.
pub const MIN_FS_COMPLEX_HZ: f64 = 1.023e6;
/// Lowest real sampling rate that holds the C/A main lobe, in Hz.
pub const MIN_FS_REAL_HZ: f64 = 2.046e6;

/// Everything needed to stream a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolved {
    /// The file holding the samples.
    pub data_path: PathBuf,
    /// The metadata file used, if any.
    pub meta_path: Option<PathBuf>,
    /// Byte offset of the first sample (a WAV header's length, else 0).
    pub data_offset: u64,
    /// Bytes of sample data.
    pub data_bytes: u64,
    /// How samples are stored.
    pub format: SampleFormat,
    /// Sampling rate.
    pub fs_hz: f64,
    /// Intermediate frequency to mix down.
    pub if_hz: f64,
    /// Read as I - jQ.
    pub invert_q: bool,
    /// Disagreements between configuration and metadata, and similar notes.
    pub warnings: Vec<String>,
}

fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Largest difference between `--if` and the metadata's IF taken as agreement, Hz.
const IF_AGREEMENT_HZ: f64 = 1.0;

/// The IF to mix down: `config_if_hz` when non-zero, else the metadata's; an error when both
/// are non-zero and disagree by more than [`IF_AGREEMENT_HZ`].
fn resolve_if(
    path: &Path,
    meta: Option<&crate::sigmf::SigmfMeta>,
    config_if_hz: f64,
) -> Result<f64, SampleError> {
    let (described, field) = meta.map_or((0.0, "none"), |m| m.described_if_hz());
    if config_if_hz == 0.0 {
        return Ok(described);
    }
    if described != 0.0 && (described - config_if_hz).abs() > IF_AGREEMENT_HZ {
        return Err(SampleError::IfConflict {
            path: path.to_path_buf(),
            given_hz: config_if_hz,
            described_hz: described,
            field,
        });
    }
    Ok(config_if_hz)
}

/// Finds the data file and its metadata file for `path`.
pub(crate) fn locate(path: &Path) -> Result<(PathBuf, Option<PathBuf>), SampleError> {
    if has_extension(path, "sigmf-meta") {
        let data =
            crate::sigmf::dataset_path(path)?.unwrap_or_else(|| path.with_extension("sigmf-data"));
        if !data.is_file() {
            return Err(SampleError::SigmfMissingData {
                meta: path.to_path_buf(),
                data,
            });
        }
        return Ok((data, Some(path.to_path_buf())));
    }
    let by_stem = path.with_extension("sigmf-meta");
    let mut by_name = path.as_os_str().to_owned();
    by_name.push(".sigmf-meta");
    let by_name = PathBuf::from(by_name);
    let meta = [by_stem, by_name].into_iter().find(|p| p.is_file());
    Ok((path.to_path_buf(), meta))
}

/// Whether a real recording's IF is a whole multiple k >= 1 of fs (to 1e-9 relative): sampling
/// then moves the IF to 0 Hz and folds the spectrum onto itself, so a carrier offset f is seen
/// at +f and -f alike (the MAX2769 set-up of SnapperGPS: IF = fs = 4.092 MHz). Mixing by such an
/// IF is the identity ([`crate::mixer::Mixer`] keeps only the fractional cycles per sample).
pub fn is_folded_if(if_hz: f64, fs_hz: f64) -> bool {
    let k = if_hz / fs_hz;
    k.is_finite() && k >= 0.5 && (k - k.round()).abs() < 1e-9
}

/// Checks fs and IF against what GPS L1 C/A needs: complex samples |IF| <= fs/2; real samples
/// 0 < IF < fs/2, or IF a whole multiple of fs ([`is_folded_if`]).
pub fn validate_rates(
    path: &Path,
    format: &SampleFormat,
    fs_hz: f64,
    if_hz: f64,
) -> Result<(), SampleError> {
    let complex = format.is_complex();
    let (min_hz, kind) = if complex {
        (MIN_FS_COMPLEX_HZ, "complex")
    } else {
        (MIN_FS_REAL_HZ, "real")
    };
    let bad = |reason| SampleError::BadSampleRate {
        path: path.to_path_buf(),
        fs_hz,
        min_hz,
        kind,
        reason,
    };
    if !(fs_hz.is_finite() && fs_hz > 0.0) {
        return Err(bad("not a positive finite number"));
    }
    if fs_hz < min_hz {
        return Err(bad("too low for GPS L1 C/A"));
    }
    let half = fs_hz / 2.0;
    let ok = if complex {
        if_hz.is_finite() && if_hz.abs() <= half
    } else {
        if_hz.is_finite() && ((if_hz > 0.0 && if_hz < half) || is_folded_if(if_hz, fs_hz))
    };
    if !ok {
        let allowed = if complex {
            format!("[-{half}, {half}] Hz (complex samples: |IF| <= fs/2)")
        } else {
            format!(
                "(0, {half}) Hz or a whole multiple of fs (real samples need 0 < IF < fs/2, or \
                 IF = k fs: the signal folded around 0 Hz)"
            )
        };
        return Err(SampleError::IfOutOfRange {
            path: path.to_path_buf(),
            if_hz,
            fs_hz,
            allowed,
        });
    }
    Ok(())
}

/// Checks a sample format and the rates it is read at, as every source does before reading:
/// the format's own parameters ([`SampleFormat::validate`]), then fs and IF
/// ([`validate_rates`]). Errors name `path`.
pub fn validate_format_and_rates(
    path: &Path,
    format: &SampleFormat,
    fs_hz: f64,
    if_hz: f64,
) -> Result<(), SampleError> {
    format.validate()?;
    validate_rates(path, format, fs_hz, if_hz)
}

/// Resolves `cfg` into a readable recording (see the module documentation).
pub fn resolve(cfg: &SourceConfig) -> Result<Resolved, SampleError> {
    let path = &cfg.path;
    if !path.exists() {
        return Err(SampleError::NotFound { path: path.clone() });
    }
    if !path.is_file() {
        return Err(SampleError::NotAFile { path: path.clone() });
    }
    let (data_path, meta_path) = locate(path)?;
    let meta = meta_path.as_deref().map(read_sigmf_meta).transpose()?;
    let wav = if meta.is_none() && looks_like_wav(&data_path) {
        Some(read_wav_layout(&data_path)?)
    } else {
        None
    };
    let mut warnings = Vec::new();

    // Format: configuration, then SigMF, then WAV.
    let described = match (&meta, &meta_path, &wav) {
        (Some(m), Some(p), _) => Some((m.sample_format(p), "SigMF metadata")),
        (_, _, Some(w)) => Some((Ok(w.format.clone()), "WAV header")),
        _ => None,
    };
    let format = match (&cfg.format, described) {
        (Some(f), Some((Ok(d), source))) => {
            if *f != d {
                warnings.push(format!(
                    "the sample format given, {f}, overrides {d} from the {source}"
                ));
            }
            f.clone()
        }
        (Some(f), _) => f.clone(),
        (None, Some((d, _))) => d?,
        (None, None) => return Err(SampleError::FormatUnknown { path: path.clone() }),
    };

    // Sampling rate likewise.
    let described_fs = meta
        .as_ref()
        .map(|m| m.sample_rate_hz)
        .filter(|&fs| fs > 0.0)
        .or(wav.as_ref().map(|w| w.fs_hz));
    let fs_hz = match (cfg.fs_hz, described_fs) {
        (Some(fs), Some(d)) => {
            if fs != d {
                warnings.push(format!(
                    "the sampling rate given, {fs} Hz, overrides {d} Hz from the metadata"
                ));
            }
            fs
        }
        (Some(fs), None) => fs,
        (None, Some(d)) => d,
        (None, None) => return Err(SampleError::SampleRateUnknown { path: path.clone() }),
    };
    let if_hz = resolve_if(path, meta.as_ref(), cfg.if_hz)?;
    let invert_q = cfg.invert_q || meta.as_ref().is_some_and(|m| m.invert_q);
    validate_format_and_rates(path, &format, fs_hz, if_hz)?;

    let file_len = std::fs::metadata(&data_path)
        .map_err(|e| SampleError::io("read the size of", &data_path, e))?
        .len();
    let (data_offset, data_bytes) = match &wav {
        Some(w) => {
            let present = file_len.saturating_sub(w.data_offset);
            if w.data_bytes > present {
                warnings.push(format!(
                    "WAV header announces {} data bytes but the file holds {present}: reading what is there",
                    w.data_bytes
                ));
            }
            (w.data_offset, w.data_bytes.min(present))
        }
        None => (0, file_len),
    };
    Ok(Resolved {
        data_path,
        meta_path,
        data_offset,
        data_bytes,
        format,
        fs_hz,
        if_hz,
        invert_q,
        warnings,
    })
}
