//! `gpsrx run --dr`: the receiver's GNSS fixes fused with a DR log (seed 000) after tracking.
//!
//! The fixes of a recording are all known when tracking ends, so the fusion runs as a second pass
//! over the DR log in time order (bounded by the log's length, not the recording's):
//! 1. the filter starts at the first fix whose velocity gives a course over ground (speed >=
//!    [`MIN_COURSE_SPEED_MPS`]), in the local level frame of that fix;
//! 2. every DR row is propagated ([`DrFusion::propagate`]); a GNSS fix at time `t_m` between rows
//!    `k` and `k+1` updates the filter at row `k`'s time `t_k` with its position moved back along
//!    its own velocity, `p(t_k) = p(t_m) - v (t_m - t_k)`, then its velocity (eq. 14), at most one
//!    fix per `update_interval_s` (the PVT's 10 Hz fixes are carrier-smoothed and correlated:
//!    updating at 1 Hz keeps the filter's white-noise assumption honest);
//! 3. an output row every `output_interval_s`: source `fused` while the last update is at most
//!    `fused_max_age_s` old, `dr` after (an outage), `gnss` before the filter starts or after the
//!    DR log ends. DR rows carry the height of the last fix (DR is horizontal) and the GPS time of
//!    the last fix's offset from the file time.

use super::gnss::GnssFix;
use gpsrx_ins_aiding::dr_filter::{heading_from_velocity, DrFilterConfig, MIN_COURSE_SPEED_MPS};
use gpsrx_ins_aiding::{DrError, DrFilterKind, DrFusion, DrLog, DrParams, FixSource};
use gpsrx_nav::frames::{enu_rotation, Llh};
use gpsrx_nav::time::GpsTime;
use nalgebra::Vector3;

/// How to fuse.
#[derive(Debug, Clone, PartialEq)]
pub struct DrFusionSettings {
    /// Which filter (seed 000's proposed 8-state or the conventional 4-state).
    pub kind: DrFilterKind,
    /// Nominal sensor parameters (the configuration's; they also convert engineering-unit
    /// rows).
    pub params: DrParams,
    /// A saved calibration to start from instead of the nominal parameters (seed 000: avoids
    /// the long convergence of the gyro scale factor).
    pub calibration: Option<DrParams>,
    /// Filter tuning.
    pub filter: DrFilterConfig,
    /// Least interval between GNSS updates, s.
    pub update_interval_s: f64,
    /// Interval between output rows, s.
    pub output_interval_s: f64,
    /// Longest time since the last GNSS update for a row to count as fused, s.
    pub fused_max_age_s: f64,
}

impl DrFusionSettings {
    /// Seed 000's filter with the given parameters: 1 Hz updates, rows at `output_interval_s`.
    pub fn new(kind: DrFilterKind, params: DrParams, output_interval_s: f64) -> Self {
        DrFusionSettings {
            kind,
            params,
            calibration: None,
            filter: DrFilterConfig::default(),
            update_interval_s: 1.0,
            output_interval_s,
            fused_max_age_s: 1.5,
        }
    }
}

/// One fused output row.
#[derive(Debug, Clone, PartialEq)]
pub struct FusedFix {
    /// Seconds since the first IF sample.
    pub t_s: f64,
    /// GPS time.
    pub time: GpsTime,
    /// Geodetic position.
    pub llh: Llh,
    /// ECEF position, m.
    pub ecef_m: Vector3<f64>,
    /// East and north velocity, m/s.
    pub vel_en_mps: [f64; 2],
    /// Heading, rad clockwise from north (DR heading, or GNSS course).
    pub heading_rad: f64,
    /// Where it came from.
    pub source: FixSource,
    /// East and north position standard deviations, m.
    pub sigma_en_m: [f64; 2],
    /// Sensor parameters in use (calibrated by the filter), None for GNSS rows.
    pub params: Option<DrParams>,
    /// Satellites in the last fix used.
    pub n_sv: usize,
    /// Speed from the GPS/accelerometer speed filter (seed 002), m/s, with `--accel`.
    pub speed_filter_mps: Option<f64>,
}

/// What a fusion pass produced.
#[derive(Debug, Clone, Default)]
pub struct DrFusionResult {
    /// The rows, in time order.
    pub fixes: Vec<FusedFix>,
    /// GNSS updates applied.
    pub updates: usize,
    /// Sensor parameters at the end (to save for the next run), if the filter started.
    pub final_params: Option<DrParams>,
}

