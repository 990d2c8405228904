//! First-order band limiter `H(s) = alpha / (s + alpha)` (seed 004 eq. 8): the limited dynamic
//! range of an IMU, on the feed-forward path.
//!
//! Discretised exactly for a piecewise-constant input held over each step `dt` (zero-order
//! hold): `y[k+1] = y[k] + (1 - exp(-alpha dt)) (u[k] - y[k])`, so its step response is exactly
//! `1 - exp(-alpha t)` at the sample instants, whatever `dt`.

/// A first-order low-pass of corner `alpha` rad/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandLimiter {
    alpha_rad_s: f64,
    y: Option<f64>,
}

impl BandLimiter {
    /// A limiter with corner `alpha_rad_s` (> 0; `f64::INFINITY` passes the input through).
    pub fn new(alpha_rad_s: f64) -> Self {
        Self {
            alpha_rad_s: alpha_rad_s.max(0.0),
            y: None,
        }
    }

    /// The current output (None before the first input).
    pub fn output(&self) -> Option<f64> {
        self.y
    }

    /// Advances by `dt_s` with the input `u` held over the step; returns the new output. The
    /// first call initialises the state to `u` (no start-up transient).
    pub fn step(&mut self, u: f64, dt_s: f64) -> f64 {
        let y = match self.y {
            None => u,
            Some(_) if self.alpha_rad_s.is_infinite() => u,
            Some(y) => {
                let g = 1.0 - (-self.alpha_rad_s * dt_s.max(0.0)).exp();
                y + g * (u - y)
            }
        };
        self.y = Some(y);
        y
    }

    /// Sets the state (e.g. to the first input after a reset).
    pub fn reset(&mut self, y: Option<f64>) {
        self.y = y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_response_is_one_minus_exp() {
        for &(alpha, dt) in &[(2.0, 1e-3), (0.5, 0.02), (10.0, 0.005)] {
            let mut f = BandLimiter::new(alpha);
            f.step(0.0, dt);
            let mut t = 0.0;
            for _ in 0..2000 {
                let y = f.step(1.0, dt);
                t += dt;
                let expected = 1.0 - (-alpha * t).exp();
                assert!(
                    (y - expected).abs() < 1e-12,
                    "alpha {alpha} dt {dt} t {t}: {y} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn ramp_lags_by_one_over_alpha() {
        // Steady-state of a ramp r t through alpha/(s+alpha): the output lags by r/alpha.
        let (alpha, r, dt) = (3.0, 2.0, 1e-3);
        let mut f = BandLimiter::new(alpha);
        let mut t = 0.0;
        let mut y = f.step(0.0, dt);
        for _ in 0..20_000 {
            // Hold the mid-step value so the discrete ramp matches the continuous one.
            y = f.step(r * (t + dt / 2.0), dt);
            t += dt;
        }
        assert!(((r * t - y) - r / alpha).abs() < 1e-3, "lag {}", r * t - y);
    }
}
