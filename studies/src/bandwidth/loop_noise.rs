//! The linearised digital loop: noise gains, start-up transients and conditional stability.

use gpsrx_tracking::{loop_analysis, LoopFilter};

/// Impulse responses of a linearised digital tracking loop to one unit of discriminator noise,
/// with the channel's timing (`super::if_sim` and `gpsrx_tracking::loop_analysis`): the NCO
/// holds `u_k` over interval k, `phi_{k+1} = phi_k + u_k T`; the discriminator sees the average
/// error over the interval, `e_k = n_k - g (phi_k + u_k T/2)` (g the discriminator slope); the
/// loop filter turns `e_k` into `u_{k+1}`.
#[derive(Debug, Clone)]
pub struct LoopNoiseGains {
    /// Update interval T, s.
    pub t_s: f64,
    /// NCO phase at the start of each interval.
    pub phase: Vec<f64>,
    /// NCO frequency held over each interval.
    pub freq: Vec<f64>,
}

impl LoopNoiseGains {
    /// Runs `filter` (as configured, from rest) for an impulse `n_0 = 1` with discriminator slope
    /// `slope`, for `150 / (Bn T slope)` updates (at most 8 million), long after the response of
    /// a stable loop has decayed (the slowest mode, order 3, decays by `exp(-22)` by then).
    pub fn new(filter: LoopFilter, bn_hz: f64, t_s: f64, slope: f64) -> Self {
        let (phase, freq) = impulse_response(filter, bn_hz, t_s, slope).unzip();
        Self { t_s, phase, freq }
    }

    /// [`LoopNoiseGains::phase_gain`] without keeping the response (for long responses in a
    /// search).
    pub fn phase_gain_of(filter: LoopFilter, bn_hz: f64, t_s: f64, slope: f64) -> f64 {
        impulse_response(filter, bn_hz, t_s, slope)
            .map(|(phi, _)| phi * phi)
            .sum()
    }

    /// `var(phi)` per unit noise variance: `sum h_phi^2`.
    pub fn phase_gain(&self) -> f64 {
        self.phase.iter().map(|x| x * x).sum()
    }

    /// `var(u)` per unit noise variance: `sum h_u^2`.
    pub fn freq_gain(&self) -> f64 {
        self.freq.iter().map(|x| x * x).sum()
    }

    /// Variance of the rate from the phase change over `m` intervals,
    /// `(phi_{j+m} - phi_j)/(m T)`, per unit noise variance.
    pub fn rate_gain(&self, m: usize) -> f64 {
        let tau = m as f64 * self.t_s;
        let n = self.phase.len();
        let at = |j: isize| {
            if j < 0 || j as usize >= n {
                0.0
            } else {
                self.phase[j as usize]
            }
        };
        (-(m as isize)..n as isize)
            .map(|j| ((at(j + m as isize) - at(j)) / tau).powi(2))
            .sum()
    }

    /// The loop's realised one-sided noise bandwidth (slope 1), Hz, defined as in
    /// `gpsrx_tracking::loop_analysis` on the phase the discriminator sees, the interval's
    /// average `phi_k + u_k T/2`: `Bn' = sum (h_phi + h_u T/2)^2 / (2 T)`. (The NCO phase at the
    /// interval's start, which the study measures, carries a little more high-frequency noise:
    /// [`LoopNoiseGains::phase_gain`]; the two agree for small `Bn T`.)
    pub fn noise_bandwidth_hz(&self) -> f64 {
        let t = self.t_s;
        self.phase
            .iter()
            .zip(&self.freq)
            .map(|(p, u)| (p + 0.5 * u * t).powi(2))
            .sum::<f64>()
            / (2.0 * t)
    }
}

/// The NCO phase and frequency `(phi_k, u_k)` of the loop's impulse response (struct docs) for
/// `150 / (Bn T slope)` updates, clamped to [1000, 8 million].
fn impulse_response(
    mut filter: LoopFilter,
    bn_hz: f64,
    t_s: f64,
    slope: f64,
) -> impl Iterator<Item = (f64, f64)> {
    let n = ((150.0 / (bn_hz * t_s * slope.max(0.05))).ceil() as usize).clamp(1000, 8_000_000);
    let (mut phi, mut u) = (0.0, 0.0);
    (0..n).map(move |k| {
        let out = (phi, u);
        let noise = if k == 0 { 1.0 } else { 0.0 };
        let e = noise - slope * (phi + 0.5 * u * t_s);
        phi += u * t_s;
        u = filter.update(e, 0.0, t_s);
        out
    })
}

/// How long the start-up transients of a linearised loop (discriminator slope `slope`) take to
/// decay to `fraction` of their size, s: the larger of the responses to an initial NCO phase
/// offset (a channel starts with a random carrier phase) and to a persistent NCO frequency step
/// (the hand-over to tracking moves the last loop output, proportional term included, into the
/// new loop's base frequency), each measured from the last time `|phi|` exceeds `fraction` of
/// its peak. The slowest closed-loop mode sets it: decay rate `zeta omega0 = 0.707 omega0` for
/// order 2, but only `0.148 omega0` for the lightly damped complex pair of the 3rd-order loop,
/// whose analog characteristic polynomial `s^3 + 2.4 s^2 + 1.1 s + 1` (omega0 = 1) has roots
/// -2.103 and -0.148 +- 0.673j (damping ratio 0.22).
pub fn transient_decay_time_s(
    filter: &LoopFilter,
    bn_hz: f64,
    t_s: f64,
    slope: f64,
    fraction: f64,
) -> f64 {
    let n = ((150.0 / (bn_hz * t_s * slope.max(0.05))).ceil() as usize).clamp(1000, 8_000_000);
    let run = |phi0: f64, df: f64| {
        let mut f = filter.clone();
        let (mut phi, mut u) = (phi0, df);
        let (mut peak, mut last) = (0.0f64, 0usize);
        let mut trace = Vec::with_capacity(n);
        for _ in 0..n {
            trace.push(phi.abs());
            peak = peak.max(phi.abs());
            let e = -slope * (phi + 0.5 * u * t_s);
            phi += u * t_s;
            u = df + f.update(e, 0.0, t_s);
        }
        if let Some(k) = trace.iter().rposition(|x| *x > fraction * peak) {
            last = k + 1;
        }
        last as f64 * t_s
    };
    run(1.0, 0.0).max(run(0.0, 1.0))
}

