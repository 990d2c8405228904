//! Acquisition settings, their validation, and the block layout they imply.

use crate::constants::{CA_CHIP_RATE_HZ, CA_CODE_PERIOD_S};
use crate::Prn;

/// Largest coherent integration, ms: half a navigation data bit, so a block straddles at most
/// one bit edge.
pub const MAX_COHERENT_MS: u32 = 10;
/// Largest number of fractional Doppler offsets (Doppler step down to 1/(8T)): finer bins buy
/// nothing, the refinement after detection does the fine part.
pub const MAX_DOPPLER_SUBDIVISION: usize = 8;
/// Upper limit of the block spectra an engine keeps for one pass of a search, bytes.
pub const MAX_SPECTRA_BYTES: usize = 1 << 30;

/// Settings of the code-phase / Doppler search.
///
/// The defaults are a cold search for a front end with a good oscillator: 1 ms coherent x 10
/// non-coherent blocks, Doppler 0 +- 5 kHz in 500 Hz bins, false-alarm probability 1e-5 per
/// PRN search, 100 ms of 1-ms prompts for the fine Doppler and C/N0, cross-correlation margin
/// 15 dB.
#[derive(Debug, Clone, PartialEq)]
pub struct AcqConfig {
    /// Coherent integration T, in whole C/A code periods (ms), 1..=10.
    pub coherent_ms: u32,
    /// Non-coherent sum of this many coherent blocks (>= 1).
    pub noncoherent: u32,
    /// Centre of the Doppler search, Hz (the front end's LO offset, if known).
    pub doppler_center_hz: f64,
    /// Half-width of the Doppler search, Hz: bins cover centre +- this.
    pub doppler_max_hz: f64,
    /// Doppler bin width, Hz; `None` = 1/(2T). Must not exceed 2/(3T); the engine uses
    /// 1/(Q T) with the smallest integer Q that gives a step no wider than the one asked for.
    pub doppler_step_hz: Option<f64>,
    /// Probability that the search of one PRN (all its cells) declares a detection on noise.
    pub pfa: f64,
    /// Bit-edge handling for T >= 2 ms: also integrate blocks shifted by floor(T/2) ms and keep
    /// the better of the two. `None` = on when `coherent_ms >= 2`.
    pub bit_edge_offsets: Option<bool>,
    /// Code periods (ms) of prompts used to refine the Doppler and estimate C/N0 after a
    /// detection (fewer when the samples end sooner; 0 = no refinement).
    pub refine_ms: u32,
    /// A detection this many dB (C/N0) below a stronger one of the same search, at a Doppler a
    /// whole number of kHz away, is taken for a cross-correlation; `None` = no check.
    pub xcorr_margin_db: Option<f64>,
    /// Most search lags per code period, i.e. length of the inverse FFTs (a fast length,
    /// 1024..=4096): [`SEARCH_SAMPLES_PER_MS`] (4096, +-2.048 MHz kept, 4 lags per chip) by
    /// default; 2048 keeps +-1.024 MHz at 2 lags per chip, half the work per block for a loss
    /// of 0.4 dB on average (0.9 dB worse at the worst code offset: 90 % of the C/A power in
    /// the band instead of 95 %, and half a chip between lags instead of a quarter), which about
    /// 20 % more blocks make up.
    pub search_lags_per_ms: usize,
}

impl Default for AcqConfig {
    fn default() -> Self {
        Self {
            coherent_ms: 1,
            noncoherent: 10,
            doppler_center_hz: 0.0,
            doppler_max_hz: 5_000.0,
            doppler_step_hz: None,
            pfa: 1e-5,
            bit_edge_offsets: None,
            refine_ms: 100,
            xcorr_margin_db: Some(15.0),
            search_lags_per_ms: SEARCH_SAMPLES_PER_MS,
        }
    }
}

