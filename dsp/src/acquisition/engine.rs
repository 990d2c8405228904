//! The acquisition engine: FFT plans, replica spectra and scratch made once, searches run many
//! times.

use super::config::{AcqConfig, AcqError, Layout};
use super::detect::{analyse, mark_cross_correlations, triangle_offset, Peak};
use super::refine::{amplitude, cn0_dbhz, correlate_periods, fine_doppler};
use super::replica::{fractional_wipeoffs, replica_spectra, ReplicaSet};
use super::spectra::Spectra;
use super::stats::detection_threshold;
use super::{AcqGrid, AcqResult, SearchTarget};
use crate::constants::{CA_CHIP_RATE_HZ, CA_CODE_LENGTH};
use crate::correlator::{Correlator, PackedCode, SampleSlice};
use crate::{CaCode, Prn};
use num_complex::{Complex32, Complex64};
use rayon::prelude::*;
use rustfft::{Fft, FftPlanner};
use std::fmt;
use std::sync::{Arc, Mutex};

/// Per-thread working memory: taken from the engine's pool for one PRN and given back, so a
/// search allocates nothing once the pool is warm.
#[derive(Default)]
pub(super) struct Scratch {
    pub(super) buf: Vec<Complex32>,
    pub(super) fft: Vec<Complex32>,
    pub(super) grid: Vec<f32>,
    /// Grid rows in the order they are filled: (slice set, row, Doppler bin).
    pub(super) rows: Vec<(usize, usize, i64)>,
    /// One decimated slice of a block spectrum, before it is stored.
    pub(super) slice: Vec<Complex32>,
    epl: [Vec<Complex64>; 3],
    /// One code period of the refinement's samples, as f32 (when held as integers).
    period: Vec<Complex32>,
    fine: Vec<Complex32>,
    floors: Vec<f64>,
}

/// The best of one target's passes so far.
#[derive(Debug, Clone, Copy)]
struct PassPeak {
    peak: Peak,
    /// The pass (index into the layout's block starts).
    pass: usize,
    /// Full-band over in-band noise power at the peak's Doppler (see
    /// [`AcquisitionEngine::band_noise_ratio`]).
    band: f64,
}

/// A parallel FFT code-phase search for GPS L1 C/A at one sampling rate and one setting.
///
/// Build it once ([`AcquisitionEngine::new`] plans the FFTs and transforms the 32 replicas), then
/// call [`AcquisitionEngine::search`] on as many sample records as needed; PRNs are searched in
/// parallel on the rayon pool. See the [module documentation](super) for the method and the
/// statistics.
pub struct AcquisitionEngine {
    pub(super) fs_hz: f64,
    pub(super) config: AcqConfig,
    pub(super) layout: Layout,
    pub(super) fwd: Arc<dyn Fft<f32>>,
    pub(super) inv: Arc<dyn Fft<f32>>,
    pub(super) fine: Arc<dyn Fft<f32>>,
    pub(super) fine_len: usize,
    /// The replica spectra and their mean power (shared with other engines of the same
    /// layout: [`AcquisitionEngine::sharing_replicas_with`]).
    pub(super) replicas: Arc<ReplicaSet>,
    pub(super) correlator: Correlator,
    pub(super) packed: Vec<PackedCode>,
    pub(super) wipeoffs: Vec<Vec<Complex32>>,
    pub(super) scratch_pool: Mutex<Vec<Scratch>>,
}

impl fmt::Debug for AcquisitionEngine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("AcquisitionEngine")
            .field("fs_hz", &self.fs_hz)
            .field("config", &self.config)
            .field("block_len", &self.layout.block_len)
            .field("inverse_fft_len", &self.layout.inv_len)
            .field("lag_samples", &self.layout.lag_samples)
            .field("doppler_step_hz", &self.layout.doppler_step_hz)
            .finish_non_exhaustive()
    }
}

