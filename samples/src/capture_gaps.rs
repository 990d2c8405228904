//! Gaps between the captures of a SigMF recording, and a source that fills them with zeros.
//!
//! A recorder that drops samples (a USB overflow) and starts a new SigMF capture after it
//! writes each capture's `core:sample_start` (its first sample in the data file) and
//! `core:datetime` (the time of that sample). Between captures `k` and `k + 1` the signal then
//! lost `(t_{k+1} - t_k) - (s_{k+1} - s_k) / fs` seconds that the data file does not hold. The
//! receiver finds lost samples in the signal itself (the carrier phases, the code, the data
//! bits, or for long gaps the coarse-time solver), but a gap the metadata states is known
//! exactly: [`GapFilled`] puts that many zero samples where it lies, so the sample count runs
//! with the time and the receiver sees an outage of known length (no signal for that long)
//! instead of samples that went missing.

use crate::error::SampleError;
use crate::format::SampleFormat;
use crate::sigmf::{parse_datetime_utc, read_captures};
use crate::source::{IntegerFormat, IntegerSamplesMut, SampleSource};
use num_complex::Complex32;
use std::path::Path;

/// Longest gap filled with zeros, s: a longer one would make the receiver track zeros for
/// longer than it spends on the signal; it is left to the receiver's own long-gap handling
/// (the coarse-time solver, or the next time of week), with a warning.
pub const MAX_FILLED_S: f64 = 600.0;
/// A capture boundary whose timestamps differ from the samples between them by less than this
/// is not a gap, s (timestamps to the microsecond, rates to a few ppm).
pub const TOLERANCE_S: f64 = 2e-6;

/// Samples lost between two captures.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureGap {
    /// The first sample of the later capture, counted from the start of the data file.
    pub at_sample: u64,
    /// Samples missing before it (the gap's length times the sampling rate, rounded).
    pub missing: u64,
    /// The gap's length by the two captures' `core:datetime`, s.
    pub length_s: f64,
}

/// What the captures of `meta_path` say about lost samples, for samples at `fs_hz`: the gaps
/// to fill, and warnings (a boundary whose time runs backwards or whose gap is longer than
/// [`MAX_FILLED_S`], left alone). Captures without a `core:datetime` say nothing. An
/// unreadable file or date is an error.
pub fn capture_gaps(
    meta_path: &Path,
    fs_hz: f64,
) -> Result<(Vec<CaptureGap>, Vec<String>), SampleError> {
    let invalid = |reason: String| SampleError::SigmfInvalid {
        path: meta_path.to_path_buf(),
        reason,
    };
    let mut timed = Vec::new();
    for c in read_captures(meta_path)? {
        if let Some(when) = c.datetime {
            let t = parse_datetime_utc(&when).map_err(|why| invalid(format!("captures: {why}")))?;
            timed.push((c.sample_start, t, when));
        }
    }
    let (mut gaps, mut warnings) = (Vec::new(), Vec::new());
    for pair in timed.windows(2) {
        let ((s0, t0, w0), (s1, t1, w1)) = (&pair[0], &pair[1]);
        let held_s = s1.saturating_sub(*s0) as f64 / fs_hz;
        let length_s = t1.diff_s(*t0) - held_s;
        let say = |what: &str| {
            format!(
                "{}: the capture at sample {s1} ({w1}) starts {length_s:.6} s {what} the samples \
                 since the one at sample {s0} ({w0}) end",
                meta_path.display()
            )
        };
        if s1 <= s0 || length_s < -TOLERANCE_S {
            warnings.push(say(
                "before (its time runs backwards): left as it is; the receiver finds any gap in \
                 the signal",
            ));
        } else if length_s > MAX_FILLED_S {
            warnings.push(say(&format!(
                "after (samples lost): longer than {MAX_FILLED_S} s, so not filled; the receiver \
                 takes its time again from the signal after it"
            )));
        } else if length_s > TOLERANCE_S {
            gaps.push(CaptureGap {
                at_sample: *s1,
                missing: (length_s * fs_hz).round() as u64,
                length_s,
            });
        }
    }
    Ok((gaps, warnings))
}

