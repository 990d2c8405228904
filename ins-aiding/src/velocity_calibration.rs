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
//! `d(t) = v_INS - v_GNSS` is fitted with a least-squares line over the first [`WARMUP_S`] of
//! fixes (offset and drift; a loop started from zero drift would take tens of seconds to learn
//! it), then followed per ECEF axis by a type-2 tracking filter of states
//! offset `e` and drift `r` (m/s and m/s^2): between fixes `e += r dt`; at a fix, with the
//! innovation `y = d - e`, `e += 2 zeta omega_n dt y` and `r += omega_n^2 dt y` (the
//! critically damped analog loop `s^2 + 2 zeta omega_n s + omega_n^2` discretised by forward
//! Euler; the gain's `dt` clamped to [`MAX_GAIN_STEP_S`] so that the gains stay well inside
//! stability and a fix after a gap moves the aid by one ordinary step, not a jump). Type 2: a
//! constant bias (a ramp in `d`) is followed without steady error, so the corrected INS
//! velocity `v_INS - e(t)` has no ramp. Its bandwidth ([`OMEGA_N_RAD_S`], about 0.03 Hz) is well
//! below the narrowest carrier loop's (0.4 Hz), so the outer loop does not fight the inner one,
//! and its noise is the fixes' velocity noise averaged over several seconds.
//!
//! The loops already hold the INS error of the moment the calibration starts (a loop's
//! integrator absorbs a constant Doppler offset), so the feed-forward is corrected by the
//! *change* of the estimate since then ([`InsVelocityCalibration::correction_mps`]):
//! subtracting the whole estimate at once would step every loop's frequency by up to some Hz.
//! What the loops cannot absorb, the drift, is taken out from then on.
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
/// A fix whose velocity sigma (per axis, largest) exceeds this is not used, m/s (a fix near a
/// lost satellite or in poor geometry; 10 cm/s is 0.5 Hz on a line of sight).
pub const MAX_FIX_SIGMA_MPS: f64 = 0.1;
/// A fix taken while the INS reports more acceleration than this is not used, m/s^2: a fix's
/// velocity is dated to within some milliseconds (its Doppler averaged over the correlation
/// interval, the fix's time tag), and a time error `dt` reads as a velocity error `a dt`
/// (0.1 m/s for 1 ms in a 10 g turn); under 2 m/s^2 a 20 ms error costs 4 cm/s. The
/// calibration learnt before a manoeuvre is extrapolated through it.
pub const MAX_ACCEL_MPS2: f64 = 2.0;
/// Longest interval whose gain one update applies, s: fixes further apart (after a gap, or
/// slower than 5 Hz) are taken in as if 0.2 s apart, so the aid never jumps.
pub const MAX_GAIN_STEP_S: f64 = 0.2;
/// The warm-up: the loop starts from a least-squares line (offset and drift) through the
/// first fixes once they span this long, s. The correction is zero until then.
pub const WARMUP_S: f64 = 4.0;
/// The warm-up needs at least this many fixes.
pub const WARMUP_FIXES: usize = 8;

/// The INS velocity error estimate (module docs). Fixed-size and `Copy`: the feed-forward
/// reads it for every aid.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct InsVelocityCalibration {
    /// The warm-up's running sums (module docs "How"), until the loop starts.
    warmup: Warmup,
    /// Time of the last update, s, and the loop's state `(e, r)` there.
    state: Option<(f64, Vector3<f64>, Vector3<f64>)>,
    /// The offset when the loop started, which the correction leaves out (module docs).
    base: Vector3<f64>,
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
    /// [`MAX_FIX_SIGMA_MPS`] or [`MAX_ACCEL_MPS2`], all finite, later than the last).
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
        let last = self.state.map(|(t, _, _)| t).or(self.warmup.last_t_s());
        if !finite || !usable || last.is_some_and(|t| t_s <= t) {
            return false;
        }
        let d = ins_minus_gnss_mps;
        self.updates += 1;
        let (e, r) = match self.state {
            Some((t_prev, e, r)) => {
                let dt = t_s - t_prev;
                let e_pred = e + r * dt;
                let y = d - e_pred;
                // After a gap the innovation is taken in as over one ordinary step, never as a
                // jump of the aid (a step of the feed-forward is a frequency step to the loops).
                let g = dt.min(MAX_GAIN_STEP_S);
                (
                    e_pred + y * (2.0 * ZETA * OMEGA_N_RAD_S * g),
                    r + y * (OMEGA_N_RAD_S * OMEGA_N_RAD_S * g),
                )
            }
            None => {
                self.warmup.push(t_s, d);
                let Some((e, r)) = self.warmup.fit() else {
                    return true;
                };
                self.warmup = Warmup::default();
                self.base = e;
                (e, r)
            }
        };
        let clamp = |v: Vector3<f64>, m: f64| v.map(|x| x.clamp(-m, m));
        self.state = Some((t_s, clamp(e, MAX_OFFSET_MPS), clamp(r, MAX_DRIFT_MPS2)));
        true
    }

    /// The change of the INS velocity error since the loop started at `t_s` (ECEF, m/s):
    /// subtract it from the INS velocity. Zero until the warm-up ends.
    pub fn correction_mps(&self, t_s: f64) -> Vector3<f64> {
        self.error_mps(t_s) - self.base
    }

    /// The whole INS velocity error estimate at `t_s` (ECEF, m/s; zero until the warm-up
    /// ends), the offset the loops already hold included.
    pub fn error_mps(&self, t_s: f64) -> Vector3<f64> {
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

/// The running sums of the warm-up fixes `(t, d)`, times taken from the first one (so that the
/// sums of squares stay exact at any time of day).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Warmup {
    /// Time of the first fix, s.
    t_first: f64,
    /// Time of the last fix less `t_first`, s.
    t_last: f64,
    n: usize,
    sum_t: f64,
    sum_tt: f64,
    sum_d: Vector3<f64>,
    sum_td: Vector3<f64>,
}