/// Fuses the fixes `gnss` (in time order) with `dr`; see the module documentation. Without a DR
/// log (or one that does not overlap a moving fix) the rows are the GNSS fixes alone.
pub fn fuse_dr(
    gnss: &[GnssFix],
    dr: Option<&DrLog>,
    set: &DrFusionSettings,
) -> Result<DrFusionResult, DrError> {
    let mut out = DrFusionResult::default();
    let Some(dr) = dr.filter(|d| !d.samples().is_empty()) else {
        push_gnss_rows(&mut out.fixes, gnss, set.output_interval_s);
        return Ok(out);
    };
    let rows = dr.samples();
    let (dr_start, dr_end) = dr.time_span_s();
    let start = gnss.iter().position(|f| {
        f.t_s >= dr_start
            && f.t_s < dr_end
            && f.vel_ecef_mps.is_some()
            && course(f, &Llh::from_ecef(&f.pos_ecef_m)).is_some()
    });
    let Some(i_start) = start else {
        // The filter never starts: the GNSS fixes alone.
        push_gnss_rows(&mut out.fixes, gnss, set.output_interval_s);
        return Ok(out);
    };
    push_gnss_rows(&mut out.fixes, &gnss[..i_start], set.output_interval_s);
    let first = &gnss[i_start];
    let origin = Llh::from_ecef(&first.pos_ecef_m);
    let rot_t = enu_rotation(&origin).transpose();
    // The DR row at or just before the first fix starts the mechanization.
    let k0 = rows
        .partition_point(|r| r.t_s <= first.t_s)
        .saturating_sub(1);
    let ([e0, n0], _) = first.en_position(&origin);
    let ([ve, vn], _) = first
        .en_velocity(&origin)
        .unwrap_or(([0.0, 0.0], Default::default()));
    let back = first.t_s - rows[k0].t_s;
    let heading0 = course(first, &origin).unwrap_or(0.0);
    let mut filter = DrFusion::new(
        set.kind,
        set.params,
        e0 - ve * back,
        n0 - vn * back,
        heading0,
        set.filter.clone(),
    )?;
    if let Some(c) = set.calibration {
        filter = filter.with_calibration(c)?;
    }
    filter.propagate(&rows[k0])?;

    // The first fix initialises the filter: it counts as an update.
    let mut next_fix = i_start + 1;
    let mut last_update = Some(first.t_s);
    let mut last_fix = first;
    // Rows start with the first propagated DR row (the initial state has no velocity yet).
    let mut next_out = rows[k0].t_s + 1e-6;
    for (k, row) in rows.iter().enumerate().skip(k0) {
        if k > k0 {
            // Fixes up to this row's time update the filter at the previous row's time.
            while next_fix < gnss.len() && gnss[next_fix].t_s < row.t_s {
                let f = &gnss[next_fix];
                next_fix += 1;
                if f.t_s < rows[k - 1].t_s {
                    continue;
                }
                last_fix = f;
                if last_update.is_some_and(|u| f.t_s - u < set.update_interval_s - 1e-6) {
                    continue;
                }
                let dt = f.t_s - rows[k - 1].t_s;
                let ([e, n], pos_cov) = f.en_position(&origin);
                let vel = f.en_velocity(&origin);
                let [ve, vn] = vel.map(|(v, _)| v).unwrap_or([0.0, 0.0]);
                filter.update_position(e - ve * dt, n - vn * dt, pos_cov)?;
                if let Some(([ve, vn], vel_cov)) = vel {
                    filter.update_velocity(ve, vn, vel_cov)?;
                }
                last_update = Some(f.t_s);
                out.updates += 1;
            }
            filter.propagate(row)?;
        }
        if row.t_s + 1e-9 < next_out {
            continue;
        }
        next_out += set.output_interval_s;
        let s = filter.state();
        let cov = filter.position_covariance();
        let up = Llh::from_ecef(&last_fix.pos_ecef_m).h_m - origin.h_m;
        let ecef = origin.to_ecef() + rot_t * Vector3::new(s.east_m, s.north_m, up);
        let source = match last_update {
            Some(u) if row.t_s - u <= set.fused_max_age_s => FixSource::Fused,
            _ => FixSource::DrOnly,
        };
        out.fixes.push(FusedFix {
            t_s: row.t_s,
            time: last_fix.time.add_seconds(row.t_s - last_fix.t_s),
            llh: Llh::from_ecef(&ecef),
            ecef_m: ecef,
            vel_en_mps: [s.vel_east_mps, s.vel_north_mps],
            heading_rad: s.heading_rad,
            source,
            sigma_en_m: [cov[(0, 0)].max(0.0).sqrt(), cov[(1, 1)].max(0.0).sqrt()],
            params: Some(*filter.params()),
            n_sv: if source == FixSource::Fused {
                last_fix.n_sv
            } else {
                0
            },
            speed_filter_mps: None,
        });
    }
    // Fixes after the end of the DR log.
    let after: Vec<GnssFix> = gnss.iter().filter(|f| f.t_s > dr_end).cloned().collect();
    push_gnss_rows(&mut out.fixes, &after, set.output_interval_s);
    out.final_params = Some(*filter.params());
    Ok(out)
}

/// The course over ground of a fix, rad, when it is moving fast enough to have one.
fn course(f: &GnssFix, origin: &Llh) -> Option<f64> {
    let ([ve, vn], _) = f.en_velocity(origin)?;
    heading_from_velocity(ve, vn, MIN_COURSE_SPEED_MPS)
}

/// Appends GNSS-only rows, at most one per `interval_s`.
fn push_gnss_rows(out: &mut Vec<FusedFix>, fixes: &[GnssFix], interval_s: f64) {
    let mut next = f64::NEG_INFINITY;
    for f in fixes {
        if f.t_s + 1e-9 < next {
            continue;
        }
        next = f.t_s + interval_s;
        let origin = Llh::from_ecef(&f.pos_ecef_m);
        let ([_, _], cov) = f.en_position(&origin);
        let vel = f.en_velocity(&origin).map(|(v, _)| v).unwrap_or([0.0, 0.0]);
        out.push(FusedFix {
            t_s: f.t_s,
            time: f.time,
            llh: origin,
            ecef_m: f.pos_ecef_m,
            vel_en_mps: vel,
            heading_rad: vel[0].atan2(vel[1]),
            source: FixSource::Gnss,
            sigma_en_m: [cov[(0, 0)].max(0.0).sqrt(), cov[(1, 1)].max(0.0).sqrt()],
            params: None,
            n_sv: f.n_sv,
            speed_filter_mps: None,
        });
    }
}
