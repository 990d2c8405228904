//! `gpsrx study bandwidth`: carrier phase jitter, Doppler (pseudorange-rate) error and code error
//! of the implemented channels on simulated IF, over a grid of C/N0, PLL order, noise bandwidth
//! Bn and integration time T, against the thermal-noise formulas (oracles.md "Noise").
//!
//! # What is simulated
//!
//! A static receiver (Seoul) with a noiseless clock (Allan deviation 0) sees three satellites
//! (G16, G25, G26, see [`PRNS`]) at the same C/N0, in in-memory recordings
//! ([`super::if_sim::SimSource`], complex floats at 2.5 MHz, no quantisation) whose length each
//! cell's settling time sets. Every satellite is tracked by one channel per (order, Bn, T) cell
//! over the same samples, started from truth (code phase, Doppler) and, unless `--unaided`, with
//! the true Doppler fed forward (a perfect INS, seed 004 eq. 7), which removes the satellites'
//! own LOS dynamics so that only the thermal noise is left. Each channel pulls in with a PLL of
//! its Bn at T = 1 ms (order 2 for the 3rd-order cells, no FLL assist; [`cell_channel_config`]);
//! its own loop and T start at the hand-over to tracking (after bit synchronisation, on a bit
//! edge). Errors are measured against
//! the simulator's truth at every integration interval after the cell's settling time from the
//! hand-over ([`transient_decay_time_s`]: start-up transients down to [`SETTLE_FRACTION`]): the
//! replica (NCO) carrier phase at the interval's first sample against the true carrier phase
//! (offset and Costas half cycle removed), the NCO frequency held over the interval against the
//! true mean Doppler, the receiver's observable Doppler (carrier-phase change over 0.1 s, the
//! 10 Hz observable rate of `gpsrx run`; and over 1 s) against the true one, and the code phase
//! against the true one. Loss of lock (a released channel, a half-cycle slip against truth, a
//! code error beyond half a chip) is detected per channel and reported, never averaged in.
//!
//! # The formulas
//!
//! - PLL, Costas (oracles.md): `sigma_phi = (360/(2 pi)) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))` deg
//!   ([`pll_jitter_deg`]).
//! - DLL, non-coherent early-minus-late power, spacing d (oracles.md):
//!   `sigma = sqrt((Bn d/(2 CN0))(1 + 2/(T CN0 (2 - d))))` chips ([`dll_jitter_chips`]). The
//!   channel's DLL is the normalised early-minus-late *envelope* `(2-d)/2 (|E|-|L|)/(|E|+|L|)`
//!   with d = 1: the same coherent term `Bn d/(2 CN0)`, a smaller squaring loss; its own value
//!   ([`envelope_dll_stats`] in the linearised loop) is reported beside the formula.
//! - FLL (oracles.md): `sigma_f = (1/(2 pi T)) sqrt((4 F Bn/CN0)(1 + 1/(T CN0)))` Hz
//!   ([`fll_jitter_hz`]); for reference (the study's loops are PLLs).
//! - Doppler of a PLL: there is no standard closed form, so it is computed from the implemented
//!   digital loop ([`LoopNoiseGains`]): with white discriminator noise of variance
//!   `s^2 = (1/(2 T CN0))(1 + 1/(2 T CN0))/(2 pi)^2` cycles^2 per update (the variance that makes
//!   `2 Bn T s^2` the Costas formula), the NCO phase `phi_k` and frequency `u_k` are linear in
//!   the noise; their impulse responses `h_phi`, `h_u` give `var(phi) = s^2 sum h_phi^2`,
//!   `var(u) = s^2 sum h_u^2` and, for the Doppler from the phase change over `tau = m T`,
//!   `var = s^2 sum_j ((h_phi[j+m] - h_phi[j])/tau)^2`. The same sums give the digital loop's
//!   realised noise bandwidth `Bn' = sum (h_phi + h_u T/2)^2 / (2 T)` (on the interval-average
//!   phase, as in `gpsrx_tracking::loop_analysis`).
//! - "loop" columns: the same linearised digital loop with the discriminator's own statistics at
//!   the prompt SNR `rho = CN0 T` instead of the formula's: for `atan(Q/I)` the slope
//!   `1 - exp(-rho)` and the output variance from the phase distribution of a carrier in
//!   Gaussian noise ([`costas_atan_stats`]). This is what the measurement should match where the
//!   formula's assumptions (analog loop, small `Bn T`, high SNR) fail.

use super::if_sim::{
    self, differenced_rate, folded_phase_deg, half_cycle_slips, satellites_with_cn0, scenario_toml,
    static_receiver, ChannelSpec, ChannelTrace, SimSource, Truth, SEOUL_LLH,
};
use super::report::{fmt, LinePlot, Series, StudyReport, Table};
use super::{run_cases, CommonStudyArgs};
use gpsrx_dsp::constants::LAMBDA_L1_M;
use gpsrx_tracking::config::MAX_BN_T;
use gpsrx_tracking::{loop_analysis, ChannelConfig, ChannelState, LoopConfig, LoopFilter};
use serde_json::json;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::time::Instant;

/// Sampling rate of the study recordings, Hz (complex; 2500 samples per code period, not a
/// multiple of the chip rate).
pub const FS_HZ: f64 = 2.5e6;
/// The satellites of every recording (all at the recording's C/N0): Dopplers +3672, -3183 and
/// +1975 Hz at the start, so that the code drifts across the sample grid at 1.3-2.4 chip/s (a
/// satellite near zero Doppler, e.g. G31 at +201 Hz, drifts at 0.13 chip/s and its code error
/// then carries the slowly varying sample-grid bias of the unfiltered correlation triangle,
/// 0.0043 instead of 0.0024 chip at 50 dB-Hz: see the study's conclusions).
pub const PRNS: [u8; 3] = [16, 25, 26];
/// DLL: order 1 (carrier-aided), this noise bandwidth, Hz.
pub const DLL_BN_HZ: f64 = 1.0;
/// Early-late spacing, chips.
pub const EL_SPACING_CHIPS: f64 = 1.0;
/// Observable interval of the receiver's Doppler (`gpsrx run` at 10 Hz), s.
pub const OBS_INTERVAL_S: f64 = 0.1;
/// The longer Doppler averaging interval also reported, s.
pub const LONG_INTERVAL_S: f64 = 1.0;
/// The thermal-noise tolerance the study checks, relative.
pub const TOLERANCE: f64 = 0.2;
/// `Bn T` up to which the formula is expected to hold within [`TOLERANCE`].
pub const BNT_LIMIT: f64 = 0.1;
/// Tracking threshold rule of thumb (oracles.md): `3 sigma <= 45` deg, so `sigma <= 15` deg.
pub const THRESHOLD_SIGMA_DEG: f64 = 15.0;

/// `gpsrx study` options of this study.
#[derive(Debug, Clone, clap::Args)]
pub struct BandwidthArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
    /// Measurement window after each cell's settling time, s [default: 24, or 12 with --quick];
    /// each recording lasts 2 s + the slowest settling time of its cells + this window.
    #[arg(long, value_name = "S")]
    pub window_s: Option<f64>,
    /// Track without the perfect (truth) Doppler feed-forward: the satellites' own LOS
    /// acceleration then loads narrow loops (a linear trend of the phase error is removed).
    #[arg(long)]
    pub unaided: bool,
}

/// One grid cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
    /// PLL order (2 or 3).
    pub order: u8,
    /// PLL noise bandwidth, Hz.
    pub bn_hz: f64,
    /// Integration time, ms.
    pub t_ms: u32,
}

impl Cell {
    /// Integration time, s.
    pub fn t_s(&self) -> f64 {
        f64::from(self.t_ms) * 1e-3
    }

    /// `Bn T`.
    pub fn bn_t(&self) -> f64 {
        self.bn_hz * self.t_s()
    }
}

/// The full grid: C/N0 {25, ..., 50} x order {2, 3} x Bn {0.5, 1, 2, 4, 10, 15, 25} Hz x
/// T {1, 20} ms.
pub fn full_grid() -> Vec<Cell> {
    let mut v = Vec::new();
    for cn0 in [25.0, 30.0, 35.0, 40.0, 45.0, 50.0] {
        for t_ms in [1, 20] {
            for order in [2, 3] {
                for bn in [0.5, 1.0, 2.0, 4.0, 10.0, 15.0, 25.0] {
                    v.push(Cell {
                        cn0_dbhz: cn0,
                        order,
                        bn_hz: bn,
                        t_ms,
                    });
                }
            }
        }
    }
    v
}

/// The `--quick` grid: C/N0 {35, 45} x order 2 x Bn {1, 4, 10} Hz x T 1 ms, and
/// 35 dB-Hz, order 2, Bn 2 Hz, T 20 ms.
pub fn quick_grid() -> Vec<Cell> {
    let mut v = Vec::new();
    for cn0 in [35.0, 45.0] {
        for bn in [1.0, 4.0, 10.0] {
            v.push(Cell {
                cn0_dbhz: cn0,
                order: 2,
                bn_hz: bn,
                t_ms: 1,
            });
        }
    }
    v.push(Cell {
        cn0_dbhz: 35.0,
        order: 2,
        bn_hz: 2.0,
        t_ms: 20,
    });
    v
}

fn lin(cn0_dbhz: f64) -> f64 {
    10f64.powf(cn0_dbhz / 10.0)
}

/// PLL thermal jitter of a Costas loop, degrees (oracles.md; Kaplan eq. 5.6):
/// `sigma = (360/(2 pi)) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))`, Bn in Hz, CN0 = 10^(C/N0 / 10) Hz,
/// T in s.
pub fn pll_jitter_deg(bn_hz: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let cn0 = lin(cn0_dbhz);
    (360.0 / (2.0 * PI)) * (bn_hz / cn0 * (1.0 + 1.0 / (2.0 * t_s * cn0))).sqrt()
}

/// DLL thermal jitter of a non-coherent early-minus-late power discriminator with E-L spacing
/// `d_chips`, chips (oracles.md): `sigma = sqrt((Bn d/(2 CN0))(1 + 2/(T CN0 (2 - d))))`.
pub fn dll_jitter_chips(bn_hz: f64, d_chips: f64, cn0_dbhz: f64, t_s: f64) -> f64 {
    let cn0 = lin(cn0_dbhz);
    (bn_hz * d_chips / (2.0 * cn0) * (1.0 + 2.0 / (t_s * cn0 * (2.0 - d_chips)))).sqrt()
}

