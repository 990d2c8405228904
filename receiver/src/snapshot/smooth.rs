//! Smoothing the horizontal track across consecutive snapshots (optional, after the fact):
//! a Rauch-Tung-Striebel smoother over the `fix` rows with a constant-velocity motion model,
//! east and north independent.
//!
//! Each snapshot is still positioned alone (and seeds the next); this only combines the
//! independent per-snapshot noise of a slowly moving receiver (a walker, an animal), as
//! trackers are post-processed. Model per axis, state `[p, v]`, between fixes `dt` apart:
//!
//! ```text
//! F = [[1, dt], [0, 1]],   Q = q [[dt^3/3, dt^2/2], [dt^2/2, dt]],   q = sigma_a^2
//! z = p + noise,           R = (HDOP sigma_rho)^2 / 2
//! ```
//!
//! with `sigma_a` the carrier's acceleration ([`SmoothOptions::accel_sigma_mps2`]) and
//! `sigma_rho` the pseudorange sigma of the solver's weighting at the zenith-ish
//! ([`SmoothOptions::range_sigma_m`]). A fix whose innovation fails the chi-square test
//! ([`GATE_NIS`], 2 degrees of freedom, false-alarm probability 1e-3) is not used and not
//! moved: a bad snapshot does not pull the others. Rows without a fix stay without one.

use super::driver::SnapshotOutcome;
use super::SnapshotQuality;
use gpsrx_core::frames::enu_rotation;
use gpsrx_nav::{Llh, Vector3};
use nalgebra::{Matrix2, Vector2};

/// Chi-square quantile of 2 degrees of freedom for a false-alarm probability of 1e-3.
pub const GATE_NIS: f64 = 13.82;
/// The default [`SmoothOptions::range_sigma_m`]: the snapshot solver's default weighting at
/// 45 deg elevation and 40 dB-Hz, sqrt(10^2 + 5^2 / sin^2 45 deg) = 12.2 m.
pub const DEFAULT_RANGE_SIGMA_M: f64 = 12.2;
/// Initial velocity sigma per axis, m/s (unknown: vague).
const INITIAL_SPEED_SIGMA_MPS: f64 = 10.0;

/// Settings of [`smooth_track`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothOptions {
    /// Acceleration sigma of the motion model, m/s^2 (a walker about 0.5, a car a few).
    pub accel_sigma_mps2: f64,
    /// Pseudorange sigma, m (with the HDOP, the sigma of a fix).
    pub range_sigma_m: f64,
}

/// One axis's filtered state.
#[derive(Debug, Clone, Copy)]
struct Step {
    x_prior: Vector2<f64>,
    p_prior: Matrix2<f64>,
    x_post: Vector2<f64>,
    p_post: Matrix2<f64>,
    f: Matrix2<f64>,
}

