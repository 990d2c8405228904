//! One run: a cell's carrier loop at one C/N0 for the pre-roll and the 30 s window, at the level
//! of 1 ms correlator outputs, and the share of the window in which the receiver reports carrier
//! lock.
//!
//! # Model
//!
//! The residual carrier phase `theta(t)` is the cell's dynamics (a constant-jerk polynomial,
//! [`Trajectory`]). Code period `k` spans `[k, k+1)` ms; the NCO holds frequency `f` over a
//! whole integration interval of `T` ms (phase-continuous, the channel's timing,
//! `gpsrx_tracking::loop_analysis`). For every 1 ms period the prompt is
//! `A d sinc(de) exp(j 2 pi e) + n`: `e` the mean phase error over the period (Simpson's rule,
//! exact for the cubic), `de` its change across the period (integrate-and-dump loss), `d` the
//! data bit (a new random bit every 20 ms), `n` complex Gaussian with unit variance per
//! component and `A = sqrt(2 (C/N0) 1 ms)`: the statistics of `gpsrx_tracking::phase_sim`, per
//! millisecond.
//!
//! The receiver's parts, as a channel runs them in tracking: the `T` prompts of an interval
//! (bit-aligned, as after bit synchronisation) summed into the carrier loop
//! ([`CarrierLoop`]: Costas `atan(Q/I)`, the cell's loop filter), which sets the NCO frequency
//! for the next interval; every 1 ms prompt into the carrier lock detector
//! ([`PllLockDetector`] with the receiver's default [`PllLockConfig`]) and the fade detector
//! ([`FadeDetector`]). **Carrier lock** in a period is what the channel reports in its epoch's
//! `pll_lock`: the lock detector locked and no fade. The detector's 20-prompt blocks are
//! aligned to the bits (as the channel aligns them once the bits are synchronised), and the
//! carrier loop's Costas gain follows the detector's C/N0, as in the channel.
//!
//! The loop starts in its steady state under the dynamics (NCO phase behind by the
//! steady-state error `theta_ss`, frequency on the signal's, a 3rd-order loop's rate memory
//! preset as the channel's hand-over presets it), so that what is measured is holding lock,
//! not pulling in. Nothing restarts a loop that has slipped: it holds lock again only if it
//! finds it by itself.

use super::params::{PRE_ROLL_S, WINDOW_S};
use super::Cell;
use gpsrx_tracking::fade_detector::FadeDetector;
use gpsrx_tracking::loop_filter::{omega0, A2, A3, B3};
use gpsrx_tracking::phase_sim::{NoiseSource, SimRng, Trajectory};
use gpsrx_tracking::{CarrierLoop, PllLockConfig, PllLockDetector};
use num_complex::Complex64;
use std::f64::consts::PI;

/// What one run measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOutcome {
    /// Share of the window's 1 ms periods with carrier lock reported.
    pub held_fraction: f64,
    /// Half-cycle slips of the loop against the truth in the window: the interval's true phase
    /// error moving more than 3/8 cycle from the half cycle the loop held (past the Costas
    /// discriminator's +-1/4 cycle by 1/8, so that noise at the boundary is not counted twice).
    pub half_cycle_slips: u32,
    /// Share of the window before the loop's first slip (1 without a slip): the loop itself
    /// holding the phase, whatever the lock detector reports.
    pub slip_free_fraction: f64,
    /// RMS true phase error over the window (modulo half cycles, so a slip does not count),
    /// deg.
    pub rms_error_deg: f64,
}

impl RunOutcome {
    /// Several runs of the same cell and C/N0 as one: the mean shares, the summed slips and
    /// the RMS error over all of them (`runs` not empty; an empty slice gives zeros).
    pub fn pool(runs: &[RunOutcome]) -> RunOutcome {
        let n = runs.len().max(1) as f64;
        RunOutcome {
            held_fraction: runs.iter().map(|r| r.held_fraction).sum::<f64>() / n,
            half_cycle_slips: runs.iter().map(|r| r.half_cycle_slips).sum(),
            slip_free_fraction: runs.iter().map(|r| r.slip_free_fraction).sum::<f64>() / n,
            rms_error_deg: (runs.iter().map(|r| r.rms_error_deg.powi(2)).sum::<f64>() / n).sqrt(),
        }
    }
}

