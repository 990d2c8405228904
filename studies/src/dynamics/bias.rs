//! The INS-bias error of an aided case against seed 004's theory (eqs. 12-16).

use super::aiding::{bias_direction_enu, Aiding};
use super::grid::Case;
use super::scenario::Prepared;
use super::stats::{mean_and_slope, MIN_SAMPLES};
use super::track::ChannelLog;
use crate::if_sim;
use gpsrx_dsp::constants::LAMBDA_L1_M;
use gpsrx_tracking::loop_filter::BN_OVER_OMEGA0;

/// Block length of the cycle-slip test ([`if_sim::half_cycle_slips`]), epochs (20 ms).
const SLIP_BLOCK_EPOCHS: usize = 20;

/// The INS-bias error of an aided case, measured and predicted, averaged over the satellites
/// that were in Track for at least half of the window without a cycle slip (NaN unaided, or
/// when there is none).
#[derive(Debug, Clone, Copy)]
pub(super) struct BiasStats {
    /// Mean over satellites of |mean discriminator error|, deg.
    pub(super) mean_abs_deg: f64,
    /// Its theory, deg.
    pub(super) predicted_deg: f64,
    /// Mean over satellites of |least-squares slope of the discriminator error|, deg/s.
    pub(super) growth_deg_s: f64,
    /// Its theory, deg/s.
    pub(super) predicted_growth_deg_s: f64,
    /// Satellites used.
    pub(super) channels: usize,
}

/// [`BiasStats`] of a case.
///
/// Theory (seed 004 eqs. 12-16, re-derived): the bias `B` gives a Doppler error
/// `B_V t / lambda` with `B_V = B . u` (`u` receiver to satellite, `t` from the INS start).
/// 1st order: error `360 B_V t / (lambda omega0)` deg, mean at the mean time of the epochs
/// used, growth `360 B_V / (lambda omega0)` deg/s; 2nd order: constant
/// `360 B_V / (lambda omega0^2)`, no growth; 3rd order: none. The measured mean also holds any
/// constant frequency offset the loop carries (a 1st-order loop keeps the one it was handed
/// over with); the growth does not.
pub(super) fn bias_theory(p: &Prepared, case: &Case, logs: &[ChannelLog]) -> BiasStats {
    let none = BiasStats {
        mean_abs_deg: f64::NAN,
        predicted_deg: f64::NAN,
        growth_deg_s: f64::NAN,
        predicted_growth_deg_s: f64::NAN,
        channels: 0,
    };
    if case.aiding == Aiding::Unaided {
        return none;
    }
    let (w0, w1) = p.spec.window_s();
    let min_epochs = (0.5 * (w1 - w0) * 1e3) as usize;
    let d = bias_direction_enu();
    let b = case.bias_mps2();
    let omega0 = case.bn_hz / BN_OVER_OMEGA0[usize::from(case.order.clamp(1, 3)) - 1];
    let mut acc = [0.0; 4];
    let mut n = 0.0;
    for (l, u) in logs.iter().zip(&p.los_enu) {
        if l.track_t_s.len() < min_epochs.max(MIN_SAMPLES)
            || if_sim::half_cycle_slips(&l.track_phase_cycles, SLIP_BLOCK_EPOCHS) > 0
        {
            continue;
        }
        let (m, slope) = mean_and_slope(&l.track_t_s, &l.track_disc_cycles);
        let b_v = b * (d[0] * u[0] + d[1] * u[1] + d[2] * u[2]);
        let t_mean = l.track_t_s.iter().sum::<f64>() / l.track_t_s.len() as f64;
        let (pred, pred_growth) = match case.order {
            1 => (
                360.0 * b_v * t_mean / (LAMBDA_L1_M * omega0),
                360.0 * b_v / (LAMBDA_L1_M * omega0),
            ),
            2 => (360.0 * b_v / (LAMBDA_L1_M * omega0 * omega0), 0.0),
            _ => (0.0, 0.0),
        };
        for (a, v) in acc
            .iter_mut()
            .zip([m * 360.0, pred, slope * 360.0, pred_growth])
        {
            *a += v.abs();
        }
        n += 1.0;
    }
    if n > 0.0 {
        BiasStats {
            mean_abs_deg: acc[0] / n,
            predicted_deg: acc[1] / n,
            growth_deg_s: acc[2] / n,
            predicted_growth_deg_s: acc[3] / n,
            channels: n as usize,
        }
    } else {
        none
    }
}
