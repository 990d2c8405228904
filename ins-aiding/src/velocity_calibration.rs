//! Calibration of an INS's velocity error from the GNSS velocity fixes, so that the Doppler
//! feed-forward does not carry the INS's drift into the tracking loops.
//!
//! # Why
//!
//! An INS whose accelerometers are biased by `b` (m/s^2 along the line of sight) reports a
//! velocity that drifts by `b t`: the aided carrier loop sees a Doppler ramp `b / lambda` (1 mg:
//! 0.052 Hz/s), which a 2nd-order loop follows with the steady phase error
//! `theta_e = (b / lambda) / omega0^2` cycles (Kaplan sec. 5.6): 0.09 cycle at Bn 0.4 Hz for
//! 1 mg, 0.16 cycle for a bias of 1 mg on every axis seen along a diagonal line of sight, past
//! the 45 deg rule. A 3rd-order loop has no steady error but a slower, larger transient.
//!
//! # How
//!
//! The fixes' velocity (from the tracked carrier Doppler, which the loops measure whatever
//! the aid) is compared with the INS velocity at the same instant; the difference
//! `d(t) = v_INS - v_GNSS` is followed per ECEF axis by a type-2 tracking filter of states
//! offset `e` and drift `r` (m/s and m/s^2): between fixes `e += r dt`; at a fix, with the
//! innovation `y = d - e`, `e += 2 zeta omega_n dt y` and `r += omega_n^2 dt y` (the
//! critically damped analog loop `s^2 + 2 zeta omega_n s + omega_n^2` discretised by forward
//! Euler; `dt` clamped to [`MAX_STEP_S`] so the gains stay well inside stability). Type 2: a
//! constant bias (a ramp in `d`) is followed without steady error, so the corrected INS
//! velocity `v_INS - e(t)` has no ramp. Its bandwidth ([`OMEGA_N_RAD_S`], about 0.03 Hz) is well
//! below the narrowest carrier loop's (0.4 Hz), so the outer loop does not fight the inner one,
//! and its noise is the fixes' velocity noise averaged over several seconds.
//!
//! # Limits
//!
//! The correction is bounded: `|e|` per axis by [`MAX_OFFSET_MPS`] and `|r|` by
//! [`MAX_DRIFT_MPS2`] (10 mg). An INS that is further off (a wrong file, a time offset in a
//! manoeuvre) is not "calibrated" into agreement: the aid's integrity monitor rejects it. A
//! fix without a velocity, or one whose velocity sigma exceeds [`MAX_FIX_SIGMA_MPS`], is not
//! used; between fixes (and in a GNSS outage) the correction is extrapolated with its drift.

use nalgebra::Vector3;

/// Natural frequency of the calibration loop, rad/s: its transients decay as
/// `exp(-zeta omega_n t)`, time constant 7 s; its crossover (~0.3 rad/s) is below the
/// narrowest aided carrier loop's `omega0` (Bn 0.4 Hz, 2nd order: 0.75 rad/s), whose lag in
/// following a change of the aid (~1/omega0) costs the outer loop about 20 deg of phase margin.
pub const OMEGA_N_RAD_S: f64 = 0.2;
/// Damping ratio of the calibration loop.
pub const ZETA: f64 = 0.707;
/// Largest velocity offset the calibration takes out, m/s per axis.
pub const MAX_OFFSET_MPS: f64 = 2.0;
/// Largest velocity drift (accelerometer bias) the calibration takes out, m/s^2 per axis (10 mg).
pub const MAX_DRIFT_MPS2: f64 = 0.098;
/// A fix whose velocity sigma (per axis, largest) exceeds this is not used, m/s.
pub const MAX_FIX_SIGMA_MPS: f64 = 0.5;
/// A fix taken while the INS reports more acceleration than this is not used, m/s^2: a fix's
/// velocity is dated to within some milliseconds (its Doppler averaged over the correlation
/// interval, the fix's time tag), and a time error `dt` reads as a velocity error `a dt`
/// (0.1 m/s for 1 ms in a 10 g turn); under 2 m/s^2 a 20 ms error costs 4 cm/s. The
/// calibration learnt before a manoeuvre is extrapolated through it.
pub const MAX_ACCEL_MPS2: f64 = 2.0;
/// Longest interval one update integrates, s (fixes further apart restart the offset).
pub const MAX_STEP_S: f64 = 2.0;

/// The INS velocity error estimate (module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InsVelocityCalibration {
    /// Time of the last update, s, and the state `(e, r)` there.
    state: Option<(f64, Vector3<f64>, Vector3<f64>)>,
    updates: usize,
}

