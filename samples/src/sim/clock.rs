//! The simulated receiver clock.
//!
//! The receiver's clock reads `t_rcv = t + b(t)` at true GPS time `t`; samples are evenly spaced
//! in receiver time. The bias is `b = b0 + d * t + w(t)` where `w` is a random walk of time error
//! driven by white frequency noise: for white FM the Allan deviation is
//! `sigma_y(tau) = sigma_1 / sqrt(tau)` and the time error diffuses as `var(dw) = sigma_1^2 * 1 s * dt`.
//! `w` is drawn on a 10 ms grid from the scenario's seed and interpolated linearly.

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Receiver clock model.
#[derive(Debug, Clone)]
pub struct ReceiverClock {
    bias0_s: f64,
    drift_s_s: f64,
    /// Random-walk time error on a [`ReceiverClock::GRID_S`] grid.
    walk_s: Vec<f64>,
}

impl ReceiverClock {
    /// Grid of the random walk, seconds.
    pub const GRID_S: f64 = 0.01;

    /// A clock over `span_s` seconds.
    pub fn new(
        bias0_s: f64,
        drift_s_s: f64,
        allan_deviation_1s: f64,
        span_s: f64,
        seed: u64,
    ) -> Self {
        let mut walk_s = vec![0.0];
        if allan_deviation_1s > 0.0 {
            let n = (span_s / Self::GRID_S).ceil() as usize + 2;
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0xC10C_C10C_C10C_C10C);
            let sd = allan_deviation_1s * Self::GRID_S.sqrt();
            let mut w = 0.0;
            walk_s.reserve(n);
            for _ in 0..n {
                let z: f64 = StandardNormal.sample(&mut rng);
                w += sd * z;
                walk_s.push(w);
            }
        }
        Self {
            bias0_s,
            drift_s_s,
            walk_s,
        }
    }

    /// Clock bias (s) at `t_s` seconds after the start.
    pub fn bias_s(&self, t_s: f64) -> f64 {
        self.bias0_s + self.drift_s_s * t_s + self.walk(t_s)
    }

    /// Clock drift (s/s) at `t_s`: the nominal drift plus the random walk's local slope.
    pub fn drift_s_s(&self, t_s: f64) -> f64 {
        let h = Self::GRID_S;
        self.drift_s_s + (self.walk(t_s + h / 2.0) - self.walk(t_s - h / 2.0)) / h
    }

    fn walk(&self, t_s: f64) -> f64 {
        if self.walk_s.len() < 2 {
            return 0.0;
        }
        let x = (t_s / Self::GRID_S).max(0.0);
        let i = (x.floor() as usize).min(self.walk_s.len() - 2);
        let u = (x - i as f64).min(1.0);
        self.walk_s[i] * (1.0 - u) + self.walk_s[i + 1] * u
    }

    /// True time (s since start) at receiver time `t_rcv_s` since start: solves `t + b(t) = t_rcv`.
    pub fn true_time(&self, t_rcv_s: f64) -> f64 {
        let mut t = t_rcv_s - self.bias_s(t_rcv_s);
        t = t_rcv_s - self.bias_s(t);
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deterministic_clock_is_linear() {
        let c = ReceiverClock::new(1e-4, 2e-8, 0.0, 10.0, 1);
        assert_eq!(c.bias_s(5.0), 1e-4 + 1e-7);
        assert!((c.true_time(1.0) + c.bias_s(c.true_time(1.0)) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn white_fm_allan_deviation_matches_setting() {
        // Overlapping-free Allan deviation at tau = 1 s from the phase record:
        // sigma_y^2(tau) = <(x(t+2tau) - 2x(t+tau) + x(t))^2> / (2 tau^2).
        let sigma = 1e-9;
        let c = ReceiverClock::new(0.0, 0.0, sigma, 4000.0, 99);
        let tau = 1.0;
        let mut acc = 0.0;
        let mut n = 0.0;
        let mut t = 0.0;
        while t + 2.0 * tau < 4000.0 {
            let d = c.bias_s(t + 2.0 * tau) - 2.0 * c.bias_s(t + tau) + c.bias_s(t);
            acc += d * d;
            n += 1.0;
            t += 2.0 * tau;
        }
        let adev = (acc / n / (2.0 * tau * tau)).sqrt();
        // 2000 samples: the estimate's relative standard error is about 1/sqrt(2*2000) = 1.6 %.
        assert!((adev / sigma - 1.0).abs() < 0.08, "adev {adev}");
    }
}
