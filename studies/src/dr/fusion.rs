//! One GPS/DR run: the proposed 8-state and the conventional 4-state filters
//! ([`gpsrx_ins_aiding::DrFusion`]) fed the same DR log and GNSS solutions, with GNSS removed in
//! the outage windows; horizontal position errors of both and of GNSS alone at every GNSS epoch.
//!
//! Both filters start at the first GNSS epoch at which the vehicle moves faster than
//! [`START_SPEED_MPS`] (position from that fix, heading from its course over ground) with the
//! sensors' *nominal* parameters. At each epoch outside an outage: position update with
//! `R = pos_sigma^2 I` (what the solution reports: white noise and bias together, not their
//! correlation), and for the proposed filter a velocity update with `R = sigma_v^2 I`.

use super::drive::Drive;
use super::gnss::{in_windows, GnssTrack};
use super::params::{DR_RATE_HZ, GNSS_RATE_HZ, GNSS_VEL_SIGMA_MPS, START_SPEED_MPS};
use anyhow::Context;
use gpsrx_ins_aiding::{
    heading_from_velocity, DrFilterConfig, DrFilterKind, DrFusion, DrParams, DrSample,
};
use nalgebra::Matrix2;

/// Per GNSS epoch from the filters' start.
#[derive(Debug, Clone, Default)]
pub struct FusionRun {
    /// Epoch times, s.
    pub t_s: Vec<f64>,
    /// Proposed filter's horizontal position error, m.
    pub err_proposed_m: Vec<f64>,
    /// Conventional filter's, m.
    pub err_conventional_m: Vec<f64>,
    /// GNSS alone (NaN in outages), m.
    pub err_gnss_m: Vec<f64>,
    /// Proposed filter's gyro scale factor estimate, deg/s/V.
    pub sf_g_dps_per_v: Vec<f64>,
    /// Proposed filter's zero-rate voltage estimate, V.
    pub v_nom_v: Vec<f64>,
    /// Proposed filter's odometer scale factor estimate, m/pulse.
    pub sf_n_m_per_pulse: Vec<f64>,
}

/// Runs both filters over `[start, end_s]` with GNSS removed in `outages`.
pub fn run_fusion(
    drive: &Drive,
    gnss: &GnssTrack,
    dr: &[DrSample],
    nominal: DrParams,
    outages: &[(f64, f64)],
    end_s: f64,
) -> anyhow::Result<FusionRun> {
    let rows_per_epoch = (DR_RATE_HZ / GNSS_RATE_HZ).round() as usize;
    let first = gnss
        .epochs
        .iter()
        .find(|e| {
            !in_windows(e.t_s, outages)
                && e.vel_enu_mps[0].hypot(e.vel_enu_mps[1]) >= START_SPEED_MPS
        })
        .context("the vehicle never moves faster than the start speed")?;
    let heading = heading_from_velocity(first.vel_enu_mps[0], first.vel_enu_mps[1], 0.0)
        .context("no course at the start")?;
    let make = |kind| {
        DrFusion::new(
            kind,
            nominal,
            first.pos_en_m[0],
            first.pos_en_m[1],
            heading,
            DrFilterConfig::default(),
        )
    };
    let mut filters = [
        make(DrFilterKind::Proposed8)?,
        make(DrFilterKind::Conventional4)?,
    ];
    let k0 = (first.t_s * DR_RATE_HZ).round() as usize;
    let mut run = FusionRun::default();
    let vel_cov = Matrix2::identity() * GNSS_VEL_SIGMA_MPS.powi(2);
    for (k, sample) in dr.iter().enumerate().skip(k0) {
        if sample.t_s > end_s + 1e-9 {
            break;
        }
        for f in &mut filters {
            f.propagate(sample)
                .with_context(|| format!("DR row at {} s", sample.t_s))?;
        }
        if k % rows_per_epoch != 0 {
            continue;
        }
        let Some(e) = gnss.epochs.get(k / rows_per_epoch) else {
            break;
        };
        let outage = in_windows(e.t_s, outages);
        if !outage {
            let pos_cov = Matrix2::identity() * e.pos_sigma_m.powi(2);
            for f in &mut filters {
                f.update_position(e.pos_en_m[0], e.pos_en_m[1], pos_cov)
                    .with_context(|| format!("GNSS position at {} s", e.t_s))?;
            }
            filters[0]
                .update_velocity(e.vel_enu_mps[0], e.vel_enu_mps[1], vel_cov)
                .with_context(|| format!("GNSS velocity at {} s", e.t_s))?;
        }
        let truth = drive.at(e.t_s);
        let err = |east: f64, north: f64| (east - truth.east_m).hypot(north - truth.north_m);
        let [p, c] = &filters;
        run.t_s.push(e.t_s);
        run.err_proposed_m
            .push(err(p.state().east_m, p.state().north_m));
        run.err_conventional_m
            .push(err(c.state().east_m, c.state().north_m));
        run.err_gnss_m.push(if outage {
            f64::NAN
        } else {
            err(e.pos_en_m[0], e.pos_en_m[1])
        });
        run.sf_g_dps_per_v.push(p.params().sf_g_dps_per_v);
        run.v_nom_v.push(p.params().v_nom_v);
        run.sf_n_m_per_pulse.push(p.params().sf_n_m_per_pulse);
    }
    Ok(run)
}
