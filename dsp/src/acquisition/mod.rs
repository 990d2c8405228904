//! GPS L1 C/A signal acquisition: a parallel FFT search over code phase and Doppler, a
//! constant-false-alarm detector, and refinement of the Doppler and C/N0 of what it finds.
//!
//! # Search (Kaplan & Hegarty 2nd ed. section 8.7; Borre et al., *A Software-Defined GPS and
//! Galileo Receiver*, 2007, section 6.7)
//!
//! The record is cut into `noncoherent` blocks of T = `coherent_ms` code periods. For each block,
//! PRN and Doppler bin f the engine computes the circular correlation with the code replica,
//! `corr[tau] = sum_n x[n] exp(-j 2 pi f n/fs) c[n - tau]`, for every lag tau of one code period
//! by FFT: `corr = IFFT( FFT(x e^{-j 2 pi f n/fs}) conj(FFT(c)) )`, and sums `|corr|^2` over the
//! blocks. Four things keep this cheap and exact:
//!
//! - **Doppler by rotation.** Bins are spaced `1/(Q T)` Hz (Q >= 2, default 2, i.e. 500 Hz at
//!   1 ms; the bin width never exceeds 2/(3T)). A bin `f = (k + q/Q)/T` is the spectrum of the
//!   block wiped off by the fractional part `q/(Q T)`, rotated by k bins; so each block needs only
//!   Q forward FFTs, shared by every PRN and every bin.
//! - **Decimated inverse FFTs.** The replica is periodic with the code period, so its spectrum
//!   lies on the 1 kHz lines: in an M-ms block of N samples, only every M-th bin counted from
//!   0 Hz (signed) is non-zero, and the correlation of an M-ms block is a one-period inverse FFT
//!   of S = N/M (rounded) bins: a 10 ms block costs the same per bin as a 1 ms one. When a code
//!   period is a whole number L = S of samples (fs a multiple of 1 kHz, e.g. 2.048, 2.6, 4, 5,
//!   16.368 MHz) the replica is one period and `C_N[M j] = M C_L[j]` exactly; at any other rate
//!   (16.3676 MHz, or a rate corrected by a few ppm) the replica is sampled over the whole block
//!   and its N-point spectrum decimated the same way (its lines fall on the bins to within
//!   `M |N - M fs 1 ms| j / N` bins, 0.06 at +-2 MHz in the worst case). Until issue 17 such
//!   rates correlated the whole N-point spectrum: a 10 ms search cost 9 times more.
//! - **A fast search length at any rate.** The inverse FFTs (32 PRNs x bins x blocks: nearly all
//!   the work) do not run at the length of that spectrum, S, but at a search length
//!   S' (`config::search_len`): S itself when it is a multiple of 16 with no prime factor above
//!   7 and at most 4096 per ms (2.048, 3.2 MHz); otherwise the next such length up to
//!   4096 per ms (2.6 MHz: 2600 -> 2688; the spectrum zero-padded), or the power of two above
//!   S when it is at most 5 % longer (4 MHz: 4000 -> 4096, 20 % faster per point than the
//!   radix-5 4000), and 4096 per ms for anything
//!   faster (5, 12, 16.368, 24 MHz: the 4096 lowest frequencies kept, +-2.048 MHz, 95 % of the
//!   C/A power). In both cases the S'-point inverse FFT of the kept bins
//!   `Y[k] = X[k] conj(C[k]) / S`, k signed, is the *band-limited circular correlation*
//!   `corr(tau) = (1/S) sum_{k kept} X[k] conj(C[k]) exp(j 2 pi k tau / S)` evaluated at
//!   `tau = m S/S'` input samples, m = 0..S'-1: exactly the correlation of the block and the
//!   replica both passed through an ideal low-pass of S' bins (nothing aliases: bins are dropped,
//!   not folded), or, when padding, the exact correlation interpolated between its samples. So
//!   a search lag is `S/S'` input samples and the code phase is converted back exactly; the
//!   forward FFTs still run at S (a handful per search, whatever the factors of S). The search
//!   then costs about the same at 5, 12, 16.368 or 25 MHz as at 4 MHz (the old per-input-sample
//!   inverse FFTs took 0.4 to 1.1 s at 12 to 25 MHz, and 16368 = 2^4 3 11 31 ran 4 times slower
//!   per point than 4096).
//! - **Code Doppler.** The lags of later blocks are shifted by the code Doppler of the bin
//!   (code rate 1.023 MHz (1 + f/f_L1)) before the non-coherent sum, so long sums stay on the peak.
//!
//! Code phase convention: `code_phase_samples` is the index, counted from the first sample of
//! the record, at which a C/A code period starts (fractional after interpolation), in
//! `[0, fs * 1 ms)`.
//!
//! # Detection statistic
//!
//! Under H0 (noise only) each correlation is complex circular Gaussian, `|corr|^2 / sigma^2` is
//! exponential, and a non-coherent sum of N blocks normalised by sigma^2 is Gamma(N, 1), i.e. half
//! a chi-square with 2N degrees of freedom ([`stats`]). `N sigma^2` is estimated from the grid
//! itself: the mean of all cells more than one chip from the peak (tens of thousands of cells, so
//! the estimate is good to a fraction of a percent and the false-alarm rate does not depend on the
//! input level). A PRN is detected when `metric = peak / floor >= threshold`, where
//! `threshold * N` is the Gamma(N, 1) quantile for a per-cell probability `pfa / cells`: the union
//! bound over all cells of the PRN's search (Doppler bins x search lags x passes), so `pfa` bounds the
//! probability that a search of one PRN on noise reports anything. Neighbouring cells share noise,
//! but this far in the tail their exceedances are nearly independent, so the bound is close to
//! exact: on 3,200 noise-only PRN searches, 31 passed the threshold for `pfa = 1e-2` and 3 the
//! one for 1e-3 (receiver/tests/acquisition.rs). Each cell of the band-limited grid is still a
//! linear function of Gaussian noise (complex circular, one variance per row), so the model is
//! unchanged by the search length; what changes is the number of cells and their correlation.
//! With about 4 search lags per chip at every rate above 4 MHz both are those of a 4 MHz
//! search, and the bound stays as tight: 1280 noise-only PRN searches at `pfa = 0.05` gave 61
//! false alarms at 4 MHz, 65 at 12 MHz and 65 at 2.6 MHz (64 expected; `tests.rs`). Searched at
//! the input rate, 12 MHz had 11.7 correlated lags per chip, 3 times the cells, and a looser
//! bound (52).
//!
//! The floor is estimated per Doppler row: a narrowband interferer or a DC offset correlated
//! with the periodic code raises a whole row evenly (a tone's correlation with the code has the
//! same magnitude at every lag), and one floor for the whole grid would take that row's largest
//! cell for a signal. Real front ends have such spurs (the PocketSDR capture has one at
//! -578 kHz, 11 dB over the median spectrum).
//!
//! Cross-correlations: a strong satellite shows on other PRNs about 21 to 24 dB down. A
//! detection at least `xcorr_margin_db` (default 15 dB) weaker than another detection of the same
//! search, and (when both have refined Dopplers) a whole number of kHz away from it in Doppler,
//! is reported as a cross-correlation, not a detection.
//!
//! The report also gives the peak-to-second-peak ratio: the peak over the largest cell more than
//! one chip away in code phase, at any Doppler.
//!
//! # Data-bit edges
//!
//! A coherent block of T ms (T <= 10) contains at most one 20-ms data-bit edge; if the bit changes
//! there the block's correlation partly cancels. With T = 1 ms that affects one block in 20 and is
//! ignored. With T >= 2 ms the engine also integrates blocks shifted by floor(T/2) ms and keeps,
//! per PRN, the better of the two passes: their block boundaries are T/2 apart, so in one of them
//! every edge lies within T/4 of a boundary and a bit change keeps at least half the coherent
//! amplitude of its block. The threshold accounts for the two looks (twice the cells). This
//! doubles the inverse FFTs for a modest gain, measured with 10 ms x 10 on the simulator: mean
//! metric/threshold +2.6 %, detection at 28 dB-Hz 83 % instead of 75 % (72 trials each);
//! [`AcqConfig::bit_edge_offsets`] turns it off.
//!
//! # After a detection
//!
//! - Code phase: triangle fit to the noise-subtracted amplitudes at the peak lag and its
//!   neighbours. Doppler: parabola through the amplitudes of the peak bin and its neighbours.
//! - Fine Doppler: 1-ms prompt correlations (the tracking loops' SIMD block correlator, at the
//!   input rate) over up to `refine_ms` whole code periods from the
//!   detected code phase (so data-bit edges fall between prompts); their squares carry no data
//!   and form a tone at twice the residual Doppler, located by a zero-padded FFT and a parabola.
//!   Measured on the simulator with 100 prompts: 0.1 Hz rms at 40 dB-Hz, 0.4 Hz at 32 dB-Hz.
//! - Code phase again: early, prompt and late correlators half a chip apart at the fine Doppler,
//!   triangle fit (to a few hundredths of a sample at 42 to 45 dB-Hz). [`code_fit`] refines it
//!   further from the shape of the peak when the front end rounds it (snapshot positioning).
//! - C/N0: power-minus-noise at the apex of that triangle,
//!   `C/N0 = (mean |p_k|^2 - sigma_p^2) / (sigma_p^2 * 1 ms)`, with the prompt noise variance
//!   `sigma_p^2` taken from the grid floor (so it is the noise the correlator sees, whatever the
//!   front-end filter) times, when the grid is band-limited, the ratio of full-band to in-band
//!   noise of a correlation, from the blocks' power spectrum weighted by the replicas' (about
//!   1.05 for white noise at 12 MHz); without a whole prompt, `(metric - 1) / T` from the grid. It reads 0.1 to
//!   0.3 dB low (the signal's own correlation sidelobes raise its row's floor by about 1/1023 of
//!   its peak power per lag).

