//! INS error models for simulation: an INS output made from a truth trajectory (seed 004).
//!
//! The simulator's `[ins]` table ([`InsErrorConfig`]) describes an INS by its errors; [`simulate_ins`]
//! samples the truth at `rate_hz` (`t_k = k / rate_hz`, `k = 0, 1, ...` while `t_k <= duration`)
//! and applies, in this order:
//!
//! 1. **Latency** `tau` (`latency_s`): the output stamped `t` is the INS solution of the instant
//!    `t' = max(t - tau, 0)`: truth *and* errors are those of `t'`, so the whole output is shifted
//!    by `tau` (and held at the start value for `t < tau`). The `gps_tow_s` of a sample is that of
//!    its stamp `t`, not of `t'`: it is the time base, the content is what is late.
//! 2. **Accelerometer bias** `B` (`accel_bias_enu_mps2`, seed 004 eqs. 12-13): a constant
//!    specific-force error integrates into `dv_B(t') = B_ecef t'` and `dp_B(t') = B_ecef t'^2 / 2`
//!    (both exact). `B` is given in the local level frame (east, north, up) at the start position
//!    `p(0)` and rotated to ECEF with the *geodetic* (WGS-84) latitude `phi` and longitude `lambda`
//!    of `p(0)`: `B_ecef = B_e e + B_n n + B_u u` with
//!    `e = (-sin lambda, cos lambda, 0)`,
//!    `n = (-sin phi cos lambda, -sin phi sin lambda, cos phi)`,
//!    `u = (cos phi cos lambda, cos phi sin lambda, sin phi)`.
//!    It stays fixed in ECEF (a level-frame bias of a vehicle that does not move far).
//! 3. **Scale factor** `k` (`scale_factor`) on the velocity change:
//!    `dv_k(t') = k (v(t') - v(0))`, whose integral is exactly
//!    `dp_k(t') = k (p(t') - p(0) - v(0) t')`.
//! 4. **Velocity random walk** `N` (`velocity_random_walk_mps_per_sqrt_s`): per ECEF component,
//!    `w(t'_k) = w(t'_{k-1}) + N sqrt(t'_k - t'_{k-1}) z_k`, `z_k ~ N(0, 1)` drawn from a
//!    xoshiro256++ stream seeded with `seed` (so `std w(t) = N sqrt(t)`, and the same seed gives
//!    the same output); its position error is the trapezoid integral
//!    `q_k = q_{k-1} + (w_{k-1} + w_k) (t'_k - t'_{k-1}) / 2`.
//! 5. **Band limiter** `alpha / (s + alpha)` (`band_limit_alpha_rad_s`, seed 004 eq. 8) on each
//!    ECEF component of the erroneous velocity `v + dv_B + dv_k + w` (not on the position), with
//!    the exact zero-order-hold discretisation of [`BandLimiter`]:
//!    `y_k = y_{k-1} + (1 - exp(-alpha (t'_k - t'_{k-1}))) (u_k - y_{k-1})`, the input held over
//!    each step at its time-centred value `u_k = (v_{k-1} + v_k) / 2`, so a velocity ramp goes
//!    through without an extra half-sample lag (the output of a ramp `r t` lags by `r / alpha`,
//!    as in continuous time, to within `r alpha dt^2 / 12`). The filter starts at the first
//!    velocity (no start-up transient).
//!
//! Output: `p_ins(t) = p(t') + dp_B + dp_k + q`, `v_ins(t) = H_alpha[v(t') + dv_B + dv_k + w]`.

use crate::band_limiter::BandLimiter;
use crate::ins_file::{InsError, InsSample};
use gpsrx_core::frames::{enu_rotation, Llh};
use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// Lowest INS output rate, Hz (the `--ins` file needs 10 Hz or faster).
pub const MIN_INS_RATE_HZ: f64 = 10.0;

/// Highest INS output rate accepted, Hz (a bound on memory: one sample is about 80 bytes).
pub const MAX_INS_RATE_HZ: f64 = 10_000.0;

fn default_rate_hz() -> f64 {
    100.0
}

