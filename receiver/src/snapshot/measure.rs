//! Code phases and Dopplers of one snapshot: an assisted FFT search of the satellites the
//! ephemerides put above the horizon, the common front-end frequency offset, a narrow second
//! search at the predicted Dopplers, and the rejection of false peaks.
//!
//! # Searches
//!
//! 1. Every predicted satellite over the whole window `0 +- doppler_max_hz` (the front-end
//!    offset is unknown), `coherent_ms` x as many non-coherent blocks as the snapshot holds
//!    ([`gpsrx_dsp::acquisition`]: the code phase is refined by early/prompt/late correlators
//!    over every whole code period of the snapshot, a triangle fit, to hundredths of a sample).
//! 2. The common offset `f_fe` from the detections ([`estimate_offset`]): the Doppler seen is
//!    `f_k = D_k + f_fe` (with `D_k` predicted from the a-priori position and time), or
//!    `+-(D_k + f_fe)` when the spectrum is folded (real samples with IF = k fs: a tone at `f`
//!    and at `-f` are the same real signal). The offset is the one that explains most
//!    detections within [`doppler_tolerance_hz`] (grid of 5 Hz; a-priori errors of 100 km and
//!    60 s move the `D_k` by at most about 60 Hz; the receiver's own speed by v / lambda).
//! 3. The satellites not yet detected are searched again in `+-(NARROW_WINDOW_HZ + v / lambda)`
//!    around `D_k + f_fe`: fewer cells, so a lower threshold for the same false-alarm
//!    probability.
//! 4. A detection whose Doppler disagrees with `D_k + f_fe` by more than
//!    [`doppler_tolerance_hz`] is a false peak (or a cross-correlation) and is dropped; the
//!    engine's own cross-correlation test (15 dB weaker and a whole kHz away) has run before.
//!
//! A wrong code phase that survives these tests is left to the solver's residual test
//! ([`gpsrx_nav::pvt::coarse_time`]: chi-square and leave-one-out).

use gpsrx_core::PosVel;
use gpsrx_dsp::acquisition::code_fit::{fit_code_phase, peak_to_noise, CodeFitOptions};
use gpsrx_dsp::acquisition::stats::detection_threshold;
use gpsrx_dsp::acquisition::{AcqConfig, AcqResult, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_nav::{GpsTime, HealthPolicy, NavData, Vector3};
use num_complex::Complex32;
use rayon::prelude::*;

use super::coherent::coherent_detect;
use super::fine_phase::band_limited_code_phase;
use crate::pipeline::channels::predict_satellite;

/// A detection must agree with the predicted Doppler plus the common offset to this, Hz, plus
/// the Doppler of the receiver's own speed ([`doppler_tolerance_hz`]).
pub const DOPPLER_TOLERANCE_HZ: f64 = 200.0;
/// GPS L1 wavelength, m.
const L1_WAVELENGTH_M: f64 = gpsrx_nav::constants::SPEED_OF_LIGHT_MPS / 1_575.42e6;

/// The Doppler tolerance for a receiver moving at up to `max_speed_mps`:
/// [`DOPPLER_TOLERANCE_HZ`] + v / lambda_L1 (the predictions are for a static receiver).
pub fn doppler_tolerance_hz(max_speed_mps: f64) -> f64 {
    DOPPLER_TOLERANCE_HZ + max_speed_mps.max(0.0) / L1_WAVELENGTH_M
}
/// Half-width of the second, narrow search around the predicted Doppler, Hz.
pub const NARROW_WINDOW_HZ: f64 = 150.0;
/// The default band of the matched replica, Hz (see [`MeasureOptions::code_band_hz`]).
pub const DEFAULT_CODE_BAND_HZ: f64 = 1.75e6;
/// Detections needed to estimate the common offset.
pub const MIN_FOR_OFFSET: usize = 2;

/// What the ephemeris predicts for one satellite at the a-priori position and time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Predicted {
    /// The satellite.
    pub prn: Prn,
    /// Doppler for a static receiver with a perfect clock, Hz.
    pub doppler_hz: f64,
    /// Elevation, deg.
    pub elevation_deg: f64,
}

