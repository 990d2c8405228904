//! Position, velocity and time (PVT) from one epoch of pseudoranges and Dopplers.
//!
//! The solver follows seed 001 (Park et al., 2011) section 3:
//!
//! - [`model`]: the pseudorange measurement model of eqs. 3.1-3.2 (satellite position at
//!   transmit time, Earth rotation during flight, satellite clock with relativity and T_GD,
//!   Klobuchar ionosphere, Saastamoinen troposphere) and the a-priori weights;
//! - [`wls`]: iterative weighted least squares in Gauss-Markov form, eqs. 3.3-3.7;
//! - [`landmark`]: ranges to surveyed points as extra observations without a clock term,
//!   eqs. 3.8-3.12;
//! - [`velocity`]: velocity and clock drift from Dopplers by least squares;
//! - [`raim`]: chi-square fault detection and exclusion (with our own chi-square quantile);
//! - [`dop`]: dilution of precision in the local East-North-Up frame;
//! - [`coarse_time`]: position and time from sub-millisecond code phases before the time of
//!   week is known (van Diggelen ch. 4), on the same model, weights and chi-square test.
//!
//! The entry point is [`solve`] ([`solve_coarse_time`] without a time of week). Every failure is a [`PvtError`]; nothing here panics on bad
//! input.

pub mod coarse_time;
pub mod dop;
pub mod landmark;
pub mod model;
pub mod raim;
pub mod velocity;
pub mod wls;

pub use coarse_time::{
    predicted_tx_time_mod_1ms, solve_coarse_time, CoarseApriori, CoarseIntegrity,
    CoarseMeasurement, CoarseSatellite, CoarseTimeError, CoarseTimeSolution, HeightConstraint,
};
pub use dop::Dop;
pub use landmark::Landmark;
pub use model::{PvtOptions, SatMeasurement, Weighting};
pub use raim::{chi_square_quantile, RaimStatus};
pub use velocity::VelocitySolution;

use crate::constants::SPEED_OF_LIGHT_MPS;
use crate::frames::{enu_rotation, Llh, Vector3};
use crate::time::GpsTime;
use nalgebra::{Matrix3, Matrix4};

/// Why an epoch gave no solution. Messages name the offending input and what to do.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PvtError {
    /// Fewer usable observations than unknowns (4: position and clock).
    #[error(
        "too few observations: {available} usable ({satellites} satellites, {landmarks} \
         landmarks) after {stage}, need at least {required}; track more satellites or add \
         landmark ranges"
    )]
    TooFewObservations {
        /// Satellites + landmarks available.
        available: usize,
        /// Satellites among them.
        satellites: usize,
        /// Landmarks among them.
        landmarks: usize,
        /// Observations needed.
        required: usize,
        /// Where they were lost ("input checks", "elevation mask").
        stage: &'static str,
    },
    /// A measurement field is NaN, infinite or out of its physical range.
    #[error("PRN {prn}: invalid {field} = {value}; drop this measurement")]
    InvalidMeasurement {
        /// PRN of the measurement.
        prn: u8,
        /// Field name.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
    /// The ephemeris handed in with a measurement belongs to another satellite.
    #[error("measurement of PRN {prn} comes with the ephemeris of PRN {eph_prn}")]
    EphemerisMismatch {
        /// PRN of the measurement.
        prn: u8,
        /// PRN of the ephemeris.
        eph_prn: u8,
    },
    /// The same PRN appears twice in one epoch.
    #[error("PRN {prn} appears more than once in the epoch; keep one measurement per satellite")]
    DuplicatePrn {
        /// The repeated PRN.
        prn: u8,
    },
    /// A landmark has a non-finite position or range, or a non-positive sigma.
    #[error("landmark {index}: invalid {field} = {value}")]
    InvalidLandmark {
        /// Index in the landmark slice.
        index: usize,
        /// Field name.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
    /// An option is out of range.
    #[error("invalid option {name} = {value}")]
    InvalidOption {
        /// Option name.
        name: &'static str,
        /// Offending value.
        value: f64,
    },
    /// The normal matrix cannot be inverted (coplanar or repeated lines of sight).
    #[error(
        "singular geometry (GDOP {gdop:.3e}): the lines of sight do not fix position and clock"
    )]
    SingularGeometry {
        /// GDOP of the failing geometry (infinite if the inverse does not exist).
        gdop: f64,
    },
    /// The least-squares point's geometry does not fix the position: PDOP above the limit (with
    /// 3 satellites and a landmark, the landmark direction is nearly perpendicular to the
    /// satellites' solution curve, or the noisy curve misses the landmark's range sphere).
    #[error(
        "the geometry does not allow a fix: PDOP {pdop:.1} > {max_pdop} ({satellites} satellites, \
         {landmarks} landmarks); wait for more satellites or a landmark in another direction"
    )]
    WeakGeometry {
        /// PDOP at the least-squares point.
        pdop: f64,
        /// The limit ([`PvtOptions::max_pdop`]).
        max_pdop: f64,
        /// Satellites used.
        satellites: usize,
        /// Landmarks used.
        landmarks: usize,
    },
    /// The iteration did not converge or left the neighbourhood of the Earth.
    #[error("least squares did not converge after {iterations} iterations (last step {last_step_m:.3e} m)")]
    Diverged {
        /// Iterations done.
        iterations: usize,
        /// Norm of the last position update, m.
        last_step_m: f64,
    },
}