impl AcquisitionEngine {
    /// Prepares a search of samples at `fs_hz` (complex baseband) with `config`.
    ///
    /// Errors: a setting out of range (see [`AcqConfig`]), with what is allowed.
    pub fn new(fs_hz: f64, config: AcqConfig) -> Result<Self, AcqError> {
        let layout = Layout::new(fs_hz, &config)?;
        let mut planner = FftPlanner::<f32>::new();
        let fwd = planner.plan_fft_forward(layout.block_len);
        let inv = planner.plan_fft_inverse(layout.inv_len);
        let fine_len = (8 * config.refine_ms as usize).next_power_of_two().max(256);
        let fine = planner.plan_fft_forward(fine_len);
        let fwd_replica = planner.plan_fft_forward(layout.replica_len);
        let replicas = Arc::new(replica_spectra(&layout, fs_hz, &fwd_replica));
        let wipeoffs = fractional_wipeoffs(&layout);
        Ok(Self {
            fs_hz,
            config,
            layout,
            fwd,
            inv,
            fine,
            fine_len,
            replicas,
            correlator: Correlator::best(),
            packed: Prn::all()
                .map(|p| PackedCode::new(CaCode::new(p).chips()))
                .collect(),
            wipeoffs,
            scratch_pool: Mutex::new(Vec::new()),
        })
    }

    /// This engine holding the replica spectra of `other` instead of its own when they are the
    /// same (the same rate and search length, and a whole number of samples per code period
    /// or the same coherent integration: every level of a background search at 4 MHz), so
    /// engines kept side by side hold one copy (32 x `inv_len` complex values: 1 MB at 4 MHz
    /// per engine). Otherwise unchanged.
    pub fn sharing_replicas_with(mut self, other: &AcquisitionEngine) -> Self {
        if other.replicas.fits(&self.layout, self.fs_hz) {
            self.replicas = Arc::clone(&other.replicas);
        }
        self
    }

    /// Whether this engine and `other` hold the same replica spectra (one copy).
    pub fn shares_replicas_with(&self, other: &AcquisitionEngine) -> bool {
        Arc::ptr_eq(&self.replicas, &other.replicas)
    }

    /// The settings.
    pub fn config(&self) -> &AcqConfig {
        &self.config
    }

    /// Sampling rate, Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The Doppler bin width actually used, Hz (1/(Q T) for an integer Q >= 2).
    pub fn doppler_step_hz(&self) -> f64 {
        self.layout.doppler_step_hz
    }

    /// The Doppler range covered by the bins, Hz (first and last bin centre).
    pub fn doppler_range_hz(&self) -> (f64, f64) {
        let s = self.layout.doppler_step_hz;
        (
            self.layout.bin_min as f64 * s,
            self.layout.bin_max as f64 * s,
        )
    }

    /// Samples a search reads (the search fails with fewer).
    pub fn samples_needed(&self) -> usize {
        self.layout.samples_needed
    }

    /// Samples a search can use: the search plus `refine_ms` prompts after the last possible
    /// code phase.
    pub fn samples_wanted(&self) -> usize {
        let refine = ((f64::from(self.config.refine_ms) + 1.0) * self.layout.period_samples).ceil();
        self.layout.samples_needed.max(refine as usize)
    }

    /// Search lags per code period: the length of the inverse FFTs, one per block, Doppler bin
    /// and PRN (nearly all the work of a search).
    pub fn search_lags(&self) -> usize {
        self.layout.n_lags
    }

    /// Coherent block duration T, s.
    pub fn coherent_s(&self) -> f64 {
        self.layout.t_block_s(self.fs_hz)
    }

    /// Searches `targets` (each PRN with its own Doppler window) in `samples`, complex baseband
    /// at the engine's rate, the first sample being the reference of the reported code phases.
    /// Results come in the order of `targets`.
    ///
    /// Errors: fewer than [`Self::samples_needed`] samples; a Doppler window outside the range.
    pub fn search(
        &self,
        samples: &[Complex32],
        targets: &[SearchTarget],
    ) -> Result<Vec<AcqResult>, AcqError> {
        self.search_slice(SampleSlice::Cf32(samples), targets)
    }

    /// [`AcquisitionEngine::search`] of samples in the format they are held in (complex f32
    /// or 8- or 16-bit integers): each block is converted to f32 when its spectrum is taken,
    /// and the prompts of a detection's refinement from its first `refine_ms` + 2 code
    /// periods, so no f32 copy of the whole search is made. The working memory of the
    /// search (block spectra, grids) is released when it returns: it is as large as the
    /// samples (10 ms x 50 at 4 MHz: 32 MB of spectra, a 3 MB grid per thread), and a
    /// background search runs every few seconds at most.
    pub fn search_slice(
        &self,
        samples: SampleSlice<'_>,
        targets: &[SearchTarget],
    ) -> Result<Vec<AcqResult>, AcqError> {
        let result = self.search_held(samples, targets);
        self.release_memory();
        result
    }