/// A source with the samples its SigMF captures say were lost put back as zeros
/// ([`capture_gaps`]): the indices it reports count time, the file's samples after a gap
/// later by the samples inserted before them.
pub struct GapFilled {
    inner: Box<dyn SampleSource>,
    gaps: Vec<CaptureGap>,
    /// Index of the next gap in `gaps` not yet reached.
    next_gap: usize,
    /// Zeros of the current gap still to deliver.
    zeros_left: u64,
    /// Zeros delivered so far.
    inserted: u64,
    /// Next sample of the file the inner source delivers (file index; `None` before the
    /// first read).
    file_pos: Option<u64>,
    warnings: Vec<String>,
}

impl std::fmt::Debug for GapFilled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GapFilled")
            .field("gaps", &self.gaps)
            .field("inserted", &self.inserted)
            .finish_non_exhaustive()
    }
}

impl GapFilled {
    /// `inner` with `gaps` filled; `warnings` are added to its own.
    pub fn new(
        inner: Box<dyn SampleSource>,
        mut gaps: Vec<CaptureGap>,
        mut warnings: Vec<String>,
    ) -> Self {
        gaps.sort_by_key(|g| g.at_sample);
        for g in &gaps {
            warnings.push(format!(
                "the SigMF captures say {:.6} s of signal ({} samples) were lost before sample {} \
                 of the data file: put back as zeros, so the receiver sees an outage of that length \
                 and keeps its time through it",
                g.length_s, g.missing, g.at_sample
            ));
        }
        Self {
            inner,
            gaps,
            next_gap: 0,
            zeros_left: 0,
            inserted: 0,
            file_pos: None,
            warnings,
        }
    }

    /// The gaps being filled.
    pub fn gaps(&self) -> &[CaptureGap] {
        &self.gaps
    }

    /// Up to `out.len()` samples into `out`, the zeros of the gaps among the file's samples
    /// (`read_inner` reads the file's): returns the index of `out[0]` and the number written
    /// (fewer only at the end of the file, as [`SampleSource::read`] promises).
    fn fill<T: Copy>(
        &mut self,
        out: &mut [T],
        zero: T,
        mut read_inner: impl FnMut(&mut dyn SampleSource, &mut [T]) -> Result<(u64, usize), SampleError>,
    ) -> Result<(u64, usize), SampleError> {
        let mut filled = 0;
        let mut first = None;
        while filled < out.len() {
            let rest = &mut out[filled..];
            let Some(pos) = self.file_pos else {
                // The first sample tells where the span starts in the file; gaps before it
                // count in the time of the samples after them but are not delivered.
                let (at, n) = read_inner(self.inner.as_mut(), &mut rest[..1])?;
                if n == 0 {
                    break;
                }
                while let Some(g) = self.gaps.get(self.next_gap).filter(|g| g.at_sample <= at) {
                    self.inserted += g.missing;
                    self.next_gap += 1;
                }
                self.file_pos = Some(at + 1);
                first.get_or_insert(at + self.inserted);
                filled += 1;
                continue;
            };
            if self.zeros_left == 0 {
                if let Some(g) = self.gaps.get(self.next_gap).filter(|g| g.at_sample == pos) {
                    self.zeros_left = g.missing;
                    self.next_gap += 1;
                }
            }
            if self.zeros_left > 0 {
                let n = rest
                    .len()
                    .min(usize::try_from(self.zeros_left).unwrap_or(usize::MAX));
                rest[..n].fill(zero);
                first.get_or_insert(pos + self.inserted);
                self.zeros_left -= n as u64;
                self.inserted += n as u64;
                filled += n;
                continue;
            }
            let limit = match self.gaps.get(self.next_gap) {
                Some(g) => rest
                    .len()
                    .min(usize::try_from(g.at_sample - pos).unwrap_or(usize::MAX)),
                None => rest.len(),
            };
            let (at, n) = read_inner(self.inner.as_mut(), &mut rest[..limit])?;
            if n == 0 {
                break;
            }
            first.get_or_insert(at + self.inserted);
            self.file_pos = Some(at + n as u64);
            filled += n;
            if n < limit {
                break;
            }
        }
        let next = self.file_pos.unwrap_or(0) + self.inserted;
        Ok((first.unwrap_or(next), filled))
    }
}

