//! `gpsrx run --accel`: seed 002's speed filter (KF1 smoothing the longitudinal accelerometer,
//! KF2 `[v, a, r]` with GPS speed) run over the accelerometer log with the receiver's fixes, and
//! attached to the fused rows.

use super::fuse::FusedFix;
use super::gnss::GnssFix;
use gpsrx_ins_aiding::{AccelLog, AccelSmoother, DrError, SpeedFilter, SpeedFilterConfig};

/// KF1's jerk PSD, (m/s^3)^2 s: a car's acceleration changes by about 1 m/s^2 in a second.
const JERK_PSD: f64 = 0.5;
/// KF1's measurement noise: vibration of a road vehicle, m/s^2.
const VIBRATION_SIGMA_MPS2: f64 = 0.3;
/// Floor of the GPS speed sigma, m/s (the Doppler solution's covariance can be optimistic).
const MIN_SPEED_SIGMA_MPS: f64 = 0.02;

/// The filtered speed `(t_s, speed_mps)` at every accelerometer row from the first fix with a
/// velocity on; GPS speed (the norm of the Doppler velocity: the accelerometer measures along
/// the road, slopes included) updates it at most every `update_interval_s`.
pub fn speed_track(
    gnss: &[GnssFix],
    accel: &AccelLog,
    update_interval_s: f64,
) -> Result<Vec<(f64, f64)>, DrError> {
    let rows = accel.samples();
    let Some(first) = gnss
        .iter()
        .find(|f| f.vel_ecef_mps.is_some() && rows.first().is_some_and(|r| f.t_s >= r.t_s))
    else {
        return Ok(Vec::new());
    };
    let (v0, s0) = gnss_speed(first).unwrap_or((0.0, 1.0));
    let mut kf1 = AccelSmoother::new(JERK_PSD, VIBRATION_SIGMA_MPS2)?;
    let mut kf2 = SpeedFilter::new(v0, s0, SpeedFilterConfig::default())?;
    let k0 = rows
        .partition_point(|r| r.t_s <= first.t_s)
        .saturating_sub(1);
    let mut next_fix = gnss.partition_point(|f| f.t_s <= first.t_s);
    let mut last_update = first.t_s;
    let mut out = Vec::with_capacity(rows.len() - k0);
    let mut t_prev = rows[k0].t_s;
    kf1.filter(rows[k0].a_long_mps2, 0.0);
    out.push((t_prev, kf2.speed_mps()));
    for r in &rows[k0 + 1..] {
        let dt = r.t_s - t_prev;
        let a = kf1.filter(r.a_long_mps2, dt);
        kf2.predict(a, dt);
        t_prev = r.t_s;
        while next_fix < gnss.len() && gnss[next_fix].t_s <= r.t_s {
            let f = &gnss[next_fix];
            next_fix += 1;
            if f.t_s - last_update < update_interval_s - 1e-6 {
                continue;
            }
            if let Some((v, sigma)) = gnss_speed(f) {
                kf2.update_speed(v, sigma)?;
                last_update = f.t_s;
            }
        }
        out.push((r.t_s, kf2.speed_mps()));
    }
    Ok(out)
}

/// Speed of a fix and its standard deviation along the velocity, m/s.
fn gnss_speed(f: &GnssFix) -> Option<(f64, f64)> {
    let v = f.vel_ecef_mps?;
    let speed = v.norm();
    let var = match (f.vel_cov, speed > 0.1) {
        (Some(c), true) => (v.transpose() * c * v)[(0, 0)] / (speed * speed),
        (Some(c), false) => c.trace() / 3.0,
        (None, _) => 0.01,
    };
    Some((speed, var.max(0.0).sqrt().max(MIN_SPEED_SIGMA_MPS)))
}

/// Sets each row's `speed_filter_mps` to the filter's latest speed at or before its time.
pub fn attach_speed(fixes: &mut [FusedFix], track: &[(f64, f64)]) {
    for f in fixes {
        let i = track.partition_point(|(t, _)| *t <= f.t_s + 1e-9);
        f.speed_filter_mps = i.checked_sub(1).map(|i| track[i].1);
    }
}
