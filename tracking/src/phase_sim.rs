//! A closed-loop simulator in the phase domain, at the level of correlator outputs: the signal
//! is a carrier-phase trajectory, the receiver is whatever loop the caller plugs in, and the
//! simulator plays the NCO and the integrate-and-dump correlator between them.
//!
//! # Model
//!
//! The input carrier phase `theta(t)` (cycles) is a piecewise constant-jerk trajectory
//! ([`Trajectory`]). Interval `k` spans `[kT, (k+1)T]`; the NCO holds frequency `f_k` over it
//! (phase-continuous, `phi_{k+1} = phi_k + f_k T`), exactly the timing documented in
//! [`crate::loop_analysis`]. For each interval the simulator forms
//!
//! - the true average phase error `e_k = mean(theta) - (phi_k + phi_{k+1})/2`, the mean by
//!   Simpson's rule (exact for a cubic phase inside one segment);
//! - the prompt `P = A d sinc(de_k) exp(j 2 pi e_k) + n`, with `de_k` the change of the phase
//!   error across the interval and `sinc(x) = sin(pi x)/(pi x)` the integrate-and-dump loss of a
//!   linear phase ramp; `n` complex Gaussian with unit variance per component and
//!   `A = sqrt(2 (C/N0) T)` (or `A = 1` and no noise); `d` a random data bit per 20 ms (bit edges
//!   on multiples of 20 ms).
//!
//! The loop under test is a closure that receives this ([`Step`]) and returns the NCO frequency
//! for the next interval. [`run`] uses the built-in seeded generator [`SimRng`];
//! [`run_with`] takes any [`NoiseSource`] and an arbitrary initial NCO phase (a phase step).

use num_complex::Complex64;
use std::f64::consts::PI;

/// Standard gravity, m/s^2.
pub const G_MPS2: f64 = 9.80665;
/// L1 carrier wavelength `c / 1575.42 MHz`, m.
pub const LAMBDA_M: f64 = gpsrx_dsp::constants::LAMBDA_L1_M;

/// Carrier Doppler rate (Hz/s) of a line-of-sight acceleration of `g` (in units of 1 g) towards
/// the satellite: `g * 9.80665 / lambda` (1 g = 51.53 Hz/s = 18,552 deg/s^2, `oracles.md`).
pub fn g_to_hz_s(g: f64) -> f64 {
    g * G_MPS2 / LAMBDA_M
}

/// A piecewise constant-jerk carrier-phase trajectory, cycles.
///
/// Inside segment `i`, starting at `t_i` with state `(p_i, f_i, a_i)` and jerk `j_i`:
/// `theta(t) = p_i + f_i dt + a_i dt^2/2 + j_i dt^3/6`, `dt = t - t_i`.
#[derive(Debug, Clone)]
pub struct Trajectory {
    /// Segment start times and jerks (Hz/s^2), ascending; the first starts at 0.
    segs: Vec<(f64, f64)>,
    /// (phase cycles, frequency Hz, frequency rate Hz/s) at each segment start.
    states: Vec<(f64, f64, f64)>,
}