impl AcqConfig {
    /// Whether the half-offset pass runs.
    pub fn uses_bit_edge_offsets(&self) -> bool {
        self.coherent_ms >= 2 && self.bit_edge_offsets.unwrap_or(true)
    }
}

/// Acquisition errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AcqError {
    /// A setting is out of range.
    #[error("acquisition setting {name} = {value}: {hint}")]
    BadSetting {
        /// The setting.
        name: &'static str,
        /// Its value, printed.
        value: String,
        /// What is allowed.
        hint: String,
    },
    /// Not enough samples for the search.
    #[error(
        "acquisition needs {needed} samples ({needed_ms:.1} ms) but got {got}: \
         read more of the recording or use fewer/shorter blocks"
    )]
    NotEnoughSamples {
        /// Samples needed.
        needed: usize,
        /// The same in ms.
        needed_ms: f64,
        /// Samples given.
        got: usize,
    },
    /// A PRN's Doppler window does not overlap the engine's Doppler range.
    #[error(
        "{prn}: Doppler window {min_hz:.0}..{max_hz:.0} Hz lies outside the search range \
         {range_min_hz:.0}..{range_max_hz:.0} Hz: widen the engine's Doppler range"
    )]
    EmptyDopplerWindow {
        /// The PRN.
        prn: Prn,
        /// Window asked for.
        min_hz: f64,
        /// Window asked for.
        max_hz: f64,
        /// The engine's range.
        range_min_hz: f64,
        /// The engine's range.
        range_max_hz: f64,
    },
}

fn bad(name: &'static str, value: impl ToString, hint: impl Into<String>) -> AcqError {
    AcqError::BadSetting {
        name,
        value: value.to_string(),
        hint: hint.into(),
    }
}

/// Search lags per code period (1 ms) at high sampling rates: about 4 per chip. The correlation
/// of a block sampled faster than this is taken from the `SEARCH_SAMPLES_PER_MS` lowest
/// frequencies of its spectrum (+-2.048 MHz, 95 % of the C/A signal power), so the search costs
/// the same at 5, 12 or 25 MHz as at 4 MHz.
pub const SEARCH_SAMPLES_PER_MS: usize = 4096;

/// Whether `n` is a multiple of 16 with no prime factor above 7: rustfft's fast butterflies,
/// no Rader or Bluestein, and enough factors of two for its SIMD radix-4 passes. Measured on
/// AVX2, inverse FFT ns per point: 2600 (13 a factor) 2.6, 2625 (odd) 2.3, 2700 1.5, 2688
/// (2^7 3 7) 1.1, 4000 1.4, 4096 1.1, 16368 (11 31) 4.3.
pub(crate) fn is_fast_len(mut n: usize) -> bool {
    if n == 0 || !n.is_multiple_of(16) {
        return false;
    }
    for p in [2, 3, 5, 7] {
        while n.is_multiple_of(p) {
            n /= p;
        }
    }
    n == 1
}

/// The inverse FFT length for a decimated block spectrum of `spec_len` bins (one code
/// period): the smallest fast length ([`is_fast_len`]) at least `spec_len` (the spectrum
/// zero-padded: band-limited interpolation, nothing lost), at most `cap`
/// ([`AcqConfig::search_lags_per_ms`]; the spectrum truncated to its lowest frequencies); but the power of two above it when that
/// is at most [`POW2_MARGIN`] longer, since powers of two run 20 % faster per point than
/// lengths with factors of 5 (4 MHz: 4000 -> 4096; measured on AVX2, 4000 points 1.4 ns per
/// point, 4096 1.1: the 4000-point transform, radix 5 and a transpose, was 64 % of a 10 ms x
/// 50 search).
pub(crate) fn search_len(spec_len: usize, cap: usize) -> usize {
    if spec_len >= cap {
        return cap;
    }
    let fast = (spec_len..cap).find(|&n| is_fast_len(n)).unwrap_or(cap);
    let pow2 = spec_len.next_power_of_two();
    if pow2 <= cap && pow2 as f64 <= fast as f64 * POW2_MARGIN {
        pow2
    } else {
        fast
    }
}