/// The loop's steady-state phase error under the cell's dynamics, cycles:
/// `(d^n theta/dt^n)/omega0^n` for a loop of order `n` equal to the residual's degree, else 0
/// (orders above the degree follow without error; below it the cell is not run).
pub fn steady_state_error_cycles(cell: &Cell) -> f64 {
    if cell.dynamics.degree() != cell.order || cell.order == 0 {
        return 0.0;
    }
    let n = usize::from(cell.order);
    cell.dynamics.phase_derivatives()[n - 1] / omega0(cell.order, cell.bn_hz).powi(n as i32)
}

/// Runs `cell` at `cn0_dbhz` with noise from `seed` (module docs).
///
/// Errors: the receiver refuses the cell's loop configuration.
pub fn run(cell: &Cell, cn0_dbhz: f64, seed: u64) -> anyhow::Result<RunOutcome> {
    let cfg = cell.loop_config();
    let t_ms = cell.t_coh_ms.max(1) as usize;
    let [v, a, j] = cell.dynamics.phase_derivatives();
    let traj = Trajectory::new(0.0, v, a, &[(0.0, j)]);
    // Steady-state start (module docs): with the error held at theta_ss the filter's
    // proportional path adds k_out theta_ss to the base frequency, and a 3rd-order loop's outer
    // integrator is fed a3 omega0^2 theta_ss on top of its rate memory.
    let theta_ss = steady_state_error_cycles(cell);
    let w0 = omega0(cell.order, cell.bn_hz);
    let (k_out, k_mid) = match cell.order {
        1 => (w0, 0.0),
        2 => (A2 * w0, 0.0),
        _ => (B3 * w0, A3 * w0 * w0),
    };
    // The NCO holds over each interval the signal's mean frequency over it (the first
    // interval's, `v + a T/2 + j T^2/6`, not the frequency at its start: for a 0.4 Hz loop at
    // T = 20 ms under 1 g the difference, 0.5 Hz, is a frequency step it slips on), and a
    // 3rd-order loop's rate memory the mean rate over it.
    let t_s = cell.t_coh_s();
    let f0 = traj.mean_freq_hz(0.0, t_s);
    let mut carrier = CarrierLoop::new(&cfg, f0 - k_out * theta_ss)?;
    if cell.order == 3 {
        carrier.preset_doppler_rate(a + 0.5 * j * t_s - k_mid * theta_ss);
    }
    let mut lock = PllLockDetector::new(PllLockConfig::default());
    let mut fade = FadeDetector::new();
    let mut rng = SimRng::new(seed);
    let amp = (2.0 * 10f64.powf(cn0_dbhz / 10.0) * 1e-3).sqrt();
    // Bits start at every 20th period from 0, the detector's blocks with them.
    let detector_start = 0;
    let window_start = detector_start + (PRE_ROLL_S * 1e3).round() as usize;
    let n_ms = window_start + (WINDOW_S * 1e3).round() as usize;
    let (mut phi, mut f) = (-theta_ss, f0);
    let mut acc = Complex64::new(0.0, 0.0);
    let mut bit = 1.0;
    let (mut held, mut counted) = (0usize, 0usize);
    let (mut slips, mut half, mut sum_e2, mut n_e) = (0u32, None::<f64>, 0.0, 0usize);
    let mut first_slip_ms = None;
    for k in 0..n_ms {
        let t0 = k as f64 * 1e-3;
        let t1 = t0 + 1e-3;
        if k % 20 == 0 {
            bit = if rng.data_bit() { 1.0 } else { -1.0 };
        }
        let (th0, th1) = (traj.phase(t0), traj.phase(t1));
        let e = traj.mean_phase(t0, t1) - (phi + 0.5 * f * 1e-3);
        let de = (th1 - th0) - f * 1e-3;
        let sinc = if de.abs() < 1e-12 {
            1.0
        } else {
            (PI * de).sin() / (PI * de)
        };
        let re = rng.gauss();
        let p =
            Complex64::from_polar(amp * bit * sinc, 2.0 * PI * e) + Complex64::new(re, rng.gauss());
        phi += f * 1e-3;
        acc += p;
        if k >= detector_start {
            let locked = lock.update(p);
            carrier.set_cn0_hz(lock.cn0_hz(1e-3));
            if (k + 1) % 20 == 0 {
                // The next period starts a bit: the channel aligns the detector's blocks to the
                // bits once they are synchronised.
                lock.align_block();
            }
            fade.push(p);
            if k >= window_start {
                counted += 1;
                held += usize::from(locked && !fade.faded());
            }
        }
        if (k + 1) % t_ms == 0 {
            f = carrier.update(acc, 0.0).nco_freq_hz;
            acc = Complex64::new(0.0, 0.0);
            if k >= window_start {
                let h = *half.get_or_insert((2.0 * e).round());
                let h = if (e - 0.5 * h).abs() > 0.375 {
                    slips += 1;
                    first_slip_ms.get_or_insert(k + 1);
                    (2.0 * e).round()
                } else {
                    h
                };
                half = Some(h);
                let r = e - 0.5 * h;
                sum_e2 += r * r;
                n_e += 1;
            }
        }
    }
    Ok(RunOutcome {
        held_fraction: held as f64 / counted.max(1) as f64,
        half_cycle_slips: slips,
        slip_free_fraction: first_slip_ms.map_or(1.0, |k| {
            (k - window_start) as f64 / (n_ms - window_start) as f64
        }),
        rms_error_deg: 360.0 * (sum_e2 / n_e.max(1) as f64).sqrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::Dynamics;
    use super::*;

    fn cell(order: u8, bn_hz: f64, t_coh_ms: u32, dynamics: Dynamics) -> Cell {
        Cell {
            order,
            bn_hz,
            t_coh_ms,
            dynamics,
        }
    }

    /// At 45 dB-Hz every loop holds lock the whole window, its phase jitter is the thermal
    /// formula's (within 20 %: Bn T = 0.018 keeps the digital loop near its design bandwidth),
    /// and under a stress its mean error sits at the steady state the start assumed.
    #[test]
    fn a_strong_signal_is_held_with_the_formula_jitter() -> anyhow::Result<()> {
        let c = cell(2, 18.0, 1, Dynamics::Static);
        let out = run(&c, 45.0, 3)?;
        assert_eq!(out.held_fraction, 1.0);
        assert_eq!(out.half_cycle_slips, 0);
        let want = gpsrx_tracking::phase_sim::pll_jitter_deg(18.0, 45.0, 1e-3);
        assert!(
            (out.rms_error_deg / want - 1.0).abs() < 0.2,
            "{} vs {want}",
            out.rms_error_deg
        );
        // 1 g into a 2nd-order 18 Hz loop: 16.1 deg steady-state error, held.
        let c = cell(2, 18.0, 1, Dynamics::AccelUnaided { g: 1.0 });
        assert!((steady_state_error_cycles(&c) * 360.0 - 16.08).abs() < 0.05);
        let out = run(&c, 45.0, 3)?;
        assert_eq!(out.held_fraction, 1.0);
        assert!(
            (out.rms_error_deg - 16.08).abs() < 1.0,
            "{}",
            out.rms_error_deg
        );
        Ok(())
    }

    /// A 3rd-order 0.4 Hz loop at T = 20 ms under 1 g starts in its steady state: no slip and
    /// no error beyond the interval-average offset `a T^2/12` (0.0017 cycle, 0.62 deg) and the
    /// thermal jitter (0.1 deg at 50 dB-Hz). Started on the frequency at t = 0 instead of the
    /// first interval's mean (0.5 Hz off) it slipped in the first second.
    #[test]
    fn a_third_order_loop_starts_in_its_steady_state_under_acceleration() -> anyhow::Result<()> {
        for t_coh_ms in [1, 20] {
            let c = cell(3, 0.4, t_coh_ms, Dynamics::AccelUnaided { g: 1.0 });
            let out = run(&c, 50.0, 1)?;
            assert_eq!(out.slip_free_fraction, 1.0, "{out:?}");
            assert!(out.rms_error_deg < 0.8, "T {t_coh_ms} ms: {out:?}");
        }
        Ok(())
    }

    /// At 15 dB-Hz and T = 1 ms (prompt SNR -15 dB) no loop holds; and a 2nd-order loop under a
    /// constant jerk (error growing without bound) loses lock at any C/N0.
    #[test]
    fn a_weak_signal_or_an_unbounded_stress_is_not_held() -> anyhow::Result<()> {
        let out = run(&cell(2, 18.0, 1, Dynamics::Static), 15.0, 3)?;
        assert!(out.held_fraction < 0.5, "{out:?}");
        let c = cell(2, 18.0, 1, Dynamics::JerkUnaided { g_per_s: 10.0 });
        let out = run(&c, 50.0, 3)?;
        assert!(
            out.held_fraction < 0.5 && out.half_cycle_slips > 0,
            "{out:?}"
        );
        Ok(())
    }
}
