//! The rows of the navigation filter from one epoch of observables: each satellite's
//! pseudorange and Doppler linearised about the filter's prior, on the same measurement model
//! as the least-squares fix (`gpsrx_nav::pvt::model`: satellite at its transmit time, Earth
//! rotation during the flight, satellite clock with relativity and T_GD, Klobuchar and
//! Saastamoinen when configured; `gpsrx_nav::pvt::velocity` for the range rate).
//!
//! - Code: `P = range_model(r) + b`, so `H = [-u^T, 0, 1, 0]` (`u` the unit line of sight
//!   from the receiver to the satellite);
//! - Doppler, as a pseudorange rate `rr = -f_D lambda`:
//!   `rr = k u.(R3 v_sv - v_rx) + d - c dt_sv'`, so `H = [0, -k u^T, 0, 1]`.
//!
//! The noise of each row comes from the channel's C/N0 (`noise`); a satellite below the
//! elevation mask, without an ephemeris, or unhealthy (unless allowed) gives no rows.

use super::ekf::{Row, RowKind, State, BIAS, DRIFT, N_STATES};
use super::noise::{code_variance_m2, doppler_variance_hz2, LoopNoise};
use crate::pipeline::sink::ObsEpoch;
use gpsrx_core::constants::LAMBDA_L1_M;
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::pvt::model::{predict, prepare};
use gpsrx_nav::pvt::velocity::sat_range_rate;
use gpsrx_nav::pvt::{PvtOptions, SatMeasurement};
use nalgebra::{SVector, Vector3};

/// What the rows of an epoch are built with besides the observables.
#[derive(Clone, Copy)]
pub struct RowModel<'a> {
    /// The measurement model's options (atmosphere, elevation mask).
    pub opts: &'a PvtOptions,
    /// The loop settings of a channel at a C/N0 (dB-Hz): the weak-signal loops below their
    /// threshold.
    pub loops: &'a dyn Fn(f64) -> LoopNoise,
    /// Interval between filter updates, s.
    pub dt_s: f64,
    /// Use satellites whose ephemeris says they are unhealthy.
    pub allow_unhealthy: bool,
}

impl std::fmt::Debug for RowModel<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RowModel")
            .field("opts", self.opts)
            .field("dt_s", &self.dt_s)
            .field("allow_unhealthy", &self.allow_unhealthy)
            .finish_non_exhaustive()
    }
}

/// The rows of `epoch` about the prior `x`, with the ephemeris `eph(prn)` of each satellite.
pub fn epoch_rows(
    epoch: &ObsEpoch,
    eph: &dyn Fn(u8) -> Option<Ephemeris>,
    x: &State,
    model: &RowModel<'_>,
) -> Vec<Row> {
    let pos: Vector3<f64> = x.fixed_rows::<3>(0).into();
    let vel: Vector3<f64> = x.fixed_rows::<3>(3).into();
    let mut rows = Vec::with_capacity(2 * epoch.sats.len());
    for s in &epoch.sats {
        let (Some(pr), Some(cn0)) = (s.pseudorange_m, s.cn0_dbhz) else {
            continue;
        };
        let Some(e) = eph(s.prn).filter(|e| e.sv_health == 0 || model.allow_unhealthy) else {
            continue;
        };
        let m = SatMeasurement {
            prn: s.prn,
            pseudorange_m: pr,
            doppler_hz: s.doppler_hz.filter(|d| d.is_finite()),
            cn0_dbhz: cn0,
            tx_time: None,
            ephemeris: &e,
        };
        let Ok(prepared) = prepare(epoch.time, &[m]) else {
            continue;
        };
        let Some(sat) = prepared.first() else {
            continue;
        };
        let pred = predict(sat, &pos, true, model.opts, epoch.time.tow_s);
        if pred.el_rad.to_degrees() < model.opts.elevation_mask_deg {
            continue;
        }
        let loops = (model.loops)(cn0);
        let mut h = SVector::<f64, N_STATES>::zeros();
        h.fixed_rows_mut::<3>(0).copy_from(&(-pred.los));
        h[BIAS] = 1.0;
        rows.push(Row {
            prn: s.prn,
            kind: RowKind::Code,
            innovation: pr - (pred.range_model_m + x[BIAS]),
            h,
            var: code_variance_m2(&loops, cn0, model.dt_s),
        });
        if let Some(f) = m.doppler_hz {
            let rate = sat_range_rate(sat, &pred);
            let rr_meas = -f * LAMBDA_L1_M;
            let rr_pred = rate.rate_mps - rate.k * pred.los.dot(&vel) + x[DRIFT];
            let mut h = SVector::<f64, N_STATES>::zeros();
            h.fixed_rows_mut::<3>(3).copy_from(&(-rate.k * pred.los));
            h[DRIFT] = 1.0;
            rows.push(Row {
                prn: s.prn,
                kind: RowKind::Doppler,
                innovation: rr_meas - rr_pred,
                h,
                var: doppler_variance_hz2(&loops, cn0, model.dt_s) * LAMBDA_L1_M * LAMBDA_L1_M,
            });
        }
    }
    rows
}