/// One satellite's measurement from a snapshot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatCodePhase {
    /// The satellite.
    pub prn: Prn,
    /// Sample index at which a C/A code period starts, interpolated, in [0, fs 1 ms).
    pub code_phase_samples: f64,
    /// Doppler as seen (sign ambiguous when folded), Hz.
    pub doppler_seen_hz: f64,
    /// Doppler with the sign and the common offset resolved: the satellite's own Doppler, Hz.
    pub doppler_hz: f64,
    /// C/N0 estimate, dB-Hz.
    pub cn0_dbhz: f64,
    /// Predicted elevation, deg.
    pub elevation_deg: f64,
}

/// The acquisition of one snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotAcquisition {
    /// Accepted measurements.
    pub sats: Vec<SatCodePhase>,
    /// Common front-end frequency offset, Hz (`None` with too few detections).
    pub offset_hz: Option<f64>,
    /// Peaks over the threshold dropped as false (Doppler inconsistent) or cross-correlations.
    pub rejected_prns: Vec<u8>,
    /// Satellites searched.
    pub searched: usize,
    /// The predictions the search used.
    pub predicted: Vec<Predicted>,
}

/// Settings of the snapshot search.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasureOptions {
    /// Coherent integration, ms (`None`: 1 ms for snapshots under 40 ms, else 10 ms).
    pub coherent_ms: Option<u32>,
    /// Half-width of the first search around 0 Hz, Hz (satellite Doppler plus front-end
    /// offset).
    pub doppler_max_hz: f64,
    /// Elevation mask of the prediction, deg.
    pub elevation_mask_deg: f64,
    /// False-alarm probability per PRN search (first, wide search).
    pub pfa: f64,
    /// Largest receiver speed, m/s: widens the Doppler tolerance and the narrow search.
    pub max_speed_mps: f64,
    /// Band of the matched replica of the final code-phase estimate, Hz
    /// ([`super::fine_phase`]); `None`: the parabola fit of
    /// [`gpsrx_dsp::acquisition::code_fit`] alone.
    pub code_band_hz: Option<f64>,
    /// Look for missed satellites with the coherent test too ([`look_at_predicted`]).
    pub coherent_predicted: bool,
}

impl Default for MeasureOptions {
    /// Automatic coherent time, +-7 kHz, 5 deg, pfa 1e-4, 50 m/s, the band-limited fit at
    /// +-1.75 MHz, no coherent test at predicted code phases.
    fn default() -> Self {
        Self {
            coherent_ms: None,
            doppler_max_hz: 7_000.0,
            elevation_mask_deg: 5.0,
            pfa: 1e-4,
            max_speed_mps: 50.0,
            code_band_hz: Some(DEFAULT_CODE_BAND_HZ),
            coherent_predicted: false,
        }
    }
}

/// The engine settings for a snapshot of `len_ms` whole code periods: `(coherent_ms,
/// noncoherent)`, or `None` when it is shorter than 1 ms.
pub fn search_layout(len_ms: u32, coherent_ms: Option<u32>) -> Option<(u32, u32)> {
    let t = coherent_ms
        .unwrap_or(if len_ms >= 40 { 10 } else { 1 })
        .max(1);
    if len_ms < t {
        return None;
    }
    // With T >= 2 ms the bit-edge pass starts T/2 later: keep room for it.
    let room = if t >= 2 { len_ms - t / 2 } else { len_ms };
    Some((t, (room / t).max(1)))
}

/// Satellites above `mask_deg` at `rx` and `t` with a valid ephemeris, highest first.
pub fn predict_visible(
    nav: &NavData,
    rx: &Vector3<f64>,
    t: GpsTime,
    mask_deg: f64,
) -> Vec<Predicted> {
    let rx = PosVel {
        pos_m: *rx,
        vel_mps: Vector3::zeros(),
    };
    let mut p: Vec<Predicted> = Prn::all()
        .filter_map(|prn| {
            let eph = nav.select_with(prn.get(), t, HealthPolicy::PreferHealthy)?;
            let p = predict_satellite(eph, &rx, t, 0.0)?;
            (p.elevation_deg >= mask_deg).then_some(Predicted {
                prn,
                doppler_hz: p.doppler_hz,
                elevation_deg: p.elevation_deg,
            })
        })
        .collect();
    p.sort_by(|a, b| b.elevation_deg.total_cmp(&a.elevation_deg));
    p
}

/// The Doppler error of a detection at `seen_hz` against a prediction `d_hz` with offset
/// `offset_hz`: `|seen - (d + off)|`, or with a folded spectrum `||seen| - |d + off||`.
pub fn doppler_error_hz(seen_hz: f64, d_hz: f64, offset_hz: f64, folded: bool) -> f64 {
    let expected = d_hz + offset_hz;
    if folded {
        (seen_hz.abs() - expected.abs()).abs()
    } else {
        (seen_hz - expected).abs()
    }
}

