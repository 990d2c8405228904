//! Pseudorange measurement model (seed 001 eqs. 3.1-3.2) and a-priori weights.
//!
//! For satellite k the modelled pseudorange is
//!
//! ```text
//! P = |R3(OmegaE tau) r_sv(t_tx) - r_rx| + c dt_rx - c dt_sv(t_tx) + I + T
//! ```
//!
//! - t_tx, the GPS transmit time, is t_sv - dt_sv(t_tx) (IS-GPS-200 20.3.3.3.3.1), iterated,
//!   where t_sv is the raw SV transmit time read from the signal
//!   ([`SatMeasurement::tx_time`]) or, when the caller does not give it,
//!   t_rx - P/c (identical by the definition of the pseudorange);
//! - R3(OmegaE tau) rotates the ECEF position at transmission into the ECEF frame at reception,
//!   tau = flight time (IS-GPS-200 20.3.3.4.3.3.2);
//! - dt_sv includes the relativistic term and -T_GD ([`crate::SvState::clock_bias_s`]);
//! - I: broadcast Klobuchar L1 group delay, T: Saastamoinen, both optional.

use super::PvtError;
use crate::atmosphere::{klobuchar_delay_s, saastamoinen_delay_m, KlobucharParams};
use crate::constants::SPEED_OF_LIGHT_MPS;
use crate::ephemeris::{Ephemeris, SvState};
use crate::frames::{azimuth_elevation, light_time, Llh, Vector3};
use crate::time::GpsTime;

/// One satellite's observables at one epoch.
#[derive(Debug, Clone, Copy)]
pub struct SatMeasurement<'a> {
    /// PRN, 1-63 (must match `ephemeris.prn`).
    pub prn: u8,
    /// Pseudorange c (t_rx - t_sv), m, by the receiver clock; positive and finite.
    pub pseudorange_m: f64,
    /// L1 Doppler, Hz, positive when the satellite approaches (range shrinking).
    pub doppler_hz: Option<f64>,
    /// Carrier-to-noise density, dB-Hz (used by [`Weighting::ElevationCn0`]).
    pub cn0_dbhz: f64,
    /// Raw SV transmit time t_sv as read from the signal (TOW + code phase), i.e. by the
    /// satellite's clock, NOT corrected for the SV clock offset: the solver applies dt_sv.
    /// None: taken as `epoch_rx_time - pseudorange_m / c`, which is the same thing.
    pub tx_time: Option<GpsTime>,
    /// Broadcast ephemeris of this satellite.
    pub ephemeris: &'a Ephemeris,
}

/// A-priori pseudorange standard deviation model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Weighting {
    /// The same sigma for every satellite, m.
    Uniform {
        /// Pseudorange sigma, m.
        sigma_m: f64,
    },
    /// sigma^2 = (a^2 + b^2 / sin^2(el)) * 10^((cn0_ref - cn0)/10): a constant term plus a term
    /// growing at low elevation (multipath, troposphere residual), scaled by the C/N0 deficit
    /// (thermal code noise variance is inversely proportional to linear C/N0).
    /// sin(el) is floored at 0.05 (2.9 deg).
    ElevationCn0 {
        /// Constant term a, m.
        a_m: f64,
        /// Elevation term b, m.
        b_m: f64,
        /// C/N0 at which the scale factor is 1, dB-Hz.
        cn0_ref_dbhz: f64,
    },
}

impl Weighting {
    /// Pseudorange sigma, m, for elevation `el_rad` and C/N0 `cn0_dbhz`.
    pub fn sigma_m(&self, el_rad: f64, cn0_dbhz: f64) -> f64 {
        match *self {
            Weighting::Uniform { sigma_m } => sigma_m,
            Weighting::ElevationCn0 {
                a_m,
                b_m,
                cn0_ref_dbhz,
            } => {
                let s = el_rad.sin().max(0.05);
                let scale = 10f64.powf((cn0_ref_dbhz - cn0_dbhz) / 10.0);
                ((a_m * a_m + b_m * b_m / (s * s)) * scale).sqrt()
            }
        }
    }

    /// C/N0-only variance scale 10^((cn0_ref - cn0)/10) (1 for `Uniform`); used for Dopplers.
    pub fn cn0_scale(&self, cn0_dbhz: f64) -> f64 {
        match *self {
            Weighting::Uniform { .. } => 1.0,
            Weighting::ElevationCn0 { cn0_ref_dbhz, .. } => {
                10f64.powf((cn0_ref_dbhz - cn0_dbhz) / 10.0)
            }
        }
    }
}

