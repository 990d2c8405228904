//! Coarse-time navigation: position and GPS time from sub-millisecond code phases alone, before
//! any time of week (TOW) is decoded or after a long gap in the samples (van Diggelen,
//! "A-GPS: Assisted GPS, GNSS, and SBAS", Artech House 2009, chapter 4).
//!
//! # Observable
//!
//! At one common reception instant every tracking channel knows its SV transmit time modulo
//! one C/A code period, phi_k = t_sv,k mod T with T = 1 ms (the code phase in chips divided by
//! 1.023e6, [`CoarseMeasurement::tx_time_mod_1ms_s`]). This is by the SV clock, like
//! [`super::SatMeasurement::tx_time`]. A receiver that holds sub-millisecond pseudoranges
//! s_k = c ((t_clk - t_sv,k) mod T) instead passes phi_k = (t_clk - s_k / c) mod T for any
//! common clock reading t_clk: a common offset is absorbed by the clock-bias unknown.
//!
//! # Whole milliseconds (van Diggelen 4.3)
//!
//! From the a-priori position x_a and time t_a the model of [`super::model`] predicts each
//! pseudorange rho_hat_k (geometric range with Earth rotation, SV clock with relativity and
//! T_GD, atmosphere; no receiver clock), hence the SV transmit time
//! t_hat_k = t_a - rho_hat_k / c. The full transmit time is t_sv,k = N_k T + phi_k with an
//! unknown integer N_k. The reference satellite r (highest elevation at the a-priori position,
//! whose prediction error from a horizontal position error is smallest) takes its integer from
//! its own prediction, N_r = round((t_hat_r - phi_r) / T). The differences of transmit times
//! do not depend on the common time error except through the satellites' motion:
//!
//! ```text
//! t_sv,k - t_sv,r = (N_k - N_r) T + phi_k - phi_r = t_hat_k - t_hat_r + eps_k
//! =>  N_k = N_r + round((t_hat_k - t_hat_r - (phi_k - phi_r)) / T)
//! ```
//!
//! (in van Diggelen's pseudorange form, N_k = N_r + round((rho_hat_k - rho_hat_r + s_r - s_k)
//! / cT), the same equation with s = -c phi). It is right when the prediction error
//! c eps_k = (e_r - e_k).dx_a + (v_k - v_r) dt_a (+ model errors) stays within half a
//! millisecond, +-74.9 km: e are the unit lines of sight, dx_a the a-priori position error,
//! v the range rates (up to ~800 m/s) and dt_a the a-priori time error. N_r itself is wrong
//! by the whole milliseconds of dt_a; that common error u (a whole number of ms) is what the
//! clock-bias unknown absorbs.
//!
//! # Five-state least squares (van Diggelen ch. 4)
//!
//! With the reconstructed transmit times t~_k = t_sv,k - u the pseudoranges against a clock
//! reading t_a are rho~_k = c (t_a - t~_k), and with t = t_a + dt_c the true reception time
//!
//! ```text
//! rho~_k = R_k(x, t_a + dt_c) + b,        b = c (u - dt_c)
//! d rho~_k = -e_k^T dx + db + v_k d(dt_c)
//! ```
//!
//! where R_k is the pseudorange model without receiver clock ([`super::model::predict`],
//! satellite at its transmit time for reception at t) and v_k its rate for a receiver fixed in
//! ECEF ([`super::velocity::sat_range_rate`]: satellite ECEF velocity rotated into the frame
//! of reception, so the Earth-rotation term is in it, minus the SV clock drift). The weighted
//! least squares over (x, y, z, b, dt_c), weights from [`super::Weighting`], is iterated with
//! the satellites re-evaluated at the corrected time until the position step is below 0.1 mm
//! and the time step moves no range by more than 0.1 mm. The coarse time is observable only
//! through the differences of the range rates, so its precision is sigma / |v| times a
//! geometry factor ([`CoarseTimeSolution::time_dop_s_per_m`]): milliseconds for metre-level
//! noise. The whole milliseconds of the absolute time are therefore known only to that
//! precision; the transmit-time differences between satellites are exact.
//!
//! # Height constraint
//!
//! With [`CoarseApriori::height`] the height above the ellipsoid enters as one more
//! observation, `h(x) = h_a` with sigma `sigma_h`: the row `[u^T, 0, 0]` (u the local up unit
//! vector at the current estimate) and the misclosure `h_a - h(x)`. Snapshot receivers near the
//! ground use it (the vertical is the worst-determined coordinate of a five-state fix with few
//! satellites, and its error leaks into the horizontal through the time unknown). The row
//! counts as one more degree of freedom in the chi-square test and in the DOPs; the
//! satellites' residuals and the search for a faulty satellite leave it out.
//!
//! [`CoarseApriori::time_sigma_s`] does the same for the time: the a-priori time itself as an
//! observation `dt_c = 0` with sigma `sigma_t` (row `[0, 0, 0, 0, 1]`, misclosure `-dt_c`),
//! for a sequence of snapshots whose device clock error is already known from the others.
//!
//! # Integrity
//!
//! With n >= 6 satellites each hypothesis must pass the chi-square test of
//! [`super::raim`] (n - 5 degrees of freedom, false-alarm probability
//! [`PvtOptions::raim_pfa`]; the test always runs, [`PvtOptions::raim`] does not switch it
//! off) and every hypothesis must land within the a-priori uncertainty
//! ([`CoarseApriori::pos_uncertainty_m`], [`CoarseApriori::time_uncertainty_s`]).
//! Hypotheses are tried in three stages, stopping after the first stage in which some pass:
//! every satellite as the reference (distinct integer sets only, so one solve when the
//! a-priori is good); +-1 ms on the satellite with the largest normalised residual of the
//! best of those; with n >= 7, each satellite left out in turn. All passing hypotheses must agree
//! (within [`AGREEMENT_M`] and [`AGREEMENT_S`]), else the fix is reported as ambiguous. With
//! exactly 5 satellites there is no redundancy: the solution is returned as
//! [`CoarseIntegrity::Unverified`] if the distinct hypotheses within the a-priori bounds agree.
//!
//! # Limits (measured with brdc0010.22n, `nav/tests/nav/coarse_time_tests.rs`)
//!
//! The reconstruction needs |c eps_k| < 74.9 km for every satellite; since eps_k is a
//! difference of projections on two lines of sight, the a-priori error itself may be larger.
//! Measured with 5 m range noise at Seoul, Longyearbyen (78 N) and Cape Town (34 S), 12
//! azimuths of horizontal a-priori error in 5 km steps: the primary hypothesis alone holds up
//! to 95-170 km (worst case 95 km) or, for time errors alone, 190-230 s; with the fallback
//! hypotheses the first refusals come at 150-225 km and 240-260 s. No wrong fix was returned
//! in any of these runs (2562), nor at 300 km with a 10 000 km stated uncertainty. The
//! defaults [`DEFAULT_POS_UNCERTAINTY_M`] = 100 km and [`DEFAULT_TIME_UNCERTAINTY_S`] = 60 s,
//! together and with any sub-millisecond clock offset, gave a right fix in 2000 random cases
//! of 2000. Beyond the limits the result was always an error, not a wrong fix. That is a
//! measurement, not a proof: with few satellites a wrong integer set can in principle fit the
//! chi-square test by chance; the a-priori bounds and the agreement check guard against it,
//! and with 5 satellites nothing but the bounds does ([`CoarseIntegrity::Unverified`]).

