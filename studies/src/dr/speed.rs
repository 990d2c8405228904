//! Seed 002's speed filter through GNSS gaps: KF1 ([`AccelSmoother`]) smoothing the longitudinal
//! accelerometer, KF2 ([`SpeedFilter`]) integrating it with GNSS speed updates (the 3-D speed
//! of the carrier velocity, 1 Hz), predicting only through the gaps; against
//! [`HoldLastSpeed`]. Errors against the truth speed at every GNSS epoch.

use super::drive::Drive;
use super::gnss::{in_windows, GnssTrack};
use super::params::{
    ACCEL_RATE_HZ, ACCEL_VIBRATION_MPS2, GAP_FIRST_S, GAP_LENGTHS_S, GAP_SPACING_S, GNSS_RATE_HZ,
    GNSS_SPEED_SIGMA_MPS,
};
use anyhow::Context;
use gpsrx_ins_aiding::{AccelSample, AccelSmoother, HoldLastSpeed, SpeedFilter, SpeedFilterConfig};

/// KF1's jerk PSD, (m/s^3)^2 s: city driving changes its acceleration within a second or two.
pub const KF1_JERK_PSD: f64 = 0.5;

/// The gap windows over a drive of `duration_s`: lengths cycling through [`GAP_LENGTHS_S`],
/// [`GAP_SPACING_S`] of GNSS between them, from [`GAP_FIRST_S`] + `phase_s`, the last ending at
/// least 10 s before the end.
pub fn gap_windows(duration_s: f64, phase_s: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut t = GAP_FIRST_S + phase_s;
    for k in 0.. {
        let len = GAP_LENGTHS_S[k % GAP_LENGTHS_S.len()];
        if t + len + 10.0 > duration_s {
            break;
        }
        out.push((t, t + len));
        t += len + GAP_SPACING_S;
    }
    out
}

/// Speed errors at every GNSS epoch.
#[derive(Debug, Clone, Default)]
pub struct SpeedRun {
    /// Epoch times, s.
    pub t_s: Vec<f64>,
    /// Filter speed minus truth, m/s.
    pub err_filter_mps: Vec<f64>,
    /// Held speed minus truth, m/s.
    pub err_hold_mps: Vec<f64>,
}

/// RMS errors of one gap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapResult {
    /// Window, s.
    pub window: (f64, f64),
    /// RMS of the filter's speed error over the gap, m/s.
    pub rms_filter_mps: f64,
    /// RMS of the held speed's error, m/s.
    pub rms_hold_mps: f64,
    /// Largest height change of the road from the gap's start, m (an unknown slope change costs
    /// the filter about `g dh / v` of speed).
    pub climb_m: f64,
    /// Speed change over the gap, m/s (what it costs holding the last speed).
    pub speed_change_mps: f64,
}

/// Runs KF1 + KF2 and the hold baseline over the drive with GNSS speed removed in `gaps`.
pub fn run_speed(
    drive: &Drive,
    gnss: &GnssTrack,
    accel: &[AccelSample],
    gaps: &[(f64, f64)],
) -> anyhow::Result<SpeedRun> {
    let per_epoch = (ACCEL_RATE_HZ / GNSS_RATE_HZ).round() as usize;
    let speed = |k: usize| {
        let v = gnss.epochs[k].vel_enu_mps;
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    };
    let mut kf1 = AccelSmoother::new(KF1_JERK_PSD, ACCEL_VIBRATION_MPS2)?;
    let mut kf2 = SpeedFilter::new(speed(0), 0.5, SpeedFilterConfig::default())?;
    let mut hold = HoldLastSpeed::new();
    let mut run = SpeedRun::default();
    let dt = 1.0 / ACCEL_RATE_HZ;
    for (k, a) in accel.iter().enumerate() {
        let smoothed = kf1.filter(a.a_long_mps2, dt);
        if k > 0 {
            kf2.predict(smoothed, dt);
        }
        if k % per_epoch != 0 {
            continue;
        }
        let e = k / per_epoch;
        let Some(epoch) = gnss.epochs.get(e) else {
            break;
        };
        if !in_windows(epoch.t_s, gaps) {
            kf2.update_speed(speed(e), GNSS_SPEED_SIGMA_MPS)
                .with_context(|| format!("GNSS speed at {} s", epoch.t_s))?;
            hold.update_speed(speed(e));
        }
        let truth = drive.at(epoch.t_s).speed_mps;
        run.t_s.push(epoch.t_s);
        run.err_filter_mps.push(kf2.speed_mps() - truth);
        run.err_hold_mps.push(hold.speed_mps() - truth);
    }
    Ok(run)
}

/// Per-gap RMS errors.
pub fn gap_results(drive: &Drive, run: &SpeedRun, gaps: &[(f64, f64)]) -> Vec<GapResult> {
    gaps.iter()
        .map(|&(a, b)| {
            let (mut sf, mut sh, mut n) = (0.0, 0.0, 0.0);
            for (i, &t) in run.t_s.iter().enumerate() {
                if t >= a && t < b {
                    sf += run.err_filter_mps[i].powi(2);
                    sh += run.err_hold_mps[i].powi(2);
                    n += 1.0;
                }
            }
            let (s0, s1) = (drive.at(a), drive.at(b));
            let climb_m = drive
                .truth
                .iter()
                .filter(|s| s.t_s >= a && s.t_s <= b)
                .map(|s| s.up_m - s0.up_m)
                .fold(0.0, |m: f64, d| if d.abs() > m.abs() { d } else { m });
            GapResult {
                window: (a, b),
                rms_filter_mps: (sf / n).sqrt(),
                rms_hold_mps: (sh / n).sqrt(),
                climb_m,
                speed_change_mps: s1.speed_mps - s0.speed_mps,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_cycle_their_lengths_with_a_minute_of_gnss_between() {
        let g = gap_windows(900.0, 15.0);
        assert_eq!(g[0].0, GAP_FIRST_S + 15.0);
        for (k, w) in g.iter().enumerate() {
            assert_eq!(w.1 - w.0, GAP_LENGTHS_S[k % GAP_LENGTHS_S.len()]);
            if k > 0 {
                assert_eq!(w.0 - g[k - 1].1, GAP_SPACING_S);
            }
        }
        assert!(g.last().is_some_and(|w| w.1 + 10.0 <= 900.0));
    }
}
