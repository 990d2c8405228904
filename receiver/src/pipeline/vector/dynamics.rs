//! The dynamics test of vector tracking: how hard the receiver accelerates, from the velocities
//! of the least-squares fixes.
//!
//! The filter is fed with epochs of observables that are complete only two epochs after their
//! time (the observables builder differences the carrier phase across the epoch) and after
//! the 40 ms round of the channels: its feed-forward is a prediction 0.2-0.3 s ahead of its
//! last measurement (at the default 10 Hz). Under an acceleration `a` along a line of sight
//! the constant-velocity prediction is off by about `a x 0.3 s`: 0.9 m/s (4.7 Hz) at
//! [`MAX_ACCEL_MPS2`], 29 m/s (150 Hz) in a 10 g turn, which no loop on top holds. Until the
//! filter is fed at the discriminator rate (a later part of issue 29), vector tracking hands
//! the channels back to their scalar loops when the acceleration exceeds [`MAX_ACCEL_MPS2`],
//! and takes them again only after [`CALM_S`] below it.
//!
//! The acceleration is `(|v(t) - v(t - T)| - k sigma) / T` over a baseline `T` of about
//! [`BASELINE_S`], `sigma = sqrt 2 sigma(t - T)` the standard deviation of the velocity
//! difference from the older fix's velocity covariance (the newer one's grows with a
//! manoeuvre's onset, which must not hide it) and `k` = [`NOISE_SIGMAS`]: only a change the
//! velocities' noise does not explain counts (a static receiver's fix velocities, noisy by 0.1-0.3 m/s,
//! read 0.3-0.9 m/s^2 raw; satellites fading to 26 dB-Hz made them noisy enough to read
//! 3.1 m/s^2 and hand the channels back just where the filter holds them best).

use nalgebra::Vector3;
use std::collections::VecDeque;

/// Acceleration above which the feed-forward cannot follow, m/s^2 (module docs).
pub const MAX_ACCEL_MPS2: f64 = 3.0;
/// Baseline of the velocity difference, s.
pub const BASELINE_S: f64 = 0.5;
/// Time below [`MAX_ACCEL_MPS2`] before the filter may take the channels again, s.
pub const CALM_S: f64 = 1.0;
/// Standard deviations of the velocity difference discounted from it (module docs).
pub const NOISE_SIGMAS: f64 = 3.0;

/// The acceleration followed from velocities (module docs).
#[derive(Debug, Clone, Default)]
pub struct AccelWatch {
    /// `(t_s, velocity, 3-D velocity sigma)`.
    samples: VecDeque<(f64, Vector3<f64>, f64)>,
    /// Time of the last acceleration above the limit, s (None: never).
    last_high_s: Option<f64>,
    /// Time of the first sample, s.
    first_s: Option<f64>,
    accel: Option<f64>,
}

impl AccelWatch {
    /// Takes the velocity `v` (m/s) at time `t_s`, with its 3-D standard deviation
    /// `sigma_mps` (the square root of its covariance's trace; 0 if unknown).
    pub fn push(&mut self, t_s: f64, v: Vector3<f64>, sigma_mps: f64) {
        if !(t_s.is_finite() && v.iter().all(|x| x.is_finite())) {
            return;
        }
        if self.samples.back().is_some_and(|(t, _, _)| t_s <= *t) {
            return;
        }
        let sigma = if sigma_mps.is_finite() && sigma_mps > 0.0 {
            sigma_mps
        } else {
            0.0
        };
        self.first_s.get_or_insert(t_s);
        self.samples.push_back((t_s, v, sigma));
        while self
            .samples
            .get(1)
            .is_some_and(|(t1, _, _)| t_s - t1 >= BASELINE_S)
        {
            self.samples.pop_front();
        }
        self.accel = match self.samples.front() {
            Some((t0, v0, s0)) if t_s - t0 >= 0.5 * BASELINE_S => {
                // The older fix's sigma for both: the newer one's grows with the stress of a
                // manoeuvre's onset (its Doppler residuals), which must not hide it.
                let noise = NOISE_SIGMAS * std::f64::consts::SQRT_2 * s0;
                Some(((v - v0).norm() - noise).max(0.0) / (t_s - t0))
            }
            _ => None,
        };
        if self.accel.is_some_and(|a| a > MAX_ACCEL_MPS2) {
            self.last_high_s = Some(t_s);
        }
    }