impl Trajectory {
    /// From the initial phase `p0` (cycles), frequency `f0` (Hz), frequency rate `a0` (Hz/s) and
    /// jerk segments `(t_start_s, jerk_hz_s2)`.
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
            states.push(Self::advance((p, f, a), j, dt));
        }
        Self { segs, states }
    }

    /// Constant frequency `f0_hz` (a phase ramp).
    pub fn constant_freq(f0_hz: f64) -> Self {
        Self::new(0.0, f0_hz, 0.0, &[])
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

    /// Taylor step of a constant-jerk state by `dt`.
    fn advance((p, f, a): (f64, f64, f64), j: f64, dt: f64) -> (f64, f64, f64) {
        (
            p + f * dt + a * dt * dt / 2.0 + j * dt * dt * dt / 6.0,
            f + a * dt + j * dt * dt / 2.0,
            a + j * dt,
        )
    }

    fn seg(&self, t: f64) -> usize {
        self.segs.partition_point(|s| s.0 <= t).saturating_sub(1)
    }

    /// (phase cycles, frequency Hz, frequency rate Hz/s) at `t_s`.
    pub fn at(&self, t_s: f64) -> (f64, f64, f64) {
        let i = self.seg(t_s);
        let (t0, j) = self.segs[i];
        Self::advance(self.states[i], j, t_s - t0)
    }

    /// Phase at `t_s`, cycles.
    pub fn phase(&self, t_s: f64) -> f64 {
        self.at(t_s).0
    }

    /// Mean phase over `[t0_s, t1_s]` (Simpson: `(theta(t0) + 4 theta(mid) + theta(t1))/6`, exact
    /// for a cubic inside one segment).
    pub fn mean_phase(&self, t0_s: f64, t1_s: f64) -> f64 {
        (self.phase(t0_s) + 4.0 * self.phase(0.5 * (t0_s + t1_s)) + self.phase(t1_s)) / 6.0
    }

    /// Mean frequency over `[t0_s, t1_s]`, Hz: `(theta(t1) - theta(t0)) / (t1 - t0)` (exact).
    pub fn mean_freq_hz(&self, t0_s: f64, t1_s: f64) -> f64 {
        (self.phase(t1_s) - self.phase(t0_s)) / (t1_s - t0_s)
    }
}

/// Signal model of the prompts.
#[derive(Debug, Clone, Copy, PartialEq)]
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
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// Interval index.
    pub k: usize,
    /// Interval start time, s.
    pub t0: f64,
    /// Prompt correlator output.
    pub prompt: Complex64,
    /// True average phase error `e_k`, cycles (not visible to a real receiver).
    pub err_cycles: f64,
    /// NCO frequency held over this interval, Hz.
    pub nco_hz: f64,
    /// True mean frequency over this interval, Hz.
    pub true_hz: f64,
}

/// Where the random data bits and the correlator noise come from.
pub trait NoiseSource {
    /// A fair random bit (`true` means data bit +1).
    fn data_bit(&mut self) -> bool;
    /// One standard normal draw.
    fn gauss(&mut self) -> f64;
}

/// The built-in seeded generator: xoshiro256++ (Blackman & Vigna) with its state filled by
/// SplitMix64 from the seed, normal draws by the Box-Muller transform
/// `sqrt(-2 ln u1) (cos 2 pi u2, sin 2 pi u2)`. Portable: the same seed gives the same numbers
/// everywhere.
#[derive(Debug, Clone)]
pub struct SimRng {
    s: [u64; 4],
    spare: Option<f64>,
}

impl SimRng {
    /// A generator seeded from `seed` (SplitMix64 fills the 256-bit state).
    pub fn new(seed: u64) -> Self {
        let mut x = seed;
        let mut s = [0u64; 4];
        for w in &mut s {
            x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            *w = z ^ (z >> 31);
        }
        Self { s, spare: None }
    }

    /// The next 64 random bits (xoshiro256++).
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let out = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        out
    }

    /// Uniform in `[0, 1)` with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

impl NoiseSource for SimRng {
    fn data_bit(&mut self) -> bool {
        self.next_u64() >> 63 == 1
    }