    /// Frees the scratch the pool keeps between searches.
    pub fn release_memory(&self) {
        if let Ok(mut p) = self.scratch_pool.lock() {
            *p = Vec::new();
        }
    }

    /// The body of [`AcquisitionEngine::search_slice`] (the scratch pool stays warm; the
    /// block spectra live only while the passes need them).
    fn search_held(
        &self,
        samples: SampleSlice<'_>,
        targets: &[SearchTarget],
    ) -> Result<Vec<AcqResult>, AcqError> {
        self.check_len(samples.len())?;
        let rows = targets
            .iter()
            .map(|t| self.bins_for(t))
            .collect::<Result<Vec<_>, _>>()?;
        let thresholds: Vec<f64> = targets
            .iter()
            .zip(&rows)
            .map(|(t, &bins)| self.threshold(t, bins))
            .collect();
        // One pass's spectra at a time (half the memory of keeping both): each target keeps
        // its best pass.
        let mut best: Vec<Option<PassPeak>> = vec![None; targets.len()];
        let mut spectra = Spectra::default();
        for pass in 0..self.layout.block_start_ms.len() {
            self.block_spectra(samples, pass, &mut spectra);
            best.par_iter_mut()
                .zip(targets.par_iter())
                .zip(rows.par_iter().zip(thresholds.par_iter()))
                .with_max_len(1)
                .for_each(|((kept, t), (&(b0, b1), &threshold))| {
                    let mut s = self.take_scratch();
                    let peak = self.pass_peak(&spectra, t.prn, (b0, b1), pass, threshold, &mut s);
                    if kept
                        .as_ref()
                        .is_none_or(|k| peak.peak.metric > k.peak.metric)
                    {
                        *kept = Some(peak);
                    }
                    self.give_scratch(s);
                });
        }
        // The spectra are not needed any more: released before the refinement (they are
        // the largest part of a search's memory).
        drop(spectra);
        // The refinement's prompts: `refine_ms` code periods from the code phase (less than
        // a period in), read where they are held (converted period by period).
        let refine_len =
            ((f64::from(self.config.refine_ms) + 2.0) * self.layout.period_samples).ceil() as usize;
        let samples = head(samples, refine_len);
        let mut results: Vec<AcqResult> = targets
            .par_iter()
            .zip(best.par_iter())
            .zip(rows.par_iter().zip(thresholds.par_iter()))
            .with_max_len(1)
            .filter_map(|((t, kept), (&(b0, _), &threshold))| {
                let kept = kept.as_ref()?;
                let mut s = self.take_scratch();
                let r = self.decide(samples, t.prn, b0, kept, threshold, &mut s);
                self.give_scratch(s);
                Some(r)
            })
            .collect();
        if let Some(margin) = self.config.xcorr_margin_db {
            mark_cross_correlations(&mut results, margin);
        }
        Ok(results)
    }

    /// Searches all 32 PRNs over the whole Doppler range.
    pub fn search_all(&self, samples: &[Complex32]) -> Result<Vec<AcqResult>, AcqError> {
        let targets: Vec<SearchTarget> = Prn::all().map(SearchTarget::full).collect();
        self.search(samples, &targets)
    }

    /// The search grid of one target (first pass: blocks from the first sample), for plots and
    /// for checking the statistics.
    pub fn grid(&self, samples: &[Complex32], target: &SearchTarget) -> Result<AcqGrid, AcqError> {
        self.check_len(samples.len())?;
        let (b0, b1) = self.bins_for(target)?;
        let mut spectra = Spectra::default();
        self.block_spectra(SampleSlice::Cf32(samples), 0, &mut spectra);
        let mut s = self.take_scratch();
        self.fill_grid(&spectra, target.prn, b0, b1, 0, &mut s);
        let step = self.layout.doppler_step_hz;
        let grid = AcqGrid {
            prn: target.prn,
            doppler_hz: (b0..=b1).map(|b| b as f64 * step).collect(),
            n_lags: self.layout.n_lags,
            lag_samples: self.layout.lag_samples,
            noncoherent: self.config.noncoherent,
            power: s.grid.clone(),
        };
        self.give_scratch(s);
        Ok(grid)
    }

