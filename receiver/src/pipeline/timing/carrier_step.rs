//! The step of a satellite's carrier phase over lost samples.
//!
//! A channel's signal phase at a report is its NCO phase plus the prompt's residual,
//! `psi = 2 pi phi_NCO + atan(Q / I)` (Costas: the residual is modulo half a cycle, and a
//! small one in lock). The NCO phase is accumulated continuously as a function of the sample
//! index, also over a jump and over a code realignment, so `psi` is unwrapped. Before the
//! jump, `psi` is fitted by a quadratic in time (phase, frequency and Doppler rate); after it,
//! the signal's phase is ahead of that prediction by what it did during the lost time `g`:
//!
//! `step = Phi(t + g) - Phi(t) = 2 pi (f(t) g + f'(t) g^2 / 2)` (modulo pi),
//!
//! with `f(t)` the frequency at the reports after the jump. A quadratic over up to a second
//! predicts the phase a few tenths of a second ahead to a few hundredths of a radian at
//! 40 dB-Hz (per-report noise `1 / sqrt(2 C/N0 T)`, 0.22 rad), and the frequency to a few
//! hundredths of a hertz, so gaps of half a second are still resolved; a linear fit over
//! 80 ms (the first version) was off by 0.2 rad after 0.15 s and by 0.6 rad over a 0.5 s gap.
//! Under dynamics the quadratic stops describing the phase over long windows: the window is
//! shortened until the fit's residuals are those of the noise.

use crate::pipeline::timing::modulo::nearest_remainder;
use gpsrx_tracking::ChannelEpoch;
use std::f64::consts::{PI, TAU};

/// A channel's carrier at one report: NCO and residual phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NcoPoint {
    /// Sample index of the report's start.
    pub sample: u64,
    /// Accumulated NCO phase at it, cycles.
    pub phase_cycles: f64,
    /// NCO frequency over the report, Hz.
    pub freq_hz: f64,
    /// Integration time, s.
    pub t_coh_s: f64,
    /// Residual phase of the prompt, `atan(Q / I)`, rad.
    pub residual_rad: f64,
    /// Standard deviation of the residual from the C/N0, `1 / sqrt(2 C/N0 T)`, rad.
    pub sigma_rad: f64,
}

impl NcoPoint {
    /// The carrier of report `e`.
    pub fn of(e: &ChannelEpoch) -> Self {
        let cn0 = 10f64.powf(e.cn0_dbhz / 10.0);
        let sigma = (1.0 / (2.0 * cn0 * e.t_coh_s)).sqrt();
        Self {
            sample: e.sample_index,
            phase_cycles: e.carrier_phase_cycles,
            freq_hz: e.doppler_hz,
            t_coh_s: e.t_coh_s,
            residual_rad: if e.prompt.re != 0.0 {
                (e.prompt.im / e.prompt.re).atan()
            } else {
                0.0
            },
            sigma_rad: if sigma.is_finite() { sigma } else { 1.0 },
        }
    }

    /// The signal's carrier phase at the middle of the report, rad: the NCO phase there plus
    /// the prompt's residual.
    fn signal_phase_rad(&self) -> f64 {
        TAU * (self.phase_cycles + 0.5 * self.freq_hz * self.t_coh_s) + self.residual_rad
    }
}

/// A satellite's carrier-phase step over lost samples, with the carrier it had.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseStep {
    /// PRN.
    pub prn: u8,
    /// The step, rad (modulo pi).
    pub step_rad: f64,
    /// Carrier frequency at the reports after the jump, Hz.
    pub freq_hz: f64,
    /// Its rate, Hz/s.
    pub rate_hz_s: f64,
}

impl PhaseStep {
    /// The step that `g_s` seconds of lost signal would make, rad (not folded):
    /// `2 pi (f g + f' g^2 / 2)`.
    pub fn predicted_rad(&self, g_s: f64) -> f64 {
        TAU * (self.freq_hz * g_s + 0.5 * self.rate_hz_s * g_s * g_s)
    }
}

/// Windows tried for the fit before a jump, reports, longest first.
const FIT_WINDOWS: [usize; 4] = [1000, 500, 250, 120];
/// A fit is taken when the RMS of its residuals is at most this many times the noise.
const FIT_RMS_RATIO: f64 = 1.4;

/// The quadratic `y = a + b t + c t^2`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Quadratic {
    a: f64,
    b: f64,
    c: f64,
}

impl Quadratic {
    /// Its value at `t`.
    pub(crate) fn at(&self, t: f64) -> f64 {
        self.a + self.b * t + self.c * t * t
    }

    /// Least squares through `(t, y)` (normal equations of 1, t, t^2, solved by nalgebra).
    pub(crate) fn fit(pts: &[(f64, f64)]) -> Option<Self> {
        let mut m = nalgebra::Matrix3::<f64>::zeros();
        let mut v = nalgebra::Vector3::<f64>::zeros();
        for &(t, y) in pts {
            let row = nalgebra::Vector3::new(1.0, t, t * t);
            m += row * row.transpose();
            v += row * y;
        }
        let x = m.lu().solve(&v)?;
        Some(Self {
            a: x[0],
            b: x[1],
            c: x[2],
        })
    }
}