    fn gauss(&mut self) -> f64 {
        if let Some(v) = self.spare.take() {
            return v;
        }
        // u1 in (0, 1] so that ln(u1) is finite.
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (2.0 * PI * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

/// The NCO state at the start of interval 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NcoStart {
    /// NCO phase at `t = 0`, cycles (the signal's phase for a loop that starts in phase; any
    /// other value is a phase step of `theta(0) - phase_cycles` into the loop).
    pub phase_cycles: f64,
    /// NCO frequency held over interval 0, Hz.
    pub freq_hz: f64,
}

/// Runs `n` intervals of `t_s` seconds with the built-in generator [`SimRng`] seeded from
/// `sig.seed`. `f_init_hz` is the NCO frequency of interval 0; its phase starts on the signal's.
/// Returns the steps (the closure's view) in order.
pub fn run(
    traj: &Trajectory,
    sig: Signal,
    t_s: f64,
    n: usize,
    f_init_hz: f64,
    lp: impl FnMut(&Step) -> f64,
) -> Vec<Step> {
    let start = NcoStart {
        phase_cycles: traj.phase(0.0),
        freq_hz: f_init_hz,
    };
    run_with(traj, sig, t_s, n, start, &mut SimRng::new(sig.seed), lp)
}

/// Runs `n` intervals of `t_s` seconds from the NCO state `start`, drawing data bits and noise
/// from `noise` (per interval: the bit first, when a new bit starts, then the in-phase and the
/// quadrature noise). `lp` receives each [`Step`] and returns the NCO frequency (Hz) to hold
/// over the next interval. The prompt of interval `k` is
/// `A d sinc(de_k) exp(j 2 pi e_k) + n` (module docs).
pub fn run_with(
    traj: &Trajectory,
    sig: Signal,
    t_s: f64,
    n: usize,
    start: NcoStart,
    noise: &mut impl NoiseSource,
    mut lp: impl FnMut(&Step) -> f64,
) -> Vec<Step> {
    let amp = sig
        .cn0_dbhz
        .map_or(1.0, |c| (2.0 * 10f64.powf(c / 10.0) * t_s).sqrt());
    let mut phi = start.phase_cycles;
    let mut f = start.freq_hz;
    let mut bit = 1.0;
    let mut bit_index = -1_i64;
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let t0 = k as f64 * t_s;
        let t1 = t0 + t_s;
        let (th0, th1) = (traj.phase(t0), traj.phase(t1));
        let e = traj.mean_phase(t0, t1) - (phi + 0.5 * f * t_s);
        let de = (th1 - phi - f * t_s) - (th0 - phi);
        if sig.data {
            let bi = ((t0 + 1e-9) / 0.02).floor() as i64;
            if bi != bit_index {
                bit_index = bi;
                bit = if noise.data_bit() { 1.0 } else { -1.0 };
            }
        }
        let sinc = if de.abs() < 1e-12 {
            1.0
        } else {
            (PI * de).sin() / (PI * de)
        };
        let mut p = Complex64::from_polar(amp * bit * sinc, 2.0 * PI * e);
        if sig.cn0_dbhz.is_some() {
            let re = noise.gauss();
            p += Complex64::new(re, noise.gauss());
        }
        let step = Step {
            k,
            t0,
            prompt: p,
            err_cycles: e,
            nco_hz: f,
            true_hz: (th1 - th0) / t_s,
        };
        out.push(step);
        let f_next = lp(&step);
        phi += f * t_s;
        f = f_next;
    }
    out
}

/// Population standard deviation `sqrt(sum (x - mean)^2 / n)` of a slice (NaN if empty).
pub fn std(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n).sqrt()
}