/// Solver options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PvtOptions {
    /// Broadcast Klobuchar coefficients; None = no ionospheric correction.
    pub iono: Option<KlobucharParams>,
    /// Apply the Saastamoinen troposphere (turn off for simulator files without troposphere).
    pub tropo: bool,
    /// Elevation mask, deg. It and the atmospheric corrections act only once the position is
    /// known: from a prior solution, or from the iteration whose update fell below 1 km. Before
    /// that (cold start at the Earth's centre) elevations are meaningless and all satellites
    /// are used with zenith weights.
    pub elevation_mask_deg: f64,
    /// Pseudorange sigma model.
    pub weighting: Weighting,
    /// Range-rate sigma at the reference C/N0, m/s (scaled by [`Weighting::cn0_scale`]).
    pub doppler_sigma_mps: f64,
    /// RAIM false-alarm probability of the chi-square test, in (0, 1); RAIM is off when `raim`
    /// is false.
    pub raim_pfa: f64,
    /// Run RAIM detection and exclusion.
    pub raim: bool,
    /// Maximum Gauss-Newton iterations (a cold start needs about 6-8; a damped iteration near
    /// a weak landmark geometry up to about 30).
    pub max_iterations: usize,
    /// PDOP above which the least-squares point is refused as
    /// [`super::PvtError::WeakGeometry`].
    pub max_pdop: f64,
}

impl Default for PvtOptions {
    /// No ionosphere (no coefficients known yet), troposphere on, 5 deg mask, elevation/C/N0
    /// weights with a = b = 1.5 m at 45 dB-Hz, Doppler sigma 0.1 m/s, RAIM at pfa 1e-3,
    /// 50 iterations, PDOP limit 50.
    fn default() -> PvtOptions {
        PvtOptions {
            iono: None,
            tropo: true,
            elevation_mask_deg: 5.0,
            weighting: Weighting::ElevationCn0 {
                a_m: 1.5,
                b_m: 1.5,
                cn0_ref_dbhz: 45.0,
            },
            doppler_sigma_mps: 0.1,
            raim_pfa: 1e-3,
            raim: true,
            max_iterations: 50,
            max_pdop: 50.0,
        }
    }
}

impl PvtOptions {
    /// Rejects out-of-range options.
    pub fn validate(&self) -> Result<(), PvtError> {
        let bad = |name, value| Err(PvtError::InvalidOption { name, value });
        if !(-90.0..=90.0).contains(&self.elevation_mask_deg) {
            return bad("elevation_mask_deg", self.elevation_mask_deg);
        }
        if !(self.raim_pfa > 0.0 && self.raim_pfa < 1.0) {
            return bad("raim_pfa", self.raim_pfa);
        }
        if !(self.doppler_sigma_mps > 0.0 && self.doppler_sigma_mps.is_finite()) {
            return bad("doppler_sigma_mps", self.doppler_sigma_mps);
        }
        if !(self.max_pdop.is_finite() && self.max_pdop > 0.0) {
            return bad("max_pdop", self.max_pdop);
        }
        if self.max_iterations == 0 {
            return bad("max_iterations", 0.0);
        }
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        match self.weighting {
            Weighting::Uniform { sigma_m } if !(ok(sigma_m) && sigma_m > 0.0) => {
                bad("weighting.sigma_m", sigma_m)
            }
            Weighting::ElevationCn0 {
                a_m,
                b_m,
                cn0_ref_dbhz,
            } if !(ok(a_m) && ok(b_m) && a_m + b_m > 0.0 && cn0_ref_dbhz.is_finite()) => {
                bad("weighting.a_m/b_m/cn0_ref_dbhz", a_m + b_m + cn0_ref_dbhz)
            }
            _ => Ok(()),
        }
    }
}

/// A validated measurement with the satellite state at its transmit time.
#[derive(Debug, Clone, Copy)]
pub struct PreparedSat {
    /// PRN.
    pub prn: u8,
    /// Pseudorange, m.
    pub pseudorange_m: f64,
    /// Doppler, Hz (positive approaching).
    pub doppler_hz: Option<f64>,
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
    /// GPS transmit time t_tx (SV clock offset removed).
    pub t_tx: GpsTime,
    /// Satellite state at t_tx in the ECEF frame of that instant.
    pub sv: SvState,
}

/// Checks what every satellite observation needs whatever its observable: PRN 1-63, the
/// ephemeris of that PRN, a finite C/N0 and a PRN not among `earlier_prns` (the satellites
/// already accepted in the epoch).
pub fn check_satellite(
    prn: u8,
    ephemeris: &Ephemeris,
    cn0_dbhz: f64,
    earlier_prns: &[u8],
) -> Result<(), PvtError> {
    if prn == 0 || prn > 63 {
        return Err(PvtError::InvalidMeasurement {
            prn,
            field: "prn",
            value: f64::from(prn),
        });
    }
    if ephemeris.prn != prn {
        return Err(PvtError::EphemerisMismatch {
            prn,
            eph_prn: ephemeris.prn,
        });
    }
    if !cn0_dbhz.is_finite() {
        return Err(PvtError::InvalidMeasurement {
            prn,
            field: "cn0_dbhz",
            value: cn0_dbhz,
        });
    }
    if earlier_prns.contains(&prn) {
        return Err(PvtError::DuplicatePrn { prn });
    }
    Ok(())
}