/// The step of the signal's carrier phase (rad, modulo pi) between the reports `pre` (before
/// a jump, oldest first) and `post` (after it), with the frequency at `post` and the rate
/// (see the module documentation). Phases are taken relative to the line of the mean NCO
/// frequency of the last window (small numbers for the fit); `None` when no window fits or
/// there are too few reports.
pub fn phase_step(prn: u8, pre: &[NcoPoint], post: &[NcoPoint], fs_hz: f64) -> Option<PhaseStep> {
    let r = pre.last()?;
    if pre.len() < 40 || post.is_empty() {
        return None;
    }
    let t = |p: &NcoPoint| (p.sample as f64 - r.sample as f64) / fs_hz;
    let sigma = {
        let mut s: Vec<f64> = pre.iter().map(|p| p.sigma_rad).collect();
        s.sort_by(f64::total_cmp);
        s[s.len() / 2].max(0.02)
    };
    for w in FIT_WINDOWS.iter().map(|&w| w.min(pre.len())) {
        let win = &pre[pre.len() - w..];
        let f_ref = win.iter().map(|p| p.freq_hz).sum::<f64>() / w as f64;
        let psi = |p: &NcoPoint| p.signal_phase_rad() - r.signal_phase_rad() - TAU * f_ref * t(p);
        let pts: Vec<(f64, f64)> = win.iter().map(|p| (t(p), psi(p))).collect();
        let Some(q) = Quadratic::fit(&pts) else {
            continue;
        };
        let rms = (pts
            .iter()
            .map(|&(ti, y)| (y - q.at(ti)).powi(2))
            .sum::<f64>()
            / w as f64)
            .sqrt();
        tracing::trace!("PRN {prn}: fit over {w} reports, rms {rms:.3} rad, sigma {sigma:.3} rad");
        if rms > FIT_RMS_RATIO * sigma && w > FIT_WINDOWS[3] {
            continue;
        }
        if rms > FIT_RMS_RATIO * sigma {
            return None;
        }
        let z: num_complex::Complex64 = post
            .iter()
            .map(|p| num_complex::Complex64::from_polar(1.0, 2.0 * (psi(p) - q.at(t(p)))))
            .sum();
        let t_post = post.iter().map(t).sum::<f64>() / post.len() as f64;
        return Some(PhaseStep {
            prn,
            step_rad: nearest_remainder(0.5 * z.arg(), PI),
            freq_hz: f_ref + (q.b + 2.0 * q.c * t_post) / TAU,
            rate_hz_s: q.c / PI,
        });
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const FS: f64 = 2.6e6;

    /// Reports of a carrier `phi(t) = f0 t + r t^2 / 2` (cycles) tracked by an NCO that holds
    /// it exactly, with deterministic residual noise of `sigma` rad; from `jump_at_s` on, the
    /// signal is `g_s` ahead (samples lost).
    fn reports(f0: f64, r: f64, sigma: f64, jump_at_s: f64, g_s: f64, n: usize) -> Vec<NcoPoint> {
        let phi = |t: f64| f0 * t + 0.5 * r * t * t;
        (0..n)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let lost = if t >= jump_at_s { g_s } else { 0.0 };
                let noise = sigma * ((k as f64 * 12.9898).sin() * 43_758.545_3).fract() * 1.7;
                let signal = phi(t + lost + 0.5e-3);
                let nco = phi(t) + 0.5e-3 * (f0 + r * t);
                NcoPoint {
                    sample: (t * FS).round() as u64,
                    phase_cycles: phi(t),
                    freq_hz: f0 + r * t,
                    t_coh_s: 1e-3,
                    residual_rad: nearest_remainder(TAU * (signal - nco) + noise, PI),
                    sigma_rad: sigma,
                }
            })
            .collect()
    }

    #[test]
    fn a_half_second_gap_is_measured_with_the_doppler_rate_and_after_a_relock_delay() {
        // 1.2 s before the jump; the step measured 0.15 s after it (a code realignment).
        for (f0, r) in [(-3186.2, 0.8), (637.8, -0.6), (1963.2, 0.3)] {
            for g in [1.25e-3, 0.5] {
                let pts = reports(f0, r, 0.2, 1.2, g, 1400);
                let pre = &pts[..1195];
                let post = &pts[1350..1370];
                let s = phase_step(7, pre, post, FS).expect("step");
                let f_post = f0 + r * 1.36;
                let want = TAU * (f_post * g + 0.5 * r * g * g);
                let err = nearest_remainder(s.step_rad - want, PI);
                assert!(err.abs() < 0.1, "f0 {f0} g {g}: err {err} rad");
                assert!((s.freq_hz - f_post).abs() < 0.05, "{s:?}");
                assert!((s.rate_hz_s - r).abs() < 0.1, "{s:?}");
            }
        }
    }

    #[test]
    fn a_phase_that_no_quadratic_follows_gives_no_step() {
        // A half-cycle slip in every window: no fit passes the residual test.
        let mut pts = reports(500.0, 0.0, 0.05, 10.0, 0.0, 1000);
        for (k, p) in pts.iter_mut().enumerate() {
            if k % 60 >= 30 {
                p.phase_cycles += 0.25;
            }
        }
        assert!(phase_step(1, &pts[..900], &pts[950..970], FS).is_none());
    }
}