/// One epoch's navigation solution.
#[derive(Debug, Clone, PartialEq)]
pub struct PvtSolution {
    /// GPS time of reception: the receiver's epoch time minus the estimated clock bias.
    pub time: GpsTime,
    /// Receiver antenna position, WGS-84 ECEF, m.
    pub pos_ecef_m: Vector3<f64>,
    /// The same position as geodetic coordinates.
    pub llh: Llh,
    /// Receiver clock bias times c, m (receiver clock ahead of GPS time is positive).
    pub clock_bias_m: f64,
    /// Receiver velocity, ECEF, m/s (None without at least 4 Dopplers on used satellites).
    pub vel_ecef_mps: Option<Vector3<f64>>,
    /// Receiver clock drift times c, m/s.
    pub clock_drift_mps: Option<f64>,
    /// Velocity/drift covariance (ECEF velocity, drift), (m/s)^2.
    pub vel_covariance: Option<Matrix4<f64>>,
    /// Number of satellites in the final solution.
    pub n_sv: usize,
    /// PRNs in the final solution, in input order.
    pub used_prns: Vec<u8>,
    /// PRNs dropped by the elevation mask.
    pub masked_prns: Vec<u8>,
    /// Geometry-only DOP of the final solution (landmark rows included when present).
    pub dop: Dop,
    /// DOP of the satellites alone, when landmarks were used and the satellites alone fix the
    /// geometry (None otherwise).
    pub dop_without_landmarks: Option<Dop>,
    /// A-posteriori standard deviation of unit weight sigma0 (eq. 3.6 / 3.11); 1 when there is
    /// no redundancy (the a-priori value).
    pub sigma0: f64,
    /// Covariance of (x, y, z, clock bias), ECEF, m^2: sigma0^2 N^-1 (eq. 3.7 / 3.12).
    pub covariance: Matrix4<f64>,
    /// Post-fit pseudorange residuals (measured - modelled), m, per used PRN.
    pub residuals_m: Vec<(u8, f64)>,
    /// Post-fit landmark range residuals, m, in landmark order.
    pub landmark_residuals_m: Vec<f64>,
    /// Integrity status from RAIM.
    pub raim: RaimStatus,
    /// Gauss-Newton iterations of the final solution.
    pub iterations: usize,
}

impl PvtSolution {
    /// Position covariance rotated to the local East-North-Up frame at the solution, m^2.
    pub fn position_covariance_enu(&self) -> Matrix3<f64> {
        let r = enu_rotation(&self.llh);
        let p: Matrix3<f64> = self.covariance.fixed_view::<3, 3>(0, 0).into_owned();
        r * p * r.transpose()
    }
}

/// Solves one epoch: position and clock by iterative weighted least squares (with landmark
/// ranges as extra observations), RAIM fault detection and exclusion, DOP, then velocity and
/// clock drift from the Dopplers of the satellites kept.
///
/// `epoch_rx_time` is the receive time by the receiver clock (the time the pseudoranges refer
/// to). `prior` only provides the starting point of the iteration (and lets the elevation mask
/// and atmospheric corrections act from the first iteration); without it the iteration starts at
/// the Earth's centre with zero clock bias.
pub fn solve(
    epoch_rx_time: GpsTime,
    meas: &[SatMeasurement<'_>],
    landmarks: &[Landmark],
    opts: &PvtOptions,
    prior: Option<&PvtSolution>,
) -> Result<PvtSolution, PvtError> {
    opts.validate()?;
    landmark::validate(landmarks)?;
    let sats = model::prepare(epoch_rx_time, meas)?;
    let total = sats.len() + landmarks.len();
    if total < wls::N_UNKNOWNS || sats.is_empty() {
        return Err(PvtError::TooFewObservations {
            available: total,
            satellites: sats.len(),
            landmarks: landmarks.len(),
            required: wls::N_UNKNOWNS,
            stage: "input checks",
        });
    }
    let start = prior
        .filter(|p| p.pos_ecef_m.iter().all(|v| v.is_finite()) && p.clock_bias_m.is_finite())
        .map(|p| (p.pos_ecef_m, p.clock_bias_m));
    let ctx = wls::Context {
        epoch_rx_time,
        sats: &sats,
        landmarks,
        opts,
        start,
    };
    let all = vec![true; sats.len()];
    let fix = wls::solve_position(&ctx, &all)?;
    let (fix, raim) = raim::check_and_exclude(&ctx, fix)?;

    let llh = Llh::from_ecef(&fix.pos_m);
    let dop = fix.dop;
    let dop_without_landmarks = if landmarks.is_empty() {
        None
    } else {
        let sat_rows: Vec<[f64; 4]> = fix
            .geometry_rows
            .iter()
            .filter(|r| r[3] != 0.0)
            .copied()
            .collect();
        dop::dop_enu(&sat_rows, &llh)
    };
    let vel = velocity::solve_velocity(&sats, &fix, opts);
    let used_prns: Vec<u8> = fix.used.iter().map(|&i| sats[i].prn).collect();
    let residuals_m = fix
        .used
        .iter()
        .zip(&fix.sat_residuals_m)
        .map(|(&i, &r)| (sats[i].prn, r))
        .collect();
    Ok(PvtSolution {
        time: epoch_rx_time.add_seconds(-fix.clock_bias_m / SPEED_OF_LIGHT_MPS),
        pos_ecef_m: fix.pos_m,
        llh,
        clock_bias_m: fix.clock_bias_m,
        vel_ecef_mps: vel.map(|v| v.vel_ecef_mps),
        clock_drift_mps: vel.map(|v| v.clock_drift_mps),
        vel_covariance: vel.map(|v| v.covariance),
        n_sv: used_prns.len(),
        used_prns,
        masked_prns: fix.masked.iter().map(|&i| sats[i].prn).collect(),
        dop,
        dop_without_landmarks,
        sigma0: fix.sigma0,
        covariance: fix.covariance,
        residuals_m,
        landmark_residuals_m: fix.landmark_residuals_m.clone(),
        raim,
        iterations: fix.iterations,
    })
}
