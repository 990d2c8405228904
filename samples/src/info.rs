//! What is in a recording: size, duration, per-component statistics, clipping, histogram,
//! spectrum, and plain-language notes on likely mistakes (wrong format, real read as complex,
//! clipping, DC spikes). Behind `gpsrx info`.
//!
//! Statistics are of the samples as stored (before IF mix-down and Q inversion), over at most
//! `max_samples` samples from the skip on; size and duration are those of the whole file.

use std::collections::HashMap;
use std::path::PathBuf;

use num_complex::Complex32;

use crate::error::SampleError;
use crate::file_source::FileSource;
use crate::format::SampleFormat;
use crate::source::SourceConfig;
use crate::spectrum::SpectrumAccumulator;

pub use crate::spectrum::{Band, SpectrumSummary};

/// Distinct values up to which an integer histogram lists every value.
pub const MAX_DISTINCT_VALUES: usize = 256;
/// Bins of a binned histogram.
pub const HISTOGRAM_BINS: usize = 32;

/// Samples per read while inspecting.
const READ_BLOCK: usize = 1 << 16;

/// Distribution of one component's values.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Histogram {
    /// Every distinct value with its count, ascending (integer formats with few values).
    Values {
        /// The distinct values.
        values: Vec<f64>,
        /// How often each occurs.
        counts: Vec<u64>,
    },
    /// Counts in equal bins from `lo` to `hi`.
    Binned {
        /// Lower edge of the first bin.
        lo: f64,
        /// Upper edge of the last bin.
        hi: f64,
        /// Count per bin.
        counts: Vec<u64>,
    },
}

/// Statistics of one component (I, Q, or the real samples).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComponentStats {
    /// Mean value.
    pub mean: f64,
    /// Standard deviation.
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Share of values at the format's extreme codes (integer formats of 8 bits or more).
    pub clip_fraction: Option<f64>,
    /// Distribution of values.
    pub histogram: Histogram,
}

/// Everything `gpsrx info` shows about a recording.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct InfoReport {
    /// The path asked about.
    pub path: PathBuf,
    /// The file holding the samples.
    pub data_path: PathBuf,
    /// SigMF metadata used, if any.
    pub meta_path: Option<PathBuf>,
    /// Size of the data file in bytes.
    pub size_bytes: u64,
    /// Whole samples in the file.
    pub n_samples: u64,
    /// Duration of the file in seconds.
    pub duration_s: f64,
    /// Format name (see [`crate::format`]).
    pub format: String,
    /// Complex (I/Q) or real samples.
    pub complex: bool,
    /// Sampling rate in Hz.
    pub fs_hz: f64,
    /// IF the samples would be mixed down by, in Hz.
    pub if_hz: f64,
    /// Whether Q would be inverted.
    pub invert_q: bool,
    /// First sample analysed.
    pub analysed_from_sample: u64,
    /// Samples analysed.
    pub analysed_samples: u64,
    /// I (or the real samples).
    pub i: ComponentStats,
    /// Q (complex formats).
    pub q: Option<ComponentStats>,
    /// Correlation coefficient of I and Q (complex formats with non-constant I and Q).
    pub iq_correlation: Option<f64>,
    /// Share of all analysed values at the format's extreme codes.
    pub clip_fraction: Option<f64>,
    /// Averaged spectrum of the stored samples (`None` with fewer than 1024 samples).
    pub spectrum: Option<SpectrumSummary>,
    /// Observations about likely problems.
    pub notes: Vec<String>,
    /// Warnings from reading (partial samples, non-finite values, ...).
    pub warnings: Vec<String>,
}

/// Running moments, extremes, exact value counts (integer formats) and clip counts.
#[derive(Debug, Default)]
struct Moments {
    n: u64,
    sum: f64,
    sum_sq: f64,
    min: f64,
    max: f64,
    at_extremes: u64,
    /// Exact counts per value (integer formats: at most 65,536 distinct values).
    values: HashMap<u32, u64>,
}

impl Moments {
    fn new() -> Self {
        Moments {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            ..Default::default()
        }
    }

    fn add(&mut self, v: f32, extremes: Option<(f32, f32)>, exact: bool) {
        let x = f64::from(v);
        self.n += 1;
        self.sum += x;
        self.sum_sq += x * x;
        self.min = self.min.min(x);
        self.max = self.max.max(x);
        if let Some((lo, hi)) = extremes {
            if v <= lo || v >= hi {
                self.at_extremes += 1;
            }
        }
        if exact {
            *self.values.entry(v.to_bits()).or_insert(0) += 1;
        }
    }

    fn mean(&self) -> f64 {
        self.sum / self.n.max(1) as f64
    }

    fn std(&self) -> f64 {
        let m = self.mean();
        (self.sum_sq / self.n.max(1) as f64 - m * m).max(0.0).sqrt()
    }
}

/// Equal-width bins over `lo..=hi`.
fn bin_index(v: f64, lo: f64, hi: f64) -> usize {
    if hi <= lo {
        return 0;
    }
    (((v - lo) / (hi - lo) * HISTOGRAM_BINS as f64) as usize).min(HISTOGRAM_BINS - 1)
}