/// How much longer than the smallest fast length a power-of-two search length may be (see
/// [`search_len`]).
pub(crate) const POW2_MARGIN: f64 = 1.05;

/// Where the coherent blocks lie and how the FFT correlation is organised; derived from the
/// sampling rate and an [`AcqConfig`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Layout {
    /// Samples per code period (1 ms), possibly fractional.
    pub period_samples: f64,
    /// Samples per coherent block (FFT length of the forward transforms).
    pub block_len: usize,
    /// Decimation of the block spectrum, D = `coherent_ms`: the replica is periodic with the
    /// code period (1 ms), so its spectrum lies on the 1 kHz lines, every D-th bin of the block
    /// spectrum counted from 0 Hz (signed bins `D j`: at negative frequencies too, whether or
    /// not D divides `block_len`).
    pub decimation: usize,
    /// Length of the decimated block spectrum the correlation is taken from: one code period
    /// of samples, `block_len / D` (rounded when a period is not a whole number of samples).
    pub spec_len: usize,
    /// Length of the forward FFT of a replica: one code period (`spec_len`) when a period is a
    /// whole number of samples, else the whole block (`block_len`, D periods of the code), of
    /// which the decimated bins are kept.
    pub replica_len: usize,
    /// Length of the inverse FFTs and of the stored replica spectra: the search length
    /// ([`search_len`]), `spec_len` itself when that is already a fast length of at most
    /// [`SEARCH_SAMPLES_PER_MS`] per ms.
    pub inv_len: usize,
    /// Bins of the spectrum kept at non-negative frequencies (`0..keep_pos`) and at negative
    /// ones (`-keep_neg..0`): `keep_pos + keep_neg = min(spec_len, inv_len)`.
    pub keep_pos: usize,
    /// See `keep_pos`.
    pub keep_neg: usize,
    /// Input samples per search lag: `block_len / (D inv_len)`, the period of the decimated
    /// spectrum's lines over the search length (1 when nothing is resampled).
    pub lag_samples: f64,
    /// Code lags searched: one code period, in search lags.
    pub n_lags: usize,
    /// Fractional Doppler offsets Q: the Doppler step is fs / (Q block_len).
    pub subdivision: usize,
    /// Doppler step, Hz.
    pub doppler_step_hz: f64,
    /// Doppler bins, as multiples of the step: `bin_min..=bin_max`.
    pub bin_min: i64,
    /// Last Doppler bin.
    pub bin_max: i64,
    /// Start of each coherent block of each pass, in whole code periods from the first sample.
    pub block_start_ms: Vec<Vec<u32>>,
    /// Samples the search reads.
    pub samples_needed: usize,
}