impl SampleSource for GapFilled {
    fn fs_hz(&self) -> f64 {
        self.inner.fs_hz()
    }

    fn format(&self) -> &SampleFormat {
        self.inner.format()
    }

    /// The inner source's samples and every gap's zeros (more than are delivered when a skip
    /// or a duration leaves gaps out: for progress only).
    fn total_samples(&self) -> Option<u64> {
        let filled: u64 = self.gaps.iter().map(|g| g.missing).sum();
        self.inner.total_samples().map(|n| n + filled)
    }

    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        self.fill(out, Complex32::new(0.0, 0.0), |src, x| src.read(x))
    }

    fn warnings(&self) -> Vec<String> {
        let mut w = self.warnings.clone();
        w.extend(self.inner.warnings());
        w
    }

    fn integer_format(&self) -> Option<IntegerFormat> {
        self.inner.integer_format()
    }

    fn read_integer(&mut self, out: IntegerSamplesMut<'_>) -> Result<(u64, usize), SampleError> {
        match out {
            IntegerSamplesMut::Ci8(x) => self.fill(x, [0, 0], |src, y| {
                src.read_integer(IntegerSamplesMut::Ci8(y))
            }),
            IntegerSamplesMut::Ci16(x) => self.fill(x, [0, 0], |src, y| {
                src.read_integer(IntegerSamplesMut::Ci16(y))
            }),
        }
    }

    fn integer_gain(&self) -> f32 {
        self.inner.integer_gain()
    }
}