/// The common offset explaining most detections `(seen, predicted)` within `tol_hz`
/// (ties: smallest summed error), searched over `-max_hz..=max_hz` in 5 Hz steps. `None` when
/// fewer than [`MIN_FOR_OFFSET`] agree.
pub fn estimate_offset(
    pairs: &[(f64, f64)],
    max_hz: f64,
    folded: bool,
    tol_hz: f64,
) -> Option<f64> {
    let steps = (max_hz / 5.0).ceil() as i64;
    let mut best: Option<(usize, f64, f64)> = None;
    for k in -steps..=steps {
        let off = k as f64 * 5.0;
        let (mut n, mut cost) = (0usize, 0.0);
        for &(seen, d) in pairs {
            let e = doppler_error_hz(seen, d, off, folded);
            if e <= tol_hz {
                n += 1;
                cost += e;
            }
        }
        let better = match best {
            None => true,
            Some((bn, bc, _)) => n > bn || (n == bn && cost < bc),
        };
        if better {
            best = Some((n, cost, off));
        }
    }
    best.and_then(|(n, _, off)| (n >= MIN_FOR_OFFSET).then_some(off))
}

/// Runs the searches of the module docs on `samples` (at the engine's rate) for the
/// satellites `pred`. `engine` is the wide search; `narrow` builds engines for the second one.
pub fn acquire_snapshot(
    samples: &[Complex32],
    folded: bool,
    pred: &[Predicted],
    wide: &AcquisitionEngine,
    narrow_config: &AcqConfig,
    fe_offset_max_hz: f64,
    opts: &MeasureOptions,
) -> Result<SnapshotAcquisition, gpsrx_dsp::acquisition::AcqError> {
    let tol = doppler_tolerance_hz(opts.max_speed_mps);
    let narrow_hz = NARROW_WINDOW_HZ + (tol - DOPPLER_TOLERANCE_HZ);
    let targets: Vec<SearchTarget> = pred.iter().map(|p| SearchTarget::full(p.prn)).collect();
    let mut results = wide.search(samples, &targets)?;
    let pairs: Vec<(f64, f64)> = detections(&results)
        .filter_map(|r| {
            let p = pred.iter().find(|p| p.prn == r.prn)?;
            Some((r.doppler_hz, p.doppler_hz))
        })
        .collect();
    let offset = estimate_offset(&pairs, fe_offset_max_hz, folded, tol);
    if let Some(off) = offset {
        let missing: Vec<SearchTarget> = pred
            .iter()
            .filter(|p| !detections(&results).any(|r| r.prn == p.prn))
            .map(|p| SearchTarget::around(p.prn, p.doppler_hz + off, narrow_hz))
            .collect();
        if !missing.is_empty() {
            let lo = missing
                .iter()
                .filter_map(|t| t.doppler_window_hz)
                .map(|w| w.0);
            let hi = missing
                .iter()
                .filter_map(|t| t.doppler_window_hz)
                .map(|w| w.1);
            let (lo, hi) = (
                lo.fold(f64::INFINITY, f64::min),
                hi.fold(f64::NEG_INFINITY, f64::max),
            );
            let cfg = AcqConfig {
                doppler_center_hz: 0.5 * (lo + hi),
                doppler_max_hz: 0.5 * (hi - lo),
                xcorr_margin_db: None,
                ..narrow_config.clone()
            };
            let engine = AcquisitionEngine::new(wide.fs_hz(), cfg)?;
            let second = engine.search(samples, &missing)?;
            results.retain(|r| !missing.iter().any(|t| t.prn == r.prn));
            results.extend(second);
        }
    }
    let mut acq = assemble(&results, pred, offset, folded, tol);
    let fit = CodeFitOptions::default();
    // Each satellite's fit on its own core (the band-limited fit is most of a snapshot's time).
    acq.sats.par_iter_mut().for_each(|s| {
        if let Some(tau) = fit_code_phase(
            samples,
            wide.fs_hz(),
            s.prn,
            s.code_phase_samples,
            (s.doppler_seen_hz, s.doppler_hz),
            &fit,
        ) {
            s.code_phase_samples = tau;
        }
        s.code_phase_samples = refine(samples, wide.fs_hz(), s, opts.code_band_hz);
    });
    Ok(acq)
}