/// FLL thermal jitter, Hz (oracles.md): `sigma = (1/(2 pi T)) sqrt((4 F Bn/CN0)(1 + 1/(T CN0)))`,
/// `F` = 1 at high C/N0 and 2 near threshold.
pub fn fll_jitter_hz(bn_hz: f64, cn0_dbhz: f64, t_s: f64, f: f64) -> f64 {
    let cn0 = lin(cn0_dbhz);
    (4.0 * f * bn_hz / cn0 * (1.0 + 1.0 / (t_s * cn0))).sqrt() / (2.0 * PI * t_s)
}

/// Variance (cycles^2) per update of the Costas discriminator noise that the PLL formula
/// implies: `s^2 = (1/(2 T CN0))(1 + 1/(2 T CN0)) / (2 pi)^2`, so that an analog loop of noise
/// bandwidth Bn gives `2 Bn T s^2 = sigma^2` ([`pll_jitter_deg`] in cycles).
pub fn costas_formula_noise_var_cycles2(cn0_dbhz: f64, t_s: f64) -> f64 {
    let x = 2.0 * t_s * lin(cn0_dbhz);
    (1.0 / x) * (1.0 + 1.0 / x) / (4.0 * PI * PI)
}

/// A discriminator linearised at zero error: mean output slope (output units per unit error)
/// and output noise variance (output units^2) per update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscriminatorStats {
    /// `d E[D] / d e` at `e = 0`.
    pub slope: f64,
    /// `var(D)` at `e = 0`.
    pub noise_var: f64,
}

/// Complementary error function, fractional error < 1.2e-7 (Numerical Recipes `erfcc`,
/// Chebyshev fit).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Probability density of the phase `psi` (rad) of a unit-phasor carrier in complex Gaussian
/// noise at SNR `rho = A^2/(2 sigma^2)`:
/// `p(psi) = (1/(2 pi)) [exp(-rho) + sqrt(pi rho) cos(psi) exp(-rho sin^2 psi)
/// erfc(-sqrt(rho) cos psi)]`.
pub fn carrier_phase_pdf(psi: f64, rho: f64) -> f64 {
    let c = psi.cos();
    let s = psi.sin();
    ((-rho).exp() + (PI * rho).sqrt() * c * (-rho * s * s).exp() * erfc(-rho.sqrt() * c))
        / (2.0 * PI)
}

/// Composite Simpson's rule of `f` over `[a, b]` with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let n = n + n % 2;
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
    }
    s * h / 3.0
}

/// Statistics of the Costas `atan(Q/I)` discriminator in cycles at the prompt SNR
/// `rho = CN0 T`: its output is the prompt's phase folded into `(-pi/2, pi/2]`, so with the
/// density [`carrier_phase_pdf`] the mean output at a phase error `phi` is
/// `m(phi) = integral fold(psi + phi) p(psi) dpsi`; the fold's jumps of `-pi` at `+-pi/2` give the
/// slope `m'(0) = 1 - pi (p(pi/2) + p(-pi/2)) = 1 - exp(-rho)`, and the variance is
/// `integral fold(psi)^2 p(psi) dpsi` (numerically; `-> 1/(2 rho)` rad^2 at high SNR, the
/// formula's coherent term, and `pi^2/12` at rho = 0).
pub fn costas_atan_stats(cn0_dbhz: f64, t_s: f64) -> DiscriminatorStats {
    let rho = lin(cn0_dbhz) * t_s;
    let n = 1 << 16;
    let half = PI / 2.0;
    let mid = simpson(|x| x * x * carrier_phase_pdf(x, rho), -half, half, n);
    // |psi| > pi/2 folds to psi -+ pi.
    let hi = simpson(
        |x| (x - PI).powi(2) * carrier_phase_pdf(x, rho),
        half,
        PI,
        n / 4,
    );
    let lo = simpson(
        |x| (x + PI).powi(2) * carrier_phase_pdf(x, rho),
        -PI,
        -half,
        n / 4,
    );
    DiscriminatorStats {
        slope: 1.0 - (-rho).exp(),
        noise_var: (mid + hi + lo) / (4.0 * PI * PI),
    }
}

/// Gauss-Hermite nodes and weights for `integral exp(-x^2) f(x) dx` (Newton on the orthonormal
/// Hermite recurrence; Numerical Recipes `gauher`).
pub fn gauss_hermite(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let pim4 = PI.powf(-0.25);
    let nf = n as f64;
    let mut z = 0.0;
    for i in 0..n.div_ceil(2) {
        z = match i {
            0 => (2.0 * nf + 1.0).sqrt() - 1.855_75 * (2.0 * nf + 1.0).powf(-1.0 / 6.0),
            1 => z - 1.14 * nf.powf(0.426) / z,
            2 => 1.86 * z - 0.86 * x[0],
            3 => 1.91 * z - 0.91 * x[1],
            _ => 2.0 * z - x[i - 2],
        };
        let mut pp = 1.0;
        for _ in 0..100 {
            let (mut p1, mut p2) = (pim4, 0.0);
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                let jf = j as f64;
                p1 = z * (2.0 / (jf + 1.0)).sqrt() * p2 - (jf / (jf + 1.0)).sqrt() * p3;
            }
            pp = (2.0 * nf).sqrt() * p2;
            let z1 = z;
            z = z1 - p1 / pp;
            if (z - z1).abs() <= 3e-14 {
                break;
            }
        }
        x[i] = z;
        x[n - 1 - i] = -z;
        w[i] = 2.0 / (pp * pp);
        w[n - 1 - i] = w[i];
    }
    (x, w)
}

