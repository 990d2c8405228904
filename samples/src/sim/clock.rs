//! The simulated receiver clock.
//!
//! The receiver's clock reads `t_rcv = t + b(t)` at true GPS time `t`; samples are evenly spaced
//! in receiver time. The bias is `b = b0 + d * t + w(t)` where `w` is the time error of the
//! two-state oscillator model (van Dierendonck, McGraw & Brown 1984; Brown & Hwang 4th ed.
//! 9.3): `dw/dt = y + e1`, `dy/dt = e2`, with white noises of spectral densities `q1` (white
//! frequency noise) and `q2` (random-walk frequency noise). In the power-law form
//! `S_y(f) = h0 + h_-2 / f^2` (h_-1, flicker FM, has no finite-state equivalent and is left
//! out): `q1 = h0 / 2`, `q2 = 2 pi^2 h_-2`, and the Allan variance is
//! `sigma_y^2(tau) = h0 / (2 tau) + (2 pi^2 / 3) h_-2 tau = q1 / tau + q2 tau / 3`
//! (Kaplan & Hegarty 2nd ed. 5.6; IEEE Std 1139). The scenario gives `sigma_1 = sqrt(q1)`
//! (`allan_deviation_1s`, the white-FM Allan deviation at 1 s) and `h_-2`
//! (`random_walk_fm_h_m2`). A TCXO has sigma_y(1 s) about 1e-10 (h0 = 2e-20), an OCXO 1e-12
//! (h0 = 2e-24). `w` is drawn on a 10 ms grid (Euler steps: `w += y dt + sqrt(q1 dt) z1`,
//! `y += sqrt(q2 dt) z2`) from the scenario's seed and interpolated linearly.

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

    /// A clock over `span_s` seconds with white FM of Allan deviation `allan_deviation_1s` at
    /// 1 s and no random-walk FM.
    pub fn new(
        bias0_s: f64,
        drift_s_s: f64,
        allan_deviation_1s: f64,
        span_s: f64,
        seed: u64,
    ) -> Self {
        Self::with_random_walk_fm(bias0_s, drift_s_s, allan_deviation_1s, 0.0, span_s, seed)
    }

    /// A clock over `span_s` seconds with white FM (`allan_deviation_1s` = sqrt(q1)) and
    /// random-walk FM of power-law coefficient `h_m2` (q2 = 2 pi^2 h_-2), module docs.
    pub fn with_random_walk_fm(
        bias0_s: f64,
        drift_s_s: f64,
        allan_deviation_1s: f64,
        h_m2: f64,
        span_s: f64,
        seed: u64,
    ) -> Self {
        let mut walk_s = vec![0.0];
        if allan_deviation_1s > 0.0 || h_m2 > 0.0 {
            let dt = Self::GRID_S;
            let n = (span_s / dt).ceil() as usize + 2;
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0xC10C_C10C_C10C_C10C);
            let mut rng_fm = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0xF4E0_F4E0_F4E0_F4E0);
            let sd = allan_deviation_1s * dt.sqrt();
            let sd_y = (2.0 * std::f64::consts::PI.powi(2) * h_m2 * dt).sqrt();
            let (mut w, mut y) = (0.0, 0.0);
            walk_s.reserve(n);
            for _ in 0..n {
                let z: f64 = StandardNormal.sample(&mut rng);
                w += sd * z + y * dt;
                if h_m2 > 0.0 {
                    let z2: f64 = StandardNormal.sample(&mut rng_fm);
                    y += sd_y * z2;
                }
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

    /// Overlapping Allan deviation from phase samples x_i (s) every `tau0`, at tau = m tau0
    /// (IEEE Std 1139: sigma^2 = sum (x_{i+2m} - 2 x_{i+m} + x_i)^2 / (2 tau^2 (N - 2m))).
    fn overlapping_adev(x: &[f64], tau0: f64, m: usize) -> f64 {
        let tau = tau0 * m as f64;
        let terms = x.len() - 2 * m;
        let sum: f64 = (0..terms)
            .map(|i| {
                let d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
                d * d
            })
            .sum();
        (sum / (2.0 * tau * tau * terms as f64)).sqrt()
    }

    #[test]
    fn two_state_oscillators_match_their_allan_deviation() {
        // TCXO-like (sigma_y(1 s) = 1e-10 white FM, h_-2 = 3e-22) and OCXO-like (1e-12,
        // h_-2 = 3e-26): sigma_y^2(tau) = q1 / tau + (2 pi^2 / 3) h_-2 tau at 1 s and 10 s,
        // from 20000 s of phase sampled every 0.1 s, averaged over 4 seeds.
        for (sigma1, h_m2) in [(1e-10, 3e-22), (1e-12, 3e-26)] {
            for tau in [1.0, 10.0] {
                let expected = (sigma1 * sigma1 / tau
                    + 2.0 * std::f64::consts::PI.powi(2) / 3.0 * h_m2 * tau)
                    .sqrt();
                let mut var = 0.0;
                for seed in 0..4 {
                    let span = 20_000.0;
                    let c = ReceiverClock::with_random_walk_fm(0.0, 0.0, sigma1, h_m2, span, seed);
                    let x: Vec<f64> = (0..200_000).map(|i| c.bias_s(0.1 * f64::from(i))).collect();
                    var += overlapping_adev(&x, 0.1, (tau / 0.1).round() as usize).powi(2) / 4.0;
                }
                let adev = var.sqrt();
                println!("sigma1 {sigma1:e} h-2 {h_m2:e} tau {tau} s: ADEV {adev:.3e}, spec {expected:.3e}");
                assert!(
                    (adev / expected - 1.0).abs() < 0.15,
                    "tau {tau}: {adev:e} vs {expected:e}"
                );
            }
        }
    }
}