use super::dop::{dop_from_cofactor, Dop};
use super::model::{
    check_satellite, predict, state_at_transmit, Predicted, PreparedSat, PvtOptions,
};
use super::raim::{chi_square_passes, chi_square_quantile, normalised_residuals};
use super::velocity::sat_range_rate;
use super::PvtError;
use crate::constants::{CA_CODE_PERIOD_S, SPEED_OF_LIGHT_MPS};
use crate::ephemeris::Ephemeris;
use crate::frames::{Llh, Vector3};
use crate::time::GpsTime;
use nalgebra::{Matrix3, SMatrix, SVector};

/// Unknowns: x, y, z, clock bias, coarse-time error.
pub const N_COARSE_UNKNOWNS: usize = 5;
/// Satellites needed for a fix (one per unknown).
pub const MIN_SATELLITES: usize = N_COARSE_UNKNOWNS;
/// Satellites needed to check the integers (one degree of freedom).
pub const MIN_SATELLITES_CHECKED: usize = N_COARSE_UNKNOWNS + 1;
/// Default a-priori position uncertainty, m: tested together with
/// [`DEFAULT_TIME_UNCERTAINTY_S`] (module docs, "Limits").
pub const DEFAULT_POS_UNCERTAINTY_M: f64 = 100.0e3;
/// Default a-priori time uncertainty, s.
pub const DEFAULT_TIME_UNCERTAINTY_S: f64 = 60.0;
/// Two passing hypotheses whose positions differ by more than this are ambiguous, m.
pub const AGREEMENT_M: f64 = 1000.0;
/// Two passing hypotheses whose times differ by more than this are ambiguous, s.
pub const AGREEMENT_S: f64 = 1.0;
/// Position update below which the iteration has converged, m.
const CONVERGED_STEP_M: f64 = 1e-4;
/// Range rate bounding |v_k| for the time-step convergence test, m/s.
const MAX_RANGE_RATE_MPS: f64 = 1000.0;
/// A position estimate further than this from the Earth's centre has diverged, m.
const MAX_RADIUS_M: f64 = 1.0e8;
/// A time correction larger than this has diverged, s (one day).
const MAX_TIME_CORRECTION_S: f64 = 86_400.0;
/// Unweighted GDOP above which the five-state geometry is singular.
const MAX_GDOP: f64 = 1.0e4;
/// Accepted a-priori distance from the Earth's centre, m.
const APRIORI_RADIUS_M: std::ops::RangeInclusive<f64> = 6.0e6..=1.0e7;

type Matrix5 = SMatrix<f64, 5, 5>;
type Vector5 = SVector<f64, 5>;

/// One satellite's coarse-time observable at the common reception instant.
#[derive(Debug, Clone, Copy)]
pub struct CoarseMeasurement<'a> {
    /// PRN, 1-63 (must match `ephemeris.prn`).
    pub prn: u8,
    /// SV transmit time modulo 1 ms, s, in [0, 1e-3): t_sv mod 1 ms by the SV clock, i.e. the
    /// code phase (chips into the C/A period being received) divided by 1.023e6.
    pub tx_time_mod_1ms_s: f64,
    /// Carrier-to-noise density, dB-Hz (for [`super::Weighting::ElevationCn0`]).
    pub cn0_dbhz: f64,
    /// Broadcast ephemeris of this satellite.
    pub ephemeris: &'a Ephemeris,
}

/// What is known before the fix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseApriori {
    /// Approximate GPS time of the common reception instant.
    pub time: GpsTime,
    /// Approximate receiver position, WGS-84 ECEF, m.
    pub pos_ecef_m: Vector3<f64>,
    /// Bound on |time error|, s. A solution needing a larger correction is rejected.
    pub time_uncertainty_s: f64,
    /// Bound on the position error, m. A solution further away is rejected.
    pub pos_uncertainty_m: f64,
    /// Optional height constraint (module docs, "Height constraint").
    pub height: Option<HeightConstraint>,
    /// Standard deviation of `time` as an observation, s (`None`: the time is a free unknown
    /// within `time_uncertainty_s`).
    pub time_sigma_s: Option<f64>,
}

/// A known height above the WGS-84 ellipsoid, used as an observation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightConstraint {
    /// Height above the ellipsoid, m.
    pub h_m: f64,
    /// Its standard deviation, m (> 0).
    pub sigma_m: f64,
}