/// Statistics of the channel's normalised early-minus-late envelope discriminator
/// `D = ((2 - d)/2) (|E| - |L|)/(|E| + |L|)` (chips) at the prompt SNR `rho = CN0 T`, spacing d:
/// `E = A(1 - d/2 + e) + n_E`, `L = A(1 - d/2 - e) + n_L` with `A^2/(2 sigma^2) = rho`, complex
/// Gaussian noise whose E and L parts correlate by `R(d) = 1 - d` (ideal triangle). Expectations
/// by 4-D Gauss-Hermite quadrature (24 nodes per dimension); slope by a central difference in
/// `e`. At high SNR `var(D) -> d/(4 rho)`, slope 1, so that a loop of noise bandwidth Bn gives
/// the coherent `Bn d/(2 CN0)`.
pub fn envelope_dll_stats(cn0_dbhz: f64, t_s: f64, d: f64) -> DiscriminatorStats {
    let rho = lin(cn0_dbhz) * t_s;
    let amp = (2.0 * rho).sqrt();
    let r = 1.0 - d;
    let (a, b) = (((1.0 + r) / 2.0).sqrt(), ((1.0 - r) / 2.0).max(0.0).sqrt());
    let (x, w) = gauss_hermite(24);
    let nodes: Vec<(f64, f64)> = x
        .iter()
        .zip(&w)
        .map(|(x, w)| (std::f64::consts::SQRT_2 * x, w / PI.sqrt()))
        .collect();
    let moments = |e: f64| {
        let (me, ml) = (amp * (1.0 - d / 2.0 + e), amp * (1.0 - d / 2.0 - e));
        let (mut m1, mut m2) = (0.0, 0.0);
        for &(sr, wsr) in &nodes {
            for &(si, wsi) in &nodes {
                for &(tr, wtr) in &nodes {
                    for &(ti, wti) in &nodes {
                        let wt = wsr * wsi * wtr * wti;
                        let ee = (me + a * sr + b * tr).hypot(a * si + b * ti);
                        let ll = (ml + a * sr - b * tr).hypot(a * si - b * ti);
                        let dd = 0.5 * (2.0 - d) * (ee - ll) / (ee + ll);
                        m1 += wt * dd;
                        m2 += wt * dd * dd;
                    }
                }
            }
        }
        (m1, m2)
    };
    let h = 1e-3;
    let (_, v0) = moments(0.0);
    let (mp, _) = moments(h);
    let (mm, _) = moments(-h);
    DiscriminatorStats {
        slope: (mp - mm) / (2.0 * h),
        noise_var: v0,
    }
}

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
    pub fn new(mut filter: LoopFilter, bn_hz: f64, t_s: f64, slope: f64) -> Self {
        let n = ((150.0 / (bn_hz * t_s * slope.max(0.05))).ceil() as usize).clamp(1000, 8_000_000);
        let mut phase = Vec::with_capacity(n);
        let mut freq = Vec::with_capacity(n);
        let (mut phi, mut u) = (0.0, 0.0);
        for k in 0..n {
            phase.push(phi);
            freq.push(u);
            let noise = if k == 0 { 1.0 } else { 0.0 };
            let e = noise - slope * (phi + 0.5 * u * t_s);
            phi += u * t_s;
            u = filter.update(e, 0.0, t_s);
        }
        Self { t_s, phase, freq }
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

/// Theoretical values for one cell (NaN where the loop is not run).
#[derive(Debug, Clone, Copy, Default)]
pub struct CellTheory {
    /// Oracle PLL formula, deg.
    pub phase_formula_deg: f64,
    /// Linearised digital loop with the atan discriminator's statistics, deg.
    pub phase_loop_deg: f64,
    /// Realised noise bandwidth of the digital loop / design Bn.
    pub bn_realised_ratio: f64,
    /// The digital loop's NCO-phase jitter (at the interval start, formula's discriminator
    /// noise) over the formula: `sqrt(sum h_phi^2 / (2 Bn T))`.
    pub phase_digital_ratio: f64,
    /// NCO frequency error std (digital loop, formula's discriminator noise), Hz.
    pub doppler_hz: f64,
    /// Pseudorange-rate error std from the carrier phase change over 0.1 s, m/s.
    pub pr_rate_mps: f64,
    /// The same over 1 s, m/s.
    pub pr_rate_1s_mps: f64,
    /// Oracle DLL formula (E-L power), chips.
    pub code_formula_chips: f64,
    /// Linearised DLL with the normalised envelope discriminator's statistics, chips.
    pub code_envelope_chips: f64,
    /// Slope of the atan discriminator at the prompt SNR, `1 - exp(-CN0 T)`.
    pub atan_slope: f64,
    /// Whether the linearised loop with that slope is stable (a 3rd-order loop needs a
    /// discriminator gain above about `1/(a3 b3)` = 0.38).
    pub linear_stable: bool,
    /// Settling time after the hand-over, s (NaN if the linearised loop is unstable):
    /// [`SETTLE_MARGIN_S`] plus the time after which the linearised loop's impulse response stays
    /// below [`SETTLE_FRACTION`] of its peak.
    pub settle_s: f64,
}

/// Start-up transients (random initial carrier phase, the hand-over) must decay to this fraction
/// of their size before errors are measured (about 8 time constants of the slowest mode).
pub const SETTLE_FRACTION: f64 = 3e-4;
/// Margin added to the settling time, s.
pub const SETTLE_MARGIN_S: f64 = 1.0;
/// Longest settling time the study waits for, s.
pub const MAX_SETTLE_S: f64 = 100.0;

/// Theory of a cell: the formulas and the linearised digital loops (module docs).
pub fn cell_theory(cell: &Cell) -> CellTheory {
    let t = cell.t_s();
    let nan = CellTheory {
        phase_formula_deg: pll_jitter_deg(cell.bn_hz, cell.cn0_dbhz, t),
        code_formula_chips: dll_jitter_chips(DLL_BN_HZ, EL_SPACING_CHIPS, cell.cn0_dbhz, t),
        phase_loop_deg: f64::NAN,
        bn_realised_ratio: f64::NAN,
        phase_digital_ratio: f64::NAN,
        doppler_hz: f64::NAN,
        pr_rate_mps: f64::NAN,
        pr_rate_1s_mps: f64::NAN,
        code_envelope_chips: f64::NAN,
        atan_slope: f64::NAN,
        linear_stable: false,
        settle_s: f64::NAN,
    };
    let Ok(filter) = LoopFilter::pll(cell.order, cell.bn_hz) else {
        return nan;
    };
    if !loop_analysis::is_stable(&filter, t) {
        return nan;
    }
    let unit = LoopNoiseGains::new(filter.clone(), cell.bn_hz, t, 1.0);
    let atan = costas_atan_stats(cell.cn0_dbhz, t);
    let code = envelope_dll_stats(cell.cn0_dbhz, t, EL_SPACING_CHIPS);
    let code_loop = LoopFilter::dll(1, DLL_BN_HZ)
        .map(|f| LoopNoiseGains::new(f, DLL_BN_HZ, t, code.slope).phase_gain())
        .unwrap_or(f64::NAN);
    let base = CellTheory {
        bn_realised_ratio: unit.noise_bandwidth_hz() / cell.bn_hz,
        phase_digital_ratio: (unit.phase_gain() / (2.0 * cell.bn_t())).sqrt(),
        code_envelope_chips: (code.noise_var * code_loop).sqrt(),
        atan_slope: atan.slope,
        ..nan
    };
    if !stable_with_slope(&filter, t, atan.slope) {
        return base;
    }
    let real = LoopNoiseGains::new(filter.clone(), cell.bn_hz, t, atan.slope);
    let m_obs = ((OBS_INTERVAL_S / t).round() as usize).max(1);
    let m_long = ((LONG_INTERVAL_S / t).round() as usize).max(1);
    let v = atan.noise_var;
    CellTheory {
        phase_loop_deg: (v * real.phase_gain()).sqrt() * 360.0,
        doppler_hz: (v * real.freq_gain()).sqrt(),
        pr_rate_mps: (v * real.rate_gain(m_obs)).sqrt() * LAMBDA_L1_M,
        pr_rate_1s_mps: (v * real.rate_gain(m_long)).sqrt() * LAMBDA_L1_M,
        linear_stable: true,
        settle_s: SETTLE_MARGIN_S
            + transient_decay_time_s(&filter, cell.bn_hz, t, atan.slope, SETTLE_FRACTION),
        ..base
    }
}

/// Whether the digital loop of `filter` (update interval `t_s`) is stable when its
/// discriminator has slope `slope`: the open loop `L = F_p N` of
/// `gpsrx_tracking::loop_analysis` scaled by the slope, closed, and tested by Schur-Cohn.
pub fn stable_with_slope(filter: &LoopFilter, t_s: f64, slope: f64) -> bool {
    let mut l = loop_analysis::open_loop(filter, t_s);
    l.num.iter_mut().for_each(|c| *c *= slope);
    slope > 0.0 && loop_analysis::polynomial_is_stable(&l.feedback().den)
}

/// The channel configuration of a cell: PLL of `order` and `bn_hz` without FLL, 1st-order
/// carrier-aided DLL at [`DLL_BN_HZ`], d = [`EL_SPACING_CHIPS`], integration `t_s`. The pull-in
/// loop is a PLL of the same Bn at T = 1 ms, of order `min(order, 2)`: the channel starts from
/// truth, so no wide or FLL-assisted pull-in is needed, but a 3rd-order loop pulling in from
/// the random initial carrier phase overshoots (damping ratio 0.22) past the Costas +-90 deg
/// and can be thrown into a slipping limit cycle (G16 at 35 dB-Hz, Bn 0.5 Hz: its phase swung by
/// tens of cycles over 140 s), and at low prompt SNR it is not even linearly stable (atan slope
/// below 0.38). A channel is released only below 20 dB-Hz (the default 25 dB-Hz would release
/// the 25 dB-Hz channels on estimator scatter).
pub fn cell_channel_config(order: u8, bn_hz: f64, t_s: f64) -> ChannelConfig {
    let track = LoopConfig {
        pll_order: order,
        pll_bw_hz: bn_hz,
        fll_order: 0,
        fll_bw_hz: 0.0,
        dll_order: 1,
        dll_bw_hz: DLL_BN_HZ,
        t_coh_s: t_s,
        el_spacing_chips: EL_SPACING_CHIPS,
        ..LoopConfig::default()
    };
    ChannelConfig {
        pull_in: LoopConfig {
            pll_order: order.min(2),
            t_coh_s: 1e-3,
            ..track
        },
        track,
        min_pull_in_s: 0.5,
        fll_assist_s: 0.0,
        cn0_lost_dbhz: 20.0,
        ..ChannelConfig::default()
    }
}

/// Whether a cell can run, and if not why.
#[derive(Debug, Clone, PartialEq)]
pub enum CellStatus {
    /// Valid configuration.
    Run,
    /// `LoopConfig::validate` rejects it; `stable` says whether the digital loop would be.
    Rejected {
        /// The validation message.
        reason: String,
        /// Whether the digital closed loop would be stable.
        stable: bool,
    },
}

/// Checks a cell's configuration.
pub fn cell_status(cell: &Cell) -> CellStatus {
    let cfg = cell_channel_config(cell.order, cell.bn_hz, cell.t_s());
    match cfg.validate() {
        Ok(()) => CellStatus::Run,
        Err(e) => CellStatus::Rejected {
            reason: e.to_string(),
            stable: LoopFilter::pll(cell.order, cell.bn_hz)
                .map(|f| loop_analysis::is_stable(&f, cell.t_s()))
                .unwrap_or(false),
        },
    }
}

/// Measured statistics of one cell (all satellites pooled; only channels that held lock).
#[derive(Debug, Clone, Default)]
pub struct CellMeasured {
    /// Channels run.
    pub channels: usize,
    /// Channels that reached tracking and held lock (no Lost state, no half-cycle slip, code
    /// error within half a chip) over the measurement.
    pub locked: usize,
    /// Half-cycle slips over all channels.
    pub slips: usize,
    /// Channels released (Lost) or never handed over to tracking.
    pub lost: usize,
    /// Phase jitter, deg.
    pub phase_deg: f64,
    /// NCO frequency error std, Hz.
    pub doppler_hz: f64,
    /// Pseudorange-rate error std over 0.1 s, m/s.
    pub pr_rate_mps: f64,
    /// Over 1 s, m/s.
    pub pr_rate_1s_mps: f64,
    /// Code error std, chips.
    pub code_chips: f64,
    /// Mean NCO Doppler error (bias), Hz.
    pub doppler_bias_hz: f64,
    /// Measured integration intervals per channel (mean).
    pub epochs: usize,
}

/// Pooled standard deviation of groups, each about its own mean:
/// `sqrt(sum_g sum_i (x_gi - mean_g)^2 / (N - G))`.
fn pooled_std(groups: &[Vec<f64>]) -> f64 {
    let (mut ss, mut n, mut g) = (0.0, 0usize, 0usize);
    for v in groups.iter().filter(|v| v.len() >= 2) {
        let m = if_sim::mean(v);
        ss += v.iter().map(|x| (x - m).powi(2)).sum::<f64>();
        n += v.len();
        g += 1;
    }
    if n > g {
        (ss / (n - g) as f64).sqrt()
    } else {
        f64::NAN
    }
}

/// Reduces the traces of one cell's channels to its statistics, measuring from `settle_s` after
/// each channel's hand-over to tracking.
pub fn measure_cell(
    cell: &Cell,
    traces: &[&ChannelTrace],
    settle_s: f64,
    detrend: bool,
) -> CellMeasured {
    let t = cell.t_s();
    let mut m = CellMeasured {
        channels: traces.len(),
        ..CellMeasured::default()
    };
    let (mut phase, mut dopp, mut rate, mut rate1, mut code) =
        (vec![], vec![], vec![], vec![], vec![]);
    let mut epochs = 0;
    for tr in traces {
        let Some(t_track) = tr
            .epochs
            .iter()
            .find(|e| e.state == ChannelState::Track)
            .map(|e| e.t_s)
        else {
            m.lost += 1;
            continue;
        };
        let lost = tr.final_state == ChannelState::Lost
            || tr.epochs.iter().any(|e| e.state == ChannelState::Lost);
        let t0 = t_track + settle_s;
        let sel: Vec<_> = tr
            .epochs
            .iter()
            .filter(|e| {
                e.t_s >= t0 && e.state == ChannelState::Track && (e.t_coh_s - t).abs() < 1e-9
            })
            .collect();
        let d: Vec<f64> = sel.iter().map(|e| e.phase_diff_cycles).collect();
        let block = ((0.1 / t).round() as usize).max(1);
        let slips = half_cycle_slips(&d, block);
        let code_lost = sel.iter().any(|e| e.code_error_chips.abs() > 0.5);
        m.slips += slips;
        if lost {
            m.lost += 1;
        }
        if lost || slips > 0 || code_lost || sel.len() < 20 {
            continue;
        }
        m.locked += 1;
        epochs += sel.len();
        phase.push(folded_phase_deg(&d, detrend));
        dopp.push(sel.iter().map(|e| e.doppler_error_hz).collect::<Vec<_>>());
        let m_obs = ((OBS_INTERVAL_S / t).round() as usize).max(1);
        let m_long = ((LONG_INTERVAL_S / t).round() as usize).max(1);
        let to_mps = |v: Vec<f64>| v.into_iter().map(|x| x * LAMBDA_L1_M).collect::<Vec<_>>();
        rate.push(to_mps(differenced_rate(&d, m_obs, t)));
        rate1.push(to_mps(differenced_rate(&d, m_long, t)));
        code.push(sel.iter().map(|e| e.code_error_chips).collect::<Vec<_>>());
    }
    m.epochs = epochs.checked_div(m.locked).unwrap_or(0);
    m.phase_deg = pooled_std(&phase);
    m.doppler_hz = pooled_std(&dopp);
    m.pr_rate_mps = pooled_std(&rate);
    m.pr_rate_1s_mps = pooled_std(&rate1);
    m.code_chips = pooled_std(&code);
    let all: Vec<f64> = dopp.concat();
    m.doppler_bias_hz = if_sim::mean(&all);
    m
}

/// One row of the study.
#[derive(Debug, Clone)]
pub struct CellResult {
    /// The cell.
    pub cell: Cell,
    /// Whether it ran.
    pub status: CellStatus,
    /// Theory.
    pub theory: CellTheory,
    /// Measurement (default when not run).
    pub measured: CellMeasured,
    /// Length of the recording it ran on, s (NaN when not run).
    pub duration_s: f64,
}

impl CellResult {
    /// All channels held lock.
    pub fn locked(&self) -> bool {
        self.status == CellStatus::Run
            && self.measured.channels > 0
            && self.measured.locked == self.measured.channels
    }

    /// Measured / formula phase jitter.
    pub fn ratio(&self) -> f64 {
        self.measured.phase_deg / self.theory.phase_formula_deg
    }

    /// Above the tracking threshold by the rule of thumb (`3 sigma_formula <= 45` deg).
    pub fn above_threshold(&self) -> bool {
        self.theory.phase_formula_deg <= THRESHOLD_SIGMA_DEG
    }

    /// In the region where the formula should hold: above threshold and `Bn T <= 0.1`.
    pub fn in_formula_region(&self) -> bool {
        self.status == CellStatus::Run
            && self.above_threshold()
            && self.cell.bn_t() <= BNT_LIMIT + 1e-12
    }

    /// Within [`TOLERANCE`] of the formula (None when not locked).
    pub fn within_tolerance(&self) -> Option<bool> {
        self.locked()
            .then(|| (self.ratio() - 1.0).abs() <= TOLERANCE)
    }
}

/// A group of cells tracked over one recording.
#[derive(Debug, Clone)]
struct Case {
    cn0_dbhz: f64,
    duration_s: f64,
    /// The cells and their settling times.
    cells: Vec<(Cell, f64)>,
    seed: u64,
}

fn run_case(case: &Case, aided: bool) -> anyhow::Result<Vec<CellMeasured>> {
    let sats: Vec<(u8, f64)> = PRNS.iter().map(|&p| (p, case.cn0_dbhz)).collect();
    let text = scenario_toml(
        case.duration_s,
        case.seed,
        FS_HZ,
        &static_receiver(SEOUL_LLH),
        &satellites_with_cn0(&sats),
        "",
    );
    let sim = if_sim::simulator(&text)?;
    let truth = Truth::new(&sim);
    let mut specs = Vec::new();
    for (cell, _) in &case.cells {
        for &prn in &PRNS {
            specs.push(ChannelSpec {
                prn,
                config: cell_channel_config(cell.order, cell.bn_hz, cell.t_s()),
                doppler_offset_hz: 0.0,
            });
        }
    }
    let aid_fn = |prn: u8, t: f64| truth.aid(prn, t);
    let aid: Option<crate::pipeline::tracker::AidSource<'_>> =
        if aided { Some(&aid_fn) } else { None };
    let mut src = SimSource::new(&sim);
    let traces = if_sim::track_vs_truth(&mut src, &sim, &truth, &specs, aid)?;
    Ok(case
        .cells
        .iter()
        .enumerate()
        .map(|(i, (cell, settle))| {
            let tr: Vec<&ChannelTrace> = traces[i * PRNS.len()..(i + 1) * PRNS.len()]
                .iter()
                .collect();
            measure_cell(cell, &tr, *settle, !aided)
        })
        .collect())
}

/// Measurement window of a cell, s: `window_s`, stretched to `window_s / Bn` (Bn in Hz) for
/// loops narrower than 1 Hz, whose errors are correlated for longer (a std estimated from a
/// window D has a relative error of about `1/sqrt(8 Bn D)` per satellite).
pub fn cell_window_s(cell: &Cell, window_s: f64) -> f64 {
    window_s * (1.0 / cell.bn_hz).max(1.0)
}

/// Recording length a cell needs, s: 2 s for the start and hand-over, its settling time (at
/// most [`MAX_SETTLE_S`]) and its measurement window.
fn needed_duration_s(settle_s: f64, window_s: f64) -> f64 {
    2.0 + settle_s.min(MAX_SETTLE_S) + window_s
}

/// Groups the cells that can run into recordings: per C/N0, the cells whose needed duration
/// rounds up to the same multiple of 8 s share one recording (both T and both orders: the same
/// samples, common random numbers). Noise is independent across C/N0 and recording lengths.
fn cases(cells: &[(Cell, f64)], seed: u64, window_s: f64) -> Vec<Case> {
    let mut out: Vec<Case> = Vec::new();
    for &(c, settle) in cells {
        let need = needed_duration_s(settle, cell_window_s(&c, window_s));
        let duration_s = (need / 8.0).ceil() * 8.0;
        match out
            .iter_mut()
            .find(|k| k.cn0_dbhz == c.cn0_dbhz && k.duration_s == duration_s)
        {
            Some(k) => k.cells.push((c, settle.min(MAX_SETTLE_S))),
            None => out.push(Case {
                cn0_dbhz: c.cn0_dbhz,
                duration_s,
                cells: vec![(c, settle.min(MAX_SETTLE_S))],
                seed: seed
                    .wrapping_mul(1_000_003)
                    .wrapping_add((c.cn0_dbhz * 10.0).round() as u64)
                    .wrapping_add((duration_s as u64) << 20),
            }),
        }
    }
    // Longest recordings first, so that the parallel cases finish together.
    out.sort_by(|a, b| {
        (b.duration_s * b.cells.len() as f64).total_cmp(&(a.duration_s * a.cells.len() as f64))
    });
    out
}

/// Runs the study.
pub fn run(args: &BandwidthArgs, progress: bool) -> anyhow::Result<StudyReport> {
    use rayon::prelude::*;
    let t_start = Instant::now();
    let quick = args.common.quick;
    let grid = if quick { quick_grid() } else { full_grid() };
    let window_s = args.window_s.unwrap_or(if quick { 12.0 } else { 24.0 });
    if !(window_s.is_finite() && (2.0..=600.0).contains(&window_s)) {
        anyhow::bail!("--window-s {window_s} is out of range; valid: 2 ..= 600 s");
    }
    let aided = !args.unaided;
    let theories: Vec<CellTheory> = grid.par_iter().map(cell_theory).collect();
    let runnable: Vec<(Cell, f64)> = grid
        .iter()
        .zip(&theories)
        .filter(|(c, _)| cell_status(c) == CellStatus::Run)
        // A loop whose linearised form is unstable still runs (to show that it loses lock),
        // measured after the longest settling time.
        .map(|(c, t)| {
            (
                *c,
                if t.settle_s.is_finite() {
                    t.settle_s
                } else {
                    MAX_SETTLE_S
                },
            )
        })
        .collect();
    let cases = cases(&runnable, args.common.seed, window_s);
    let outcomes = run_cases(&cases, "bandwidth", progress, |c| run_case(c, aided));
    let mut measured: Vec<(Cell, CellMeasured, f64)> = Vec::new();
    for (case, out) in cases.iter().zip(outcomes) {
        let out = out?;
        measured.extend(
            case.cells
                .iter()
                .zip(out)
                .map(|((c, _), m)| (*c, m, case.duration_s)),
        );
    }
    let results: Vec<CellResult> = grid
        .iter()
        .zip(theories)
        .map(|(cell, theory)| {
            let m = measured.iter().find(|(c, _, _)| c == cell);
            CellResult {
                cell: *cell,
                status: cell_status(cell),
                theory,
                measured: m.map(|(_, m, _)| m.clone()).unwrap_or_default(),
                duration_s: m.map(|(_, _, d)| *d).unwrap_or(f64::NAN),
            }
        })
        .collect();
    let recorded_s: f64 = cases.iter().map(|c| c.duration_s).sum();
    let wall_s = t_start.elapsed().as_secs_f64();
    Ok(build_report(
        &results,
        &RunInfo {
            window_s,
            aided,
            quick,
            seed: args.common.seed,
            recordings: cases.len(),
            recorded_s,
            wall_s,
        },
    ))
}

/// How the study ran.
#[derive(Debug, Clone, Copy)]
struct RunInfo {
    window_s: f64,
    aided: bool,
    quick: bool,
    seed: u64,
    recordings: usize,
    recorded_s: f64,
    wall_s: f64,
}

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.to_string()
}