pub mod code_fit;
mod config;
mod correlate;
mod detect;
mod engine;
mod input;
mod refine;
mod replica;
mod spectra;
pub mod stats;
mod wide;

pub use config::{
    AcqConfig, AcqError, MAX_COHERENT_MS, MAX_DOPPLER_SUBDIVISION, SEARCH_SAMPLES_PER_MS,
};
pub use engine::AcquisitionEngine;

use crate::Prn;

/// One PRN to search, with an optional Doppler window (Hz, inclusive; assisted search). `None`
/// searches the engine's whole Doppler range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchTarget {
    /// The satellite.
    pub prn: Prn,
    /// Doppler window (min, max), Hz, or `None` for the engine's whole range.
    pub doppler_window_hz: Option<(f64, f64)>,
    /// False-alarm probability of this search (`None`: the engine's): a scheduler that
    /// searches a PRN again and again spends its false-alarm probability over the searches.
    pub pfa: Option<f64>,
}

impl SearchTarget {
    /// Search `prn` over the engine's whole Doppler range.
    pub fn full(prn: Prn) -> Self {
        Self {
            prn,
            doppler_window_hz: None,
            pfa: None,
        }
    }

    /// Search `prn` for Dopplers in `center_hz +- half_width_hz`.
    pub fn around(prn: Prn, center_hz: f64, half_width_hz: f64) -> Self {
        Self {
            prn,
            doppler_window_hz: Some((center_hz - half_width_hz, center_hz + half_width_hz)),
            pfa: None,
        }
    }