impl CoarseApriori {
    /// A-priori with the default uncertainties ([`DEFAULT_POS_UNCERTAINTY_M`],
    /// [`DEFAULT_TIME_UNCERTAINTY_S`]).
    pub fn new(time: GpsTime, pos_ecef_m: Vector3<f64>) -> CoarseApriori {
        CoarseApriori {
            time,
            pos_ecef_m,
            time_uncertainty_s: DEFAULT_TIME_UNCERTAINTY_S,
            pos_uncertainty_m: DEFAULT_POS_UNCERTAINTY_M,
            height: None,
            time_sigma_s: None,
        }
    }

    /// The same from geodetic coordinates.
    pub fn from_llh(time: GpsTime, llh: &Llh) -> CoarseApriori {
        CoarseApriori::new(time, llh.to_ecef())
    }
}

/// One satellite of the solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseSatellite {
    /// PRN.
    pub prn: u8,
    /// Full SV transmit time t_sv (SV clock, like [`super::SatMeasurement::tx_time`]): the
    /// channel's SV time. Exact relative to the other satellites; the common whole
    /// milliseconds are as good as the coarse time ([`CoarseTimeSolution::time_sigma_s`]).
    pub tx_time: GpsTime,
    /// Full pseudorange c (time - tx_time), m, against the corrected reception time.
    pub pseudorange_m: f64,
    /// Post-fit residual, m.
    pub residual_m: f64,
    /// Elevation at the solution, rad.
    pub el_rad: f64,
}

/// How far the integers could be checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CoarseIntegrity {
    /// The chi-square test passed: e^T P e = `wsse` <= `threshold` with `dof` = n - 5.
    Passed {
        /// Weighted residual sum of squares.
        wsse: f64,
        /// Chi-square quantile at 1 - pfa.
        threshold: f64,
        /// Degrees of freedom.
        dof: usize,
    },
    /// Exactly 5 satellites: no redundancy; only the a-priori bounds were checked.
    Unverified,
}

/// A coarse-time fix.
#[derive(Debug, Clone, PartialEq)]
pub struct CoarseTimeSolution {
    /// Corrected GPS time of the common reception instant, t_a + dt_c.
    pub time: GpsTime,
    /// Correction dt_c applied to the a-priori time, s.
    pub time_correction_s: f64,
    /// Standard deviation of the corrected time, s (from [`Self::covariance`]).
    pub time_sigma_s: f64,
    /// Receiver position, WGS-84 ECEF, m.
    pub pos_ecef_m: Vector3<f64>,
    /// The same position as geodetic coordinates.
    pub llh: Llh,
    /// Clock-bias unknown b, m: the common offset of the reconstructed pseudoranges
    /// c (t_a - t~_k) against the model, b = c (u - dt_c) with u the whole milliseconds by
    /// which the reference's integer was wrong (see the module docs).
    pub clock_bias_m: f64,
    /// b / c, s.
    pub clock_bias_s: f64,
    /// The whole milliseconds u = round((b/c + dt_c) / 1 ms) added to the reconstructed
    /// transmit times to refer them to the corrected time.
    pub common_ms_shift: i64,
    /// Satellites used, in input order.
    pub satellites: Vec<CoarseSatellite>,
    /// PRN of the reference satellite of the accepted hypothesis.
    pub reference_prn: u8,
    /// A satellite whose integer was moved by +-1 ms from the reference-based value.
    pub adjusted: Option<(u8, i64)>,
    /// Satellites left out (above the mask) because no hypothesis with all of them passed.
    pub excluded_prns: Vec<u8>,
    /// Satellites below the elevation mask at the a-priori position.
    pub masked_prns: Vec<u8>,
    /// DOP of the five-state geometry (position and clock terms; its GDOP leaves out the
    /// time unknown, see [`Self::time_dop_s_per_m`]).
    pub dop: Dop,
    /// Time DOP, s per m of range sigma: sqrt((G^T G)^-1 [dt_c, dt_c]).
    pub time_dop_s_per_m: f64,
    /// A-posteriori sigma0 (1 without redundancy).
    pub sigma0: f64,
    /// Covariance of (x, y, z, b, dt_c): sigma0^2 (A^T P A)^-1, m^2, m s, s^2.
    pub covariance: SMatrix<f64, 5, 5>,
    /// Residual check of the accepted hypothesis.
    pub integrity: CoarseIntegrity,
    /// Distinct integer hypotheses solved.
    pub hypotheses_tried: usize,
    /// Whether the accepted hypothesis is a fallback (another reference, a +-1 ms adjustment
    /// or a satellite left out) because the primary one (all satellites, highest-elevation
    /// reference) failed: the a-priori was beyond the plain reconstruction's limit or a code
    /// phase is faulty.
    pub used_fallback: bool,
    /// Gauss-Newton iterations of the accepted hypothesis.
    pub iterations: usize,
}

