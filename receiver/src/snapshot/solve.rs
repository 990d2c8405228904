//! From a snapshot's code phases to a position: the coarse-time solver of
//! [`gpsrx_nav::pvt::coarse_time`] (van Diggelen ch. 4) with the snapshot's first sample as the
//! common reception instant.
//!
//! # Observable
//!
//! The acquisition gives the sample `tau_k` at which a C/A code period of satellite k starts
//! (a whole millisecond of SV time). At the first sample the SV transmit time is therefore
//! `tau_k / fs` of code earlier, scaled by the code Doppler (the code runs at
//! `1.023 MHz (1 + D_k / f_L1)`):
//!
//! ```text
//! phi_k = t_sv,k(0) mod 1 ms = (-(tau_k / fs) (1 + D_k / f_L1)) mod 1 ms
//! ```
//!
//! (the code-Doppler term is at most 3.4e-6 of 1 ms, 1 m). Both the a-priori time and the
//! snapshot's time tag refer to that first sample.
//!
//! # Checks
//!
//! The solver checks the integers (chi-square over n - 5 degrees of freedom, leave-one-out);
//! on top of that a fix is kept only if its residual RMS is at most
//! [`SolveOptions::max_residual_rms_m`] and its HDOP at most [`SolveOptions::max_hdop`]. With
//! exactly five satellites nothing can be checked: such a fix is reported as `unverified`.

use super::measure::{Predicted, PredictedPhase, SatCodePhase};
use gpsrx_dsp::constants::F_L1_HZ;
use gpsrx_dsp::Prn;
use gpsrx_nav::pvt::{
    predicted_tx_time_mod_1ms, solve_coarse_time, CoarseApriori, CoarseIntegrity,
    CoarseMeasurement, CoarseTimeSolution, HeightConstraint, PvtOptions,
};
use gpsrx_nav::{GpsTime, HealthPolicy, NavData, Vector3};

/// C/A code period, s.
const CODE_PERIOD_S: f64 = 1e-3;

/// Checks a fix must pass on top of the solver's own.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveOptions {
    /// Largest accepted RMS of the post-fit residuals, m.
    pub max_residual_rms_m: f64,
    /// Largest accepted HDOP.
    pub max_hdop: f64,
    /// Navigation options (atmosphere, mask, weighting, RAIM false-alarm probability).
    pub pvt: PvtOptions,
    /// A-priori position uncertainty, m (the solver's bound).
    pub pos_uncertainty_m: f64,
    /// A-priori time uncertainty, s (the solver's bound).
    pub time_uncertainty_s: f64,
    /// Height above the ellipsoid used as an observation (`None`: five free unknowns).
    pub height: Option<HeightConstraint>,
}

/// How good a snapshot's position is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SnapshotQuality {
    /// Six or more satellites, the integers passed the residual test, RMS and HDOP in bounds.
    Fix,
    /// Exactly five satellites: nothing could be checked; not used to seed the next snapshot.
    Unverified,
    /// No position (see the reason).
    None,
}

impl SnapshotQuality {
    /// The name in `snapshots.csv`.
    pub fn name(self) -> &'static str {
        match self {
            SnapshotQuality::Fix => "fix",
            SnapshotQuality::Unverified => "unverified",
            SnapshotQuality::None => "none",
        }
    }
}

/// The transmit time modulo 1 ms at the first sample (module docs).
pub fn tx_time_mod_1ms_s(code_phase_samples: f64, fs_hz: f64, doppler_hz: f64) -> f64 {
    let phi =
        (-(code_phase_samples / fs_hz) * (1.0 + doppler_hz / F_L1_HZ)).rem_euclid(CODE_PERIOD_S);
    if phi >= CODE_PERIOD_S {
        0.0
    } else {
        phi
    }
}