/// The `[ins]` table of a simulator scenario: an INS made from the truth trajectory through error
/// models (see the module documentation for the equations).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InsErrorConfig {
    /// Output rate, Hz (>= 10).
    #[serde(default = "default_rate_hz")]
    pub rate_hz: f64,
    /// Accelerometer bias `B` (east, north, up), m/s^2, in the local level frame at the start
    /// position: velocity error `B t`, position error `B t^2 / 2`.
    #[serde(default)]
    pub accel_bias_enu_mps2: [f64; 3],
    /// Velocity random walk `N`, m/s/sqrt(s): velocity error standard deviation `N sqrt(t)`.
    #[serde(default)]
    pub velocity_random_walk_mps_per_sqrt_s: f64,
    /// Scale-factor error `k` on the velocity change (e.g. 1e-3): velocity error `k (v(t) - v(0))`.
    #[serde(default)]
    pub scale_factor: f64,
    /// Output latency `tau`, s (>= 0): the output at `t` is the INS solution of `t - tau`.
    #[serde(default)]
    pub latency_s: f64,
    /// Corner `alpha` (rad/s) of the band limiter `alpha / (s + alpha)` on the velocity (seed 004
    /// eq. 8); None: unlimited.
    #[serde(default)]
    pub band_limit_alpha_rad_s: Option<f64>,
    /// Seed of the random walk: the same seed gives the same output.
    #[serde(default)]
    pub seed: u64,
}

impl Default for InsErrorConfig {
    /// A perfect INS at 100 Hz.
    fn default() -> Self {
        Self {
            rate_hz: default_rate_hz(),
            accel_bias_enu_mps2: [0.0; 3],
            velocity_random_walk_mps_per_sqrt_s: 0.0,
            scale_factor: 0.0,
            latency_s: 0.0,
            band_limit_alpha_rad_s: None,
            seed: 0,
        }
    }
}

impl InsErrorConfig {
    /// Checks the values that the types cannot: finite numbers, `rate_hz` in [10, 10000],
    /// `latency_s >= 0`, random walk `>= 0`, `scale_factor > -1`, `band_limit_alpha_rad_s > 0`.
    pub fn validate(&self) -> Result<(), InsError> {
        let bad = |m: String| Err(InsError::Config(m));
        if !(self.rate_hz.is_finite()
            && (MIN_INS_RATE_HZ..=MAX_INS_RATE_HZ).contains(&self.rate_hz))
        {
            return bad(format!(
                "rate_hz = {} must be between {MIN_INS_RATE_HZ} and {MAX_INS_RATE_HZ} Hz: the receiver needs the INS at 10 Hz or faster",
                self.rate_hz
            ));
        }
        if let Some(b) = self.accel_bias_enu_mps2.iter().find(|b| !b.is_finite()) {
            return bad(format!(
                "accel_bias_enu_mps2 has {b}: give three finite numbers [east, north, up] in m/s^2"
            ));
        }
        let n = self.velocity_random_walk_mps_per_sqrt_s;
        if !(n.is_finite() && n >= 0.0) {
            return bad(format!(
                "velocity_random_walk_mps_per_sqrt_s = {n} must be a finite number >= 0 (0 = none)"
            ));
        }
        let k = self.scale_factor;
        if !(k.is_finite() && k > -1.0) {
            return bad(format!(
                "scale_factor = {k} must be a finite number above -1 (e.g. 1e-3 for 0.1 %)"
            ));
        }
        let tau = self.latency_s;
        if !(tau.is_finite() && tau >= 0.0) {
            return bad(format!(
                "latency_s = {tau} must be a finite number >= 0 (the output is delayed by it)"
            ));
        }
        if let Some(a) = self.band_limit_alpha_rad_s {
            if a.is_nan() || a <= 0.0 {
                return bad(format!(
                    "band_limit_alpha_rad_s = {a} must be positive (rad/s); leave it out for an unlimited INS"
                ));
            }
        }
        Ok(())
    }
}

/// Truth at one instant (time from the first IF sample, in the recording's sample clock).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthState {
    /// Seconds from the first IF sample.
    pub t_s: f64,
    /// GPS time of week of that instant, if known.
    pub gps_tow_s: Option<f64>,
    /// ECEF position, m.
    pub pos_m: Vector3<f64>,
    /// ECEF velocity, m/s.
    pub vel_mps: Vector3<f64>,
}

/// The rotation from the local level frame (east, north, up) at `pos_m` to ECEF: its columns are
/// `e`, `n`, `u` of the module documentation (geodetic WGS-84 latitude and longitude from
/// [`Llh::from_ecef`]; the transpose of the ECEF -> ENU [`enu_rotation`]).
fn enu_to_ecef(pos_m: &Vector3<f64>) -> Matrix3<f64> {
    enu_rotation(&Llh::from_ecef(pos_m)).transpose()
}