/// Smooths the horizontal positions of the `fix` rows of `outcomes` in place (module docs);
/// returns how many were moved. Fewer than three fixes: nothing is done.
pub fn smooth_track(outcomes: &mut [SnapshotOutcome], opts: &SmoothOptions) -> usize {
    let rows: Vec<usize> = (0..outcomes.len())
        .filter(|&i| {
            let o = &outcomes[i];
            o.quality == SnapshotQuality::Fix && o.ecef_m.is_some() && o.time.is_some()
        })
        .collect();
    if rows.len() < 3 || !(opts.accel_sigma_mps2 > 0.0 && opts.range_sigma_m > 0.0) {
        return 0;
    }
    let (Some(x0), Some(t0)) = (outcomes[rows[0]].ecef_m, outcomes[rows[0]].time) else {
        return 0;
    };
    let origin = Llh::from_ecef(&x0);
    let rot = enu_rotation(&origin);
    let meas: Vec<(f64, [f64; 2], f64)> = rows
        .iter()
        .filter_map(|&i| {
            let o = &outcomes[i];
            let d = rot * (o.ecef_m? - x0);
            let r = (o.hdop?.max(0.5) * opts.range_sigma_m).powi(2) / 2.0;
            Some((o.time?.diff_s(t0), [d.x, d.y], r))
        })
        .collect();
    if meas.len() != rows.len() {
        return 0;
    }
    let q = opts.accel_sigma_mps2.powi(2);
    let gated = gate(&meas, q);
    let mut moved = 0;
    let smoothed: [Vec<f64>; 2] = [0, 1].map(|axis| smooth_axis(&meas, &gated, q, axis));
    for (j, &i) in rows.iter().enumerate() {
        if gated[j] {
            let o = &mut outcomes[i];
            o.reason = "not smoothed: disagrees with the track of the others".into();
            continue;
        }
        let (de, dn) = (smoothed[0][j] - meas[j].1[0], smoothed[1][j] - meas[j].1[1]);
        let o = &mut outcomes[i];
        if let Some(x) = o.ecef_m {
            let shift: Vector3<f64> = rot.transpose() * Vector3::new(de, dn, 0.0);
            let new = x + shift;
            o.ecef_m = Some(new);
            o.llh = Some(Llh::from_ecef(&new));
            moved += 1;
        }
    }
    moved
}

/// One axis of the gate's forward filter: state, covariance, time of the last fix used.
type AxisState = Option<(Vector2<f64>, Matrix2<f64>, f64)>;

/// Which fixes fail the innovation test of a forward filter on both axes together.
fn gate(meas: &[(f64, [f64; 2], f64)], q: f64) -> Vec<bool> {
    let mut state: [AxisState; 2] = [None, None];
    meas.iter()
        .map(|&(t, z, r)| {
            let mut nis = 0.0;
            let mut next = state;
            for axis in 0..2 {
                let (x, p) = match state[axis] {
                    None => (
                        Vector2::new(z[axis], 0.0),
                        Matrix2::new(r, 0.0, 0.0, INITIAL_SPEED_SIGMA_MPS.powi(2)),
                    ),
                    Some((x, p, t_prev)) => {
                        let (f, qm) = model(t - t_prev, q);
                        let (x, p) = (f * x, f * p * f.transpose() + qm);
                        let s = p[(0, 0)] + r;
                        let y = z[axis] - x[0];
                        nis += y * y / s;
                        update(x, p, z[axis], r)
                    }
                };
                next[axis] = Some((x, p, t));
            }
            let bad = nis > GATE_NIS;
            if !bad {
                state = next;
            }
            bad
        })
        .collect()
}

/// The RTS-smoothed positions of one axis (gated fixes used as no measurement).
fn smooth_axis(meas: &[(f64, [f64; 2], f64)], gated: &[bool], q: f64, axis: usize) -> Vec<f64> {
    let mut steps: Vec<Step> = Vec::with_capacity(meas.len());
    for (j, &(t, z, r)) in meas.iter().enumerate() {
        let (x_prior, p_prior, f) = match steps.last() {
            None => (
                Vector2::new(z[axis], 0.0),
                Matrix2::new(r * 100.0, 0.0, 0.0, INITIAL_SPEED_SIGMA_MPS.powi(2)),
                Matrix2::identity(),
            ),
            Some(prev) => {
                let (f, qm) = model(t - meas[j - 1].0, q);
                (f * prev.x_post, f * prev.p_post * f.transpose() + qm, f)
            }
        };
        let (x_post, p_post) = if gated[j] {
            (x_prior, p_prior)
        } else {
            update(x_prior, p_prior, z[axis], r)
        };
        steps.push(Step {
            x_prior,
            p_prior,
            x_post,
            p_post,
            f,
        });
    }
    let n = steps.len();
    let mut xs = vec![Vector2::zeros(); n];
    xs[n - 1] = steps[n - 1].x_post;
    for j in (0..n - 1).rev() {
        let next = &steps[j + 1];
        let Some(inv) = next.p_prior.try_inverse() else {
            xs[j] = steps[j].x_post;
            continue;
        };
        let c = steps[j].p_post * next.f.transpose() * inv;
        xs[j] = steps[j].x_post + c * (xs[j + 1] - next.x_prior);
    }
    xs.iter().map(|x| x[0]).collect()
}