fn note(r: &CellResult) -> String {
    match &r.status {
        CellStatus::Rejected { stable, .. } => format!(
            "not run: Bn T = {:.2} > {MAX_BN_T} (LoopConfig::validate); digital loop {}",
            r.cell.bn_t(),
            if *stable { "stable" } else { "unstable" }
        ),
        CellStatus::Run => {
            let m = &r.measured;
            let mut parts = Vec::new();
            if !r.above_threshold() {
                parts.push("below threshold (3 sigma > 45 deg)".to_string());
            }
            if m.lost > 0 {
                parts.push(format!("{}/{} lost", m.lost, m.channels));
            }
            if m.slips > 0 {
                parts.push(format!("{} half-cycle slips", m.slips));
            }
            if m.locked < m.channels && m.lost == 0 && m.slips == 0 {
                parts.push(format!("{}/{} locked", m.locked, m.channels));
            }
            if !r.theory.linear_stable {
                parts.push(format!(
                    "linearised loop unstable at atan slope {:.2}",
                    r.theory.atan_slope
                ));
            } else if r.theory.settle_s > MAX_SETTLE_S {
                parts.push(format!(
                    "needs {:.0} s to settle, measured after {MAX_SETTLE_S} s",
                    r.theory.settle_s
                ));
            }
            if r.cell.bn_t() > BNT_LIMIT + 1e-12 {
                parts.push(format!(
                    "Bn T > {BNT_LIMIT}: realised Bn {:.2} x design",
                    r.theory.bn_realised_ratio
                ));
            }
            parts.join("; ")
        }
    }
}

/// Ratio of the Bn = 4 Hz to the Bn = 1 Hz pseudorange-rate error std at each (C/N0, order, T).
#[derive(Debug, Clone, serde::Serialize)]
pub struct TableTwoRatio {
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
    /// PLL order.
    pub order: u8,
    /// Integration time, ms.
    pub t_ms: u32,
    /// Measured ratio of the NCO Doppler error std.
    pub nco_measured: f64,
    /// Theory (digital loop).
    pub nco_theory: f64,
    /// Measured ratio over 0.1 s.
    pub obs_0p1s_measured: f64,
    /// Theory over 0.1 s.
    pub obs_0p1s_theory: f64,
    /// Measured ratio over 1 s.
    pub obs_1s_measured: f64,
    /// Theory over 1 s.
    pub obs_1s_theory: f64,
}