/// Histogram from exact value counts: every value if few, else binned.
fn histogram_from_values(m: &Moments) -> Histogram {
    let mut pairs: Vec<(f64, u64)> = m
        .values
        .iter()
        .map(|(&bits, &c)| (f64::from(f32::from_bits(bits)), c))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    if pairs.len() <= MAX_DISTINCT_VALUES {
        return Histogram::Values {
            values: pairs.iter().map(|p| p.0).collect(),
            counts: pairs.iter().map(|p| p.1).collect(),
        };
    }
    let mut counts = vec![0; HISTOGRAM_BINS];
    for (v, c) in pairs {
        counts[bin_index(v, m.min, m.max)] += c;
    }
    Histogram::Binned {
        lo: m.min,
        hi: m.max,
        counts,
    }
}

/// The values at the format's extreme codes, for clipping statistics.
fn extreme_values(format: &SampleFormat) -> Option<(f32, f32)> {
    match format {
        SampleFormat::Ci8 | SampleFormat::Ri8 => Some((-128.0, 127.0)),
        SampleFormat::Cu8 { zero } => Some((-zero, 255.0 - zero)),
        SampleFormat::Ci16Le | SampleFormat::Ri16Le => Some((-32768.0, 32767.0)),
        _ => None,
    }
}

/// Reads up to `max_samples` raw samples of `cfg`, handing each block to `f`.
fn stream(
    cfg: &SourceConfig,
    max_samples: u64,
    mut f: impl FnMut(&[Complex32]),
) -> Result<FileSource, SampleError> {
    let mut src = FileSource::open(cfg)?;
    let mut buf = vec![Complex32::default(); READ_BLOCK];
    let mut left = max_samples;
    while left > 0 {
        let want = usize::try_from(left).unwrap_or(usize::MAX).min(READ_BLOCK);
        let (_, n) = src.read_raw(&mut buf[..want])?;
        if n == 0 {
            break;
        }
        f(&buf[..n]);
        left -= n as u64;
    }
    Ok(src)
}

/// Inspects the recording `cfg` describes, analysing at most `max_samples` samples (from the
/// skip on) but reporting the size and duration of the whole file.
pub fn inspect(cfg: &SourceConfig, max_samples: u64) -> Result<InfoReport, SampleError> {
    let probe = FileSource::open(cfg)?;
    let format = probe.resolved().format.clone();
    drop(probe);
    let complex = format.is_complex();
    let exact = !format.is_float();
    let extremes = extreme_values(&format);
    let (mut mi, mut mq) = (Moments::new(), Moments::new());
    let mut sum_iq = 0.0f64;
    let mut spectrum = SpectrumAccumulator::new();
    let src = stream(cfg, max_samples, |block| {
        for s in block {
            mi.add(s.re, extremes, exact);
            if complex {
                mq.add(s.im, extremes, exact);
                sum_iq += f64::from(s.re) * f64::from(s.im);
            }
        }
        spectrum.push(block);
    })?;

    // Float formats: a second pass bins values over the range the first pass found.
    let (hist_i, hist_q) = if exact {
        (histogram_from_values(&mi), histogram_from_values(&mq))
    } else {
        let (mut ci, mut cq) = (vec![0u64; HISTOGRAM_BINS], vec![0u64; HISTOGRAM_BINS]);
        stream(cfg, max_samples, |block| {
            for s in block {
                ci[bin_index(f64::from(s.re), mi.min, mi.max)] += 1;
                cq[bin_index(f64::from(s.im), mq.min, mq.max)] += 1;
            }
        })?;
        let binned = |lo, hi, counts| Histogram::Binned { lo, hi, counts };
        (binned(mi.min, mi.max, ci), binned(mq.min, mq.max, cq))
    };

    let stats = |m: &Moments, histogram| ComponentStats {
        mean: m.mean(),
        std: m.std(),
        min: if m.n > 0 { m.min } else { 0.0 },
        max: if m.n > 0 { m.max } else { 0.0 },
        clip_fraction: extremes.map(|_| m.at_extremes as f64 / m.n.max(1) as f64),
        histogram,
    };
    let i = stats(&mi, hist_i);
    let q = complex.then(|| stats(&mq, hist_q));
    let iq_correlation = q.as_ref().and_then(|q| {
        let cov = sum_iq / mi.n.max(1) as f64 - i.mean * q.mean;
        (i.std > 0.0 && q.std > 0.0).then(|| cov / (i.std * q.std))
    });
    let clip_fraction =
        extremes.map(|_| (mi.at_extremes + mq.at_extremes) as f64 / (mi.n + mq.n).max(1) as f64);

    let resolved = src.resolved();
    let span = src.span();
    let mut report = InfoReport {
        path: cfg.path.clone(),
        data_path: resolved.data_path.clone(),
        meta_path: resolved.meta_path.clone(),
        size_bytes: std::fs::metadata(&resolved.data_path)
            .map_err(|e| SampleError::io("read the size of", &resolved.data_path, e))?
            .len(),
        n_samples: span.file_samples,
        duration_s: span.file_samples as f64 / resolved.fs_hz,
        format: format.name(),
        complex,
        fs_hz: resolved.fs_hz,
        if_hz: resolved.if_hz,
        invert_q: resolved.invert_q,
        analysed_from_sample: span.first_sample,
        analysed_samples: mi.n,
        i,
        q,
        iq_correlation,
        clip_fraction,
        spectrum: spectrum.finish(resolved.fs_hz, complex),
        notes: Vec::new(),
        warnings: crate::source::SampleSource::warnings(&src),
    };
    report.notes = crate::info_notes::notes(&report, &format);
    Ok(report)
}
