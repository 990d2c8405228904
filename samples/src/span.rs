//! Which samples of a file to read: sample ⇄ byte arithmetic and skip/duration, all in `u64`
//! (recordings of many GiB are common: 1 h of `ci8` at 26 MHz is 187 GB).
//!
//! Sample `n` starts at bit `n * bits_per_sample` of the data; for byte-aligned formats that is
//! byte `n * bytes_per_sample`, for packed formats a byte plus a sub-byte position.

use std::path::Path;

use crate::error::SampleError;
use crate::format::SampleFormat;

/// The samples a source delivers, counted from the first sample of the data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Span {
    /// Whole samples in the data.
    pub file_samples: u64,
    /// Bytes after the last whole sample (a truncated final sample), dropped with a warning.
    pub trailing_bytes: u64,
    /// First sample delivered (the skip).
    pub first_sample: u64,
    /// Samples delivered.
    pub n_samples: u64,
    /// True when the asked-for duration ran past the end of the data and was shortened.
    pub duration_truncated: bool,
}

/// Byte (from the start of the data) holding the start of sample `n`, and how many samples of the
/// same byte come before it (always 0 for byte-aligned formats).
pub fn sample_position(format: &SampleFormat, n: u64) -> (u64, usize) {
    let bits = u128::from(format.bits_per_sample());
    let bit = u128::from(n) * bits;
    // bit / 8 < 2^64 for any n < 2^64 and bits <= 128 divided by 8 ... saturate to be safe.
    let byte = u64::try_from(bit / 8).unwrap_or(u64::MAX);
    let phase = ((bit % 8) / bits) as usize;
    (byte, phase)
}

/// Bytes needed to hold samples `0..n` (a partial final byte of packed formats counts whole).
pub fn bytes_for_samples(format: &SampleFormat, n: u64) -> u64 {
    let bits = u128::from(n) * u128::from(format.bits_per_sample());
    u64::try_from(bits.div_ceil(8)).unwrap_or(u64::MAX)
}

/// Whole samples in `data_bytes` bytes and the bytes left over.
pub fn samples_in_bytes(format: &SampleFormat, data_bytes: u64) -> (u64, u64) {
    let bits = u128::from(format.bits_per_sample());
    let n = u128::from(data_bytes) * 8 / bits;
    let used = (n * bits).div_ceil(8);
    let n = u64::try_from(n).unwrap_or(u64::MAX);
    (n, data_bytes - u64::try_from(used).unwrap_or(data_bytes))
}

/// Converts seconds to a whole number of samples (nearest), for validated non-negative times.
pub fn seconds_to_samples(t_s: f64, fs_hz: f64) -> u64 {
    let n = (t_s * fs_hz).round();
    if n >= u64::MAX as f64 {
        u64::MAX
    } else {
        n as u64
    }
}

/// Checks a skip and a duration: both finite and non-negative (errors name `path`).
pub fn validate_times(
    path: &Path,
    skip_s: f64,
    duration_s: Option<f64>,
) -> Result<(), SampleError> {
    let bad = |what, value| SampleError::BadTimeSpan {
        path: path.to_path_buf(),
        what,
        value,
    };
    if !(skip_s.is_finite() && skip_s >= 0.0) {
        return Err(bad("skip", skip_s));
    }
    if let Some(d) = duration_s {
        if !(d.is_finite() && d >= 0.0) {
            return Err(bad("duration", d));
        }
    }
    Ok(())
}

impl Span {
    /// Plans which samples to deliver from `data_bytes` bytes of `format` data at `fs_hz`,
    /// skipping `skip_s` seconds and keeping `duration_s` seconds (to the end when `None`).
    ///
    /// Errors: negative or non-finite times, an empty file, a skip at or beyond the end.
    pub fn plan(
        path: &Path,
        format: &SampleFormat,
        data_bytes: u64,
        fs_hz: f64,
        skip_s: f64,
        duration_s: Option<f64>,
    ) -> Result<Span, SampleError> {
        validate_times(path, skip_s, duration_s)?;
        let (file_samples, trailing_bytes) = samples_in_bytes(format, data_bytes);
        if file_samples == 0 {
            return Err(SampleError::EmptyFile {
                path: path.to_path_buf(),
                size_bytes: data_bytes,
                format: format.name(),
            });
        }
        let first_sample = seconds_to_samples(skip_s, fs_hz);
        if first_sample >= file_samples {
            return Err(SampleError::SkipBeyondEnd {
                path: path.to_path_buf(),
                skip_s,
                file_duration_s: file_samples as f64 / fs_hz,
                file_samples,
            });
        }
        let available = file_samples - first_sample;
        let (n_samples, duration_truncated) = match duration_s {
            None => (available, false),
            Some(d) => {
                let want = seconds_to_samples(d, fs_hz);
                (want.min(available), want > available)
            }
        };
        Ok(Span {
            file_samples,
            trailing_bytes,
            first_sample,
            n_samples,
            duration_truncated,
        })
    }

    /// One past the last sample delivered.
    pub fn end_sample(&self) -> u64 {
        self.first_sample + self.n_samples
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_positions() {
        let ci2 = SampleFormat::ci2();
        assert_eq!(sample_position(&ci2, 0), (0, 0));
        assert_eq!(sample_position(&ci2, 3), (1, 1));
        let ci1 = SampleFormat::Packed1Complex;
        assert_eq!(sample_position(&ci1, 7), (1, 3));
        assert_eq!(bytes_for_samples(&ci1, 5), 2);
        assert_eq!(samples_in_bytes(&SampleFormat::Ci16Le, 10), (2, 2));
        assert_eq!(samples_in_bytes(&ci1, 3), (12, 0));
    }
}