/// The Table-2 ratios of all (C/N0, order, T) that have both a locked 1 Hz and 4 Hz cell.
pub fn table_two_ratios(results: &[CellResult]) -> Vec<TableTwoRatio> {
    let mut out = Vec::new();
    for r1 in results.iter().filter(|r| r.cell.bn_hz == 1.0 && r.locked()) {
        let Some(r4) = results.iter().find(|r| {
            r.cell.bn_hz == 4.0
                && r.cell.cn0_dbhz == r1.cell.cn0_dbhz
                && r.cell.order == r1.cell.order
                && r.cell.t_ms == r1.cell.t_ms
                && r.locked()
        }) else {
            continue;
        };
        let (m1, m4, t1, t4) = (&r1.measured, &r4.measured, &r1.theory, &r4.theory);
        out.push(TableTwoRatio {
            cn0_dbhz: r1.cell.cn0_dbhz,
            order: r1.cell.order,
            t_ms: r1.cell.t_ms,
            nco_measured: m4.doppler_hz / m1.doppler_hz,
            nco_theory: t4.doppler_hz / t1.doppler_hz,
            obs_0p1s_measured: m4.pr_rate_mps / m1.pr_rate_mps,
            obs_0p1s_theory: t4.pr_rate_mps / t1.pr_rate_mps,
            obs_1s_measured: m4.pr_rate_1s_mps / m1.pr_rate_1s_mps,
            obs_1s_theory: t4.pr_rate_1s_mps / t1.pr_rate_1s_mps,
        });
    }
    out
}

fn cell_json(r: &CellResult) -> serde_json::Value {
    let f = |v: f64| if v.is_finite() { json!(v) } else { json!(null) };
    json!({
        "cn0_dbhz": r.cell.cn0_dbhz,
        "order": r.cell.order,
        "bn_hz": r.cell.bn_hz,
        "t_ms": r.cell.t_ms,
        "bn_t": r.cell.bn_t(),
        "ratio": f(r.ratio()),
        "loop_theory_ratio": f(r.theory.phase_loop_deg / r.theory.phase_formula_deg),
        "measured_over_loop_theory": f(r.measured.phase_deg / r.theory.phase_loop_deg),
        "bn_realised_ratio": f(r.theory.bn_realised_ratio),
        "digital_loop_ratio": f(r.theory.phase_digital_ratio),
        "locked": r.locked(),
    })
}

const COLUMNS: [&str; 23] = [
    "cn0_dbhz",
    "order",
    "bn_hz",
    "t_ms",
    "bn_t",
    "phase_jitter_deg",
    "phase_jitter_formula_deg",
    "ratio",
    "phase_jitter_loop_deg",
    "doppler_std_hz",
    "doppler_theory_hz",
    "pr_rate_std_mps",
    "pr_rate_theory_mps",
    "pr_rate_1s_std_mps",
    "pr_rate_1s_theory_mps",
    "code_std_chips",
    "code_formula_chips",
    "code_envelope_chips",
    "locked",
    "within_20pct",
    "epochs",
    "settle_s",
    "note",
];

fn build_report(results: &[CellResult], info: &RunInfo) -> StudyReport {
    let mut table = Table::new(&COLUMNS);
    for r in results {
        let (m, t) = (&r.measured, &r.theory);
        let run = r.status == CellStatus::Run;
        table.push(vec![
            fmt(r.cell.cn0_dbhz, 0),
            r.cell.order.to_string(),
            fmt(r.cell.bn_hz, 1),
            r.cell.t_ms.to_string(),
            fmt(r.cell.bn_t(), 4),
            fmt(m.phase_deg_or_nan(run), 3),
            fmt(t.phase_formula_deg, 3),
            fmt(if run { r.ratio() } else { f64::NAN }, 3),
            fmt(t.phase_loop_deg, 3),
            fmt(m.or_nan(run, m.doppler_hz), 4),
            fmt(t.doppler_hz, 4),
            fmt(m.or_nan(run, m.pr_rate_mps), 4),
            fmt(t.pr_rate_mps, 4),
            fmt(m.or_nan(run, m.pr_rate_1s_mps), 5),
            fmt(t.pr_rate_1s_mps, 5),
            fmt(m.or_nan(run, m.code_chips), 5),
            fmt(t.code_formula_chips, 5),
            fmt(t.code_envelope_chips, 5),
            if run { yes_no(r.locked()) } else { "-".into() },
            match r.within_tolerance() {
                Some(b) => yes_no(b),
                None => "n.a.".into(),
            },
            m.epochs.to_string(),
            fmt(if run { r.theory.settle_s } else { f64::NAN }, 1),
            note(r),
        ]);
    }

    // Summary.
    let region: Vec<&CellResult> = results.iter().filter(|r| r.in_formula_region()).collect();
    let region_locked: Vec<&&CellResult> = region.iter().filter(|r| r.locked()).collect();
    let region_within = region_locked
        .iter()
        .filter(|r| r.within_tolerance() == Some(true))
        .count();
    let worst = region_locked
        .iter()
        .max_by(|a, b| (a.ratio() - 1.0).abs().total_cmp(&(b.ratio() - 1.0).abs()));
    let region_not_locked: Vec<serde_json::Value> = region
        .iter()
        .filter(|r| !r.locked())
        .map(|r| cell_json(r))
        .collect();
    let outside_tol: Vec<serde_json::Value> = region_locked
        .iter()
        .filter(|r| r.within_tolerance() == Some(false))
        .map(|r| cell_json(r))
        .collect();
    let beyond: Vec<&CellResult> = results
        .iter()
        .filter(|r| r.status == CellStatus::Run && r.cell.bn_t() > BNT_LIMIT + 1e-12)
        .collect();
    let rejected: Vec<serde_json::Value> = results
        .iter()
        .filter_map(|r| match &r.status {
            CellStatus::Rejected { stable, .. } => Some(json!({
                "cn0_dbhz": r.cell.cn0_dbhz, "order": r.cell.order, "bn_hz": r.cell.bn_hz,
                "t_ms": r.cell.t_ms, "bn_t": r.cell.bn_t(), "digital_loop_stable": stable,
            })),
            CellStatus::Run => None,
        })
        .collect();
    let not_locked: Vec<serde_json::Value> = results
        .iter()
        .filter(|r| r.status == CellStatus::Run && !r.locked())
        .map(|r| {
            let mut v = cell_json(r);
            v["note"] = json!(note(r));
            v
        })
        .collect();
    let ratios = table_two_ratios(results);
    let below_threshold_locked: Vec<serde_json::Value> = results
        .iter()
        .filter(|r| r.locked() && !r.above_threshold())
        .map(cell_json)
        .collect();
    let summary = json!({
        "study": "bandwidth",
        "quick": info.quick,
        "seed": info.seed,
        "aided_by_truth_doppler": info.aided,
        "window_s": info.window_s,
        "recordings": info.recordings,
        "recorded_s": info.recorded_s,
        "fs_hz": FS_HZ,
        "prns_per_cn0": PRNS,
        "dll": {"order": 1, "bn_hz": DLL_BN_HZ, "el_spacing_chips": EL_SPACING_CHIPS,
                "discriminator": "normalised early-minus-late envelope"},
        "tolerance": TOLERANCE,
        "bnt_limit": BNT_LIMIT,
        "threshold_sigma_deg": THRESHOLD_SIGMA_DEG,
        "cells_total": results.len(),
        "cells_run": results.iter().filter(|r| r.status == CellStatus::Run).count(),
        "cells_rejected": rejected,
        "cells_not_locked": not_locked,
        "formula_region": {
            "description": "Bn T <= 0.1 and formula sigma <= 15 deg (3 sigma <= 45 deg)",
            "cells": region.len(),
            "locked": region_locked.len(),
            "within_20pct": region_within,
            "worst": worst.map(|r| cell_json(r)),
            "worst_ratio": worst.map(|r| r.ratio()),
            "outside_20pct": outside_tol,
            "not_locked": region_not_locked,
            "by_prompt_snr": {
                "cn0_t_ge_3": region_counts(&region, true),
                "cn0_t_lt_3": region_counts(&region, false),
            },
        },
        "beyond_bnt_0p1": beyond.iter().map(|r| {
            let mut v = cell_json(r);
            v["note"] = json!(note(r));
            v
        }).collect::<Vec<_>>(),
        "locked_below_threshold": below_threshold_locked,
        "pr_rate_ratio_4hz_over_1hz": ratios,
        "seed004_table2": {"bn_1hz_mps": [0.03134, 0.04001, 0.03885],
                           "bn_4hz_mps": [0.05183, 0.06877, 0.07015],
                           "ratios": [0.05183 / 0.03134, 0.06877 / 0.04001, 0.07015 / 0.03885]},
        "wall_s": info.wall_s,
    });

    let intro_md = intro(info);
    let conclusions_md = conclusions(results, &ratios, info);
    StudyReport {
        title: "Loop bandwidth study: thermal noise of the PLL, Doppler and DLL".into(),
        intro_md,
        table,
        conclusions_md,
        summary,
        plots: plots(results),
    }
}

impl CellMeasured {
    fn or_nan(&self, run: bool, v: f64) -> f64 {
        if run && self.locked > 0 {
            v
        } else {
            f64::NAN
        }
    }

    fn phase_deg_or_nan(&self, run: bool) -> f64 {
        self.or_nan(run, self.phase_deg)
    }
}