fn finite(v: &Vector3<f64>) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Samples `truth` at `cfg.rate_hz` from 0 to `duration_s` and applies the error models; returns
/// the INS outputs: `p_ins(t) = p(t') + B t'^2/2 + k (p(t') - p(0) - v(0) t') + q(t')` and
/// `v_ins(t) = H_alpha[v(t') + B t' + k (v(t') - v(0)) + w(t')]` with `t' = max(t - tau, 0)`
/// (module documentation).
pub fn simulate_ins(
    truth: &dyn Fn(f64) -> TruthState,
    duration_s: f64,
    cfg: &InsErrorConfig,
) -> Result<Vec<InsSample>, InsError> {
    cfg.validate()?;
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(InsError::Config(format!(
            "the INS duration {duration_s} s must be positive"
        )));
    }
    let dt = 1.0 / cfg.rate_hz;
    let last = (duration_s * cfg.rate_hz + 1e-9).floor() as usize;
    if last < 1 {
        return Err(InsError::Config(format!(
            "a {duration_s} s INS record at rate_hz = {} has a single sample: make it longer or the rate higher",
            cfg.rate_hz
        )));
    }
    let checked = |t: f64| -> Result<TruthState, InsError> {
        let s = truth(t);
        if finite(&s.pos_m) && finite(&s.vel_mps) {
            Ok(s)
        } else {
            Err(InsError::Config(format!(
                "the truth at t = {t} s is not finite: position {:?}, velocity {:?}",
                s.pos_m, s.vel_mps
            )))
        }
    };
    let s0 = checked(0.0)?;
    let b = Vector3::from(cfg.accel_bias_enu_mps2);
    let bias_ecef = if b == Vector3::zeros() {
        b
    } else {
        enu_to_ecef(&s0.pos_m) * b
    };
    let k = cfg.scale_factor;
    let vrw = cfg.velocity_random_walk_mps_per_sqrt_s;
    let tau = cfg.latency_s;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(cfg.seed);
    let mut limiters: Option<[BandLimiter; 3]> =
        cfg.band_limit_alpha_rad_s.map(|a| [BandLimiter::new(a); 3]);
    let mut walk = Vector3::<f64>::zeros();
    let mut walk_int = Vector3::<f64>::zeros();
    let mut prev: Option<(f64, Vector3<f64>)> = None; // (t', erroneous velocity) of the last step
    let mut out = Vec::with_capacity(last + 1);
    for i in 0..=last {
        let t = i as f64 * dt;
        let td = (t - tau).max(0.0);
        let st = checked(td)?;
        let stamp_tow = if tau > 0.0 {
            truth(t).gps_tow_s
        } else {
            st.gps_tow_s
        };
        let step_s = prev.map_or(0.0, |(tp, _)| td - tp);
        if vrw > 0.0 && step_s > 0.0 {
            let w_prev = walk;
            let sd = vrw * step_s.sqrt();
            for c in 0..3 {
                let z: f64 = rng.sample(StandardNormal);
                walk[c] += sd * z;
            }
            walk_int += (w_prev + walk) * (0.5 * step_s);
        }
        let dv = bias_ecef * td + (st.vel_mps - s0.vel_mps) * k + walk;
        let dp =
            bias_ecef * (0.5 * td * td) + (st.pos_m - s0.pos_m - s0.vel_mps * td) * k + walk_int;
        let v_err = st.vel_mps + dv;
        let vel_mps = match limiters.as_mut() {
            None => v_err,
            Some(lim) => {
                let hold = prev.map_or(v_err, |(_, vp)| (vp + v_err) * 0.5);
                Vector3::new(
                    lim[0].step(hold.x, step_s),
                    lim[1].step(hold.y, step_s),
                    lim[2].step(hold.z, step_s),
                )
            }
        };
        prev = Some((td, v_err));
        out.push(InsSample {
            t_s: t,
            gps_tow_s: stamp_tow,
            pos_m: st.pos_m + dp,
            vel_mps,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// WGS-84 geodetic (degrees, m) -> ECEF.
    fn ecef(lat_deg: f64, lon_deg: f64, h_m: f64) -> Vector3<f64> {
        Llh::from_degrees(lat_deg, lon_deg, h_m).to_ecef()
    }

    fn seoul() -> Vector3<f64> {
        ecef(37.5665, 126.9780, 40.0)
    }

    fn run(
        truth: &dyn Fn(f64) -> TruthState,
        duration_s: f64,
        cfg: &InsErrorConfig,
    ) -> Vec<InsSample> {
        simulate_ins(truth, duration_s, cfg).unwrap_or_else(|e| panic!("{e}"))
    }

    /// A truth with constant acceleration `a` from `p0`, `v0`, and `tow = 100 + t`.
    fn accelerating(
        p0: Vector3<f64>,
        v0: Vector3<f64>,
        a: Vector3<f64>,
    ) -> impl Fn(f64) -> TruthState {
        move |t| TruthState {
            t_s: t,
            gps_tow_s: Some(100.0 + t),
            pos_m: p0 + v0 * t + a * (0.5 * t * t),
            vel_mps: v0 + a * t,
        }
    }

    #[test]
    fn enu_axes_at_known_points() {
        let close = |a: Vector3<f64>, b: Vector3<f64>| (a - b).norm() < 1e-12;
        // Equator, Greenwich: east = +y, north = +z, up = +x.
        let r = enu_to_ecef(&ecef(0.0, 0.0, 0.0));
        assert!(close(r * Vector3::z(), Vector3::x()));
        assert!(close(r * Vector3::x(), Vector3::y()));
        assert!(close(r * Vector3::y(), Vector3::z()));
        // Equator, 90 deg east: east = -x, up = +y.
        let r = enu_to_ecef(&ecef(0.0, 90.0, 100.0));
        assert!(close(r * Vector3::x(), -Vector3::x()));
        assert!(close(r * Vector3::z(), Vector3::y()));
        // Near the north pole, up is +z and north points away from the pole along -x (lon 0).
        let r = enu_to_ecef(&ecef(89.999_999, 0.0, 0.0));
        assert!((r * Vector3::z() - Vector3::z()).norm() < 1e-7);
        assert!((r * Vector3::y() + Vector3::x()).norm() < 1e-7);
        // Up is the ellipsoid normal: the direction in which ECEF moves when h grows (closed form
        // above, differenced over 1 km: exact, since ECEF is linear in h).
        for &(lat, lon) in &[
            (37.5665, 126.978),
            (-33.9, 18.4),
            (64.1, -21.9),
            (89.9, -45.0),
        ] {
            let up = (ecef(lat, lon, 1000.0) - ecef(lat, lon, 0.0)) / 1000.0;
            let r = enu_to_ecef(&ecef(lat, lon, 250.0));
            assert!((r * Vector3::z() - up).norm() < 1e-9, "lat {lat} lon {lon}");
            let g = Llh::from_ecef(&ecef(lat, lon, 250.0));
            assert!((g.lat_rad - lat.to_radians()).abs() < 1e-12, "lat {lat}");
            assert!((g.lon_rad - lon.to_radians()).abs() < 1e-12, "lon {lon}");
            // A rotation: orthonormal and right-handed.
            assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-12);
            assert!((r.determinant() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn accelerometer_bias_gives_bt_and_bt2_over_2() {
        let p0 = seoul();
        let v0 = Vector3::new(3.0, -20.0, 7.0);
        let truth = accelerating(p0, v0, Vector3::zeros());
        let cfg = InsErrorConfig {
            rate_hz: 10.0,
            accel_bias_enu_mps2: [0.01, -0.02, 0.005],
            ..InsErrorConfig::default()
        };
        let out = run(&truth, 100.0, &cfg);
        assert_eq!(out.len(), 1001);
        let b = enu_to_ecef(&p0) * Vector3::new(0.01, -0.02, 0.005);
        for s in &out {
            let t = s.t_s;
            let tr = truth(t);
            assert_eq!(s.gps_tow_s, tr.gps_tow_s);
            let dv = s.vel_mps - tr.vel_mps;
            let dp = s.pos_m - tr.pos_m;
            // Positions near 6.4e6 m carry ~1e-9 m of rounding: an absolute floor for dp.
            assert!(
                (dv - b * t).norm() <= 1e-9 * (b * t).norm() + 1e-15,
                "t {t}"
            );
            assert!(
                (dp - b * (0.5 * t * t)).norm() <= 1e-9 * (b * (0.5 * t * t)).norm() + 2e-9,
                "t {t}"
            );
        }
        // The last row: 100 s of 0.0229 m/s^2 is 2.29 m/s and 114.6 m.
        let last = out[out.len() - 1];
        assert!((last.t_s - 100.0).abs() < 1e-12);
        let bias_norm = (0.01f64.powi(2) + 0.02f64.powi(2) + 0.005f64.powi(2)).sqrt();
        let dv = (last.vel_mps - truth(100.0).vel_mps).norm();
        assert!((dv - bias_norm * 100.0).abs() < 1e-12, "{dv}");
    }

    #[test]
    fn bias_up_at_the_equator_is_along_x() {
        let p0 = ecef(0.0, 0.0, 0.0);
        let truth = accelerating(p0, Vector3::zeros(), Vector3::zeros());
        let cfg = InsErrorConfig {
            accel_bias_enu_mps2: [0.0, 0.0, 0.1],
            ..InsErrorConfig::default()
        };
        let out = run(&truth, 2.0, &cfg);
        let last = out[out.len() - 1];
        assert!((last.vel_mps - Vector3::new(0.2, 0.0, 0.0)).norm() < 1e-14);
        assert!((last.pos_m - p0 - Vector3::new(0.2, 0.0, 0.0)).norm() < 1e-9);
    }

    #[test]
    fn velocity_random_walk_std_is_n_sqrt_t() {
        let p0 = seoul();
        let truth = accelerating(p0, Vector3::zeros(), Vector3::zeros());
        let vrw = 0.05;
        let rate = 10.0;
        let seeds = 400u64;
        let check_s = [1.0, 5.0, 20.0];
        // Sums of squares over seeds and the 3 components: velocity and position errors.
        let mut sv = [0.0; 3];
        let mut sp = [0.0; 3];
        for seed in 0..seeds {
            let cfg = InsErrorConfig {
                rate_hz: rate,
                velocity_random_walk_mps_per_sqrt_s: vrw,
                seed,
                ..InsErrorConfig::default()
            };
            let out = run(&truth, 20.0, &cfg);
            for (j, &t) in check_s.iter().enumerate() {
                let s = out[(t * rate).round() as usize];
                assert!((s.t_s - t).abs() < 1e-12);
                sv[j] += s.vel_mps.norm_squared();
                sp[j] += (s.pos_m - p0).norm_squared();
            }
        }
        let n = (seeds * 3) as f64;
        for (j, &t) in check_s.iter().enumerate() {
            // 1200 independent draws: the std estimate's relative standard error is ~2 %.
            let std_v = (sv[j] / n).sqrt();
            let want_v = vrw * t.sqrt();
            assert!(
                (std_v / want_v - 1.0).abs() < 0.1,
                "t {t}: {std_v} vs {want_v}"
            );
            // Integral of a Wiener process: var = N^2 t^3 / 3 (the trapezoid rule on a 0.1 s
            // grid adds N^2 t dt^2 / 12, negligible).
            let std_p = (sp[j] / n).sqrt();
            let want_p = vrw * (t * t * t / 3.0).sqrt();
            assert!(
                (std_p / want_p - 1.0).abs() < 0.1,
                "t {t}: {std_p} vs {want_p}"
            );
        }
    }

    #[test]
    fn scale_factor_scales_the_velocity_change() {
        let (p0, v0, a) = (
            seoul(),
            Vector3::new(10.0, 20.0, -3.0),
            Vector3::new(1.5, -2.0, 0.5),
        );
        let truth = accelerating(p0, v0, a);
        let k = 1e-3;
        let cfg = InsErrorConfig {
            rate_hz: 50.0,
            scale_factor: k,
            ..InsErrorConfig::default()
        };
        for s in run(&truth, 10.0, &cfg) {
            let t = s.t_s;
            let tr = truth(t);
            // dv = k a t, dp = k a t^2 / 2 (the velocity change is a t).
            assert!(
                (s.vel_mps - tr.vel_mps - a * (k * t)).norm() < 1e-12,
                "t {t}"
            );
            assert!(
                (s.pos_m - tr.pos_m - a * (0.5 * k * t * t)).norm() < 5e-9,
                "t {t}"
            );
        }
    }

    #[test]
    fn latency_shifts_a_ramp_by_tau() {
        let (p0, v0, a) = (
            seoul(),
            Vector3::new(0.0, 5.0, 0.0),
            Vector3::new(2.0, -1.0, 0.3),
        );
        let truth = accelerating(p0, v0, a);
        let tau = 0.25;
        let cfg = InsErrorConfig {
            latency_s: tau,
            ..InsErrorConfig::default()
        };
        let out = run(&truth, 3.0, &cfg);
        assert_eq!(out.len(), 301);
        for s in &out {
            let t = s.t_s;
            let td = (t - tau).max(0.0);
            assert!((s.vel_mps - (v0 + a * td)).norm() < 1e-12, "t {t}");
            assert!(
                (s.pos_m - (p0 + v0 * td + a * (0.5 * td * td))).norm() < 1e-8,
                "t {t}"
            );
            // The time stamp is not delayed.
            assert_eq!(s.gps_tow_s, Some(100.0 + t));
        }
        // Latency and bias: the whole INS solution is late, its bias error included.
        let cfg = InsErrorConfig {
            latency_s: tau,
            accel_bias_enu_mps2: [0.0, 0.0, 1.0],
            ..InsErrorConfig::default()
        };
        let up = enu_to_ecef(&p0) * Vector3::z();
        let s = run(&truth, 3.0, &cfg)[300];
        assert!((s.vel_mps - (v0 + (a + up) * 2.75)).norm() < 1e-12);
    }

    /// A truth whose velocity jumps from 0 to `v1` at `t_step` (position irrelevant here).
    fn velocity_step(v1: Vector3<f64>, t_step: f64) -> impl Fn(f64) -> TruthState {
        move |t| TruthState {
            t_s: t,
            gps_tow_s: None,
            pos_m: seoul(),
            vel_mps: if t >= t_step { v1 } else { Vector3::zeros() },
        }
    }

    #[test]
    fn band_limiter_step_response_is_one_minus_exp() {
        let v1 = Vector3::new(30.0, -10.0, 5.0);
        let rate = 100.0;
        let dt = 1.0 / rate;
        for &alpha in &[0.5, 2.0, 10.0] {
            // The step halfway between two samples: the time-centred hold then sees it at the
            // right instant, and the only discretisation error is the step's first partial
            // interval, at most (1 - exp(-alpha dt/2))^2 / 2 <= (alpha dt)^2 / 8 of the step,
            // decaying as exp(-alpha t) afterwards.
            let t_step = 1.0 + dt / 2.0;
            let truth = velocity_step(v1, t_step);
            let cfg = InsErrorConfig {
                rate_hz: rate,
                band_limit_alpha_rad_s: Some(alpha),
                ..InsErrorConfig::default()
            };
            let tol = (alpha * dt).powi(2) / 8.0 * v1.norm() * 1.01;
            for s in run(&truth, 4.0, &cfg) {
                let t = s.t_s;
                let want = if t < t_step {
                    Vector3::zeros()
                } else {
                    v1 * (1.0 - (-alpha * (t - t_step)).exp())
                };
                assert!(
                    (s.vel_mps - want).norm() <= tol,
                    "alpha {alpha} t {t}: {:?} vs {want:?}",
                    s.vel_mps
                );
            }
        }
        // Without a limiter the step goes straight through.
        let truth = velocity_step(v1, 1.005);
        let out = run(&truth, 2.0, &InsErrorConfig::default());
        assert_eq!(out[100].vel_mps, Vector3::zeros());
        assert_eq!(out[101].vel_mps, v1);
    }

    #[test]
    fn band_limited_ramp_lags_by_one_over_alpha() {
        // u = a t from y(0) = 0 through alpha/(s+alpha): y = a (t - (1 - exp(-alpha t)) / alpha).
        let a = Vector3::new(49.0, 0.0, -9.8);
        let truth = accelerating(seoul(), Vector3::zeros(), a);
        let (alpha, rate) = (3.0, 100.0);
        let cfg = InsErrorConfig {
            rate_hz: rate,
            band_limit_alpha_rad_s: Some(alpha),
            ..InsErrorConfig::default()
        };
        // Time-centred hold: the error settles at a alpha dt^2 / 12 = 1.25e-3 m/s here (a hold
        // at the previous sample would lag by a dt / 2 = 0.25 m/s).
        let dt = 1.0 / rate;
        let tol = a.norm() * alpha * dt * dt / 12.0 * 1.01;
        for s in run(&truth, 5.0, &cfg) {
            let t = s.t_s;
            let want = a * (t - (1.0 - (-alpha * t).exp()) / alpha);
            assert!(
                (s.vel_mps - want).norm() <= tol,
                "t {t}: {:?}",
                s.vel_mps - want
            );
        }
    }

    #[test]
    fn same_seed_same_output() {
        let truth = accelerating(seoul(), Vector3::new(1.0, 2.0, 3.0), Vector3::zeros());
        let cfg = InsErrorConfig {
            velocity_random_walk_mps_per_sqrt_s: 0.1,
            accel_bias_enu_mps2: [0.01, 0.01, 0.0],
            scale_factor: 2e-3,
            latency_s: 0.013,
            band_limit_alpha_rad_s: Some(5.0),
            seed: 42,
            ..InsErrorConfig::default()
        };
        let a = run(&truth, 5.0, &cfg);
        assert_eq!(a, run(&truth, 5.0, &cfg));
        let other = InsErrorConfig { seed: 43, ..cfg };
        assert_ne!(a, run(&truth, 5.0, &other));
    }

    #[test]
    fn default_is_a_perfect_100_hz_ins() {
        let cfg = InsErrorConfig::default();
        assert_eq!(cfg.rate_hz, 100.0);
        assert!(cfg.validate().is_ok());
        let truth = accelerating(
            seoul(),
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(0.1, 0.0, 0.0),
        );
        let out = run(&truth, 1.0, &cfg);
        assert_eq!(out.len(), 101);
        for s in out {
            let tr = truth(s.t_s);
            assert_eq!(
                (s.pos_m, s.vel_mps, s.gps_tow_s),
                (tr.pos_m, tr.vel_mps, tr.gps_tow_s)
            );
        }
    }

    #[test]
    fn bad_settings_are_named() {
        let base = InsErrorConfig::default();
        let cases = [
            (
                InsErrorConfig {
                    rate_hz: 5.0,
                    ..base.clone()
                },
                "rate_hz = 5",
            ),
            (
                InsErrorConfig {
                    rate_hz: f64::NAN,
                    ..base.clone()
                },
                "rate_hz = NaN",
            ),
            (
                InsErrorConfig {
                    accel_bias_enu_mps2: [0.0, f64::INFINITY, 0.0],
                    ..base.clone()
                },
                "accel_bias_enu_mps2 has inf",
            ),
            (
                InsErrorConfig {
                    velocity_random_walk_mps_per_sqrt_s: -0.1,
                    ..base.clone()
                },
                "velocity_random_walk_mps_per_sqrt_s = -0.1",
            ),
            (
                InsErrorConfig {
                    scale_factor: f64::NAN,
                    ..base.clone()
                },
                "scale_factor = NaN",
            ),
            (
                InsErrorConfig {
                    latency_s: -0.01,
                    ..base.clone()
                },
                "latency_s = -0.01",
            ),
            (
                InsErrorConfig {
                    band_limit_alpha_rad_s: Some(0.0),
                    ..base.clone()
                },
                "band_limit_alpha_rad_s = 0 must be positive",
            ),
            (
                InsErrorConfig {
                    band_limit_alpha_rad_s: Some(f64::NAN),
                    ..base.clone()
                },
                "band_limit_alpha_rad_s = NaN",
            ),
        ];
        let truth = accelerating(seoul(), Vector3::zeros(), Vector3::zeros());
        for (cfg, needle) in cases {
            let e = cfg
                .validate()
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(e.contains(needle), "{e} (wanted {needle})");
            assert!(e.starts_with("INS error model: "), "{e}");
            // simulate_ins validates too.
            let e = simulate_ins(&truth, 1.0, &cfg)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(e.contains(needle), "{e} (wanted {needle})");
        }
        for d in [0.0, -1.0, f64::NAN, 0.005] {
            assert!(simulate_ins(&truth, d, &base).is_err(), "duration {d}");
        }
        let nan_truth = |t: f64| TruthState {
            t_s: t,
            gps_tow_s: None,
            pos_m: Vector3::new(f64::NAN, 0.0, 0.0),
            vel_mps: Vector3::zeros(),
        };
        let e = simulate_ins(&nan_truth, 1.0, &base)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("not finite"), "{e}");
    }
}