impl Layout {
    pub(crate) fn new(fs_hz: f64, cfg: &AcqConfig) -> Result<Self, AcqError> {
        validate(fs_hz, cfg)?;
        let period_samples = fs_hz * CA_CODE_PERIOD_S;
        let m = cfg.coherent_ms as usize;
        let integer_period = (period_samples - period_samples.round()).abs() < 1e-6;
        let block_len = (m as f64 * period_samples).round() as usize;
        let decimation = m;
        let spec_len = (block_len as f64 / m as f64).round() as usize;
        let replica_len = if integer_period { spec_len } else { block_len };
        let inv_len = search_len(spec_len, cfg.search_lags_per_ms);
        let kept = spec_len.min(inv_len);
        let keep_pos = kept.div_ceil(2);
        let keep_neg = kept - keep_pos;
        let lag_samples = block_len as f64 / (m * inv_len) as f64;
        let n_lags = inv_len;
        let t_block_s = block_len as f64 / fs_hz;
        let subdivision = doppler_subdivision(cfg.doppler_step_hz, t_block_s)?;
        let doppler_step_hz = 1.0 / (subdivision as f64 * t_block_s);
        let lo = cfg.doppler_center_hz - cfg.doppler_max_hz;
        let hi = cfg.doppler_center_hz + cfg.doppler_max_hz;
        let bin_min = (lo / doppler_step_hz - 1e-9).ceil() as i64;
        let bin_max = ((hi / doppler_step_hz + 1e-9).floor() as i64).max(bin_min);
        let block_start_ms = block_starts_ms(cfg);
        let last_start = block_start_ms
            .iter()
            .filter_map(|p| p.last())
            .max()
            .copied()
            .unwrap_or(0);
        let samples_needed = (f64::from(last_start) * period_samples).round() as usize + block_len;
        // The spectra of one pass are held at a time.
        let spectra_bytes = cfg.noncoherent as usize
            * subdivision
            * (decimation * spec_len)
            * std::mem::size_of::<num_complex::Complex32>();
        if spectra_bytes > MAX_SPECTRA_BYTES {
            return Err(bad(
                "noncoherent",
                cfg.noncoherent,
                format!(
                    "the block spectra would take {} MiB: use fewer blocks or a coarser Doppler step",
                    spectra_bytes >> 20
                ),
            ));
        }
        Ok(Self {
            period_samples,
            block_len,
            decimation,
            spec_len,
            replica_len,
            inv_len,
            keep_pos,
            keep_neg,
            lag_samples,
            n_lags,
            subdivision,
            doppler_step_hz,
            bin_min,
            bin_max,
            block_start_ms,
            samples_needed,
        })
    }

    /// Where the `jj`-th bin of residue `r` of the decimated spectrum (signed bin
    /// `j = jj` or `jj - spec_len` for the upper half, as in an FFT) lies in a spectrum of
    /// `len` bins decimated by `d`: bin `(d j + r) mod len`. With `len = d spec_len` this is
    /// the plain polyphase split `d jj + r`; otherwise the negative frequencies are counted from
    /// the top of the spectrum, where their 1 kHz lines are.
    pub(crate) fn decimated_bin(&self, jj: usize, r: usize, d: usize, len: usize) -> usize {
        let s = self.spec_len as i64;
        let j = if (jj as i64) < s - s / 2 {
            jj as i64
        } else {
            jj as i64 - s
        };
        (d as i64 * j + r as i64).rem_euclid(len as i64) as usize
    }

    /// A Doppler shift of `k` bins of the block spectrum as (residue, rotation) of the
    /// decimated spectrum: `k = D a + r`, `0 <= r < D`, `a` taken modulo `spec_len`.
    pub(crate) fn residue_rotation(&self, k: i64) -> (usize, usize) {
        let d = self.decimation as i64;
        let r = k.rem_euclid(d);
        let a = ((k - r) / d).rem_euclid(self.spec_len as i64);
        (r as usize, a as usize)
    }

    /// First sample of a block that starts `ms` code periods after the first sample.
    pub(crate) fn block_start_sample(&self, ms: u32) -> usize {
        (f64::from(ms) * self.period_samples).round() as usize
    }

    /// Coherent block duration T, s.
    pub(crate) fn t_block_s(&self, fs_hz: f64) -> f64 {
        self.block_len as f64 / fs_hz
    }
}