fn intro(info: &RunInfo) -> String {
    let (aided, quick) = (info.aided, info.quick);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Simulated static receiver (Seoul, {}), clock without noise (Allan deviation 0): the \
         loops see thermal noise only. Real oscillators add the Allan term (oracles.md: about \
         `144 sigma_A f_L1 / Bn` deg for a 2nd-order loop, `160 sigma_A f_L1 / Bn` for a 3rd; \
         7.6 deg at 3 Hz for sigma_A = 1e-10), which grows as Bn shrinks and is not in this table.\n",
        if quick { "`--quick` grid" } else { "full grid" }
    );
    let _ = writeln!(
        s,
        "- {} recordings, {:.0} s in all (complex floats at {:.1} MHz, no quantisation), each \
         with G16, G25 and G26 at one C/N0; every satellite tracked by one channel per (order, \
         Bn, T) cell over the same samples, started from truth. {}\n\
         - Channel: Costas `atan(Q/I)` PLL of the cell's order and Bn (no FLL); the pull-in loop \
         is a PLL of the same Bn at T = 1 ms (order 2 for the 3rd-order cells: a 3rd-order loop \
         pulling in from a random carrier phase overshoots past +-90 deg and can slip), and the \
         cell's loop and T start at a bit edge after bit synchronisation; DLL 1st order, carrier-aided, Bn = {DLL_BN_HZ} Hz, normalised \
         early-minus-late envelope with d = {EL_SPACING_CHIPS} chip.\n\
         - Measured over at least {:.0} s (`window / Bn` for Bn < 1 Hz) after each cell's \
         settling time `settle_s` from the hand-over to \
         tracking (1 s plus the time the cell's linearised loop takes to bring a start-up \
         transient down to {SETTLE_FRACTION:e} of its size: about 8 time constants of its \
         slowest mode; 6.3/Bn s for order 2 but 43/Bn s for the lightly damped 3rd-order loop; \
         at most {MAX_SETTLE_S} s), per integration interval against the simulator's truth, \
         pooled over the three satellites: `phase_jitter_deg` = \
         std of the replica (NCO) carrier phase minus the true carrier phase (offset and Costas \
         half cycle removed){}; `doppler_std_hz` = NCO frequency held over each interval minus \
         the true mean Doppler; `pr_rate_std_mps` = carrier-phase change over {OBS_INTERVAL_S} s \
         (the receiver's 10 Hz observable Doppler) minus the true one, times lambda; \
         `pr_rate_1s_std_mps` the same over {LONG_INTERVAL_S} s; `code_std_chips` = replica minus \
         true code phase.\n\
         - `phase_jitter_formula_deg`: oracles.md Costas formula; `ratio` = measured / formula; \
         `phase_jitter_loop_deg`: the implemented digital loop (its realised noise bandwidth) \
         with the atan discriminator's own slope `1 - exp(-C/N0 T)` and noise at the prompt SNR. \
         `doppler_theory_hz`, `pr_rate_theory_mps`, `pr_rate_1s_theory_mps`: the same \
         linearised digital loop's impulse responses (there is no standard closed form; module \
         docs of `receiver/src/study/bandwidth.rs`); at high C/N0 T they reduce to the loop \
         driven by the formula's discriminator noise. \
         A `-` in the theory columns: the linearised loop is unstable at that discriminator \
         slope. `code_formula_chips`: the oracle \
         early-minus-late *power* formula; `code_envelope_chips`: the normalised envelope \
         discriminator the channel uses, in the same linearised loop.\n\
         - `locked`: every channel reached tracking, was never released, had no half-cycle slip \
         (0.1 s block means of the phase error against truth stay on one branch) and kept the \
         code within half a chip; statistics use only channels that held lock, and a cell with \
         any loss of lock is reported, not averaged in. `within_20pct`: |ratio - 1| <= 0.2 \
         (n.a. when not locked). Tracking threshold: formula `3 sigma <= 45` deg. `epochs`: \
         measured intervals per channel.\n",
        info.recordings,
        info.recorded_s,
        FS_HZ / 1e6,
        if aided {
            "The true Doppler (and its rate) is fed forward (a perfect INS, seed 004 eq. 7), so \
             the satellites' own LOS dynamics do not load the loops."
        } else {
            "Unaided (`--unaided`): the satellites' own LOS acceleration loads the loops \
             (steady-state error a/omega0^2 for order 2)."
        },
        info.window_s,
        if aided {
            ""
        } else {
            " and a least-squares straight line (the slowly varying dynamic error)"
        },
    );
    s
}

/// Counts of formula-region cells at high (`C/N0 T >= 3`) or low prompt SNR: cells, locked,
/// within 20 %, and the range of measured / formula over the locked ones.
fn region_counts(region: &[&CellResult], high: bool) -> serde_json::Value {
    let cells: Vec<&&CellResult> = region
        .iter()
        .filter(|r| (cn0_t(&r.cell) >= HIGH_SNR_CN0_T) == high)
        .collect();
    let locked: Vec<&&&CellResult> = cells.iter().filter(|r| r.locked()).collect();
    let (lo, hi) = range_of(locked.iter().map(|r| r.ratio()));
    let f = |v: f64| if v.is_finite() { json!(v) } else { json!(null) };
    json!({
        "cells": cells.len(),
        "locked": locked.len(),
        "within_20pct": locked.iter().filter(|r| r.within_tolerance() == Some(true)).count(),
        "ratio_min": f(lo),
        "ratio_max": f(hi),
    })
}

/// `C/N0 T` (linear) of a cell: the prompt SNR the discriminators work at.
fn cn0_t(cell: &Cell) -> f64 {
    lin(cell.cn0_dbhz) * cell.t_s()
}

/// Prompt SNR (`C/N0 T`) from which the atan discriminator is close to linear (slope
/// `1 - exp(-3)` = 0.95) and the formulas are expected to hold.
pub const HIGH_SNR_CN0_T: f64 = 3.0;

fn cell_label(c: &Cell) -> String {
    format!("{}/{}/{}/{}", c.cn0_dbhz, c.order, c.bn_hz, c.t_ms)
}

fn range_of(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        })
}