impl InsVelocityCalibration {
    /// No calibration yet (the correction is zero).
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes a fix at `t_s`: `ins_minus_gnss_mps` is the INS velocity less the fix's, ECEF;
    /// `fix_sigma_mps` the fix velocity's largest per-axis sigma; `accel_mps2` the magnitude
    /// of the INS acceleration then. Returns whether it was used (not above
    /// [`MAX_FIX_SIGMA_MPS`] or [`MAX_ACCEL_MPS2`], all finite).
    pub fn update(
        &mut self,
        t_s: f64,
        ins_minus_gnss_mps: Vector3<f64>,
        fix_sigma_mps: f64,
        accel_mps2: f64,
    ) -> bool {
        let finite = ins_minus_gnss_mps.iter().all(|x| x.is_finite()) && t_s.is_finite();
        // NaN sigmas and accelerations fail these comparisons too.
        let usable = (0.0..=MAX_FIX_SIGMA_MPS).contains(&fix_sigma_mps)
            && (0.0..=MAX_ACCEL_MPS2).contains(&accel_mps2);
        if !finite || !usable {
            return false;
        }
        let d = ins_minus_gnss_mps;
        let (e, r) = match self.state {
            Some((t_prev, e, r)) if t_s > t_prev && t_s - t_prev <= MAX_STEP_S => {
                let dt = t_s - t_prev;
                let e_pred = e + r * dt;
                let y = d - e_pred;
                (
                    e_pred + y * (2.0 * ZETA * OMEGA_N_RAD_S * dt),
                    r + y * (OMEGA_N_RAD_S * OMEGA_N_RAD_S * dt),
                )
            }
            Some((t_prev, e, r)) if t_s <= t_prev => (e, r),
            // The first fix, or after a long gap: start from the fix, keeping the drift.
            Some((_, _, r)) => (d, r),
            None => (d, Vector3::zeros()),
        };
        let clamp = |v: Vector3<f64>, m: f64| v.map(|x| x.clamp(-m, m));
        self.state = Some((t_s, clamp(e, MAX_OFFSET_MPS), clamp(r, MAX_DRIFT_MPS2)));
        self.updates += 1;
        true
    }

    /// The INS velocity error at `t_s` (ECEF, m/s): subtract it from the INS velocity. Zero
    /// before the first fix.
    pub fn correction_mps(&self, t_s: f64) -> Vector3<f64> {
        match self.state {
            Some((t, e, r)) => e + r * (t_s - t),
            None => Vector3::zeros(),
        }
    }

    /// The drift estimate (the accelerometer bias the INS behaves as having), m/s^2, ECEF.
    pub fn drift_mps2(&self) -> Vector3<f64> {
        self.state.map_or_else(Vector3::zeros, |(_, _, r)| r)
    }

    /// Number of fixes used.
    pub fn updates(&self) -> usize {
        self.updates
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An INS biased by 1 mg on every axis drifts by `b t`; after 40 s of 10 Hz fixes (with
    /// 2 cm/s of white noise, fixed seed) the drift estimate is within 5 % of the bias and the
    /// corrected velocity within 1 cm/s of the truth: no ramp is left for the loops.
    #[test]
    fn a_constant_bias_is_followed_without_steady_error() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let b = Vector3::new(0.0098, 0.0098, 0.0098);
        let v0 = Vector3::new(0.05, -0.03, 0.02);
        let mut cal = InsVelocityCalibration::new();
        for k in 0..400 {
            let t = 5.0 + 0.1 * f64::from(k);
            let noise = Vector3::from_fn(|_, _| 0.02 * (rng.random::<f64>() - 0.5) * 3.46);
            assert!(cal.update(t, v0 + b * t + noise, 0.05, 0.0));
        }
        let t = 45.0;
        let err = cal.correction_mps(t) - (v0 + b * t);
        assert!(err.amax() < 0.01, "{err}");
        let drift = cal.drift_mps2();
        assert!((drift - b).amax() < 0.05 * b.amax(), "{drift}");
        // Between fixes the correction is extrapolated with the drift.
        let ahead = cal.correction_mps(t + 1.0) - cal.correction_mps(t);
        assert!((ahead - drift).amax() < 1e-12);
    }

    /// A wrong INS is not calibrated into agreement: a 50 m/s offset and a 1 m/s^2 drift are
    /// taken out only up to the limits; noisy fixes, NaN and fixes in a manoeuvre are not used.
    #[test]
    fn the_correction_is_bounded_and_bad_fixes_are_ignored() {
        let mut cal = InsVelocityCalibration::new();
        for k in 0..600 {
            let t = 0.1 * f64::from(k);
            cal.update(t, Vector3::new(50.0 + 1.0 * t, 0.0, 0.0), 0.05, 0.0);
        }
        assert!(cal.correction_mps(60.0).x <= MAX_OFFSET_MPS + MAX_DRIFT_MPS2 * 0.1);
        assert!(cal.drift_mps2().x <= MAX_DRIFT_MPS2);
        let before = cal.clone();
        assert!(!cal.update(61.0, Vector3::new(f64::NAN, 0.0, 0.0), 0.05, 0.0));
        assert!(!cal.update(61.0, Vector3::zeros(), 2.0, 0.0));
        // In a manoeuvre (a 10 g turn) the fix's dating error would read as velocity.
        assert!(!cal.update(61.0, Vector3::zeros(), 0.05, 98.0));
        assert!(!cal.update(f64::NAN, Vector3::zeros(), 0.05, 0.0));
        assert_eq!(cal, before);
        assert_eq!(
            InsVelocityCalibration::new().correction_mps(3.0),
            Vector3::zeros()
        );
    }

    /// A step of 1 m/s in the INS error is taken out with the overshoot of a type-2 loop at
    /// `zeta` = 0.707 (about 20 %: the proportional path's zero) and within 1 % after 60 s
    /// (8 time constants of `zeta omega_n`).
    #[test]
    fn a_velocity_step_settles_within_a_minute() {
        let mut cal = InsVelocityCalibration::new();
        cal.update(0.0, Vector3::zeros(), 0.05, 0.0);
        let mut peak: f64 = 0.0;
        for k in 1..=600 {
            let t = 0.1 * f64::from(k);
            cal.update(t, Vector3::new(1.0, 0.0, 0.0), 0.05, 0.0);
            peak = peak.max(cal.correction_mps(t).x);
        }
        assert!(peak > 1.1 && peak < 1.3, "{peak}");
        assert!((cal.correction_mps(60.0).x - 1.0).abs() < 0.01);
    }
}
