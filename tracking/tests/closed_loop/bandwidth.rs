//! Closed-loop noise bandwidth of the implemented digital loops against the design (table) value,
//! and their stability limits.
//!
//! Relation used (derived in `gpsrx_tracking::loop_analysis`): white noise of variance `s^2` per
//! update added to the discriminator output gives an NCO-phase variance `2 Bn T s^2`, so
//! `Bn = var_out / (2 T s^2)`; the same number is `sum_k h_k^2 / (2T)` for the impulse response
//! `h` and `integral_0^{1/2T} |H|^2 df` for the transfer function.

use gpsrx_tracking::loop_analysis::{is_stable, noise_bandwidth_hz};
use gpsrx_tracking::LoopFilter;

use crate::sim::{gauss, rng, run, Signal, Trajectory};

const T: f64 = 1e-3;

#[derive(Debug, Clone, Copy)]
enum Kind {
    Pll(u8),
    Fll(u8),
    /// FLL-assisted PLL with the FLL at half the PLL bandwidth.
    Assisted(u8, u8),
}

impl Kind {
    fn name(self) -> String {
        match self {
            Kind::Pll(o) => format!("PLL {o} (= DLL {o})"),
            Kind::Fll(o) => format!("FLL {o}"),
            Kind::Assisted(p, f) => format!("PLL {p} + FLL {f} (Bn_fll = Bn_pll/2)"),
        }
    }

    fn filter(self, bn: f64) -> LoopFilter {
        let f = match self {
            Kind::Pll(o) => LoopFilter::pll(o, bn),
            Kind::Fll(o) => LoopFilter::fll(o, bn),
            Kind::Assisted(p, f) => LoopFilter::fll_assisted_pll(p, bn, f, bn / 2.0),
        };
        match f {
            Ok(f) => f,
            Err(e) => panic!("{e}"),
        }
    }
}

/// Drives the implemented filter in the phase-domain simulator (input phase 0) with an additive
/// perturbation per update and returns the loop output the noise bandwidth refers to
/// (`gpsrx_tracking::loop_analysis`):
/// - loops with a phase input: the perturbation is added to the phase reading, which feeds the
///   PLL discriminator and (as consecutive differences / T, as a cross/dot discriminator would
///   see it) the FLL input; output: the NCO average phase (= minus the true error);
/// - pure FLL: the perturbation (Hz) is added to the FLL discriminator output; output: the NCO
///   frequency as the discriminator sees it, the mean over the two intervals it spans.
fn respond(kind: Kind, bn: f64, n: usize, mut perturb: impl FnMut(usize) -> f64) -> Vec<f64> {
    let mut filt = kind.filter(bn);
    let fll_only = matches!(kind, Kind::Fll(_));
    let mut prev: Option<f64> = None;
    let steps = run(
        &Trajectory::constant_freq(0.0),
        Signal::clean(),
        T,
        n,
        0.0,
        |s| {
            if fll_only {
                let ef = prev.map_or(0.0, |p| (s.err_cycles - p) / T) + perturb(s.k);
                prev = Some(s.err_cycles);
                filt.update(0.0, ef, T)
            } else {
                let reading = s.err_cycles + perturb(s.k);
                let ef = prev.map_or(0.0, |p| (reading - p) / T);
                prev = Some(reading);
                filt.update(reading, ef, T)
            }
        },
    );
    if fll_only {
        steps
            .windows(2)
            .map(|w| 0.5 * (w[0].nco_hz + w[1].nco_hz))
            .collect()
    } else {
        steps.iter().map(|s| -s.err_cycles).collect()
    }
}

/// Impulse at update 10 (after the FLL discriminator has a previous reading).
const K_IMPULSE: usize = 10;

fn impulse_bn(kind: Kind, bn: f64) -> f64 {
    let n = (25.0 / (bn * T)) as usize + 2000;
    let h = respond(kind, bn, n, |k| if k == K_IMPULSE { 1.0 } else { 0.0 });
    h.iter().map(|v| v * v).sum::<f64>() / (2.0 * T)
}

fn monte_carlo_bn(kind: Kind, bn: f64, seed: u64) -> f64 {
    let sigma = 0.01;
    let n = ((2000.0 / (bn * T)) as usize).max(200_000);
    let mut r = rng(seed);
    let out = respond(kind, bn, n, |_| sigma * gauss(&mut r));
    let skip = (5.0 / (bn * T)) as usize;
    let tail = &out[skip.min(n / 2)..];
    let var = tail.iter().map(|v| v * v).sum::<f64>() / tail.len() as f64;
    var / (2.0 * T * sigma * sigma)
}

