//! Steady-state dynamic errors of the implemented carrier loops against the table
//! (`oracles.md` "Loop filters": theta_e = (d^n R/dt^n)/omega0^n for an order-n loop).
//!
//! All runs are noise-free and use the real `CarrierLoop` (Costas discriminator on the simulated
//! prompt), so the discriminator nonlinearity and the digital timing are included. The analog
//! steady-state formulas hold exactly for the digital loop too (in steady state the integrator
//! ramp rate must equal the input's, which fixes the error), so the 10 % tolerance asked for is
//! loose; the assertions use it and the printed ratios show the actual agreement.

use gpsrx_tracking::loop_filter::omega0;
use gpsrx_tracking::{CarrierLoop, LoopConfig};

use crate::sim::{g_to_hz_s, run, Signal, Trajectory};

fn pll_cfg(order: u8, bn: f64, t: f64) -> LoopConfig {
    LoopConfig {
        pll_order: order,
        pll_bw_hz: bn,
        fll_order: 0,
        t_coh_s: t,
        ..LoopConfig::default()
    }
}

fn carrier(cfg: &LoopConfig) -> CarrierLoop {
    match CarrierLoop::new(cfg, 0.0) {
        Ok(l) => l,
        Err(e) => panic!("{e}"),
    }
}

/// Final true phase error (degrees) of a noise-free run of `dur_s`.
fn final_error_deg(order: u8, bn: f64, t: f64, traj: &Trajectory, dur_s: f64) -> f64 {
    let mut l = carrier(&pll_cfg(order, bn, t));
    let steps = run(traj, Signal::clean(), t, (dur_s / t) as usize, 0.0, |s| {
        l.update(s.prompt, 0.0).nco_freq_hz
    });
    steps.last().map_or(f64::NAN, |s| s.err_cycles * 360.0)
}

fn check(what: &str, got: f64, want: f64, tol: f64) {
    println!(
        "{what}: measured {got:.3} deg, table {want:.3} deg, ratio {:.4}",
        got / want
    );
    assert!((got / want - 1.0).abs() < tol, "{what}: {got} vs {want}");
}

/// 1st order under constant LOS velocity: theta_e = (dR/dt)/omega0.
#[test]
fn first_order_velocity_error() {
    for (bn, v_mps) in [(15.0, 1.0), (10.0, 0.5), (5.0, 0.2)] {
        for t in [1e-3, 5e-3] {
            let f = v_mps / crate::sim::LAMBDA; // Hz
            let want = 360.0 * f / omega0(1, bn);
            let got = final_error_deg(1, bn, t, &Trajectory::constant_freq(f), 3.0);
            check(
                &format!("PLL1 Bn {bn} T {t} v {v_mps} m/s"),
                got,
                want,
                0.10,
            );
        }
    }
}

/// 2nd order under constant LOS acceleration: theta_e = (d2R/dt2)/omega0^2
/// = 0.2809 * a[deg/s^2] / Bn^2 (1 g = 18,552 deg/s^2).
#[test]
fn second_order_acceleration_error() {
    for (bn, g) in [(18.0, 1.0), (10.0, 0.5), (5.0, 0.1), (2.0, 0.02)] {
        for t in [1e-3, 20e-3] {
            if bn * t > 0.1 {
                continue;
            }
            let a = g_to_hz_s(g); // Hz/s
            let want = 360.0 * a / omega0(2, bn).powi(2);
            let oracle_form = 0.2809 * g * 18_552.0 / (bn * bn);
            assert!((want / oracle_form - 1.0).abs() < 2e-3);
            let traj = Trajectory::new(0.0, 0.0, a, &[]);
            let got = final_error_deg(2, bn, t, &traj, 12.0 / bn + 2.0);
            check(&format!("PLL2 Bn {bn} T {t} a {g} g"), got, want, 0.10);
        }
    }
}

/// 3rd order under constant LOS jerk: theta_e = (d3R/dt3)/omega0^3 = 0.4828 j[deg/s^3]/Bn^3.
#[test]
fn third_order_jerk_error() {
    for (bn, gps) in [(12.0, 5.0), (18.0, 10.0), (6.0, 0.5)] {
        let t = 1e-3;
        let j = g_to_hz_s(gps); // Hz/s^2
        let want = 360.0 * j / omega0(3, bn).powi(3);
        let oracle_form = 0.4828 * gps * 18_552.0 / (bn * bn * bn);
        assert!((want / oracle_form - 1.0).abs() < 2e-3);
        let traj = Trajectory::new(0.0, 0.0, 0.0, &[(0.0, j)]);
        let got = final_error_deg(3, bn, t, &traj, 15.0 / bn + 1.0);
        check(&format!("PLL3 Bn {bn} a' {gps} g/s"), got, want, 0.10);
    }
}

/// 2nd order under constant jerk: the error grows without bound. Asymptotically
/// `e(t) = (j/omega0^2)(t - a2/omega0)` (partial fractions of `j / (s^2 (s^2 + a2 w s + w^2))`),
/// so it crosses the Costas rule-of-thumb limit of 45 deg at
/// `t45 = 45 deg * omega0^2 / j + a2/omega0`; the quasi-static table reading
/// `theta_e(t) = (j t)/omega0^2` gives `45 omega0^2/j`. Then the loop slips cycles.
#[test]
fn second_order_under_jerk_loses_lock_on_time() {
    for (bn, gps) in [(10.0, 1.0), (5.0, 0.2), (15.0, 3.0)] {
        let t = 1e-3;
        let j = g_to_hz_s(gps);
        let w = omega0(2, bn);
        let t45 = (45.0 / 360.0) * w * w / j + gpsrx_tracking::loop_filter::A2 / w;
        let t45_quasi_static = (45.0 / 360.0) * w * w / j;
        let mut l = carrier(&pll_cfg(2, bn, t));
        let traj = Trajectory::new(0.0, 0.0, 0.0, &[(0.0, j)]);
        let steps = run(
            &traj,
            Signal::clean(),
            t,
            (3.0 * t45 / t) as usize,
            0.0,
            |s| l.update(s.prompt, 0.0).nco_freq_hz,
        );
        let crossing = steps
            .iter()
            .find(|s| s.err_cycles.abs() * 360.0 > 45.0)
            .map_or(f64::NAN, |s| s.t0 + 0.5 * t);
        let max_err = steps.iter().fold(0.0_f64, |m, s| m.max(s.err_cycles.abs()));
        println!(
            "PLL2 Bn {bn} under {gps} g/s: 45 deg crossed at {crossing:.4} s, predicted {t45:.4} s \
             (quasi-static {t45_quasi_static:.4} s); max |error| afterwards {max_err:.2} cycles"
        );
        assert!((crossing / t45 - 1.0).abs() < 0.10);
        assert!(max_err > 0.5, "should have slipped at least a half cycle");
    }
}