    fn check_len(&self, got: usize) -> Result<(), AcqError> {
        if got < self.layout.samples_needed {
            return Err(AcqError::NotEnoughSamples {
                needed: self.layout.samples_needed,
                needed_ms: self.layout.samples_needed as f64 / self.fs_hz * 1e3,
                got,
            });
        }
        Ok(())
    }

    /// Doppler bins (inclusive range) of a target's window within the engine's range.
    fn bins_for(&self, t: &SearchTarget) -> Result<(i64, i64), AcqError> {
        let l = &self.layout;
        let Some((lo, hi)) = t.doppler_window_hz else {
            return Ok((l.bin_min, l.bin_max));
        };
        let s = l.doppler_step_hz;
        let b0 = if lo.is_finite() {
            (lo / s).floor() as i64
        } else {
            l.bin_min
        };
        let b1 = if hi.is_finite() {
            (hi / s).ceil() as i64
        } else {
            l.bin_max
        };
        let (b0, b1) = (b0.max(l.bin_min), b1.min(l.bin_max));
        if b0 > b1 || lo.is_nan() || hi.is_nan() {
            let (range_min_hz, range_max_hz) = self.doppler_range_hz();
            return Err(AcqError::EmptyDopplerWindow {
                prn: t.prn,
                min_hz: lo,
                max_hz: hi,
                range_min_hz,
                range_max_hz,
            });
        }
        Ok((b0, b1))
    }

    pub(super) fn take_scratch(&self) -> Scratch {
        let mut s = self
            .scratch_pool
            .lock()
            .ok()
            .and_then(|mut p| p.pop())
            .unwrap_or_default();
        let zero = Complex32::new(0.0, 0.0);
        let fft_len = self
            .fwd
            .get_inplace_scratch_len()
            .max(self.inv.get_inplace_scratch_len())
            .max(self.fine.get_inplace_scratch_len());
        s.buf
            .resize(self.layout.block_len.max(self.layout.inv_len), zero);
        s.fft.resize(fft_len, zero);
        s.fine.resize(self.fine_len, zero);
        s
    }

    pub(super) fn give_scratch(&self, s: Scratch) {
        if let Ok(mut p) = self.scratch_pool.lock() {
            p.push(s);
        }
    }

    /// The detection threshold of a search of `t` over Doppler bins `b0..=b1`: on the
    /// per-block mean of the grid over its floor, for the target's false-alarm probability
    /// spread over every cell of every pass.
    fn threshold(&self, t: &SearchTarget, (b0, b1): (i64, i64)) -> f64 {
        let l = &self.layout;
        let nc = self.config.noncoherent;
        let cells = (b1 - b0 + 1) as usize * l.n_lags * l.block_start_ms.len();
        let pfa = t.pfa.unwrap_or(self.config.pfa);
        detection_threshold(nc, pfa, cells) / f64::from(nc)
    }

    /// One pass's grid of `prn` over Doppler bins `b0..=b1`, analysed; the band-noise ratio
    /// at its peak is taken while the pass's spectra are at hand, when the peak is a detection.
    fn pass_peak(
        &self,
        spectra: &Spectra,
        prn: Prn,
        (b0, b1): (i64, i64),
        pass: usize,
        threshold: f64,
        s: &mut Scratch,
    ) -> PassPeak {
        let l = &self.layout;
        let rows = (b1 - b0 + 1) as usize;
        // One chip in search lags.
        let exclusion = (self.fs_hz / CA_CHIP_RATE_HZ / l.lag_samples).ceil() as usize;
        self.fill_grid(spectra, prn, b0, b1, pass, s);
        let peak = analyse(&s.grid, rows, l.n_lags, exclusion, &mut s.floors);
        let band = if peak.metric >= threshold {
            self.band_noise_ratio(spectra, b0 + peak.row as i64)
        } else {
            1.0
        };
        PassPeak { peak, pass, band }
    }