/// A satellite the searches missed, where a fix predicts it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictedPhase {
    /// The satellite.
    pub prn: Prn,
    /// Predicted code phase, samples.
    pub code_phase_samples: f64,
    /// Predicted satellite Doppler, Hz (without the front-end offset).
    pub doppler_hz: f64,
    /// Elevation, deg.
    pub elevation_deg: f64,
}

/// False-alarm probability of the check at a predicted code phase (one cell per satellite).
pub const PREDICTED_PFA: f64 = 1e-3;
/// A peak found at a predicted code phase must lie this close to it after the fit, chips.
pub const PREDICTED_MAX_SHIFT_CHIPS: f64 = 0.3;

/// Looks for each missed satellite at its predicted code phase and Doppler (plus the
/// front-end offset): accepted when the non-coherent power there over the noise passes the
/// Gamma(K) threshold for [`PREDICTED_PFA`] (one cell: the position is known) and the fitted
/// peak stays within [`PREDICTED_MAX_SHIFT_CHIPS`]; else, with `coherent`, when the coherent
/// statistic over the whole snapshot with the bit edge hypothesised passes its threshold for
/// the same probability ([`super::coherent`]) and the band-limited fit stays as close. A wrong
/// one is left to the residual test.
pub fn look_at_predicted(
    samples: &[Complex32],
    fs_hz: f64,
    offset_hz: f64,
    missed: &[PredictedPhase],
    code_band_hz: Option<f64>,
    coherent: bool,
) -> Vec<SatCodePhase> {
    missed
        .par_iter()
        .filter_map(|m| {
            look_non_coherent(samples, fs_hz, offset_hz, m, code_band_hz).or_else(|| {
                coherent
                    .then(|| look_coherent(samples, fs_hz, offset_hz, m, code_band_hz))
                    .flatten()
            })
        })
        .collect()
}

/// Whether `tau` lies within [`PREDICTED_MAX_SHIFT_CHIPS`] of the prediction (modulo 1 ms).
fn near_prediction(tau: f64, m: &PredictedPhase, fs_hz: f64) -> bool {
    let period = fs_hz * 1e-3;
    let per_chip = fs_hz / gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
    let d = (tau - m.code_phase_samples + 0.5 * period).rem_euclid(period) - 0.5 * period;
    d.abs() <= PREDICTED_MAX_SHIFT_CHIPS * per_chip
}

/// The non-coherent test of [`look_at_predicted`].
fn look_non_coherent(
    samples: &[Complex32],
    fs_hz: f64,
    offset_hz: f64,
    m: &PredictedPhase,
    code_band_hz: Option<f64>,
) -> Option<SatCodePhase> {
    let fit = CodeFitOptions::default();
    let seen = m.doppler_hz + offset_hz;
    let dopplers = (seen, m.doppler_hz);
    let tau = fit_code_phase(samples, fs_hz, m.prn, m.code_phase_samples, dopplers, &fit)?;
    if !near_prediction(tau, m, fs_hz) {
        return None;
    }
    let (ratio, k) = peak_to_noise(samples, fs_hz, m.prn, tau, dopplers, 1000)?;
    let threshold = detection_threshold(k as u32, PREDICTED_PFA, 1) / k as f64;
    let mut s = SatCodePhase {
        prn: m.prn,
        code_phase_samples: tau,
        doppler_seen_hz: seen,
        doppler_hz: m.doppler_hz,
        cn0_dbhz: 10.0 * ((ratio - 1.0).max(1e-3) / 1e-3).log10(),
        elevation_deg: m.elevation_deg,
    };
    s.code_phase_samples = refine(samples, fs_hz, &s, code_band_hz);
    (ratio >= threshold).then_some(s)
}

/// The coherent test of [`look_at_predicted`] at the predicted code phase; the C/N0 from the
/// statistic's mean `1 + M T C/N0`.
fn look_coherent(
    samples: &[Complex32],
    fs_hz: f64,
    offset_hz: f64,
    m: &PredictedPhase,
    code_band_hz: Option<f64>,
) -> Option<SatCodePhase> {
    let seen = m.doppler_hz + offset_hz;
    let d = coherent_detect(
        samples,
        fs_hz,
        m.prn,
        m.code_phase_samples,
        (seen, m.doppler_hz),
        PREDICTED_PFA,
    )?;
    if !d.detected() {
        return None;
    }
    let cn0 = (d.z - 1.0).max(1e-3) / (d.periods as f64 * 1e-3);
    let mut s = SatCodePhase {
        prn: m.prn,
        code_phase_samples: m.code_phase_samples,
        doppler_seen_hz: seen + d.doppler_offset_hz,
        doppler_hz: m.doppler_hz,
        cn0_dbhz: 10.0 * cn0.log10(),
        elevation_deg: m.elevation_deg,
    };
    s.code_phase_samples = refine(samples, fs_hz, &s, code_band_hz);
    near_prediction(s.code_phase_samples, m, fs_hz).then_some(s)
}