/// Whether the digital loop of `filter` (update interval `t_s`) is stable when its
/// discriminator has slope `slope`: the open loop `L = F_p N` of
/// `gpsrx_tracking::loop_analysis` scaled by the slope, closed, and tested by Schur-Cohn.
pub fn stable_with_slope(filter: &LoopFilter, t_s: f64, slope: f64) -> bool {
    let mut l = loop_analysis::open_loop(filter, t_s);
    l.num.iter_mut().for_each(|c| *c *= slope);
    slope > 0.0 && loop_analysis::polynomial_is_stable(&l.feedback().den)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bandwidth::{costas_formula_noise_var_cycles2, pll_jitter_deg};

    #[test]
    fn linear_loop_gives_the_formula_for_a_narrow_loop() {
        // Bn T = 0.002: the digital loop's realised Bn is within 1 % of design, so the impulse
        // response sum reproduces the formula (2 Bn T s^2 = sigma^2) within 1 %.
        for order in [2u8, 3] {
            let f = LoopFilter::pll(order, 2.0).ok();
            let g = f.map(|f| LoopNoiseGains::new(f, 2.0, 1e-3, 1.0));
            let bn = g.as_ref().map(|g| g.noise_bandwidth_hz()).unwrap_or(0.0);
            assert!((bn / 2.0 - 1.0).abs() < 0.01, "order {order}: Bn' {bn}");
            let s2 = costas_formula_noise_var_cycles2(40.0, 1e-3);
            let sigma = g
                .map(|g| (s2 * g.phase_gain()).sqrt() * 360.0)
                .unwrap_or(0.0);
            let want = pll_jitter_deg(2.0, 40.0, 1e-3);
            assert!((sigma / want - 1.0).abs() < 0.01, "{sigma} vs {want}");
        }
        // The realised Bn at Bn T = 0.1 matches tracking/README.md (order 2: 1.288).
        let g = LoopFilter::pll(2, 100.0)
            .ok()
            .map(|f| LoopNoiseGains::new(f, 100.0, 1e-3, 1.0).noise_bandwidth_hz() / 100.0);
        assert!(g.is_some_and(|r| (r - 1.288).abs() < 0.005), "{g:?}");
    }

    #[test]
    fn rate_gain_of_a_long_interval_is_twice_the_phase_variance() {
        // tau much longer than the loop's memory: var((phi_{j+m} - phi_j)/tau) = 2 var(phi)/tau^2.
        let t = 1e-3;
        let g = LoopFilter::pll(2, 10.0)
            .ok()
            .map(|f| LoopNoiseGains::new(f, 10.0, t, 1.0));
        let Some(g) = g else { panic!("filter") };
        let m = 5000;
        let tau = m as f64 * t;
        let want = 2.0 * g.phase_gain() / (tau * tau);
        assert!((g.rate_gain(m) / want - 1.0).abs() < 0.01);
    }

    #[test]
    fn settling_times_and_conditional_stability() {
        // Decay to 3e-4 = exp(-8.1): 8.1 / (decay rate). Order 2: 0.707 omega0, omega0 = Bn/0.53;
        // order 3: 0.1485 omega0, omega0 = Bn/0.7845 (analog roots; the digital loop at
        // Bn T = 0.001 is within a few per cent, and the envelope of a ringing response crosses
        // the level up to a half period early: 25 % tolerance).
        let decay = |order: u8| {
            LoopFilter::pll(order, 1.0)
                .ok()
                .map(|f| transient_decay_time_s(&f, 1.0, 1e-3, 1.0, 3e-4))
                .unwrap_or(0.0)
        };
        let want2 = (1.0 / 3e-4f64).ln() / (0.707 / 0.53);
        let want3 = (1.0 / 3e-4f64).ln() / (0.148_47 / 0.7845);
        assert!(
            (decay(2) / want2 - 1.0).abs() < 0.25,
            "{} vs {want2}",
            decay(2)
        );
        assert!(
            (decay(3) / want3 - 1.0).abs() < 0.25,
            "{} vs {want3}",
            decay(3)
        );
        // Routh: the analog 3rd-order loop with discriminator gain g is stable iff
        // g a3 b3 > 1, g > 0.379; the 2nd-order loop for any g > 0.
        let f3 = LoopFilter::pll(3, 1.0).ok();
        let f2 = LoopFilter::pll(2, 1.0).ok();
        let st =
            |f: &Option<LoopFilter>, g| f.as_ref().is_some_and(|f| stable_with_slope(f, 1e-3, g));
        assert!(!st(&f3, 0.36) && st(&f3, 0.40));
        assert!(st(&f2, 0.05) && st(&f2, 1.0));
    }
}