    /// The same search with the false-alarm probability `pfa`.
    pub fn with_pfa(mut self, pfa: f64) -> Self {
        self.pfa = Some(pfa);
        self
    }
}

/// The outcome of searching one PRN.
#[derive(Debug, Clone, PartialEq)]
pub struct AcqResult {
    /// The satellite.
    pub prn: Prn,
    /// Whether the peak passed the threshold.
    pub detected: bool,
    /// Sample index (from the first sample) where a C/A code period starts, in
    /// `[0, samples per code period)`, interpolated.
    pub code_phase_samples: f64,
    /// `code_phase_samples` in chips at the nominal chip rate (1.023 MHz), in `[0, 1023)`.
    pub code_phase_chips: f64,
    /// Carrier Doppler, Hz: refined after a detection, else the interpolated peak bin.
    pub doppler_hz: f64,
    /// Doppler from the search grid alone (peak bin with interpolation), Hz.
    pub doppler_coarse_hz: f64,
    /// Carrier-to-noise density estimate, dB-Hz (detections only).
    pub cn0_dbhz: Option<f64>,
    /// Peak cell over the mean noise cell.
    pub metric: f64,
    /// The detection threshold in the same units as `metric`.
    pub threshold: f64,
    /// Peak over the largest cell more than one chip away (any Doppler).
    pub peak_ratio: f64,
    /// First-block offset (ms) of the pass that gave the peak (0, or floor(T/2) ms with the
    /// bit-edge pass).
    pub bit_offset_ms: u32,
    /// Number of 1-ms prompts used for the refinement.
    pub refine_ms: u32,
    /// Set when the peak passed the threshold but was taken for a cross-correlation with this
    /// stronger satellite of the same search (then `detected` is false).
    pub cross_correlation_of: Option<Prn>,
}

/// A PRN's non-coherent search grid (first pass).
#[derive(Debug, Clone, PartialEq)]
pub struct AcqGrid {
    /// The satellite.
    pub prn: Prn,
    /// Doppler of each row, Hz.
    pub doppler_hz: Vec<f64>,
    /// Code lags per row: one code period of search lags (one lag = `lag_samples` input
    /// samples; the input rate itself up to 4096 samples per ms with a fast FFT length).
    pub n_lags: usize,
    /// Input samples per code lag of the grid (1 when the search runs at the input rate).
    pub lag_samples: f64,
    /// Blocks summed in each cell.
    pub noncoherent: u32,
    /// Row-major `doppler_hz.len() x n_lags` sums of `|corr|^2`.
    pub power: Vec<f32>,
}

#[cfg(test)]
mod tests;
