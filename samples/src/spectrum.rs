//! Averaged power spectrum of a recording (Welch's method: Hann-windowed, non-overlapping
//! blocks, periodograms averaged; Welch 1967, IEEE Trans. Audio Electroacoust. 15(2)), summarised
//! in bands.

use std::sync::Arc;

use num_complex::Complex32;
use rustfft::{Fft, FftPlanner};

/// FFT length of the averaged spectrum.
pub const FFT_SIZE: usize = 1024;
/// Bands the spectrum is summarised in.
pub const N_BANDS: usize = 32;

/// Power in one frequency band.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Band {
    /// Lower edge in Hz (negative frequencies for complex samples): the centre of the band's
    /// first FFT bin.
    pub f_lo_hz: f64,
    /// Upper edge in Hz: the centre of the next band's first bin.
    pub f_hi_hz: f64,
    /// Mean power in the band, dB relative to the mean over all bands.
    pub power_db: f64,
}

/// Summary of the averaged spectrum of the stored samples (before IF mix-down and Q inversion).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpectrumSummary {
    /// FFT length.
    pub fft_size: usize,
    /// Periodograms averaged.
    pub blocks: u64,
    /// Bands from the lowest frequency up: -fs/2..fs/2 (complex) or 0..fs/2 (real).
    pub bands: Vec<Band>,
    /// Index of the band with the most power.
    pub peak_band: usize,
    /// Strongest single FFT bin (DC excluded), in Hz.
    pub peak_bin_hz: f64,
    /// Strongest bin over the median bin, in dB (a narrowband line stands well above 10 dB).
    pub peak_bin_over_median_db: f64,
    /// Spectral flatness (geometric over arithmetic mean of bin powers, DC bins excluded):
    /// 1 = white, near 0 = a few strong lines.
    pub flatness: f64,
    /// DC bin over the median bin, in dB (LO leakage or a DC offset shows as a spike).
    pub dc_spike_db: f64,
}

/// Accumulates averaged periodograms.
pub(crate) struct SpectrumAccumulator {
    fft: Arc<dyn Fft<f32>>,
    window: Vec<f32>,
    block: Vec<Complex32>,
    scratch: Vec<Complex32>,
    fill: usize,
    power: Vec<f64>,
    blocks: u64,
}

impl std::fmt::Debug for SpectrumAccumulator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpectrumAccumulator")
            .field("blocks", &self.blocks)
            .finish_non_exhaustive()
    }
}

impl SpectrumAccumulator {
    pub fn new() -> Self {
        let fft = FftPlanner::new().plan_fft_forward(FFT_SIZE);
        let window = (0..FFT_SIZE)
            .map(|k| {
                let x = std::f64::consts::TAU * k as f64 / FFT_SIZE as f64;
                (0.5 - 0.5 * x.cos()) as f32
            })
            .collect();
        let scratch = vec![Complex32::default(); fft.get_inplace_scratch_len()];
        SpectrumAccumulator {
            fft,
            window,
            block: vec![Complex32::default(); FFT_SIZE],
            scratch,
            fill: 0,
            power: vec![0.0; FFT_SIZE],
            blocks: 0,
        }
    }

    /// Adds samples; every full block of [`FFT_SIZE`] becomes one periodogram.
    pub fn push(&mut self, mut samples: &[Complex32]) {
        while !samples.is_empty() {
            let take = (FFT_SIZE - self.fill).min(samples.len());
            for (k, s) in samples[..take].iter().enumerate() {
                let i = self.fill + k;
                self.block[i] = s * self.window[i];
            }
            self.fill += take;
            samples = &samples[take..];
            if self.fill == FFT_SIZE {
                self.fft
                    .process_with_scratch(&mut self.block, &mut self.scratch);
                for (p, x) in self.power.iter_mut().zip(&self.block) {
                    *p += f64::from(x.norm_sqr());
                }
                self.blocks += 1;
                self.fill = 0;
            }
        }
    }