/// Why there is no coarse-time fix. Messages say what to do.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CoarseTimeError {
    /// An input or option error shared with [`super::solve`], or a singular or diverging
    /// least squares.
    #[error(transparent)]
    Pvt(#[from] PvtError),
    /// Fewer satellites than unknowns.
    #[error(
        "too few satellites for a coarse-time fix: {available} usable after {stage}, need at \
         least {required} (position, clock bias and time); track more satellites"
    )]
    TooFewObservations {
        /// Satellites available.
        available: usize,
        /// Satellites needed.
        required: usize,
        /// Where they were lost ("input checks", "elevation mask").
        stage: &'static str,
    },
    /// A code phase outside [0, 1 ms) or not finite.
    #[error(
        "PRN {prn}: tx_time_mod_1ms_s = {value} is not in [0, 1e-3) s; pass the SV transmit \
         time modulo 1 ms (code phase in chips / 1.023e6)"
    )]
    InvalidCodePhase {
        /// PRN.
        prn: u8,
        /// Offending value.
        value: f64,
    },
    /// A-priori time, position or uncertainty unusable.
    #[error(
        "invalid a-priori {field} = {value}; give a finite time, a position near the Earth's \
         surface and positive, finite uncertainties"
    )]
    InvalidApriori {
        /// Field name.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
    /// No integer hypothesis passed the residual test.
    #[error(
        "no whole-millisecond hypothesis fits the code phases ({hypotheses} tried, best \
         chi-square {best_ratio:.1} times its threshold): the a-priori position or time is \
         probably beyond the coarse-time limits (tested: 100 km and 60 s, see the \
         pvt::coarse_time docs) or a code phase is wrong; give a better a-priori or wait for \
         the time of week"
    )]
    NoConsistentIntegers {
        /// Distinct hypotheses solved.
        hypotheses: usize,
        /// Smallest e^T P e / threshold among them (infinite if none converged).
        best_ratio: f64,
    },
    /// Only solutions outside the stated a-priori uncertainty fit.
    #[error(
        "the only consistent solutions lie {pos_shift_m:.0} m and {time_shift_s:.1} s from the \
         a-priori, beyond its stated uncertainty; check the a-priori position and time (or \
         widen the uncertainty if it really is that poor)"
    )]
    OutsideApriori {
        /// Distance of the nearest such solution from the a-priori position, m.
        pos_shift_m: f64,
        /// Its time correction, s.
        time_shift_s: f64,
    },
    /// Different hypotheses fit equally.
    #[error(
        "{count} different whole-millisecond hypotheses fit the code phases (solutions up to \
         {separation_m:.0} m and {separation_s:.3} s apart): the fix is ambiguous; track more \
         satellites or tighten the a-priori"
    )]
    Ambiguous {
        /// Passing hypotheses.
        count: usize,
        /// Largest position separation from the best, m.
        separation_m: f64,
        /// Largest time separation from the best, s.
        separation_s: f64,
    },
}

/// A satellite evaluated at a receiver position and reception time.
#[derive(Debug, Clone, Copy)]
struct Evaluated {
    pred: Predicted,
    /// d(range_model_m)/dt for a receiver fixed in ECEF, m/s.
    rate_mps: f64,
}

/// The validated problem.
#[derive(Debug)]
struct Problem<'a> {
    /// Measurements above the mask.
    meas: Vec<CoarseMeasurement<'a>>,
    apriori: CoarseApriori,
    opts: &'a PvtOptions,
    /// Each satellite at the a-priori position and time (parallel to `meas`).
    at_apriori: Vec<Evaluated>,
}

/// One whole-millisecond hypothesis. The transmit times are kept as the reference's
/// t~_r plus small differences, so that the rounding of a GpsTime (1e-10 s at a TOW of 6e5 s)
/// is common to all satellites and goes into the clock bias.
#[derive(Debug, Clone)]
struct Hypothesis {
    /// Reconstructed full transmit time of the reference, t~_r.
    tx_ref: GpsTime,
    /// t~_k - t~_r per satellite (parallel to `Problem::meas`), s.
    tx_offset_s: Vec<f64>,
    /// Satellites taking part.
    active: Vec<bool>,
    /// Index of the reference satellite.
    reference: usize,
    /// Satellite index and +-1 ms moved away from the reference-based integer.
    adjusted: Option<(usize, i64)>,
    /// The first hypothesis: all satellites, highest-elevation reference, no adjustment.
    primary: bool,
}

/// A converged five-state fix of one hypothesis.
#[derive(Debug, Clone)]
struct CoarseFix {
    pos_m: Vector3<f64>,
    clock_bias_m: f64,
    time_correction_s: f64,
    /// Indices of the satellites used.
    used: Vec<usize>,
    evals: Vec<Evaluated>,
    rows: Vec<[f64; 5]>,
    sigmas_m: Vec<f64>,
    residuals_m: Vec<f64>,
    n_inv: Matrix5,
    wsse: f64,
    dof: usize,
    iterations: usize,
}

impl CoarseFix {
    /// Chi-square threshold at 1 - pfa (None without redundancy).
    fn threshold(&self, pfa: f64) -> Option<f64> {
        chi_square_quantile(1.0 - pfa, self.dof as f64)
    }
}

/// A solved hypothesis.
#[derive(Debug, Clone)]
struct Candidate {
    hyp: Hypothesis,
    fix: CoarseFix,
}