    /// The latest acceleration, m/s^2 (None before half a baseline of samples).
    pub fn accel_mps2(&self) -> Option<f64> {
        self.accel
    }

    /// Whether the acceleration is above the limit now.
    pub fn too_high(&self) -> bool {
        self.accel.is_some_and(|a| a > MAX_ACCEL_MPS2)
    }

    /// Whether it has been known and below the limit for [`CALM_S`] up to `t_s`.
    pub fn calm_at(&self, t_s: f64) -> bool {
        let since = match (self.last_high_s, self.first_s) {
            (Some(h), _) => h,
            (None, Some(f)) => f,
            (None, None) => return false,
        };
        self.accel.is_some() && !self.too_high() && t_s - since >= CALM_S
    }

    /// Forgets the velocities (after a gap in the fixes).
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_10_g_turn_is_too_much_and_a_static_receiver_is_calm() {
        let mut w = AccelWatch::default();
        // Static, velocity noise +-0.2 m/s (alternating): 0.4 m/s over 0.5 s at most.
        for k in 0..30 {
            let s = if k % 2 == 0 { 0.2 } else { -0.2 };
            w.push(k as f64 * 0.1, Vector3::new(s, 0.0, 0.0), 0.0);
        }
        assert!(w.calm_at(2.9), "{:?}", w.accel_mps2());
        // A 10 g acceleration along x.
        for k in 30..36 {
            w.push(
                k as f64 * 0.1,
                Vector3::new(98.0 * (k as f64 * 0.1 - 2.9), 0.0, 0.0),
                0.0,
            );
        }
        assert!(w.too_high() && !w.calm_at(3.5), "{:?}", w.accel_mps2());
        // Back to a constant velocity: calm again only CALM_S after the last high reading.
        let v_end = 98.0 * 0.6;
        let mut t_calm = None;
        for k in 36..70 {
            let t = k as f64 * 0.1;
            w.push(t, Vector3::new(v_end, 0.0, 0.0), 0.0);
            if t_calm.is_none() && w.calm_at(t) {
                t_calm = Some(t);
            }
        }
        let t = t_calm.unwrap_or(f64::NAN);
        assert!((4.5..=5.2).contains(&t), "calm again at {t} s");
    }

    #[test]
    fn velocity_noise_its_sigma_explains_is_no_acceleration() {
        // Static, velocities jumping by 2 m/s with a stated 3-D sigma of 0.6 m/s: 4 m/s^2 raw,
        // within 3 sigma of the difference (2.5 m/s): calm. Without the sigma: too high.
        let (mut with, mut without) = (AccelWatch::default(), AccelWatch::default());
        for k in 0..30 {
            let v = Vector3::new(if k % 5 == 0 { 1.0 } else { -1.0 }, 0.0, 0.0);
            with.push(k as f64 * 0.1, v, 0.6);
            without.push(k as f64 * 0.1, v, 0.0);
        }
        assert!(with.calm_at(2.9), "{:?}", with.accel_mps2());
        assert!(without.last_high_s.is_some(), "{:?}", without.accel_mps2());
        // A 10 g acceleration with the same sigma is still too much.
        for k in 30..36 {
            let v = Vector3::new(98.0 * (k as f64 * 0.1 - 2.9), 0.0, 0.0);
            with.push(k as f64 * 0.1, v, 0.6);
        }
        assert!(with.too_high(), "{:?}", with.accel_mps2());
    }
}
