//! Per-satellite code-phase errors of a SnapperGPS snapshot set against its truth track: for
//! every snapshot with a fix, each detected satellite's measured transmit time modulo 1 ms
//! against the one the pseudorange model predicts at the truth position (at the fix's time and
//! clock), in metres, less the snapshot's mean (the common clock). Printed per satellite with
//! the sub-sample part of the code phase and the Cramer-Rao bound of its C/N0
//! ([`gpsrx_receiver::snapshot::crlb`], band `GPSRX_CRLB_BAND_HZ`, default 1.75 MHz), then binned
//! by the sub-sample part. A second error removes, besides the mean, a term proportional to
//! each satellite's Doppler (least squares): what an error of the fix's time does (the
//! predicted ranges move by range rate x time error), so that it is the code phase's own.
//!
//! `cargo run --profile ci -p gpsrx-receiver --example snapshot_errors -- JSON NAV TRUTH H`

use gpsrx_nav::pvt::{predicted_tx_time_mod_1ms, CoarseTimeSolution, HeightConstraint};
use gpsrx_nav::{HealthPolicy, Llh};
use gpsrx_receiver::snapshot::crlb::code_delay_crlb_m;
use gpsrx_receiver::snapshot::driver::Seed;
use gpsrx_receiver::snapshot::output::read_truth_track;
use gpsrx_receiver::snapshot::snappergps::read_snappergps;
use gpsrx_receiver::snapshot::solve::{solve_snapshot, tx_time_mod_1ms_s};
use gpsrx_receiver::snapshot::{SnapshotOptions, SnapshotProcessor, SnapshotQuality};
use std::path::Path;

