//! A small closed-loop simulator in the phase domain, at the level of correlator outputs.
//!
//! The input carrier phase `theta(t)` (cycles) is a piecewise constant-jerk trajectory. Interval
//! `k` spans `[kT, (k+1)T]`; the NCO holds frequency `f_k` over it (phase-continuous), exactly the
//! timing documented in `gpsrx_tracking::loop_analysis`. For each interval the simulator forms
//!
//! - the true average phase error `e_k = mean(theta) - (phi_k + phi_{k+1})/2` (Simpson's rule,
//!   exact for a cubic phase inside one segment);
//! - the prompt `P = A d sinc(e_end - e_start) exp(j 2 pi e_k) + n`, `n` complex Gaussian with
//!   unit variance per component and `A = sqrt(2 C/N0 T)` (or `A = 1` and no noise), `d` a random
//!   data bit per 20 ms (bit edges on multiples of 20 ms). The sinc is the integrate-and-dump loss
//!   of a linear phase ramp across the interval.
//!
//! The loop under test is a closure that receives this and returns the NCO frequency for the next
//! interval.

use num_complex::Complex64;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::PI;

/// 1 g, m/s^2.
pub const G: f64 = 9.80665;
/// L1 wavelength, m.
pub const LAMBDA: f64 = gpsrx_dsp::constants::LAMBDA_L1_M;

/// Seeded, portable RNG.
pub fn rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

/// One standard normal draw.
pub fn gauss(r: &mut Xoshiro256PlusPlus) -> f64 {
    r.sample(StandardNormal)
}

/// Converts a LOS acceleration in g to a carrier Doppler rate in Hz/s (range shrinking).
pub fn g_to_hz_s(g: f64) -> f64 {
    g * G / LAMBDA
}

/// A piecewise constant-jerk phase trajectory, cycles.
#[derive(Debug, Clone)]
pub struct Trajectory {
    /// Segment start times and jerks (Hz/s^2), ascending; the first starts at 0.
    segs: Vec<(f64, f64)>,
    /// (phase, freq, accel) at each segment start.
    states: Vec<(f64, f64, f64)>,
}

impl Trajectory {
    /// From initial phase (cycles), frequency (Hz), frequency rate (Hz/s) and jerk segments
    /// `(t_start, jerk Hz/s^2)`.
    pub fn new(p0: f64, f0: f64, a0: f64, segs: &[(f64, f64)]) -> Self {
        let mut segs: Vec<(f64, f64)> = segs.to_vec();
        if segs.first().is_none_or(|s| s.0 > 0.0) {
            segs.insert(0, (0.0, 0.0));
        }
        let mut states = vec![(p0, f0, a0)];
        for w in segs.windows(2) {
            let (t0, j) = w[0];
            let dt = w[1].0 - t0;
            let (p, f, a) = states[states.len() - 1];
            states.push((
                p + f * dt + a * dt * dt / 2.0 + j * dt * dt * dt / 6.0,
                f + a * dt + j * dt * dt / 2.0,
                a + j * dt,
            ));
        }
        Self { segs, states }
    }

    /// Constant frequency.
    pub fn constant_freq(f0: f64) -> Self {
        Self::new(0.0, f0, 0.0, &[])
    }

    /// A jerk-limited manoeuvre: frequency rate rising to `peak_hz_s` over `ramp_s` from
    /// `start_s`, held for `hold_s`, then back to zero over `ramp_s`.
    pub fn manoeuvre(start_s: f64, ramp_s: f64, hold_s: f64, peak_hz_s: f64) -> Self {
        let j = peak_hz_s / ramp_s;
        let t1 = start_s + ramp_s;
        let t2 = t1 + hold_s;
        let t3 = t2 + ramp_s;
        Self::new(
            0.0,
            0.0,
            0.0,
            &[(start_s, j), (t1, 0.0), (t2, -j), (t3, 0.0)],
        )
    }

    fn seg(&self, t: f64) -> usize {
        self.segs.partition_point(|s| s.0 <= t).saturating_sub(1)
    }