/// The code phase of `s` from the band-limited matched replica when `band_hz` is set and the
/// rate allows it ([`super::fine_phase`]), else as it is.
fn refine(samples: &[Complex32], fs_hz: f64, s: &SatCodePhase, band_hz: Option<f64>) -> f64 {
    band_hz
        .and_then(|b| {
            band_limited_code_phase(
                samples,
                fs_hz,
                s.prn,
                s.code_phase_samples,
                (s.doppler_seen_hz, s.doppler_hz),
                b,
            )
        })
        .unwrap_or(s.code_phase_samples)
}

fn detections(results: &[AcqResult]) -> impl Iterator<Item = &AcqResult> {
    results.iter().filter(|r| r.detected)
}

/// The accepted measurements: detections whose Doppler agrees with the prediction and offset.
fn assemble(
    results: &[AcqResult],
    pred: &[Predicted],
    offset: Option<f64>,
    folded: bool,
    tol_hz: f64,
) -> SnapshotAcquisition {
    let mut out = SnapshotAcquisition {
        sats: Vec::new(),
        offset_hz: offset,
        rejected_prns: Vec::new(),
        searched: pred.len(),
        predicted: pred.to_vec(),
    };
    for r in results {
        if r.cross_correlation_of.is_some() {
            out.rejected_prns.push(r.prn.get());
            continue;
        }
        if !r.detected {
            continue;
        }
        let (Some(p), Some(off)) = (pred.iter().find(|p| p.prn == r.prn), offset) else {
            continue;
        };
        if doppler_error_hz(r.doppler_hz, p.doppler_hz, off, folded) > tol_hz {
            out.rejected_prns.push(r.prn.get());
            continue;
        }
        // The satellite's Doppler: the seen one with the predicted sign, less the offset.
        let expected = p.doppler_hz + off;
        let seen = if folded {
            r.doppler_hz.abs() * expected.signum()
        } else {
            r.doppler_hz
        };
        out.sats.push(SatCodePhase {
            prn: r.prn,
            code_phase_samples: r.code_phase_samples,
            doppler_seen_hz: r.doppler_hz,
            doppler_hz: seen - off,
            cn0_dbhz: r.cn0_dbhz.unwrap_or(30.0),
            elevation_deg: p.elevation_deg,
        });
    }
    out.sats
        .sort_by(|a, b| b.elevation_deg.total_cmp(&a.elevation_deg));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_explains_folded_and_signed_detections() {
        // Predicted Dopplers and an offset of -700 Hz; seen with random signs when folded.
        let d = [2500.0, -1800.0, 300.0, -3200.0, 1100.0];
        let off = -700.0;
        let folded: Vec<(f64, f64)> = d
            .iter()
            .enumerate()
            .map(|(k, &dk)| (if k % 2 == 0 { 1.0 } else { -1.0 } * (dk + off + 20.0), dk))
            .collect();
        let est = estimate_offset(&folded, 3000.0, true, 200.0).expect("offset");
        assert!((est - off).abs() <= 40.0, "{est}");
        let signed: Vec<(f64, f64)> = d.iter().map(|&dk| (dk + off - 15.0, dk)).collect();
        let est = estimate_offset(&signed, 3000.0, false, 200.0).expect("offset");
        assert!((est - off).abs() <= 40.0, "{est}");
        assert_eq!(estimate_offset(&signed[..1], 3000.0, false, 200.0), None);
        // 100 m/s adds up to 525 Hz.
        assert!((doppler_tolerance_hz(100.0) - 725.5).abs() < 1.0);
    }

    #[test]
    fn layouts_fit_the_snapshot() {
        assert_eq!(search_layout(12, None), Some((1, 12)));
        assert_eq!(search_layout(107, None), Some((10, 10)));
        assert_eq!(search_layout(0, None), None);
        assert_eq!(search_layout(4, Some(5)), None);
    }
}