impl Warmup {
    fn push(&mut self, t_s: f64, d: Vector3<f64>) {
        if self.n == 0 {
            self.t_first = t_s;
        }
        let t = t_s - self.t_first;
        self.n += 1;
        self.t_last = t;
        self.sum_t += t;
        self.sum_tt += t * t;
        self.sum_d += d;
        self.sum_td += d * t;
    }

    fn last_t_s(&self) -> Option<f64> {
        (self.n > 0).then_some(self.t_first + self.t_last)
    }

    /// The least-squares line `d(t) = e + r (t - t_last)` through the fixes, per axis, once
    /// they span [`WARMUP_S`] with at least [`WARMUP_FIXES`] fixes: `(e, r)` at the last one.
    fn fit(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        if self.t_last < WARMUP_S || self.n < WARMUP_FIXES {
            return None;
        }
        let n = self.n as f64;
        let (t_mean, d_mean) = (self.sum_t / n, self.sum_d / n);
        let stt = self.sum_tt - n * t_mean * t_mean;
        let std = self.sum_td - d_mean * (n * t_mean);
        let r = std / stt;
        Some((d_mean + r * (self.t_last - t_mean), r))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An INS biased by 1 mg on every axis drifts by `b t`; nothing is corrected during the 4 s
    /// warm-up; with 10 Hz fixes with 2 cm/s of white noise (fixed seed) the corrected velocity
    /// is within 2 cm/s of the truth 10 s after the first fix, and after 40 s the drift is
    /// within 10 % of the bias and the velocity within 1 cm/s: no ramp is left for the loops.
    #[test]
    fn a_constant_bias_is_followed_without_steady_error() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let b = Vector3::new(0.0098, 0.0098, 0.0098);
        let v0 = Vector3::new(0.05, -0.03, 0.02);
        let mut cal = InsVelocityCalibration::new();
        let mut fix = |cal: &mut InsVelocityCalibration, t: f64| {
            let noise = Vector3::from_fn(|_, _| 0.02 * (rng.random::<f64>() - 0.5) * 3.46);
            assert!(cal.update(t, v0 + b * t + noise, 0.05, 0.0));
        };
        for k in 0..40 {
            fix(&mut cal, 5.0 + 0.1 * f64::from(k));
        }
        assert_eq!(cal.error_mps(8.9), Vector3::zeros(), "warm-up");
        for k in 40..100 {
            fix(&mut cal, 5.0 + 0.1 * f64::from(k));
        }
        // 10 s in: the warm-up's drift is good to `sigma sqrt(12 / (N T^2))` = 0.3 mg (40
        // fixes over 4 s), so the velocity is within 2 cm/s.
        let err = cal.error_mps(15.0) - (v0 + b * 15.0);
        assert!(err.amax() < 0.02, "{err}");
        for k in 100..400 {
            fix(&mut cal, 5.0 + 0.1 * f64::from(k));
        }
        let t = 45.0;
        let err = cal.error_mps(t) - (v0 + b * t);
        assert!(err.amax() < 0.01, "{err}");
        // The correction leaves out the offset the loops held when it started (at 9 s, the
        // warm-up's end): it is the error's change since then.
        let since = cal.correction_mps(t) - (b * (t - 8.9));
        assert!(since.amax() < 0.03, "{since}");
        let drift = cal.drift_mps2();
        assert!((drift - b).amax() < 0.1 * b.amax(), "{drift}");
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
        assert!(cal.error_mps(60.0).x <= MAX_OFFSET_MPS + MAX_DRIFT_MPS2 * 0.1);
        assert!(cal.drift_mps2().x <= MAX_DRIFT_MPS2);
        let before = cal;
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

    /// After a warm-up on zeros, a step of 1 m/s in the INS error is taken out with the
    /// overshoot of a type-2 loop at `zeta` = 0.707 (about 20 %: the proportional path's zero)
    /// and within 1 % after 60 s (8 time constants of `zeta omega_n`); a fix after a 7 s gap
    /// moves the correction by one ordinary step (at most `2 zeta omega_n 0.2 s` = 5.7 % of the
    /// innovation), not a jump.
    #[test]
    fn a_velocity_step_settles_within_a_minute_and_a_gap_makes_no_jump() {
        let mut cal = InsVelocityCalibration::new();
        for k in 0..50 {
            cal.update(0.1 * f64::from(k), Vector3::zeros(), 0.05, 0.0);
        }
        let mut peak: f64 = 0.0;
        for k in 50..=650 {
            let t = 0.1 * f64::from(k);
            cal.update(t, Vector3::new(1.0, 0.0, 0.0), 0.05, 0.0);
            peak = peak.max(cal.correction_mps(t).x);
        }
        assert!(peak > 1.1 && peak < 1.3, "{peak}");
        assert!((cal.correction_mps(65.0).x - 1.0).abs() < 0.01);
        let before = cal.correction_mps(72.0).x;
        assert!(cal.update(72.0, Vector3::new(2.0, 0.0, 0.0), 0.05, 0.0));
        let step = cal.correction_mps(72.0).x - before;
        assert!(
            step > 0.0 && step <= 2.0 * ZETA * OMEGA_N_RAD_S * MAX_GAIN_STEP_S * 1.001,
            "{step}"
        );
    }
}