fn conclusions(results: &[CellResult], ratios: &[TableTwoRatio], info: &RunInfo) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Conclusions\n\nCells are written C/N0/order/Bn/T (dB-Hz/-/Hz/ms).\n"
    );
    // 1. The formula region, split by prompt SNR.
    let region: Vec<&CellResult> = results.iter().filter(|r| r.in_formula_region()).collect();
    for (title, high) in [
        (
            "C/N0 T >= 3 (35 dB-Hz and up at 1 ms, every C/N0 at 20 ms)",
            true,
        ),
        ("C/N0 T < 3 (25 and 30 dB-Hz at 1 ms)", false),
    ] {
        let cells: Vec<&&CellResult> = region
            .iter()
            .filter(|r| (cn0_t(&r.cell) >= HIGH_SNR_CN0_T) == high)
            .collect();
        if cells.is_empty() {
            continue;
        }
        let locked: Vec<&&&CellResult> = cells.iter().filter(|r| r.locked()).collect();
        let within = locked
            .iter()
            .filter(|r| r.within_tolerance() == Some(true))
            .count();
        let (lo, hi) = range_of(locked.iter().map(|r| r.ratio()));
        let (llo, lhi) = range_of(
            locked
                .iter()
                .map(|r| r.measured.phase_deg / r.theory.phase_loop_deg),
        );
        let _ = writeln!(
            s,
            "- Formula region (Bn T <= {BNT_LIMIT}, formula sigma <= {THRESHOLD_SIGMA_DEG} deg), \
             {title}: {} cells, {} held lock, {within} of those within 20 % of the Costas \
             formula (measured / formula {lo:.2}-{hi:.2}; measured / linearised digital loop \
             {llo:.2}-{lhi:.2}).",
            cells.len(),
            locked.len(),
        );
        let out: Vec<String> = locked
            .iter()
            .filter(|r| r.within_tolerance() == Some(false))
            .map(|r| {
                format!(
                    "{} at {:.2} (Bn T {:.3}; the digital loop predicts {:.2}, with the atan \
                     statistics {:.2})",
                    cell_label(&r.cell),
                    r.ratio(),
                    r.cell.bn_t(),
                    r.theory.phase_digital_ratio,
                    r.theory.phase_loop_deg / r.theory.phase_formula_deg
                )
            })
            .collect();
        if !out.is_empty() {
            let _ = writeln!(s, "  - Beyond 20 %: {}.", out.join("; "));
        }
        let lost: Vec<String> = cells
            .iter()
            .filter(|r| !r.locked())
            .map(|r| format!("{} ({})", cell_label(&r.cell), note(r)))
            .collect();
        if !lost.is_empty() {
            let _ = writeln!(s, "  - Lost lock or slipped: {}.", lost.join("; "));
        }
    }
    let low_run = results
        .iter()
        .any(|r| r.status == CellStatus::Run && cn0_t(&r.cell) < HIGH_SNR_CN0_T);
    if low_run {
        let order3 = |cn0: f64| {
            let v: Vec<&CellResult> = results
                .iter()
                .filter(|r| {
                    r.status == CellStatus::Run
                        && r.cell.order == 3
                        && r.cell.t_ms == 1
                        && r.cell.cn0_dbhz == cn0
                })
                .collect();
            (v.iter().filter(|r| r.locked()).count(), v.len())
        };
        let (l25, n25) = order3(25.0);
        let (l30, n30) = order3(30.0);
        let _ = writeln!(
            s,
            "- Why the formula fails near C/N0 T = 1: the `atan(Q/I)` discriminator's mean slope \
             is `1 - exp(-C/N0 T)` (0.27 at 25 dB-Hz, 0.63 at 30 dB-Hz, 1 ms) and its output \
             saturates at +-90 deg, so the formula's squaring loss `1 + 1/(2 T C/N0)` no longer \
             describes it (`phase_jitter_loop_deg` uses the discriminator's own statistics). A \
             3rd-order loop is only conditionally stable: with discriminator gain g its analog \
             characteristic polynomial `s^3 + g(b3 w s^2 + a3 w^2 s + w^3)` needs \
             `g a3 b3 > 1`, g > 0.38 (Routh); at 25 dB-Hz and 1 ms every 3rd-order loop is \
             linearly unstable ({l25} of {n25} held lock), and at 30 dB-Hz (g = 0.63, little \
             margin) {l30} of {n30} held lock. The oracle's rule of thumb (`3 sigma <= 45` deg \
             with the formula's sigma) is optimistic at this prompt SNR."
        );
    }
    // 2. Beyond Bn T = 0.1.
    let beyond: Vec<String> = results
        .iter()
        .filter(|r| r.locked() && r.cell.bn_t() > BNT_LIMIT + 1e-12)
        .map(|r| {
            format!(
                "{}: {:.2} (digital loop {:.2})",
                cell_label(&r.cell),
                r.ratio(),
                r.theory.phase_loop_deg / r.theory.phase_formula_deg
            )
        })
        .collect();
    if !beyond.is_empty() {
        let _ = writeln!(
            s,
            "- Beyond Bn T = {BNT_LIMIT} (here Bn T = 0.2: 10 Hz at 20 ms) the digital loop's \
             noise bandwidth is well above the design value (1.82 x for order 2, 1.57 x for \
             order 3, on the interval-average phase: tracking/README.md), and the NCO phase at \
             the interval start carries more: the measured jitter departs from the formula by \
             40-55 %, as the linearised digital loop predicts. Measured / formula: {}.",
            beyond.join("; ")
        );
    }
    let rejected: Vec<String> = results
        .iter()
        .filter_map(|r| match &r.status {
            CellStatus::Rejected { stable, .. } => Some(format!(
                "order {} Bn {} Hz T {} ms (Bn T {:.2}, digital loop {})",
                r.cell.order,
                r.cell.bn_hz,
                r.cell.t_ms,
                r.cell.bn_t(),
                if *stable { "stable" } else { "unstable" }
            )),
            CellStatus::Run => None,
        })
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    if !rejected.is_empty() {
        let _ = writeln!(
            s,
            "- Not run (every C/N0): {}. `LoopConfig::validate` rejects Bn T > {MAX_BN_T}; the \
             2nd-order digital loop becomes unstable at Bn T = 0.44, the 3rd-order at 0.56 \
             (tracking/README.md).",
            rejected.join("; ")
        );
    }
    // 3. Settling.
    let order3_run = results
        .iter()
        .any(|r| r.status == CellStatus::Run && r.cell.order == 3);
    let _ = writeln!(
        s,
        "- Settling: every cell is measured from `settle_s` after its hand-over to tracking{}",
        if order3_run {
            ":"
        } else {
            " (1 s + 6.3/Bn s for the 2nd-order loops)."
        }
    );
    if order3_run {
        let _ = writeln!(
            s,
            "  - The Kaplan 3rd-order loop (a3 = 1.1, b3 = 2.4) has a lightly damped pair of \
             closed-loop poles (damping ratio 0.22, decay rate 0.148 omega0). The hand-over to \
             tracking moves the pull-in loop's last output, proportional term included, into \
             the new loop's base frequency: a frequency step of the size of the NCO's frequency \
             noise, which excites that pair; it takes about 43/Bn s to decay to 3e-4 (90 s at \
             0.5 Hz) against 6.3/Bn s for the 2nd-order loop. In a first version of this study \
             (3rd-order pull-in from the random initial carrier phase, errors measured from \
             `1 + 5/Bn` s) the 0.5 Hz 3rd-order loops read up to 9.7 deg at 50 dB-Hz against \
             0.13 deg thermal, and at 35 dB-Hz one satellite fell into a slipping limit cycle \
             (its phase swung by tens of cycles over 140 s). Handing over only the integrator \
             state would remove the hand-over step."
        );
    }
    // 4. Doppler and code.
    let high: Vec<&CellResult> = results
        .iter()
        .filter(|r| r.locked() && cn0_t(&r.cell) >= HIGH_SNR_CN0_T)
        .collect();
    let (dlo, dhi) = range_of(
        high.iter()
            .map(|r| r.measured.doppler_hz / r.theory.doppler_hz),
    );
    let (plo, phi) = range_of(
        high.iter()
            .map(|r| r.measured.pr_rate_mps / r.theory.pr_rate_mps),
    );
    let (qlo, qhi) = range_of(
        high.iter()
            .map(|r| r.measured.pr_rate_1s_mps / r.theory.pr_rate_1s_mps),
    );
    let _ = writeln!(
        s,
        "- Doppler (C/N0 T >= 3, locked): the NCO frequency error std is {dlo:.2}-{dhi:.2} x the \
         linearised digital loop's value, the 0.1 s carrier-phase pseudorange rate \
         {plo:.2}-{phi:.2} x and the 1 s one {qlo:.2}-{qhi:.2} x (about 24-48 one-second \
         differences per satellite: +-15 %). The PLL's Doppler has no standard closed form; its \
         std depends on what is output (NCO frequency or a phase difference over tau)."
    );
    let code_rows = |pred: &dyn Fn(f64) -> bool| -> (f64, f64, f64, f64) {
        let v: Vec<&CellResult> = results
            .iter()
            .filter(|r| r.locked() && pred(cn0_t(&r.cell)))
            .collect();
        let (a, b) = range_of(
            v.iter()
                .map(|r| r.measured.code_chips / r.theory.code_envelope_chips),
        );
        let (c, d) = range_of(
            v.iter()
                .map(|r| r.measured.code_chips / r.theory.code_formula_chips),
        );
        (a, b, c, d)
    };
    let (a, b, c, d) = code_rows(&|x| x >= 10.0);
    let (e, f, g, h) = code_rows(&|x| x < 10.0);
    let _ = writeln!(
        s,
        "- Code (DLL 1st order, Bn {DLL_BN_HZ} Hz, d = {EL_SPACING_CHIPS} chip, normalised \
         envelope): at C/N0 T >= 10 the measured std is {a:.2}-{b:.2} x the linearised \
         envelope DLL and {c:.2}-{d:.2} x the oracle's E-L *power* formula (both tend to the \
         coherent `Bn d/(2 C/N0)`). Below (C/N0 T < 10) it is {e:.2}-{f:.2} x the envelope \
         value and {g:.2}-{h:.2} x the power formula: the envelope discriminator's squaring \
         loss is about half the power discriminator's (`1 + 1/(T C/N0 (2 - d))` against \
         `1 + 2/(T C/N0 (2 - d))` to first order) and its gain drops with the noise-biased \
         envelope sum, so the power formula overstates the channel's code noise up to \
         threefold at 25 dB-Hz and 1 ms."
    );
    let _ = writeln!(
        s,
        "- Satellite choice: the simulator's chips are ideal (no front-end filter) and the \
         correlation triangle is sampled at 2.44 samples per chip; its E-L null moves with the \
         code phase relative to the sample grid. A satellite whose code drifts slowly across \
         the grid (G31, +201 Hz Doppler: 0.13 chip/s, a 3 s period) carries that bias into the \
         code error: in a separate run at 50 dB-Hz (Bn 10 Hz, T 1 ms) G31 read 0.0043 chip \
         against 0.0024 chip for G16 (+3672 Hz) and the 0.00225 chip theory. The study uses \
         G16, G25 and G26 (1.3-2.4 chip/s) so that the bias averages out within the DLL's time \
         constant."
    );
    let lost: Vec<String> = results
        .iter()
        .filter(|r| r.status == CellStatus::Run && r.measured.lost > 0)
        .map(|r| {
            format!(
                "{} ({}/{})",
                cell_label(&r.cell),
                r.measured.lost,
                r.measured.channels
            )
        })
        .collect();
    if !lost.is_empty() {
        let _ = writeln!(
            s,
            "- Channels released or never handed over to tracking: {}. Besides the loops that \
             lose lock at low prompt SNR (above), a channel at 25 dB-Hz can be released a few \
             seconds after start when its bit synchronisation (sized for 30 dB-Hz at a \
             false-sync probability of 1e-4) picks a wrong edge: its C/N0 estimate over 20 ms \
             blocks that straddle bit edges then falls below 20 dB-Hz (G25 in the 40 s \
             recording at 25 dB-Hz: edge 7 ms off, C/N0 read 2-16 dB-Hz, released at 3.3 s, in \
             every configuration tracked on it).",
            lost.join(", ")
        );
    }
    if !ratios.is_empty() {
        let _ = writeln!(
            s,
            "\n### Seed 004 Table 2: pseudorange-rate error std at Bn = 4 Hz over Bn = 1 Hz\n\n\
             Seed 004 measured 1.65, 1.72 and 1.81 (static, 2nd-order PLL, real front end and \
             oscillator, averaging interval not stated).\n\n\
             | C/N0 | order | T ms | NCO Doppler measured | theory | 0.1 s measured | theory | \
             1 s measured | theory |\n|---|---|---|---|---|---|---|---|---|"
        );
        for r in ratios {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
                r.cn0_dbhz,
                r.order,
                r.t_ms,
                r.nco_measured,
                r.nco_theory,
                r.obs_0p1s_measured,
                r.obs_0p1s_theory,
                r.obs_1s_measured,
                r.obs_1s_theory
            );
        }
        let o2: Vec<&TableTwoRatio> = ratios.iter().filter(|r| r.order == 2).collect();
        let (a, b) = range_of(o2.iter().map(|r| r.obs_1s_measured));
        let (c, d) = range_of(o2.iter().map(|r| r.obs_0p1s_measured));
        let (e, f) = range_of(o2.iter().map(|r| r.nco_measured));
        let _ = writeln!(
            s,
            "\nWhich ratio one gets depends on what is called the Doppler. The NCO frequency \
             carries the loop filter's proportional path, which passes the white discriminator \
             noise straight through (`u ~ a2 omega0 e`): its std grows as Bn (order 2 measured \
             {e:.2}-{f:.2}; theory 4.0 at 1 ms, 4.3 at 20 ms where Bn T = 0.08 widens the 4 Hz \
             loop). The Doppler a receiver outputs is a carrier-phase \
             difference over its observable interval tau. For tau much longer than the loop's \
             time constant (`1/omega0` = 0.53 s at 1 Hz, 0.13 s at 4 Hz) it is \
             `sqrt(2) sigma_phi / tau` and the ratio is `sqrt(4) = 2` because the thermal \
             jitter grows as `sqrt(Bn)` (1 s: measured {a:.2}-{b:.2}); for tau = 0.1 s, shorter \
             than the 1 Hz loop's time constant, the narrow loop's phase is still correlated \
             over tau and the ratio is larger (measured {c:.2}-{d:.2}). The often-quoted `Bn^1.5` \
             (8x) applies to the low-frequency part of the loop's frequency error alone, not to \
             either output. Seed 004's 1.65-1.81 is therefore consistent with a Doppler averaged \
             over about a second plus a noise share that does not grow with Bn: in a real receiver the oscillator's Allan \
             term grows as 1/Bn and pulls the ratio below 2, and this simulation has no \
             oscillator noise."
        );
    }
    let _ = writeln!(
        s,
        "\nRun: {} recordings, {:.0} s of simulated signal, {:.1} s wall time.",
        info.recordings, info.recorded_s, info.wall_s
    );
    s
}