    /// The result of `prn` from its best pass: detected when over `threshold`, then refined.
    fn decide(
        &self,
        samples: SampleSlice<'_>,
        prn: Prn,
        b0: i64,
        kept: &PassPeak,
        threshold: f64,
        s: &mut Scratch,
    ) -> AcqResult {
        let l = &self.layout;
        let peak = &kept.peak;
        let detected = peak.metric >= threshold;
        let step = l.doppler_step_hz;
        let coarse_hz = (b0 as f64 + peak.row as f64 + peak.row_frac) * step;
        let code_phase = (peak.lag_frac * l.lag_samples).rem_euclid(l.period_samples);
        let mut result = AcqResult {
            prn,
            detected,
            code_phase_samples: code_phase,
            code_phase_chips: (code_phase * CA_CHIP_RATE_HZ / self.fs_hz)
                .rem_euclid(CA_CODE_LENGTH as f64),
            doppler_hz: coarse_hz,
            doppler_coarse_hz: coarse_hz,
            cn0_dbhz: None,
            metric: peak.metric,
            threshold,
            peak_ratio: peak.peak_ratio,
            bit_offset_ms: l.block_start_ms[kept.pass].first().copied().unwrap_or(0),
            refine_ms: 0,
            cross_correlation_of: None,
        };
        if detected {
            self.refine(samples, peak, kept.band, &mut result, s);
        }
        result
    }

    /// Fine Doppler from squared prompts, then the code phase from early/prompt/late
    /// correlators at that Doppler, and the C/N0 at the apex of their triangle.
    /// `band` is the full-band over in-band noise power of a correlation (1 when the search
    /// keeps the whole spectrum; see [`Self::band_noise_ratio`]).
    fn refine(
        &self,
        samples: SampleSlice<'_>,
        peak: &Peak,
        band: f64,
        r: &mut AcqResult,
        s: &mut Scratch,
    ) {
        let l = &self.layout;
        let code = &self.packed[r.prn.index()];
        let k_max = self.config.refine_ms as usize;
        let t_p = 1e-3;
        let max_dev = l.doppler_step_hz.min(240.0);
        // sigma_x^2 per sample from the grid floor: E|corr|^2 = block_len sigma_x^2 per block
        // for a full-band correlation (the prompts below), `1/band` of that in the grid.
        let var_per_sample =
            peak.noise_mean * band / (f64::from(self.config.noncoherent) * l.block_len as f64);
        let noise_var = var_per_sample * l.period_samples;
        let fs = self.fs_hz;
        let tau = r.code_phase_samples;
        correlate_periods(
            samples,
            &mut s.period,
            &self.correlator,
            code,
            fs,
            tau,
            (r.doppler_hz, r.doppler_hz),
            k_max,
            &[0.0],
            &mut s.epl[..1],
        );
        let fine = fine_doppler(&s.epl[0], t_p, max_dev, &self.fine, &mut s.fine, &mut s.fft);
        if let Some(df) = fine {
            r.doppler_hz += df;
        }
        // Early/prompt/late half a chip apart (late = replica delayed).
        let d = 0.5 * fs / CA_CHIP_RATE_HZ;
        correlate_periods(
            samples,
            &mut s.period,
            &self.correlator,
            code,
            fs,
            tau,
            (r.doppler_hz, r.doppler_hz),
            k_max,
            &[-d, 0.0, d],
            &mut s.epl,
        );
        r.refine_ms = s.epl[1].len() as u32;
        let [e, p, lt] = [0, 1, 2].map(|i| amplitude(&s.epl[i], noise_var));
        let mut apex = p;
        if r.refine_ms > 0 && p > 0.0 && p >= e && p >= lt {
            let off = triangle_offset(e, p, lt);
            let slope = if lt >= e { p - e } else { p - lt };
            apex = p + slope * off.abs();
            r.code_phase_samples = (tau + off * d).rem_euclid(l.period_samples);
            r.code_phase_chips =
                (r.code_phase_samples * CA_CHIP_RATE_HZ / fs).rem_euclid(CA_CODE_LENGTH as f64);
        }
        r.cn0_dbhz = cn0_dbhz(apex, noise_var, t_p).or_else(|| {
            // No prompt: the peak's own SNR per block, (metric - 1) = T C/N0 (minus losses).
            let snr = peak.metric - 1.0;
            (snr > 0.0).then(|| 10.0 * (snr / self.coherent_s()).log10())
        });
    }
}

/// The first `len` samples of `samples` (all of them when fewer), as held.
fn head(samples: SampleSlice<'_>, len: usize) -> SampleSlice<'_> {
    let n = len.min(samples.len());
    match samples {
        SampleSlice::Cf32(x) => SampleSlice::Cf32(&x[..n]),
        SampleSlice::Ci16(x) => SampleSlice::Ci16(&x[..n]),
        SampleSlice::Ci8(x) => SampleSlice::Ci8(&x[..n]),
    }
}