/// `F` and `Q` of the constant-velocity model over `dt` (module docs).
fn model(dt: f64, q: f64) -> (Matrix2<f64>, Matrix2<f64>) {
    let dt = dt.abs();
    (
        Matrix2::new(1.0, dt, 0.0, 1.0),
        Matrix2::new(
            q * dt.powi(3) / 3.0,
            q * dt * dt / 2.0,
            q * dt * dt / 2.0,
            q * dt,
        ),
    )
}

/// The Kalman update of `[p, v]` with a position `z` of variance `r`.
fn update(x: Vector2<f64>, p: Matrix2<f64>, z: f64, r: f64) -> (Vector2<f64>, Matrix2<f64>) {
    let s = p[(0, 0)] + r;
    let k = Vector2::new(p[(0, 0)] / s, p[(1, 0)] / s);
    let x = x + k * (z - x[0]);
    let kh = Matrix2::new(k[0], 0.0, k[1], 0.0);
    let p = (Matrix2::identity() - kh) * p;
    (x, p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_nav::GpsTime;
    use rand::{Rng, SeedableRng};

    /// A walk at 1.2 m/s east sampled once a second with 10 m of noise per axis (fixed seed),
    /// one fix 300 m off: the smoothed track is closer to the truth than the fixes, and the
    /// outlier is refused without moving its neighbours towards it.
    #[test]
    fn smoothing_a_noisy_walk_reduces_the_error_and_refuses_an_outlier() {
        let origin = Llh::from_degrees(51.76, -1.257, 112.0);
        let rot = enu_rotation(&origin);
        let x0 = origin.to_ecef();
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut gauss = || {
            // Box-Muller from two uniforms.
            let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-12), rng.random::<f64>());
            (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
        };
        let truth = |k: usize| Vector3::new(1.2 * k as f64, 0.0, 0.0);
        let mut rows = Vec::new();
        for k in 0..60 {
            let mut enu = truth(k) + Vector3::new(10.0 * gauss(), 10.0 * gauss(), 0.0);
            if k == 30 {
                enu.x += 300.0;
            }
            let ecef = x0 + rot.transpose() * enu;
            rows.push(SnapshotOutcome {
                quality: SnapshotQuality::Fix,
                time: Some(GpsTime::new(2185, 132_000.0 + k as f64)),
                ecef_m: Some(ecef),
                llh: Some(Llh::from_ecef(&ecef)),
                hdop: Some(1.2),
                ..SnapshotOutcome::empty(k)
            });
        }
        let err = |rows: &[SnapshotOutcome], k: usize| {
            let d = rot * (rows[k].ecef_m.unwrap_or(x0) - x0) - truth(k);
            d.x.hypot(d.y)
        };
        let before: Vec<f64> = (0..60)
            .filter(|&k| k != 30)
            .map(|k| err(&rows, k))
            .collect();
        let opts = SmoothOptions {
            accel_sigma_mps2: 0.5,
            range_sigma_m: 12.2,
        };
        let moved = smooth_track(&mut rows, &opts);
        assert_eq!(moved, 59);
        assert!(
            rows[30].reason.contains("not smoothed"),
            "{}",
            rows[30].reason
        );
        let after: Vec<f64> = (0..60)
            .filter(|&k| k != 30)
            .map(|k| err(&rows, k))
            .collect();
        let rms = |v: &[f64]| (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
        assert!(
            rms(&after) < 0.6 * rms(&before),
            "{} -> {}",
            rms(&before),
            rms(&after)
        );
        // The neighbours of the outlier are not dragged 300 m east.
        assert!(err(&rows, 29) < 20.0 && err(&rows, 31) < 20.0);
    }
}