fn plots(results: &[CellResult]) -> Vec<LinePlot> {
    let mut cn0s: Vec<f64> = Vec::new();
    for r in results {
        if !cn0s.contains(&r.cell.cn0_dbhz) {
            cn0s.push(r.cell.cn0_dbhz);
        }
    }
    // At most four C/N0 values, spread over the range.
    let pick: Vec<f64> = if cn0s.len() <= 4 {
        cn0s.clone()
    } else {
        let n = cn0s.len() - 1;
        (0..4).map(|i| cn0s[(i * n + 1) / 3]).collect::<Vec<_>>()
    };
    let pick: Vec<f64> = {
        let mut p = pick;
        p.dedup();
        p
    };
    let sel = |cn0: f64, order: u8, t_ms: u32| -> Vec<&CellResult> {
        results
            .iter()
            .filter(|r| {
                r.cell.cn0_dbhz == cn0
                    && r.cell.order == order
                    && r.cell.t_ms == t_ms
                    && r.status == CellStatus::Run
            })
            .collect()
    };
    let mut out = Vec::new();
    for t_ms in [1u32, 20] {
        let mut series = Vec::new();
        for &cn0 in &pick {
            let cells = sel(cn0, 2, t_ms);
            if cells.is_empty() {
                continue;
            }
            series.push(Series {
                name: format!("{cn0} dB-Hz measured"),
                points: cells
                    .iter()
                    .filter(|r| r.locked())
                    .map(|r| (r.cell.bn_hz, r.measured.phase_deg))
                    .collect(),
                reference: false,
            });
            series.push(Series {
                name: format!("{cn0} dB-Hz formula"),
                points: cells
                    .iter()
                    .map(|r| (r.cell.bn_hz, r.theory.phase_formula_deg))
                    .collect(),
                reference: true,
            });
        }
        if series.iter().any(|s| !s.points.is_empty() && !s.reference) {
            out.push(LinePlot {
                file_name: format!("jitter_vs_bn_t{t_ms}ms.png"),
                title: format!("PLL phase jitter vs Bn (order 2, T = {t_ms} ms)"),
                x_label: "Bn (Hz)".into(),
                y_label: "phase jitter (deg)".into(),
                log_x: true,
                log_y: true,
                series,
            });
        }
    }
    // Measured / formula against Bn T: the mean over C/N0 of the locked cells at high prompt
    // SNR (C/N0 T >= 3) for each (order, T, Bn), with the digital loop's prediction.
    let mut series = Vec::new();
    for order in [2u8, 3] {
        for t_ms in [1u32, 20] {
            let mut pts: Vec<(f64, f64)> = Vec::new();
            for r in results.iter().filter(|r| {
                r.locked()
                    && r.cell.order == order
                    && r.cell.t_ms == t_ms
                    && r.above_threshold()
                    && cn0_t(&r.cell) >= HIGH_SNR_CN0_T
            }) {
                if pts.iter().any(|p| p.0 == r.cell.bn_t()) {
                    continue;
                }
                let same: Vec<f64> = results
                    .iter()
                    .filter(|q| {
                        q.locked()
                            && q.cell.order == order
                            && q.cell.t_ms == t_ms
                            && q.cell.bn_hz == r.cell.bn_hz
                            && q.above_threshold()
                            && cn0_t(&q.cell) >= HIGH_SNR_CN0_T
                    })
                    .map(|q| q.ratio())
                    .collect();
                pts.push((r.cell.bn_t(), if_sim::mean(&same)));
            }
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if !pts.is_empty() {
                series.push(Series {
                    name: format!("order {order}, T {t_ms} ms (mean over C/N0)"),
                    points: pts,
                    reference: false,
                });
            }
        }
        let mut curve: Vec<(f64, f64)> = results
            .iter()
            .filter(|r| {
                r.cell.order == order
                    && r.status == CellStatus::Run
                    && r.theory.phase_digital_ratio.is_finite()
            })
            .map(|r| (r.cell.bn_t(), r.theory.phase_digital_ratio))
            .collect();
        curve.sort_by(|a, b| a.0.total_cmp(&b.0));
        curve.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-12);
        series.push(Series {
            name: format!("digital loop / formula, order {order}"),
            points: curve,
            reference: true,
        });
    }
    out.push(LinePlot {
        file_name: "ratio_vs_bnt.png".into(),
        title: "Measured / formula phase jitter vs Bn T (C/N0 T >= 3, locked)".into(),
        x_label: "Bn T".into(),
        y_label: "measured / formula".into(),
        log_x: true,
        log_y: false,
        series,
    });
    // Pseudorange-rate error vs Bn.
    let mut series = Vec::new();
    for &cn0 in &pick {
        let cells = sel(cn0, 2, 1);
        if cells.is_empty() {
            continue;
        }
        series.push(Series {
            name: format!("{cn0} dB-Hz, 0.1 s measured"),
            points: cells
                .iter()
                .filter(|r| r.locked())
                .map(|r| (r.cell.bn_hz, r.measured.pr_rate_mps))
                .collect(),
            reference: false,
        });
        series.push(Series {
            name: format!("{cn0} dB-Hz, 0.1 s theory"),
            points: cells
                .iter()
                .map(|r| (r.cell.bn_hz, r.theory.pr_rate_mps))
                .collect(),
            reference: true,
        });
    }
    out.push(LinePlot {
        file_name: "pr_rate_vs_bn.png".into(),
        title: "Pseudorange-rate error std (0.1 s carrier-phase Doppler) vs Bn (order 2, T 1 ms)"
            .into(),
        x_label: "Bn (Hz)".into(),
        y_label: "pseudorange-rate error std (m/s)".into(),
        log_x: true,
        log_y: true,
        series,
    });
    // Code error vs C/N0: the cells at the median Bn of each (C/N0, T) (the DLL is the same in
    // every cell of a row).
    let mut series = Vec::new();
    for t_ms in [1u32, 20] {
        let mut meas = Vec::new();
        let mut formula = Vec::new();
        let mut envelope = Vec::new();
        for &cn0 in &cn0s {
            let cells: Vec<&CellResult> = results
                .iter()
                .filter(|r| r.cell.cn0_dbhz == cn0 && r.cell.t_ms == t_ms && r.locked())
                .collect();
            if cells.is_empty() {
                continue;
            }
            let mut v: Vec<f64> = cells.iter().map(|r| r.measured.code_chips).collect();
            v.sort_by(f64::total_cmp);
            meas.push((cn0, v[v.len() / 2]));
            formula.push((cn0, cells[0].theory.code_formula_chips));
            envelope.push((cn0, cells[0].theory.code_envelope_chips));
        }
        if meas.is_empty() {
            continue;
        }
        series.push(Series {
            name: format!("T {t_ms} ms measured"),
            points: meas,
            reference: false,
        });
        series.push(Series {
            name: format!("T {t_ms} ms E-L power formula"),
            points: formula,
            reference: true,
        });
        series.push(Series {
            name: format!("T {t_ms} ms normalised envelope"),
            points: envelope,
            reference: true,
        });
    }
    out.push(LinePlot {
        file_name: "code_vs_cn0.png".into(),
        title: format!("DLL code error std vs C/N0 (Bn {DLL_BN_HZ} Hz, d {EL_SPACING_CHIPS} chip)"),
        x_label: "C/N0 (dB-Hz)".into(),
        y_label: "code error std (chips)".into(),
        log_x: false,
        log_y: true,
        series,
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formulas_reproduce_the_oracle_examples() {
        // oracles.md: T = 1 ms: Bn 2 Hz at 45 dB-Hz 0.46 deg; Bn 10 Hz at 35 dB-Hz 3.47 deg;
        // Bn 18 Hz at 30 dB-Hz 9.41 deg. DLL d = 1, Bn 0.5 Hz, 45 dB-Hz: 0.0029 chip.
        assert!((pll_jitter_deg(2.0, 45.0, 1e-3) - 0.46).abs() < 0.005);
        assert!((pll_jitter_deg(10.0, 35.0, 1e-3) - 3.47).abs() < 0.005);
        assert!((pll_jitter_deg(18.0, 30.0, 1e-3) - 9.41).abs() < 0.005);
        assert!((dll_jitter_chips(0.5, 1.0, 45.0, 1e-3) - 0.0029).abs() < 0.00005);
        // FLL: 1/(2 pi T) sqrt(4 Bn/CN0 (1 + 1/(T CN0))) at 10 Hz, 45 dB-Hz, 1 ms, F = 1.
        let cn0 = 10f64.powf(4.5);
        let want = (4.0 * 10.0 / cn0 * (1.0 + 1.0 / (1e-3 * cn0))).sqrt() / (2.0 * PI * 1e-3);
        assert!((fll_jitter_hz(10.0, 45.0, 1e-3, 1.0) - want).abs() < 1e-12);
    }

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
    fn discriminator_statistics_have_the_right_limits() {
        // The phase density integrates to 1.
        for rho in [0.0, 0.3, 3.0, 300.0] {
            let s = simpson(|x| carrier_phase_pdf(x, rho), -PI, PI, 1 << 14);
            assert!((s - 1.0).abs() < 1e-5, "rho {rho}: {s}");
        }
        // High SNR: atan(Q/I) variance -> 1/(2 rho) rad^2, slope 1 (50 dB-Hz, 20 ms: rho 2000).
        let st = costas_atan_stats(50.0, 20e-3);
        let rho = 10f64.powf(5.0) * 0.02;
        assert!((st.noise_var * 4.0 * PI * PI * 2.0 * rho - 1.0).abs() < 0.01);
        assert!((st.slope - 1.0).abs() < 1e-9);
        // rho -> 0: uniform over (-pi/2, pi/2]: pi^2/12 rad^2, slope 0.
        let st = costas_atan_stats(-60.0, 1e-3);
        assert!((st.noise_var * 4.0 * PI * PI - PI * PI / 12.0).abs() < 1e-3);
        assert!(st.slope < 1e-6);
        // Gauss-Hermite: sum w = sqrt(pi), E[X^2] = 1/2 for weight exp(-x^2).
        let (x, w) = gauss_hermite(24);
        assert!((w.iter().sum::<f64>() - PI.sqrt()).abs() < 1e-10);
        let m2: f64 = x.iter().zip(&w).map(|(x, w)| w * x * x).sum::<f64>() / PI.sqrt();
        assert!((m2 - 0.5).abs() < 1e-10);
        // Envelope DLL at high SNR (45 dB-Hz, 20 ms): slope 1, var d/(4 rho), d = 1.
        let st = envelope_dll_stats(45.0, 20e-3, 1.0);
        let rho = 10f64.powf(4.5) * 0.02;
        assert!((st.slope - 1.0).abs() < 0.01, "{st:?}");
        assert!((st.noise_var * 4.0 * rho - 1.0).abs() < 0.02, "{st:?}");
    }

    #[test]
    fn grids_and_rejections() {
        let g = full_grid();
        assert_eq!(g.len(), 6 * 2 * 7 * 2);
        let rejected: Vec<&Cell> = g
            .iter()
            .filter(|c| cell_status(c) != CellStatus::Run)
            .collect();
        // T = 20 ms with Bn 15 and 25 Hz (Bn T 0.3, 0.5), both orders, every C/N0.
        assert_eq!(rejected.len(), 6 * 2 * 2);
        assert!(rejected.iter().all(|c| c.t_ms == 20 && c.bn_hz >= 15.0));
        // Order 2 at Bn T = 0.5 is unstable, order 3 at 0.3 is stable (tracking/README.md).
        let st = |order, bn| {
            cell_status(&Cell {
                cn0_dbhz: 40.0,
                order,
                bn_hz: bn,
                t_ms: 20,
            })
        };
        assert!(matches!(
            st(2, 25.0),
            CellStatus::Rejected { stable: false, .. }
        ));
        assert!(matches!(
            st(3, 15.0),
            CellStatus::Rejected { stable: true, .. }
        ));
        // The quick grid: one recording per C/N0 (1 and 20 ms cells share it).
        let quick: Vec<(Cell, f64)> = quick_grid().iter().map(|c| (*c, 5.0)).collect();
        assert_eq!(cases(&quick, 1, 8.0).len(), 2);
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