/// The state of satellite `prn` at GPS transmit time `t_tx` from `ephemeris`
/// ([`Ephemeris::sv_state`]), rejecting a non-finite position or clock.
pub fn state_at_transmit(
    prn: u8,
    ephemeris: &Ephemeris,
    t_tx: GpsTime,
) -> Result<SvState, PvtError> {
    let sv = ephemeris.sv_state(t_tx);
    if sv.pos_m.iter().all(|v| v.is_finite()) && sv.clock_bias_s.is_finite() {
        Ok(sv)
    } else {
        Err(PvtError::InvalidMeasurement {
            prn,
            field: "ephemeris (non-finite satellite state)",
            value: f64::NAN,
        })
    }
}

/// Checks the inputs (finite values, PRN/ephemeris match, no duplicates) and computes each
/// satellite's GPS transmit time t_tx = t_sv - dt_sv(t_tx) (3 fixed-point passes; dt_sv
/// changes by < 1e-11 s/s so the error after the third is far below 1e-15 s) and its state.
pub fn prepare(
    epoch_rx_time: GpsTime,
    meas: &[SatMeasurement<'_>],
) -> Result<Vec<PreparedSat>, PvtError> {
    let mut out: Vec<PreparedSat> = Vec::with_capacity(meas.len());
    let mut prns: Vec<u8> = Vec::with_capacity(meas.len());
    for m in meas {
        let invalid = |field, value| PvtError::InvalidMeasurement {
            prn: m.prn,
            field,
            value,
        };
        check_satellite(m.prn, m.ephemeris, m.cn0_dbhz, &prns)?;
        if !(m.pseudorange_m.is_finite() && m.pseudorange_m > 0.0) {
            return Err(invalid("pseudorange_m", m.pseudorange_m));
        }
        if let Some(d) = m.doppler_hz.filter(|d| !d.is_finite()) {
            return Err(invalid("doppler_hz", d));
        }
        if let Some(t) = m.tx_time.filter(|t| !t.tow_s.is_finite()) {
            return Err(invalid("tx_time.tow_s", t.tow_s));
        }
        if !epoch_rx_time.tow_s.is_finite() {
            return Err(invalid("epoch_rx_time.tow_s", epoch_rx_time.tow_s));
        }
        let t_sv = m
            .tx_time
            .unwrap_or_else(|| epoch_rx_time.add_seconds(-m.pseudorange_m / SPEED_OF_LIGHT_MPS));
        let mut t_tx = t_sv;
        for _ in 0..3 {
            t_tx = t_sv.add_seconds(-m.ephemeris.sv_state(t_tx).clock_bias_s);
        }
        let sv = state_at_transmit(m.prn, m.ephemeris, t_tx)?;
        prns.push(m.prn);
        out.push(PreparedSat {
            prn: m.prn,
            pseudorange_m: m.pseudorange_m,
            doppler_hz: m.doppler_hz,
            cn0_dbhz: m.cn0_dbhz,
            t_tx,
            sv,
        });
    }
    Ok(out)
}

/// The model evaluated at a receiver position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Predicted {
    /// Unit vector from the receiver to the satellite (rotated to the reception frame).
    pub los: Vector3<f64>,
    /// Satellite position in the reception frame, m.
    pub sv_pos_m: Vector3<f64>,
    /// Flight time tau, s.
    pub flight_time_s: f64,
    /// Modelled pseudorange without the receiver clock term, m.
    pub range_model_m: f64,
    /// Elevation, rad (pi/2 while the position is unknown).
    pub el_rad: f64,
}

/// Evaluates the pseudorange model for `sat` seen from `rx`. When `position_known` is false
/// the atmosphere is skipped and the elevation reported as the zenith.
pub fn predict(
    sat: &PreparedSat,
    rx: &Vector3<f64>,
    position_known: bool,
    opts: &PvtOptions,
    rx_tow_s: f64,
) -> Predicted {
    // Flight time from the geometry: two passes of tau = |R3(w tau) r_sv - r_rx| / c suffice
    // (the rotation moves the satellite by ~40 m, changing tau by < 1.4e-7 s, i.e. 1e-5 m).
    // The transmit time is known (prepare), so the state is fixed and only the rotation moves.
    let tau0 = (sat.sv.pos_m - rx).norm() / SPEED_OF_LIGHT_MPS;
    let seen = light_time(|_| sat.sv, rx, tau0, 3);
    let (sv_pos, tau) = (seen.sv.pos_m, seen.flight_time_s);
    let d = sv_pos - rx;
    let rho = d.norm();
    let los = if rho > 0.0 { d / rho } else { Vector3::z() };
    let mut range_model_m = rho - SPEED_OF_LIGHT_MPS * sat.sv.clock_bias_s;
    let mut el_rad = std::f64::consts::FRAC_PI_2;
    if position_known {
        let (az, el) = azimuth_elevation(rx, &sv_pos);
        el_rad = el;
        let llh = Llh::from_ecef(rx);
        if let Some(k) = &opts.iono {
            range_model_m += SPEED_OF_LIGHT_MPS * klobuchar_delay_s(k, rx_tow_s, &llh, az, el);
        }
        if opts.tropo {
            range_model_m += saastamoinen_delay_m(&llh, el);
        }
    }
    Predicted {
        los,
        sv_pos_m: sv_pos,
        flight_time_s: tau,
        range_model_m,
        el_rad,
    }
}