/// Solves one snapshot (the a-priori time an observation of sigma `time_sigma_s` if given);
/// `Err` carries the reason in words.
pub fn solve_snapshot(
    sats: &[SatCodePhase],
    fs_hz: f64,
    nav: &NavData,
    apriori_time: GpsTime,
    apriori_pos: &Vector3<f64>,
    time_sigma_s: Option<f64>,
    opts: &SolveOptions,
) -> Result<(CoarseTimeSolution, SnapshotQuality), String> {
    let meas: Vec<CoarseMeasurement<'_>> = sats
        .iter()
        .filter_map(|s| {
            let eph = nav.select_with(s.prn.get(), apriori_time, HealthPolicy::HealthyOnly)?;
            Some(CoarseMeasurement {
                prn: s.prn.get(),
                tx_time_mod_1ms_s: tx_time_mod_1ms_s(s.code_phase_samples, fs_hz, s.doppler_hz),
                cn0_dbhz: s.cn0_dbhz,
                ephemeris: eph,
            })
        })
        .collect();
    let apriori = CoarseApriori {
        time: apriori_time,
        pos_ecef_m: *apriori_pos,
        time_uncertainty_s: opts.time_uncertainty_s,
        pos_uncertainty_m: opts.pos_uncertainty_m,
        height: opts.height,
        time_sigma_s,
    };
    let sol = solve_coarse_time(&meas, &apriori, &opts.pvt).map_err(|e| e.to_string())?;
    let rms = residual_rms_m(&sol);
    if rms > opts.max_residual_rms_m {
        return Err(format!(
            "residual RMS {rms:.1} m above {:.0} m: inconsistent code phases",
            opts.max_residual_rms_m
        ));
    }
    if sol.dop.hdop.is_nan() || sol.dop.hdop > opts.max_hdop {
        return Err(format!(
            "HDOP {:.1} above {:.0}: weak geometry",
            sol.dop.hdop, opts.max_hdop
        ));
    }
    let quality = match sol.integrity {
        CoarseIntegrity::Passed { .. } => SnapshotQuality::Fix,
        CoarseIntegrity::Unverified => SnapshotQuality::Unverified,
    };
    Ok((sol, quality))
}

/// The code phases at which a fix `sol` (solved at a-priori time `apriori_time`) predicts the
/// satellites of `pred` that are not in `have`
/// ([`gpsrx_nav::pvt::coarse_time::predicted_tx_time_mod_1ms`]; `tau = -phi fs mod fs 1 ms`).
pub fn predict_missed(
    sol: &CoarseTimeSolution,
    apriori_time: GpsTime,
    nav: &NavData,
    opts: &PvtOptions,
    fs_hz: f64,
    pred: &[Predicted],
    have: &[Prn],
) -> Vec<PredictedPhase> {
    let period = fs_hz * CODE_PERIOD_S;
    pred.iter()
        .filter(|p| !have.contains(&p.prn))
        .filter_map(|p| {
            let eph = nav.select_with(p.prn.get(), apriori_time, HealthPolicy::HealthyOnly)?;
            let phi = predicted_tx_time_mod_1ms(sol, apriori_time, eph, opts).ok()?;
            Some(PredictedPhase {
                prn: p.prn,
                code_phase_samples: (-phi * fs_hz).rem_euclid(period),
                doppler_hz: p.doppler_hz,
                elevation_deg: p.elevation_deg,
            })
        })
        .collect()
}

/// RMS of the post-fit residuals, m.
pub fn residual_rms_m(sol: &CoarseTimeSolution) -> f64 {
    let n = sol.satellites.len().max(1) as f64;
    (sol.satellites
        .iter()
        .map(|s| s.residual_m * s.residual_m)
        .sum::<f64>()
        / n)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn code_phase_becomes_transmit_time_modulo_1ms() {
        // A period starting 1000 samples in at 4 MHz: 0.25 ms of code still to come, so the
        // SV time at the first sample is 0.75 ms into a period.
        let phi = tx_time_mod_1ms_s(1000.0, 4.0e6, 0.0);
        assert!((phi - 0.75e-3).abs() < 1e-15, "{phi}");
        assert_eq!(tx_time_mod_1ms_s(0.0, 4.0e6, 0.0), 0.0);
        // Code Doppler: a satellite approaching at 4 kHz runs its code 2.5e-6 faster.
        let phi = tx_time_mod_1ms_s(1000.0, 4.0e6, 4000.0);
        assert!((phi - (1e-3 - 0.25e-3 * (1.0 + 4000.0 / F_L1_HZ))).abs() < 1e-15);
    }
}