/// [`crate::open_source`] for a receiver run: a SigMF recording whose captures say samples
/// were lost between them gets them back as zeros ([`GapFilled`], [`capture_gaps`]); anything
/// else is opened as it is. (Not for a set of snapshots, one per capture: their gaps are not
/// lost signal.)
pub fn open_filling_capture_gaps(
    cfg: &crate::SourceConfig,
) -> Result<Box<dyn SampleSource>, SampleError> {
    let src = crate::open_source(cfg)?;
    if crate::stream_source::is_stdin_path(&cfg.path) || !cfg.path.is_file() {
        return Ok(src);
    }
    let (_, Some(meta)) = crate::resolve::locate(&cfg.path)? else {
        return Ok(src);
    };
    let (gaps, warnings) = capture_gaps(&meta, src.fs_hz())?;
    if gaps.is_empty() && warnings.is_empty() {
        return Ok(src);
    }
    Ok(Box::new(GapFilled::new(src, gaps, warnings)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::SourceConfig;
    use serde_json::Value;

    const FS: f64 = 2.048e6;

    /// A ci8 recording of `n` samples whose sample `k` is `(k mod 100, -(k mod 50))`, with
    /// SigMF captures at `starts` timed `times_s` after 2022-01-01T00:00:00Z.
    fn recording(dir: &Path, n: usize, captures: &[(u64, f64)]) -> std::path::PathBuf {
        let data: Vec<u8> = (0..n)
            .flat_map(|k| [(k % 100) as i8 as u8, (-((k % 50) as i8)) as u8])
            .collect();
        let data_path = dir.join("rec.sigmf-data");
        std::fs::write(&data_path, data).expect("data");
        let caps: Vec<Value> = captures
            .iter()
            .map(|&(start, t)| {
                let us = (t * 1e6).round() as u64;
                serde_json::json!({
                    "core:sample_start": start,
                    "core:datetime": format!(
                        "2022-01-01T00:00:{:02}.{:06}Z", us / 1_000_000, us % 1_000_000
                    ),
                })
            })
            .collect();
        let meta = serde_json::json!({
            "global": {"core:datatype": "ci8", "core:sample_rate": FS, "core:version": "1.0.0"},
            "captures": caps,
            "annotations": [],
        });
        let meta_path = dir.join("rec.sigmf-meta");
        std::fs::write(&meta_path, meta.to_string()).expect("meta");
        meta_path
    }

    /// Reads everything in chunks of `chunk` (as f32), checking that the indices run on.
    fn read_all(src: &mut dyn SampleSource, chunk: usize) -> Vec<Complex32> {
        let mut out = Vec::new();
        let mut buf = vec![Complex32::new(0.0, 0.0); chunk];
        loop {
            let (at, n) = src.read(&mut buf).expect("read");
            if n == 0 {
                return out;
            }
            assert_eq!(at, out.len() as u64, "indices do not run on");
            out.extend_from_slice(&buf[..n]);
        }
    }

    fn file_sample(k: usize) -> Complex32 {
        Complex32::new((k % 100) as f32, -((k % 50) as f32))
    }

    #[test]
    fn the_samples_two_captures_lost_come_back_as_zeros_where_they_were() {
        let dir = tempfile::tempdir().expect("tempdir");
        // 2048 samples (1 ms: timestamps are to the microsecond), then 0.5 ms (1024 samples)
        // lost, then 3952 more.
        let meta = recording(dir.path(), 6000, &[(0, 1.0), (2048, 1.0015)]);
        let (gaps, warnings) = capture_gaps(&meta, FS).expect("gaps");
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(gaps.len(), 1);
        assert_eq!((gaps[0].at_sample, gaps[0].missing), (2048, 1024));
        let mut src = open_filling_capture_gaps(&SourceConfig::new(meta)).expect("open");
        assert_eq!(src.total_samples(), Some(7024));
        assert!(src.warnings().iter().any(|w| w.contains("1024 samples")));
        let got = read_all(src.as_mut(), 700);
        assert_eq!(got.len(), 7024);
        for (i, s) in got.iter().enumerate() {
            let want = match i {
                0..2048 => file_sample(i),
                2048..3072 => Complex32::new(0.0, 0.0),
                _ => file_sample(i - 1024),
            };
            assert_eq!(*s, want, "sample {i}");
        }
        // The integers the correlators read in place: the same.
        let mut src =
            open_filling_capture_gaps(&SourceConfig::new(dir.path().join("rec.sigmf-meta")))
                .expect("open");
        assert_eq!(src.integer_format(), Some(IntegerFormat::Ci8));
        let mut ints = Vec::new();
        let mut buf = vec![[0i8; 2]; 333];
        loop {
            let (at, n) = src
                .read_integer(IntegerSamplesMut::Ci8(&mut buf))
                .expect("read");
            if n == 0 {
                break;
            }
            assert_eq!(at, ints.len() as u64);
            ints.extend_from_slice(&buf[..n]);
        }
        let as_f32: Vec<Complex32> = ints
            .iter()
            .map(|&[i, q]| Complex32::new(f32::from(i), f32::from(q)))
            .collect();
        assert_eq!(as_f32, got);
    }

    #[test]
    fn a_span_after_the_gap_keeps_the_time_of_its_samples() {
        let dir = tempfile::tempdir().expect("tempdir");
        let meta = recording(dir.path(), 6000, &[(0, 1.0), (2048, 1.0015)]);
        // Skipping 3000 file samples: the first delivered is file sample 3000, 1024 later in
        // time than its place in the file.
        let cfg = SourceConfig {
            skip_s: 3000.0 / FS,
            ..SourceConfig::new(meta)
        };
        let mut src = open_filling_capture_gaps(&cfg).expect("open");
        let mut buf = vec![Complex32::new(0.0, 0.0); 10];
        let (at, n) = src.read(&mut buf).expect("read");
        assert_eq!((at, n), (3000 + 1024, 10));
        assert_eq!(buf[0], file_sample(3000));
    }

    #[test]
    fn captures_that_run_backwards_or_agree_fill_nothing() {
        let dir = tempfile::tempdir().expect("tempdir");
        // The second capture's time runs 0.5 ms backwards; the third follows on exactly.
        let t1 = 1.0005;
        let meta = recording(
            dir.path(),
            4000,
            &[(0, 1.0), (2048, t1), (4096, t1 + 0.001)],
        );
        let (gaps, warnings) = capture_gaps(&meta, FS).expect("gaps");
        assert!(gaps.is_empty(), "{gaps:?}");
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("backwards"), "{}", warnings[0]);
        let mut src = open_filling_capture_gaps(&SourceConfig::new(meta)).expect("open");
        assert_eq!(read_all(src.as_mut(), 512).len(), 4000);
    }
}