    /// The summary, or `None` when not one full block was seen or all power is zero.
    pub fn finish(self, fs_hz: f64, complex: bool) -> Option<SpectrumSummary> {
        if self.blocks == 0 {
            return None;
        }
        let n = FFT_SIZE;
        let bin_hz = fs_hz / n as f64;
        // (frequency, power) from the lowest frequency up.
        let bins: Vec<(f64, f64)> = if complex {
            (0..n)
                .map(|j| {
                    let k = (j + n / 2) % n;
                    let f = if k < n / 2 {
                        k as f64
                    } else {
                        k as f64 - n as f64
                    };
                    (f * bin_hz, self.power[k] / self.blocks as f64)
                })
                .collect()
        } else {
            (0..n / 2)
                .map(|k| (k as f64 * bin_hz, self.power[k] / self.blocks as f64))
                .collect()
        };
        let total: f64 = bins.iter().map(|b| b.1).sum();
        if total <= 0.0 {
            return None;
        }
        // Bins within one bin of DC (the Hann window spreads a DC offset over them).
        let near_dc = |f: f64| f.abs() < 1.5 * bin_hz;
        let mut others: Vec<f64> = bins.iter().filter(|b| !near_dc(b.0)).map(|b| b.1).collect();
        others.sort_by(f64::total_cmp);
        let median = others[others.len() / 2].max(f64::MIN_POSITIVE);
        let dc = bins
            .iter()
            .find(|b| b.0 == 0.0)
            .map_or(0.0, |b| b.1)
            .max(f64::MIN_POSITIVE);
        let floor = total / bins.len() as f64 * 1e-12;
        let log_mean = others.iter().map(|p| p.max(floor).ln()).sum::<f64>() / others.len() as f64;
        let mean = others.iter().sum::<f64>() / others.len() as f64;
        let flatness = if mean > 0.0 {
            log_mean.exp() / mean
        } else {
            0.0
        };
        let (peak_bin_hz, peak_p) = bins
            .iter()
            .filter(|b| !near_dc(b.0))
            .fold((0.0, 0.0), |acc, b| if b.1 > acc.1 { *b } else { acc });

        let per_band = bins.len() / N_BANDS;
        let band_mean = total / bins.len() as f64;
        let bands: Vec<Band> = bins
            .chunks(per_band)
            .map(|c| {
                let p = c.iter().map(|b| b.1).sum::<f64>() / c.len() as f64;
                Band {
                    f_lo_hz: c[0].0,
                    f_hi_hz: c[c.len() - 1].0 + bin_hz,
                    power_db: 10.0 * (p.max(band_mean * 1e-12) / band_mean).log10(),
                }
            })
            .collect();
        let peak_band = bands.iter().enumerate().fold(0, |best, (i, b)| {
            if b.power_db > bands[best].power_db {
                i
            } else {
                best
            }
        });
        Some(SpectrumSummary {
            fft_size: n,
            blocks: self.blocks,
            bands,
            peak_band,
            peak_bin_hz,
            peak_bin_over_median_db: 10.0 * (peak_p.max(f64::MIN_POSITIVE) / median).log10(),
            flatness,
            dc_spike_db: 10.0 * (dc / median).log10(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_lands_in_its_band() {
        let fs = 4.0e6;
        let f = 1.1e6;
        let mut acc = SpectrumAccumulator::new();
        let x: Vec<Complex32> = (0..FFT_SIZE * 8)
            .map(|n| {
                let ph = std::f64::consts::TAU * f * n as f64 / fs;
                Complex32::new(ph.cos() as f32, ph.sin() as f32)
            })
            .collect();
        acc.push(&x);
        let s = acc.finish(fs, true).expect("spectrum");
        let b = &s.bands[s.peak_band];
        assert!(b.f_lo_hz <= f && f < b.f_hi_hz, "{b:?}");
        assert!((s.peak_bin_hz - f).abs() < fs / FFT_SIZE as f64);
        assert!(s.flatness < 0.1);
    }
}