/// Mean `sum x / n` of a slice (NaN if empty).
pub fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// PLL thermal jitter of a Costas loop (Kaplan eq. 5.6, `oracles.md` "Noise"), degrees:
/// `(360/2pi) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))`, CN0 linear.
pub fn pll_jitter_deg(bn_hz: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let c = 10f64.powf(cn0_dbhz / 10.0);
    (360.0 / (2.0 * PI)) * ((bn_hz / c) * (1.0 + 1.0 / (2.0 * t_s * c))).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngCore, SeedableRng};

    /// The built-in generator is xoshiro256++ seeded by SplitMix64, bit for bit the reference
    /// implementation in `rand_xoshiro` (`seed_from_u64`).
    #[test]
    fn sim_rng_is_xoshiro256plusplus() {
        for seed in [0u64, 1, 42, u64::MAX] {
            let mut a = SimRng::new(seed);
            let mut b = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
            for _ in 0..1000 {
                assert_eq!(a.next_u64(), b.next_u64());
            }
        }
    }

    /// Box-Muller draws: mean 0 and variance 1 within 5 standard errors of the sample estimates
    /// (1/sqrt(n) for the mean, sqrt(2/n) for the variance), and fair bits.
    #[test]
    fn gauss_and_bits_have_the_stated_moments() {
        let n = 200_000;
        let mut r = SimRng::new(7);
        let x: Vec<f64> = (0..n).map(|_| r.gauss()).collect();
        let m = mean(&x);
        let v = std(&x).powi(2);
        let nf = n as f64;
        assert!(m.abs() < 5.0 / nf.sqrt(), "mean {m}");
        assert!((v - 1.0).abs() < 5.0 * (2.0 / nf).sqrt(), "variance {v}");
        let ones = (0..n).filter(|_| r.data_bit()).count() as f64;
        assert!((ones / nf - 0.5).abs() < 5.0 * 0.5 / nf.sqrt());
    }

    /// Constant-jerk trajectory against its Taylor polynomial, across segment boundaries.
    #[test]
    fn trajectory_is_piecewise_cubic() {
        let (j, t1) = (3.0, 2.0);
        let tr = Trajectory::new(0.1, 5.0, 1.0, &[(0.0, j), (t1, 0.0)]);
        let cubic = |t: f64| 0.1 + 5.0 * t + t * t / 2.0 + j * t * t * t / 6.0;
        assert!((tr.phase(1.3) - cubic(1.3)).abs() < 1e-12);
        // After t1 the jerk stops: phase continues with the state at t1.
        let (p1, f1, a1) = (cubic(t1), 5.0 + t1 + j * t1 * t1 / 2.0, 1.0 + j * t1);
        let dt = 0.7;
        let want = p1 + f1 * dt + a1 * dt * dt / 2.0;
        assert!((tr.phase(t1 + dt) - want).abs() < 1e-12);
        // Simpson's mean is exact for the cubic: compare with the antiderivative.
        let anti = |t: f64| 0.1 * t + 2.5 * t * t + t * t * t / 6.0 + j * t.powi(4) / 24.0;
        let (a, b) = (0.2, 0.9);
        assert!((tr.mean_phase(a, b) - (anti(b) - anti(a)) / (b - a)).abs() < 1e-12);
        assert!((tr.mean_freq_hz(a, b) - (cubic(b) - cubic(a)) / (b - a)).abs() < 1e-12);
    }

    /// A loop that holds the true mean frequency of every interval never accumulates error; a
    /// phase step at the start is seen as a constant error `theta(0) - phi(0)` by an NCO that
    /// then follows the signal's frequency exactly.
    #[test]
    fn nco_timing_and_phase_step() {
        let tr = Trajectory::new(0.0, 20.0, 4.0, &[(0.0, 1.5)]);
        let t = 1e-3;
        let start = NcoStart {
            phase_cycles: -0.03,
            freq_hz: tr.mean_freq_hz(0.0, t),
        };
        let steps = run_with(
            &tr,
            Signal::clean(),
            t,
            500,
            start,
            &mut SimRng::new(1),
            |s| tr.mean_freq_hz(s.t0 + t, s.t0 + 2.0 * t),
        );
        for s in &steps {
            // e_k = mean(theta) - (phi_k + phi_{k+1})/2 with phi following theta at the interval
            // ends: for a cubic the mean minus the end-point average is exactly
            // -theta''(mid) T^2/12 (odd terms cancel), so e_k = 0.03 - theta''(mid) T^2/12.
            let a_mid = tr.at(s.t0 + 0.5 * t).2;
            let want = 0.03 - a_mid * t * t / 12.0;
            assert!(
                (s.err_cycles - want).abs() < 1e-12,
                "{}: {}",
                s.k,
                s.err_cycles
            );
            assert!((s.prompt.arg() / (2.0 * PI) - want).abs() < 1e-12);
        }
    }

    #[test]
    fn jitter_formula_matches_the_oracle_examples() {
        // oracles.md "Noise": T = 1 ms, Bn 10 Hz at 35 dB-Hz 3.47 deg; Bn 2 Hz at 45 dB-Hz 0.46.
        assert!((pll_jitter_deg(10.0, 35.0, 1e-3) - 3.47).abs() < 0.01);
        assert!((pll_jitter_deg(2.0, 45.0, 1e-3) - 0.46).abs() < 0.01);
        assert!((g_to_hz_s(1.0) * 360.0 - 18_552.0).abs() < 1.0);
    }
}