/// Checks the settings against the sampling rate `fs_hz`: every field in its range, or an
/// error naming it and what to use.
fn validate(fs_hz: f64, cfg: &AcqConfig) -> Result<(), AcqError> {
    if !(CA_CHIP_RATE_HZ..=200e6).contains(&fs_hz) {
        return Err(bad(
            "fs_hz",
            fs_hz,
            "use a sampling rate between 1.023 MHz and 200 MHz",
        ));
    }
    if !(1..=MAX_COHERENT_MS).contains(&cfg.coherent_ms) {
        return Err(bad(
            "coherent_ms",
            cfg.coherent_ms,
            format!("use 1 to {MAX_COHERENT_MS} ms"),
        ));
    }
    if !(1..=100_000).contains(&cfg.noncoherent) {
        return Err(bad(
            "noncoherent",
            cfg.noncoherent,
            "use 1 to 100000 blocks",
        ));
    }
    if !(cfg.pfa > 0.0 && cfg.pfa < 1.0) {
        return Err(bad(
            "pfa",
            cfg.pfa,
            "use a probability in (0, 1), e.g. 1e-5",
        ));
    }
    if !cfg.doppler_center_hz.is_finite() || cfg.doppler_center_hz.abs() > fs_hz / 2.0 {
        return Err(bad(
            "doppler_center_hz",
            cfg.doppler_center_hz,
            "use |centre| < fs/2",
        ));
    }
    if !cfg.doppler_max_hz.is_finite()
        || cfg.doppler_max_hz < 0.0
        || cfg.doppler_max_hz > fs_hz / 2.0
    {
        return Err(bad(
            "doppler_max_hz",
            cfg.doppler_max_hz,
            "use a half-width between 0 and fs/2",
        ));
    }
    if cfg
        .xcorr_margin_db
        .is_some_and(|m| !(m.is_finite() && m >= 0.0))
    {
        return Err(bad(
            "xcorr_margin_db",
            format!("{:?}", cfg.xcorr_margin_db),
            "use a non-negative number of dB (15 is typical) or none",
        ));
    }
    let lags = cfg.search_lags_per_ms;
    if !((1024..=SEARCH_SAMPLES_PER_MS).contains(&lags) && is_fast_len(lags)) {
        return Err(bad(
            "search_lags_per_ms",
            lags,
            "use 1024 to 4096 lags with no prime factor above 7 (2048, 3072, 4096)",
        ));
    }
    if cfg.refine_ms > 10_000 {
        return Err(bad("refine_ms", cfg.refine_ms, "use 0 to 10000 ms"));
    }
    Ok(())
}

/// Doppler bins per `1 / T` (`T = t_block_s`): 2 by default, else the least that gives a bin no
/// wider than `step_hz` (at most 2/(3T), at least 1/(8T)).
fn doppler_subdivision(step_hz: Option<f64>, t_block_s: f64) -> Result<usize, AcqError> {
    let max_step = 2.0 / (3.0 * t_block_s);
    match step_hz {
        None => Ok(2),
        Some(s) => {
            if !(s.is_finite() && s > 0.0 && s <= max_step * (1.0 + 1e-9)) {
                return Err(bad(
                    "doppler_step_hz",
                    s,
                    format!("use a bin width in (0, 2/(3T)] = (0, {max_step:.1}] Hz"),
                ));
            }
            let q = (1.0 / (t_block_s * s) - 1e-9).ceil().max(2.0) as usize;
            if q > MAX_DOPPLER_SUBDIVISION {
                let min_step = 1.0 / (MAX_DOPPLER_SUBDIVISION as f64 * t_block_s);
                return Err(bad(
                    "doppler_step_hz",
                    s,
                    format!("use at least 1/(8T) = {min_step:.1} Hz (finer is done by refinement)"),
                ));
            }
            Ok(q)
        }
    }
}

/// Per pass (blocks from the first sample; with the bit-edge guard also blocks shifted by
/// half a coherent block), the code period at which each non-coherent block starts.
fn block_starts_ms(cfg: &AcqConfig) -> Vec<Vec<u32>> {
    let passes: Vec<u32> = if cfg.uses_bit_edge_offsets() {
        vec![0, cfg.coherent_ms / 2]
    } else {
        vec![0]
    };
    passes
        .iter()
        .map(|&off| {
            (0..cfg.noncoherent)
                .map(|b| b * cfg.coherent_ms + off)
                .collect()
        })
        .collect()
}