    /// (phase cycles, frequency Hz, frequency rate Hz/s) at `t`.
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        let i = self.seg(t);
        let (t0, j) = self.segs[i];
        let (p, f, a) = self.states[i];
        let dt = t - t0;
        (
            p + f * dt + a * dt * dt / 2.0 + j * dt * dt * dt / 6.0,
            f + a * dt + j * dt * dt / 2.0,
            a + j * dt,
        )
    }

    /// Phase at `t`, cycles.
    pub fn phase(&self, t: f64) -> f64 {
        self.at(t).0
    }

    /// Mean phase over `[t0, t1]` (Simpson).
    pub fn mean_phase(&self, t0: f64, t1: f64) -> f64 {
        (self.phase(t0) + 4.0 * self.phase(0.5 * (t0 + t1)) + self.phase(t1)) / 6.0
    }
}

/// Signal model of the prompts.
#[derive(Debug, Clone, Copy)]
pub struct Signal {
    /// C/N0 in dB-Hz; `None` for a noise-free unit-amplitude prompt.
    pub cn0_dbhz: Option<f64>,
    /// Random data bits every 20 ms.
    pub data: bool,
    /// RNG seed.
    pub seed: u64,
}

impl Signal {
    /// Noise-free, no data.
    pub fn clean() -> Self {
        Self {
            cn0_dbhz: None,
            data: false,
            seed: 0,
        }
    }

    /// Noisy with data bits.
    pub fn noisy(cn0_dbhz: f64, seed: u64) -> Self {
        Self {
            cn0_dbhz: Some(cn0_dbhz),
            data: true,
            seed,
        }
    }
}

/// What the loop closure sees for interval `k`.
#[derive(Debug, Clone, Copy)]
pub struct Step {
    /// Interval index.
    pub k: usize,
    /// Interval start time, s.
    pub t0: f64,
    /// Prompt correlator output.
    pub prompt: Complex64,
    /// True average phase error, cycles (not visible to a real receiver).
    pub err_cycles: f64,
    /// NCO frequency held over this interval, Hz.
    pub nco_hz: f64,
    /// True mean frequency over this interval, Hz.
    pub true_hz: f64,
}

/// Runs `n` intervals of `t` seconds. `f_init` is the NCO frequency of interval 0 (its phase
/// starts on the signal's). Returns the steps (the closure's view) in order.
pub fn run(
    traj: &Trajectory,
    sig: Signal,
    t: f64,
    n: usize,
    f_init: f64,
    mut lp: impl FnMut(&Step) -> f64,
) -> Vec<Step> {
    let mut r = rng(sig.seed);
    let amp = sig
        .cn0_dbhz
        .map_or(1.0, |c| (2.0 * 10f64.powf(c / 10.0) * t).sqrt());
    let mut phi = traj.phase(0.0);
    let mut f = f_init;
    let mut bit = 1.0;
    let mut bit_index = -1_i64;
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let t0 = k as f64 * t;
        let t1 = t0 + t;
        let (th0, th1) = (traj.phase(t0), traj.phase(t1));
        let e = traj.mean_phase(t0, t1) - (phi + 0.5 * f * t);
        let de = (th1 - phi - f * t) - (th0 - phi);
        if sig.data {
            let bi = ((t0 + 1e-9) / 0.02).floor() as i64;
            if bi != bit_index {
                bit_index = bi;
                bit = if r.random::<bool>() { 1.0 } else { -1.0 };
            }
        }
        let sinc = if de.abs() < 1e-12 {
            1.0
        } else {
            (PI * de).sin() / (PI * de)
        };
        let mut p = Complex64::from_polar(amp * bit * sinc, 2.0 * PI * e);
        if sig.cn0_dbhz.is_some() {
            p += Complex64::new(gauss(&mut r), gauss(&mut r));
        }
        let step = Step {
            k,
            t0,
            prompt: p,
            err_cycles: e,
            nco_hz: f,
            true_hz: (th1 - th0) / t,
        };
        out.push(step);
        let f_next = lp(&step);
        phi += f * t;
        f = f_next;
    }
    out
}

/// Standard deviation of a slice.
pub fn std(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n).sqrt()
}

/// Mean of a slice.
pub fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// PLL thermal jitter of the oracle (Costas), degrees:
/// `(360/2pi) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))`.
pub fn pll_jitter_deg(bn: f64, cn0_dbhz: f64, t: f64) -> f64 {
    let c = 10f64.powf(cn0_dbhz / 10.0);
    (360.0 / (2.0 * PI)) * ((bn / c) * (1.0 + 1.0 / (2.0 * t * c))).sqrt()
}
