//! FLL frequency jitter and FLL-assisted PLL pull-in.

use num_complex::Complex64;
use std::f64::consts::PI;

use gpsrx_tracking::{CarrierLoop, LoopConfig, PllLockConfig, PllLockDetector};

use crate::sim::{run, std, Signal, Step, Trajectory};

const T: f64 = 1e-3;

fn carrier(cfg: &LoopConfig) -> CarrierLoop {
    match CarrierLoop::new(cfg, 0.0) {
        Ok(l) => l,
        Err(e) => panic!("{e}"),
    }
}

fn fll_cfg(order: u8, bn: f64) -> LoopConfig {
    LoopConfig {
        pll_order: 0,
        fll_order: order,
        fll_bw_hz: bn,
        t_coh_s: T,
        ..LoopConfig::default()
    }
}

/// Oracle FLL jitter (Hz): `(1/(2 pi T)) sqrt((4 F Bn/CN0)(1 + 1/(T CN0)))`, F = 1.
fn fll_oracle_hz(bn: f64, cn0_dbhz: f64) -> f64 {
    let c = 10f64.powf(cn0_dbhz / 10.0);
    (1.0 / (2.0 * PI * T)) * ((4.0 * bn / c) * (1.0 + 1.0 / (T * c))).sqrt()
}

/// Linear prediction for this implementation: the response `g_k` of the NCO frequency error to a
/// phase perturbation `delta` of one prompt (noise-free run with and without it), times the
/// per-prompt phase-noise variance `1/(2 CN0 T)` rad^2: `var = sigma_phi^2 sum g_k^2`.
fn fll_linear_prediction_hz(order: u8, bn: f64, cn0_dbhz: f64) -> f64 {
    let n = (30.0 / (bn * T)) as usize;
    let k0 = 100;
    let delta = 1e-4; // cycles
    let traj = Trajectory::constant_freq(0.0);
    let freq_err = |perturb: bool| -> Vec<f64> {
        let mut l = carrier(&fll_cfg(order, bn));
        run(&traj, Signal::clean(), T, n, 0.0, |s| {
            let p = if perturb && s.k == k0 {
                s.prompt * Complex64::from_polar(1.0, 2.0 * PI * delta)
            } else {
                s.prompt
            };
            l.update(p, 0.0).nco_freq_hz
        })
        .iter()
        .map(|s| s.nco_hz - s.true_hz)
        .collect()
    };
    let (a, b) = (freq_err(false), freq_err(true));
    let sum_g2: f64 = a
        .iter()
        .zip(&b)
        .map(|(x, y)| ((y - x) / delta).powi(2))
        .sum();
    let c = 10f64.powf(cn0_dbhz / 10.0);
    let sigma_phi_cycles2 = 1.0 / (2.0 * c * T) / (2.0 * PI).powi(2);
    (sigma_phi_cycles2 * sum_g2).sqrt()
}

/// Frequency-error jitter of a pure FLL (data-insensitive cross/dot discriminator, data bits on)
/// at 45 dB-Hz, T = 1 ms.
///
/// The oracle formula models the discriminator noise as white. Consecutive cross/dot pairs share
/// a prompt, so the discriminator noise is the first difference of white phase noise, whose
/// spectrum vanishes at DC: the loop filters it far better than white noise of the same
/// variance. The test therefore compares (a) with the linear prediction for this implementation
/// (tolerance 15 %: 60 s runs give a ~3 % standard error; the rest is the atan nonlinearity at
/// a per-prompt phase noise of 7 deg) and (b) checks that the oracle is a bound (printed ratio).
#[test]
fn fll_frequency_jitter() {
    println!("| FLL order | Bn (Hz) | C/N0 | measured (Hz) | linear prediction (Hz) | oracle (Hz) | measured/oracle |");
    println!("|---|---|---|---|---|---|---|");
    let mut seed = 900;
    for order in [1u8, 2] {
        for bn in [2.0, 5.0, 10.0] {
            let cn0 = 45.0;
            seed += 1;
            let mut l = carrier(&fll_cfg(order, bn));
            let n = (60.0 / T) as usize;
            let steps = run(
                &Trajectory::constant_freq(0.0),
                Signal::noisy(cn0, seed),
                T,
                n,
                0.0,
                |s| l.update(s.prompt, 0.0).nco_freq_hz,
            );
            let fe: Vec<f64> = steps[2000..].iter().map(|s| s.nco_hz - s.true_hz).collect();
            let got = std(&fe);
            let lin = fll_linear_prediction_hz(order, bn, cn0);
            let oracle = fll_oracle_hz(bn, cn0);
            println!(
                "| {order} | {bn} | {cn0} | {got:.4} | {lin:.4} | {oracle:.3} | {:.3} |",
                got / oracle
            );
            assert!(
                (got / lin - 1.0).abs() < 0.15,
                "order {order} Bn {bn}: {got} vs {lin}"
            );
            assert!(got < oracle);
        }
    }
}

/// Pull-in time: the time after which the Costas phase error stays within +-30 deg (mod 180 deg)
/// until the end of the run (7 sigma of the thermal jitter at 35 dB-Hz, so noise alone does not
/// reset it; staying in phase lock implies frequency lock).
fn pull_in_time(steps: &[Step]) -> f64 {
    let bad = |e: f64| (e - (e * 2.0).round() / 2.0).abs() * 360.0 > 30.0;
    steps
        .iter()
        .rposition(|s| bad(s.err_cycles))
        .map_or(0.0, |i| (i + 1) as f64 * T)
}

