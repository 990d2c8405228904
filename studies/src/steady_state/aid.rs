//! The feed-forward (aiding) generator of one cell.

use gpsrx_ins_aiding::BandLimiter;
use gpsrx_tracking::phase_sim::{Trajectory, LAMBDA_M};

use super::{Aiding, Cell};

/// Band-limiter sub-steps per integration interval.
const LIMITER_SUBSTEPS: usize = 16;

/// The feed-forward generator of one cell: called once per interval, in order, for the mean
/// Doppler to hold over the interval starting at `t_s`.
pub(super) struct Aid<'a> {
    traj: &'a Trajectory,
    aiding: Aiding,
    t_coh_s: f64,
    bias_hz_s: f64,
    limiter: BandLimiter,
}

impl<'a> Aid<'a> {
    pub(super) fn new(traj: &'a Trajectory, cell: &Cell) -> Self {
        let mut limiter = BandLimiter::new(cell.aid.alpha_rad_s);
        // The first step initialises the limiter to the true Doppler at t = 0.
        limiter.step(traj.at(0.0).1, 0.0);
        Self {
            traj,
            aiding: cell.aiding,
            t_coh_s: cell.t_coh_s,
            bias_hz_s: cell.aid.b_v_mps2 / LAMBDA_M,
            limiter,
        }
    }

    /// Feed-forward (Hz) for `[t_s, t_s + T]`: unaided 0; perfect `mean f_true`; biased
    /// `mean f_true + (B_V/lambda)(t + T/2)`; band-limited: the limiter stepped over the interval
    /// with the true Doppler at each sub-step's middle held (ZOH), its output averaged by the
    /// trapezoid rule.
    pub(super) fn next(&mut self, t_s: f64) -> f64 {
        let t = self.t_coh_s;
        match self.aiding {
            Aiding::Unaided => 0.0,
            Aiding::Perfect => self.traj.mean_freq_hz(t_s, t_s + t),
            Aiding::BiasedIns => {
                self.traj.mean_freq_hz(t_s, t_s + t) + self.bias_hz_s * (t_s + 0.5 * t)
            }
            Aiding::BandLimited => {
                let h = t / LIMITER_SUBSTEPS as f64;
                let mut y0 = self.limiter.output().unwrap_or(0.0);
                let mut sum = 0.0;
                for i in 0..LIMITER_SUBSTEPS {
                    let u = self.traj.at(t_s + (i as f64 + 0.5) * h).1;
                    let y1 = self.limiter.step(u, h);
                    sum += 0.5 * (y0 + y1);
                    y0 = y1;
                }
                sum / LIMITER_SUBSTEPS as f64
            }
        }
    }
}