const C_MPS: f64 = 299_792_458.0;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, json, nav, truth, h] = &args[..] else {
        return Err("give JSON NAV TRUTH H".into());
    };
    let snaps = read_snappergps(Path::new(json))?;
    let nav = gpsrx_nav::read_rinex_nav(Path::new(nav))?;
    let truth = read_truth_track(Path::new(truth), h.parse()?)?;
    let apriori = Llh::from_degrees(52.03, -1.2574, 112.0);
    let mut opts = SnapshotOptions::default();
    // GPSRX_CODE_BAND_HZ: the matched replica's band (0: the parabola fit alone).
    if let Some(b) = std::env::var("GPSRX_CODE_BAND_HZ")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
    {
        opts.measure.code_band_hz = (b > 0.0).then_some(b);
    }
    opts.solve.height = Some(HeightConstraint {
        h_m: apriori.h_m,
        sigma_m: 30.0,
    });
    let mut p = SnapshotProcessor::new(&nav, opts.clone())?;
    let seed = Seed {
        pos_ecef_m: apriori.to_ecef(),
        time_correction_s: 0.0,
        time: None,
    };
    let outcomes = p.run(&snaps, seed, |_| {});
    let band_hz = std::env::var("GPSRX_CRLB_BAND_HZ")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(1.75e6);
    let mut bins = vec![Vec::new(); 8];
    let mut all = Vec::new();
    let mut refit_all = Vec::new();
    let mut normalised = Vec::new();
    let mut bounds = Vec::new();
    println!("snap prn el_deg cn0 frac_sample err_m err_refit_m crlb_m");
    for (s, o) in snaps.iter().zip(&outcomes) {
        let (Some(x), Some(dt), Some(t_truth)) = (o.ecef_m, o.time_correction_s, truth.at(o))
        else {
            continue;
        };
        if o.quality != SnapshotQuality::Fix {
            continue;
        }
        let seed = Seed {
            pos_ecef_m: x,
            time_correction_s: dt,
            time: None,
        };
        let (_, Some(acq)) = p.process(s, &seed) else {
            continue;
        };
        let Some(t_a) = s.approx_time.map(|t| t.add_seconds(dt)) else {
            continue;
        };
        let Ok((sol, _)) = solve_snapshot(&acq.sats, s.fs_hz, &nav, t_a, &x, None, &opts.solve)
        else {
            continue;
        };
        let at_truth = CoarseTimeSolution {
            pos_ecef_m: t_truth.to_ecef(),
            ..sol.clone()
        };
        let mut rows = Vec::new();
        for sat in &acq.sats {
            let Some(eph) = nav.select_with(sat.prn.get(), t_a, HealthPolicy::HealthyOnly) else {
                continue;
            };
            let Ok(pred) = predicted_tx_time_mod_1ms(&at_truth, t_a, eph, &opts.solve.pvt) else {
                continue;
            };
            let meas = tx_time_mod_1ms_s(sat.code_phase_samples, s.fs_hz, sat.doppler_hz);
            let d = ((meas - pred) / 1e-3 + 0.5).rem_euclid(1.0) - 0.5;
            rows.push((sat, d * 1e-3 * C_MPS));
        }
        if rows.len() < 2 {
            continue;
        }
        let mean = rows.iter().map(|r| r.1).sum::<f64>() / rows.len() as f64;
        let refit = clock_and_time_removed(&rows);
        let len_s = s.samples.len() as f64 / s.fs_hz;
        for ((sat, e), r) in rows.into_iter().zip(refit) {
            let e = e - mean;
            let frac = sat.code_phase_samples.rem_euclid(1.0);
            let bound = code_delay_crlb_m(sat.cn0_dbhz, len_s, 1e-3, band_hz);
            println!(
                "{} G{:02} {:.1} {:.1} {:.3} {:.1} {:.1} {:.1}",
                s.index,
                sat.prn.get(),
                sat.elevation_deg,
                sat.cn0_dbhz,
                frac,
                e,
                r,
                bound
            );
            bins[((frac * 8.0) as usize).min(7)].push(e);
            all.push(e);
            if r.is_finite() {
                refit_all.push(r);
                normalised.push(r / bound);
                bounds.push(bound);
            }
        }
    }
    let rms = |v: &[f64]| (v.iter().map(|e| e * e).sum::<f64>() / v.len().max(1) as f64).sqrt();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    println!("all: n {} rms {:.1} m", all.len(), rms(&all));
    println!(
        "mean and Doppler term removed (per satellite, for n - 2 dof): n {} rms {:.1} m; Cramer-Rao bound rms {:.1} m \
         (band +-{:.2} MHz); rms of error / bound {:.2}",
        refit_all.len(),
        rms(&refit_all),
        rms(&bounds),
        band_hz / 1e6,
        rms(&normalised)
    );
    for (k, b) in bins.iter().enumerate() {
        println!(
            "frac [{:.3}, {:.3}): n {:3} mean {:+6.1} m rms {:5.1} m",
            k as f64 / 8.0,
            (k + 1) as f64 / 8.0,
            b.len(),
            mean(b),
            rms(b)
        );
    }
    Ok(())
}

/// The errors less the least-squares fit `a + b D_k` (D_k the satellite's Doppler): a common
/// clock and an error of the fix's time; scaled by sqrt(n / (n - 2)) so that their RMS
/// estimates the noise of one satellite (the fit of 2 parameters to n errors leaves n - 2
/// degrees of freedom). NaN for all with fewer than 4 satellites.
fn clock_and_time_removed(
    rows: &[(&gpsrx_receiver::snapshot::measure::SatCodePhase, f64)],
) -> Vec<f64> {
    let n = rows.len() as f64;
    if rows.len() < 4 {
        return vec![f64::NAN; rows.len()];
    }
    let (sx, sy) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (s, e)| (a + s.doppler_hz, b + e));
    let (mx, my) = (sx / n, sy / n);
    let (sxx, sxy) = rows.iter().fold((0.0, 0.0), |(a, b), (s, e)| {
        let dx = s.doppler_hz - mx;
        (a + dx * dx, b + dx * (e - my))
    });
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let dof = (n / (n - 2.0)).sqrt();
    rows.iter()
        .map(|(s, e)| dof * (e - my - slope * (s.doppler_hz - mx)))
        .collect()
}