/// Measured (Monte Carlo and impulse response) against the transfer-function integral and the
/// design, PLL orders 1-3 and FLL orders 1-2 (FLL: the frequency loop), Bn T = 0.001 .. 0.05.
///
/// Tolerances: impulse response vs TF integral 0.5 % (both exact up to truncation and quadrature);
/// Monte Carlo vs TF 5 % (its standard error is about 2 % with >= 2000/(Bn T) samples, skipping
/// the first 5/(Bn T)); TF vs design: PLL (= DLL) within 5 % for Bn T <= 0.02 and 13 % at 0.05,
/// and every loop between -1 % and +(4 Bn T + 0.5 %), because the digital loop's bandwidth grows
/// as about Bn (1 + c Bn T) with c = 2.0-2.6 for the PLLs (1st order exactly Bn/(1 - 2 Bn T)) and
/// 3.2-4 for the FLLs: a property of the discrete loop, not a defect the test should hide.
#[test]
fn noise_bandwidth_matches_design_and_transfer_function() {
    println!(
        "| loop | Bn T | design Bn (Hz) | TF integral | impulse resp. | Monte Carlo | MC/design |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut seed = 100;
    for kind in [
        Kind::Pll(1),
        Kind::Pll(2),
        Kind::Pll(3),
        Kind::Fll(1),
        Kind::Fll(2),
    ] {
        for bnt in [0.001, 0.005, 0.01, 0.02, 0.05] {
            let bn = bnt / T;
            let tf = noise_bandwidth_hz(&kind.filter(bn), T).unwrap_or(f64::NAN);
            let imp = impulse_bn(kind, bn);
            seed += 1;
            let mc = monte_carlo_bn(kind, bn, seed);
            println!(
                "| {} | {bnt} | {bn:.1} | {tf:.3} | {imp:.3} | {mc:.3} | {:.3} |",
                kind.name(),
                mc / bn
            );
            assert!(
                (imp / tf - 1.0).abs() < 5e-3,
                "{kind:?} {bnt}: impulse {imp} vs TF {tf}"
            );
            assert!(
                (mc / tf - 1.0).abs() < 0.05,
                "{kind:?} {bnt}: MC {mc} vs TF {tf}"
            );
            let excess = tf / bn - 1.0;
            assert!(
                excess > -0.01 && excess < 4.0 * bnt + 0.005,
                "{kind:?} {bnt}: TF {tf} vs design {bn}"
            );
            if matches!(kind, Kind::Pll(_)) {
                let tol = if bnt <= 0.02 { 0.05 } else { 0.13 };
                assert!(excess.abs() < tol, "{kind:?} {bnt}: TF {tf} vs design {bn}");
            }
        }
    }
}

/// Largest stable `Bn T` by bisection on the Schur-Cohn test of the closed loop.
fn stability_limit(kind: Kind) -> f64 {
    let (mut lo, mut hi) = (0.001, 2.0);
    if is_stable(&kind.filter(hi / T), T) {
        return f64::INFINITY;
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if is_stable(&kind.filter(mid / T), T) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Whether the implemented loop's impulse response has died out (last 10 % of 40,000 updates
/// holds less than 1e-6 of the energy) or grown.
fn simulated_decays(kind: Kind, bnt: f64) -> bool {
    let h = respond(kind, bnt / T, 40_000, |k| {
        if k == K_IMPULSE {
            1.0
        } else {
            0.0
        }
    });
    let total: f64 = h.iter().map(|v| v * v).sum();
    let tail: f64 = h[36_000..].iter().map(|v| v * v).sum();
    total.is_finite() && tail < 1e-6 * total
}

/// Departure of the digital Bn from design as Bn T grows, and where each loop goes unstable;
/// the analytic limit is confirmed by simulating the implemented loop 3 % below and above it.
#[test]
fn departure_and_stability_limits() {
    let grid = [0.001, 0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3];
    let mut head = String::from("| loop |");
    for g in grid {
        head.push_str(&format!(" Bn T = {g} |"));
    }
    println!("{head} unstable at Bn T |");
    println!("|---|{}---|", "---|".repeat(grid.len()));
    let kinds = [
        Kind::Pll(1),
        Kind::Pll(2),
        Kind::Pll(3),
        Kind::Fll(1),
        Kind::Fll(2),
        Kind::Assisted(2, 1),
        Kind::Assisted(3, 2),
    ];
    for kind in kinds {
        let limit = stability_limit(kind);
        let mut row = format!("| {} |", kind.name());
        for g in grid {
            match noise_bandwidth_hz(&kind.filter(g / T), T) {
                Some(b) => row.push_str(&format!(" {:.3} |", b / (g / T))),
                None => row.push_str(" unstable |"),
            }
        }
        println!("{row} {limit:.3} |");
        assert!(
            simulated_decays(kind, 0.97 * limit),
            "{kind:?} below {limit}"
        );
        assert!(
            !simulated_decays(kind, 1.03 * limit),
            "{kind:?} above {limit}"
        );
        // Every loop must be stable up to the configuration limit MAX_BN_T = 0.2.
        assert!(
            limit > gpsrx_tracking::config::MAX_BN_T,
            "{kind:?}: {limit}"
        );
    }
    // The 1st-order limit is exact: poles of z^2 + (w0 T/2 - 1) z + w0 T/2 reach |z| = 1 at
    // w0 T = 2, i.e. Bn T = 0.5.
    assert!((stability_limit(Kind::Pll(1)) - 0.5).abs() < 1e-6);
}