/// Solves position, clock bias and the coarse-time error from sub-millisecond transmit times
/// (module docs: van Diggelen ch. 4). Needs at least 5 satellites above the elevation mask at
/// the a-priori position, 6 to check the integers. Uses from `opts` the atmosphere, the mask,
/// the weighting, `raim_pfa` and `max_iterations`.
pub fn solve_coarse_time(
    meas: &[CoarseMeasurement<'_>],
    apriori: &CoarseApriori,
    opts: &PvtOptions,
) -> Result<CoarseTimeSolution, CoarseTimeError> {
    opts.validate()?;
    validate_apriori(apriori)?;
    validate_measurements(meas)?;
    if meas.len() < MIN_SATELLITES {
        return Err(CoarseTimeError::TooFewObservations {
            available: meas.len(),
            required: MIN_SATELLITES,
            stage: "input checks",
        });
    }
    let mask_rad = opts.elevation_mask_deg.to_radians();
    let (mut kept, mut at_apriori, mut masked_prns) = (Vec::new(), Vec::new(), Vec::new());
    for m in meas {
        let e = evaluate(m, 0.0, &apriori.pos_ecef_m, apriori.time, opts)?;
        if e.pred.el_rad < mask_rad {
            masked_prns.push(m.prn);
        } else {
            kept.push(*m);
            at_apriori.push(e);
        }
    }
    if kept.len() < MIN_SATELLITES {
        return Err(CoarseTimeError::TooFewObservations {
            available: kept.len(),
            required: MIN_SATELLITES,
            stage: "elevation mask",
        });
    }
    let problem = Problem {
        meas: kept,
        apriori: *apriori,
        opts,
        at_apriori,
    };
    let (best, tried) = search(&problem)?;
    Ok(assemble(&problem, &best, tried, masked_prns))
}

fn validate_apriori(a: &CoarseApriori) -> Result<(), CoarseTimeError> {
    let bad = |field, value| Err(CoarseTimeError::InvalidApriori { field, value });
    let radius = a.pos_ecef_m.norm();
    if !a.time.tow_s.is_finite() {
        return bad("time.tow_s", a.time.tow_s);
    }
    if !APRIORI_RADIUS_M.contains(&radius) {
        return bad("pos_ecef_m (distance from the Earth's centre, m)", radius);
    }
    if !(a.time_uncertainty_s.is_finite() && a.time_uncertainty_s > 0.0) {
        return bad("time_uncertainty_s", a.time_uncertainty_s);
    }
    if !(a.pos_uncertainty_m.is_finite() && a.pos_uncertainty_m > 0.0) {
        return bad("pos_uncertainty_m", a.pos_uncertainty_m);
    }
    if let Some(h) = a.height {
        if !(h.h_m.is_finite() && h.h_m.abs() < 1.0e6) {
            return bad("height.h_m", h.h_m);
        }
        if !(h.sigma_m.is_finite() && h.sigma_m > 0.0) {
            return bad("height.sigma_m", h.sigma_m);
        }
    }
    if let Some(s) = a.time_sigma_s {
        if !(s.is_finite() && s > 0.0) {
            return bad("time_sigma_s", s);
        }
    }
    Ok(())
}

fn validate_measurements(meas: &[CoarseMeasurement<'_>]) -> Result<(), CoarseTimeError> {
    let mut prns = Vec::with_capacity(meas.len());
    for m in meas {
        check_satellite(m.prn, m.ephemeris, m.cn0_dbhz, &prns)?;
        if !(0.0..CA_CODE_PERIOD_S).contains(&m.tx_time_mod_1ms_s) {
            return Err(CoarseTimeError::InvalidCodePhase {
                prn: m.prn,
                value: m.tx_time_mod_1ms_s,
            });
        }
        prns.push(m.prn);
    }
    Ok(())
}

/// Satellite `m` seen from `rx` at GPS reception time `t`: transmit time by the light-time
/// solution of [`Ephemeris::at_reception`], state there, the pseudorange model
/// ([`predict`], atmosphere on) and its rate. `pseudorange_m` is only carried along.
fn evaluate(
    m: &CoarseMeasurement<'_>,
    pseudorange_m: f64,
    rx: &Vector3<f64>,
    t: GpsTime,
    opts: &PvtOptions,
) -> Result<Evaluated, PvtError> {
    let seen = m.ephemeris.at_reception(t, rx, 0.075, 3);
    let t_tx = t.add_seconds(-seen.flight_time_s);
    let sat = PreparedSat {
        prn: m.prn,
        pseudorange_m,
        doppler_hz: None,
        cn0_dbhz: m.cn0_dbhz,
        t_tx,
        sv: state_at_transmit(m.prn, m.ephemeris, t_tx)?,
    };
    let pred = predict(&sat, rx, true, opts, t.tow_s);
    let rate_mps = sat_range_rate(&sat, &pred).rate_mps;
    Ok(Evaluated { pred, rate_mps })
}

/// The SV transmit time modulo 1 ms that satellite `prn` (ephemeris `eph`) should show at the
/// common reception instant of `sol`, solved with the a-priori time `apriori_time`:
/// `phi = (t_a - (R(x, t) + b) / c) mod 1 ms` with R the pseudorange model at the solution's
/// position x and time t, and b its clock-bias unknown (module docs). Used to look for a
/// satellite the search missed at the code phase the fix predicts.
pub fn predicted_tx_time_mod_1ms(
    sol: &CoarseTimeSolution,
    apriori_time: GpsTime,
    eph: &Ephemeris,
    opts: &PvtOptions,
) -> Result<f64, PvtError> {
    let m = CoarseMeasurement {
        prn: eph.prn,
        tx_time_mod_1ms_s: 0.0,
        cn0_dbhz: 40.0,
        ephemeris: eph,
    };
    let e = evaluate(&m, 0.0, &sol.pos_ecef_m, sol.time, opts)?;
    let tx =
        apriori_time.add_seconds(-(e.pred.range_model_m + sol.clock_bias_m) / SPEED_OF_LIGHT_MPS);
    let phi = tx.tow_s.rem_euclid(CA_CODE_PERIOD_S);
    Ok(if phi >= CA_CODE_PERIOD_S { 0.0 } else { phi })
}

/// Indices of the active satellites, highest a-priori elevation first.
fn by_elevation(p: &Problem<'_>, active: &[bool]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..p.meas.len()).filter(|&i| active[i]).collect();
    idx.sort_by(|&a, &b| {
        let (ea, eb) = (p.at_apriori[a].pred.el_rad, p.at_apriori[b].pred.el_rad);
        eb.total_cmp(&ea)
    });
    idx
}

/// The whole-millisecond reconstruction of the module docs with `reference` as r:
/// N_r = round((t_hat_r - phi_r)/T), N_k = N_r + round((t_hat_k - t_hat_r - (phi_k - phi_r))/T).
fn reconstruct(p: &Problem<'_>, reference: usize, active: &[bool]) -> Hypothesis {
    let t_hat = |k: usize| {
        p.apriori
            .time
            .add_seconds(-p.at_apriori[k].pred.range_model_m / SPEED_OF_LIGHT_MPS)
    };
    let phi = |k: usize| p.meas[k].tx_time_mod_1ms_s;
    let t_ref = t_hat(reference);
    let n_ref = ((t_ref.tow_s - phi(reference)) / CA_CODE_PERIOD_S).round();
    let tx_ref = GpsTime::new(t_ref.week, n_ref * CA_CODE_PERIOD_S + phi(reference));
    let tx_offset_s = (0..p.meas.len())
        .map(|k| {
            let d_phi = phi(k) - phi(reference);
            let n_k = ((t_hat(k).diff_s(t_ref) - d_phi) / CA_CODE_PERIOD_S).round();
            n_k * CA_CODE_PERIOD_S + d_phi
        })
        .collect();
    Hypothesis {
        tx_ref,
        tx_offset_s,
        active: active.to_vec(),
        reference,
        adjusted: None,
        primary: false,
    }
}

/// Identity of a hypothesis up to a common shift: the active set and each active satellite's
/// whole milliseconds relative to the first active one.
fn key(p: &Problem<'_>, h: &Hypothesis) -> Vec<Option<i64>> {
    let Some(first) = h.active.iter().position(|&a| a) else {
        return Vec::new();
    };
    let phi = |k: usize| p.meas[k].tx_time_mod_1ms_s;
    (0..h.tx_offset_s.len())
        .map(|k| {
            h.active[k].then(|| {
                let d = h.tx_offset_s[k] - h.tx_offset_s[first] - (phi(k) - phi(first));
                (d / CA_CODE_PERIOD_S).round() as i64
            })
        })
        .collect()
}

/// Linearised observation equations of one iteration.
#[derive(Debug)]
struct Linearised {
    used: Vec<usize>,
    evals: Vec<Evaluated>,
    rows: Vec<[f64; 5]>,
    sigmas_m: Vec<f64>,
    y_m: Vec<f64>,
}

/// Rows [-e^T, 1, v] and observed-minus-computed rho~_k - R_k(x, t_a + dt) - b.
fn linearise(
    p: &Problem<'_>,
    h: &Hypothesis,
    x: &Vector3<f64>,
    clock_bias_m: f64,
    dt_s: f64,
) -> Result<Linearised, PvtError> {
    let t = p.apriori.time.add_seconds(dt_s);
    let rho_ref_m = SPEED_OF_LIGHT_MPS * p.apriori.time.diff_s(h.tx_ref);
    let mut lin = Linearised {
        used: Vec::new(),
        evals: Vec::new(),
        rows: Vec::new(),
        sigmas_m: Vec::new(),
        y_m: Vec::new(),
    };
    for (k, m) in p.meas.iter().enumerate() {
        if !h.active[k] {
            continue;
        }
        let rho_m = rho_ref_m - SPEED_OF_LIGHT_MPS * h.tx_offset_s[k];
        let e = evaluate(m, rho_m, x, t, p.opts)?;
        let l = e.pred.los;
        lin.rows.push([-l.x, -l.y, -l.z, 1.0, e.rate_mps]);
        lin.sigmas_m
            .push(p.opts.weighting.sigma_m(e.pred.el_rad, m.cn0_dbhz));
        lin.y_m.push(rho_m - e.pred.range_model_m - clock_bias_m);
        lin.used.push(k);
        lin.evals.push(e);
    }
    if let Some(hc) = p.apriori.height {
        // Up unit vector and height at the current estimate: d h = u . dx.
        let llh = Llh::from_ecef(x);
        let (slat, clat) = llh.lat_rad.sin_cos();
        let (slon, clon) = llh.lon_rad.sin_cos();
        lin.rows.push([clat * clon, clat * slon, slat, 0.0, 0.0]);
        lin.sigmas_m.push(hc.sigma_m);
        lin.y_m.push(hc.h_m - llh.h_m);
    }
    if let Some(sigma_s) = p.apriori.time_sigma_s {
        lin.rows.push([0.0, 0.0, 0.0, 0.0, 1.0]);
        lin.sigmas_m.push(sigma_s);
        lin.y_m.push(-dt_s);
    }
    Ok(lin)
}

/// Unweighted cofactor matrix (G^T G)^-1 of five-state rows, if the geometry is not singular.
fn cofactor(rows: &[[f64; 5]]) -> Option<Matrix5> {
    let mut g = Matrix5::zeros();
    for r in rows {
        let a = Vector5::from(*r);
        g += a * a.transpose();
    }
    let q = g.try_inverse()?;
    (q.trace() >= 0.0 && q.trace().sqrt() <= MAX_GDOP).then_some(q)
}

/// One weighted least-squares step: (A^T P A)^-1 A^T P y and (A^T P A)^-1.
fn weighted_step(lin: &Linearised) -> Result<(Vector5, Matrix5), PvtError> {
    let singular = PvtError::SingularGeometry {
        gdop: f64::INFINITY,
    };
    if cofactor(&lin.rows).is_none() {
        return Err(singular);
    }
    let mut n = Matrix5::zeros();
    let mut c = Vector5::zeros();
    for ((r, s), y) in lin.rows.iter().zip(&lin.sigmas_m).zip(&lin.y_m) {
        let a = Vector5::from(*r);
        let w = 1.0 / (s * s);
        n += a * a.transpose() * w;
        c += a * (w * y);
    }
    let n_inv = n.try_inverse().ok_or(singular)?;
    Ok((n_inv * c, n_inv))
}

/// Iterates the five-state least squares of hypothesis `h` from the a-priori to convergence.
fn solve_hypothesis(p: &Problem<'_>, h: &Hypothesis) -> Result<CoarseFix, PvtError> {
    let mut x = p.apriori.pos_ecef_m;
    let (mut clock_bias_m, mut dt_s) = (0.0, 0.0);
    let mut last_step_m = f64::INFINITY;
    for iteration in 1..=p.opts.max_iterations {
        let lin = linearise(p, h, &x, clock_bias_m, dt_s)?;
        if lin.rows.len() < N_COARSE_UNKNOWNS {
            return Err(PvtError::SingularGeometry {
                gdop: f64::INFINITY,
            });
        }
        let (dx, n_inv) = weighted_step(&lin)?;
        let dpos = Vector3::new(dx[0], dx[1], dx[2]);
        x += dpos;
        clock_bias_m += dx[3];
        dt_s += dx[4];
        last_step_m = dpos.norm();
        let finite = x.iter().all(|v| v.is_finite()) && clock_bias_m.is_finite();
        if !(finite && x.norm() <= MAX_RADIUS_M && dt_s.abs() <= MAX_TIME_CORRECTION_S) {
            break;
        }
        if last_step_m < CONVERGED_STEP_M && dx[4].abs() * MAX_RANGE_RATE_MPS < CONVERGED_STEP_M {
            // Post-fit residuals e = y - A dx (the model at the final point differs by the
            // update squared over the range).
            let residuals_m: Vec<f64> = lin
                .rows
                .iter()
                .zip(&lin.y_m)
                .map(|(r, y)| y - Vector5::from(*r).dot(&dx))
                .collect();
            let wsse = residuals_m
                .iter()
                .zip(&lin.sigmas_m)
                .map(|(e, s)| (e / s) * (e / s))
                .sum();
            let dof = lin.rows.len() - N_COARSE_UNKNOWNS;
            return Ok(CoarseFix {
                pos_m: x,
                clock_bias_m,
                time_correction_s: dt_s,
                used: lin.used,
                evals: lin.evals,
                rows: lin.rows,
                sigmas_m: lin.sigmas_m,
                residuals_m,
                n_inv,
                wsse,
                dof,
                iterations: iteration,
            });
        }
    }
    Err(PvtError::Diverged {
        iterations: p.opts.max_iterations,
        last_step_m,
    })
}

/// The hypotheses tried so far and their outcomes.
#[derive(Debug, Default)]
struct Search {
    seen: Vec<Vec<Option<i64>>>,
    /// Converged hypotheses.
    solved: Vec<Candidate>,
}

impl Search {
    /// Solves `h` unless an equivalent hypothesis was solved already.
    fn try_hypothesis(&mut self, p: &Problem<'_>, h: Hypothesis) {
        let k = key(p, &h);
        if self.seen.contains(&k) {
            return;
        }
        self.seen.push(k);
        if let Ok(fix) = solve_hypothesis(p, &h) {
            self.solved.push(Candidate { hyp: h, fix });
        }
    }
}

/// Whether a candidate passes the chi-square test.
fn passes_test(p: &Problem<'_>, c: &Candidate) -> bool {
    chi_square_passes(c.fix.wsse, c.fix.dof, p.opts.raim_pfa)
}

/// Whether a candidate lies within the a-priori uncertainty.
fn within_apriori(p: &Problem<'_>, c: &Candidate) -> bool {
    (c.fix.pos_m - p.apriori.pos_ecef_m).norm() <= p.apriori.pos_uncertainty_m
        && c.fix.time_correction_s.abs() <= p.apriori.time_uncertainty_s
}

/// The hypothesis search of the module docs; returns the accepted candidate and the number of
/// distinct hypotheses solved.
fn search(p: &Problem<'_>) -> Result<(Candidate, usize), CoarseTimeError> {
    let n = p.meas.len();
    let all = vec![true; n];
    let mut s = Search::default();
    for (i, r) in by_elevation(p, &all).into_iter().enumerate() {
        let mut h = reconstruct(p, r, &all);
        h.primary = i == 0;
        s.try_hypothesis(p, h);
    }
    if let Some(best) = accept(p, &s.solved)? {
        return Ok((best, s.seen.len()));
    }
    // +-1 ms on the satellite with the largest normalised residual of the best hypothesis.
    if let Some((base, worst)) = worst_satellite(p, &s.solved) {
        for shift in [-1i64, 1] {
            let mut h = base.clone();
            h.tx_offset_s[worst] += shift as f64 * CA_CODE_PERIOD_S;
            h.adjusted = Some((worst, shift));
            h.primary = false;
            s.try_hypothesis(p, h);
        }
        if let Some(best) = accept(p, &s.solved)? {
            return Ok((best, s.seen.len()));
        }
    }
    // Each satellite left out in turn, while the rest can still be checked.
    if n > MIN_SATELLITES_CHECKED {
        for left_out in 0..n {
            let mut active = all.clone();
            active[left_out] = false;
            if let Some(&r) = by_elevation(p, &active).first() {
                s.try_hypothesis(p, reconstruct(p, r, &active));
            }
        }
        if let Some(best) = accept(p, &s.solved)? {
            return Ok((best, s.seen.len()));
        }
    }
    Err(rejection(p, &s))
}

/// The hypothesis with the smallest chi-square ratio and its satellite with the largest
/// normalised residual (index into `Problem::meas`).
fn worst_satellite(p: &Problem<'_>, solved: &[Candidate]) -> Option<(Hypothesis, usize)> {
    let ratio = |c: &Candidate| c.fix.threshold(p.opts.raim_pfa).map(|t| c.fix.wsse / t);
    let best = solved
        .iter()
        .filter(|c| ratio(c).is_some())
        .min_by(|a, b| {
            ratio(a)
                .unwrap_or(f64::INFINITY)
                .total_cmp(&ratio(b).unwrap_or(f64::INFINITY))
        })?;
    let f = &best.fix;
    let w = normalised_residuals(&f.rows, &f.sigmas_m, &f.residuals_m, &f.n_inv);
    // Satellite rows only (a height row comes after them).
    let n_sat = f.used.len().min(w.len());
    let j = (0..n_sat).max_by(|&a, &b| w[a].total_cmp(&w[b]))?;
    Some((best.hyp.clone(), f.used[j]))
}

/// Among the solved candidates, those passing the test and the a-priori bounds: none (Ok(None)),
/// agreeing ones (the one with most satellites, then smallest e^T P e), or an ambiguity.
fn accept(p: &Problem<'_>, solved: &[Candidate]) -> Result<Option<Candidate>, CoarseTimeError> {
    let good: Vec<&Candidate> = solved
        .iter()
        .filter(|c| passes_test(p, c) && within_apriori(p, c))
        .collect();
    let Some(best) = good.iter().copied().min_by(|a, b| {
        b.fix
            .used
            .len()
            .cmp(&a.fix.used.len())
            .then(a.fix.wsse.total_cmp(&b.fix.wsse))
    }) else {
        return Ok(None);
    };
    let separation_m = good
        .iter()
        .map(|c| (c.fix.pos_m - best.fix.pos_m).norm())
        .fold(0.0, f64::max);
    let separation_s = good
        .iter()
        .map(|c| (c.fix.time_correction_s - best.fix.time_correction_s).abs())
        .fold(0.0, f64::max);
    if separation_m > AGREEMENT_M || separation_s > AGREEMENT_S {
        return Err(CoarseTimeError::Ambiguous {
            count: good.len(),
            separation_m,
            separation_s,
        });
    }
    Ok(Some(best.clone()))
}

/// The error when nothing was accepted: solutions outside the a-priori bounds if some passed
/// the test, otherwise no consistent integers.
fn rejection(p: &Problem<'_>, s: &Search) -> CoarseTimeError {
    let outside = s
        .solved
        .iter()
        .filter(|c| passes_test(p, c))
        .min_by(|a, b| {
            let d = |c: &Candidate| (c.fix.pos_m - p.apriori.pos_ecef_m).norm();
            d(a).total_cmp(&d(b))
        });
    if let Some(c) = outside {
        return CoarseTimeError::OutsideApriori {
            pos_shift_m: (c.fix.pos_m - p.apriori.pos_ecef_m).norm(),
            time_shift_s: c.fix.time_correction_s,
        };
    }
    let best_ratio = s
        .solved
        .iter()
        .filter_map(|c| c.fix.threshold(p.opts.raim_pfa).map(|t| c.fix.wsse / t))
        .fold(f64::INFINITY, f64::min);
    CoarseTimeError::NoConsistentIntegers {
        hypotheses: s.seen.len(),
        best_ratio,
    }
}

/// Builds the solution of the accepted candidate: the common whole milliseconds
/// u = round((b/c + dt_c) / T) refer the transmit times to the corrected time.
fn assemble(
    p: &Problem<'_>,
    c: &Candidate,
    tried: usize,
    masked_prns: Vec<u8>,
) -> CoarseTimeSolution {
    let f = &c.fix;
    let time = p.apriori.time.add_seconds(f.time_correction_s);
    let u_ms =
        ((f.clock_bias_m / SPEED_OF_LIGHT_MPS + f.time_correction_s) / CA_CODE_PERIOD_S).round();
    // c (time - t_sv,k) = c (t_a - t~_r) + c (dt_c - u) - c (t~_k - t~_r), small terms apart.
    let rho_ref_m = SPEED_OF_LIGHT_MPS
        * (p.apriori.time.diff_s(c.hyp.tx_ref) + f.time_correction_s - u_ms * CA_CODE_PERIOD_S);
    let satellites = f
        .used
        .iter()
        .zip(&f.evals)
        .zip(&f.residuals_m)
        .map(|((&k, e), &residual_m)| {
            let offset_s = c.hyp.tx_offset_s[k];
            CoarseSatellite {
                prn: p.meas[k].prn,
                tx_time: c.hyp.tx_ref.add_seconds(u_ms * CA_CODE_PERIOD_S + offset_s),
                pseudorange_m: rho_ref_m - SPEED_OF_LIGHT_MPS * offset_s,
                residual_m,
                el_rad: e.pred.el_rad,
            }
        })
        .collect();
    let sigma0 = if f.dof > 0 {
        (f.wsse / f.dof as f64).sqrt()
    } else {
        1.0
    };
    let covariance = f.n_inv * (sigma0 * sigma0);
    let llh = Llh::from_ecef(&f.pos_m);
    let q = cofactor(&f.rows).unwrap_or_else(|| Matrix5::from_element(f64::NAN));
    let q_pos: Matrix3<f64> = q.fixed_view::<3, 3>(0, 0).into_owned();
    let nan_dop = Dop {
        gdop: f64::NAN,
        pdop: f64::NAN,
        hdop: f64::NAN,
        vdop: f64::NAN,
        tdop: f64::NAN,
    };
    let integrity = match f.threshold(p.opts.raim_pfa) {
        Some(threshold) => CoarseIntegrity::Passed {
            wsse: f.wsse,
            threshold,
            dof: f.dof,
        },
        None => CoarseIntegrity::Unverified,
    };
    let used_prns: Vec<u8> = f.used.iter().map(|&k| p.meas[k].prn).collect();
    CoarseTimeSolution {
        time,
        time_correction_s: f.time_correction_s,
        time_sigma_s: covariance[(4, 4)].sqrt(),
        pos_ecef_m: f.pos_m,
        llh,
        clock_bias_m: f.clock_bias_m,
        clock_bias_s: f.clock_bias_m / SPEED_OF_LIGHT_MPS,
        common_ms_shift: u_ms as i64,
        satellites,
        reference_prn: p.meas[c.hyp.reference].prn,
        adjusted: c.hyp.adjusted.map(|(k, s)| (p.meas[k].prn, s)),
        excluded_prns: p
            .meas
            .iter()
            .map(|m| m.prn)
            .filter(|prn| !used_prns.contains(prn))
            .collect(),
        masked_prns,
        dop: dop_from_cofactor(&q_pos, q[(3, 3)], &llh).unwrap_or(nan_dop),
        time_dop_s_per_m: q[(4, 4)].sqrt(),
        sigma0,
        covariance,
        integrity,
        hypotheses_tried: tried,
        used_fallback: !c.hyp.primary,
        iterations: f.iterations,
    }
}