/// Runs a carrier loop from NCO frequency 0 against a constant Doppler `df` for `n` updates; the
/// FLL assist is switched off after `assist_s` seconds (the channel's hand-over policy).
fn pull_in_run(
    cfg: &LoopConfig,
    df: f64,
    cn0: f64,
    seed: u64,
    n: usize,
    assist_s: f64,
) -> (f64, bool, f64) {
    let mut l = carrier(cfg);
    let mut lock = PllLockDetector::new(PllLockConfig::default());
    let mut locked = false;
    let steps = run(
        &Trajectory::constant_freq(df),
        Signal::noisy(cn0, seed),
        T,
        n,
        0.0,
        |s| {
            if s.k as f64 * T >= assist_s {
                l.set_fll_assist(false);
            }
            locked = lock.update(s.prompt);
            l.update(s.prompt, 0.0).nco_freq_hz
        },
    );
    (pull_in_time(&steps), locked, lock.cos_2phi())
}

fn assisted(po: u8, fo: u8, fll_bw: f64) -> LoopConfig {
    LoopConfig {
        pll_order: po,
        pll_bw_hz: 15.0,
        fll_order: fo,
        fll_bw_hz: fll_bw,
        t_coh_s: T,
        ..LoopConfig::default()
    }
}

/// FLL-assisted PLL pull-in from 100, 150 and 200 Hz (the data-insensitive FLL at T = 1 ms reaches
/// +-250 Hz), PLL Bn 15 Hz, FLL Bn 10 Hz, data bits on.
///
/// - 45 dB-Hz, assist kept on: PLL2 + FLL1 pulls in within 0.3 s and PLL3 + FLL2 (lightly damped
///   slow pole pair) within 0.6 s (stated bounds); the lock detector reports lock.
/// - 35 dB-Hz: with the assist kept on the phase jitter is 30-40 deg (each fold of the
///   data-insensitive discriminator at +-90 deg of phase change, ~0.5 % of updates at a
///   per-prompt phase noise of 23 deg, kicks the NCO by ~20 Hz), so the channel must hand over to
///   the PLL alone. PLL2 + FLL1 with the assist switched off at 0.3 s pulls in within 2 s (stated
///   bound; typically 0.2-0.7 s, the tail comes from cycle slips of the PLL pulling in the FLL's
///   residual error of ~10 Hz) in all 8 seeds at each offset. PLL3 + FLL2 is not reliable at 35 dB-Hz (its rate
///   integrator is corrupted by the same kicks): printed, not asserted; pull in with PLL2 + FLL1 and
///   then start a PLL3 at the reached frequency instead.
/// - A PLL2 alone at 15 Hz does not pull in from 100 Hz (printed for contrast).
#[test]
fn fll_assisted_pll_pull_in() {
    println!("| loop | C/N0 | FLL assist | initial error (Hz) | pull-in time (s), per seed | locked at end |");
    println!("|---|---|---|---|---|---|");
    let mut seed = 4000;
    let n = 3000;
    struct Case {
        name: &'static str,
        cfg: LoopConfig,
        cn0: f64,
        assist_s: f64,
        seeds: usize,
        bound_s: Option<f64>,
    }
    let case = |name, cfg, cn0, assist_s, seeds, bound_s| Case {
        name,
        cfg,
        cn0,
        assist_s,
        seeds,
        bound_s,
    };
    let cases = [
        case(
            "PLL2 15 Hz + FLL1 10 Hz",
            assisted(2, 1, 10.0),
            45.0,
            f64::INFINITY,
            2,
            Some(0.3),
        ),
        case(
            "PLL3 15 Hz + FLL2 10 Hz",
            assisted(3, 2, 10.0),
            45.0,
            f64::INFINITY,
            2,
            Some(0.6),
        ),
        case(
            "PLL2 15 Hz + FLL1 10 Hz",
            assisted(2, 1, 10.0),
            35.0,
            0.3,
            8,
            Some(2.0),
        ),
        case(
            "PLL3 15 Hz + FLL2 10 Hz",
            assisted(3, 2, 10.0),
            35.0,
            0.5,
            4,
            None,
        ),
        case("PLL2 15 Hz alone", assisted(2, 0, 10.0), 45.0, 0.0, 1, None),
    ];
    for Case {
        name,
        cfg,
        cn0,
        assist_s,
        seeds,
        bound_s,
    } in cases
    {
        for df in [100.0, 150.0, 200.0] {
            let mut times = Vec::new();
            let mut all_locked = true;
            for _ in 0..seeds {
                seed += 1;
                let (t_pull, locked, _) = pull_in_run(&cfg, df, cn0, seed, n, assist_s);
                times.push(t_pull);
                all_locked &= locked;
            }
            let shown: Vec<String> = times
                .iter()
                .map(|t| {
                    if *t < (n as f64 - 50.0) * T {
                        format!("{t:.2}")
                    } else {
                        "none".into()
                    }
                })
                .collect();
            let assist = if cfg.fll_order == 0 {
                "none".to_string()
            } else if assist_s.is_finite() {
                format!("off after {assist_s} s")
            } else {
                "on".to_string()
            };
            println!(
                "| {name} | {cn0} | {assist} | {df} | {} | {all_locked} |",
                shown.join(" ")
            );
            if let Some(b) = bound_s {
                assert!(
                    times.iter().all(|t| *t < b),
                    "{name} {cn0} dB-Hz {df} Hz: {times:?}"
                );
                assert!(all_locked);
            }
        }
    }
}
