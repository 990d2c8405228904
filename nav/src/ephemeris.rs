//! Broadcast ephemeris and satellite position, velocity and clock from it:
//! IS-GPS-200 20.3.3.3.3.1 (SV clock correction, relativistic term, TGD) and Table 20-IV
//! (user algorithm for ephemeris determination), with the velocity equations that Table 20-IV
//! gives for the same model (derivatives of the position equations, not finite differences).

use crate::constants::{F_REL_S_PER_SQRT_M, MU_M3_S2, OMEGA_E_DOT_RAD_S, SECONDS_PER_WEEK};
use crate::frames::{light_time, SvAtReception, Vector3};
use crate::time::GpsTime;

/// One GPS LNAV broadcast ephemeris + clock set (subframes 1-3, IS-GPS-200 Table 20-I/20-III),
/// in SI units (angles in radians, not semicircles).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ephemeris {
    /// PRN number, 1-32 (1-63 accepted for completeness).
    pub prn: u8,
    /// Clock data reference time.
    pub toc: GpsTime,
    /// SV clock bias, s.
    pub af0_s: f64,
    /// SV clock drift, s/s.
    pub af1_s_s: f64,
    /// SV clock drift rate, s/s^2.
    pub af2_s_s2: f64,
    /// Issue of data, ephemeris (8 bits).
    pub iode: u32,
    /// Issue of data, clock (10 bits).
    pub iodc: u32,
    /// Sine harmonic correction to the orbit radius, m.
    pub crs_m: f64,
    /// Mean motion difference from the computed value, rad/s.
    pub delta_n_rad_s: f64,
    /// Mean anomaly at reference time, rad.
    pub m0_rad: f64,
    /// Cosine harmonic correction to the argument of latitude, rad.
    pub cuc_rad: f64,
    /// Eccentricity (dimensionless).
    pub e: f64,
    /// Sine harmonic correction to the argument of latitude, rad.
    pub cus_rad: f64,
    /// Square root of the semi-major axis, sqrt(m).
    pub sqrt_a_sqrt_m: f64,
    /// Ephemeris reference time.
    pub toe: GpsTime,
    /// Cosine harmonic correction to the inclination, rad.
    pub cic_rad: f64,
    /// Longitude of ascending node of the orbit plane at weekly epoch, rad.
    pub omega0_rad: f64,
    /// Sine harmonic correction to the inclination, rad.
    pub cis_rad: f64,
    /// Inclination at reference time, rad.
    pub i0_rad: f64,
    /// Cosine harmonic correction to the orbit radius, m.
    pub crc_m: f64,
    /// Argument of perigee, rad.
    pub omega_rad: f64,
    /// Rate of right ascension, rad/s.
    pub omega_dot_rad_s: f64,
    /// Rate of inclination, rad/s.
    pub idot_rad_s: f64,
    /// L1-L2 group delay differential T_GD, s.
    pub tgd_s: f64,
    /// User range accuracy index N, 0-15 (20.3.3.3.1.3).
    pub ura_index: u8,
    /// 6-bit SV health (20.3.3.3.1.4); 0 = all signals OK.
    pub sv_health: u8,
    /// Codes on L2 (2 bits, 20.3.3.3.1.2).
    pub codes_on_l2: u8,
    /// L2 P data flag (20.3.3.3.1.6).
    pub l2p_data_flag: bool,
    /// Fit interval flag (20.3.3.4.3.1): false = 4 hours, true = more than 4 hours.
    pub fit_interval_flag: bool,
}

/// Satellite position, velocity and clock at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SvState {
    /// Antenna phase centre in WGS-84 ECEF at the requested time, m (no Earth rotation during
    /// signal flight applied).
    pub pos_m: Vector3<f64>,
    /// ECEF velocity, m/s (includes the frame rotation term, i.e. d(pos_m)/dt).
    pub vel_mps: Vector3<f64>,
    /// SV clock offset for an L1 C/A user, s: af0 + af1 dt + af2 dt^2 + F e sqrt(A) sin(E) - T_GD
    /// (20.3.3.3.3.1 and 20.3.3.3.3.2). The SV transmits early by this amount, so the
    /// corrected pseudorange is rho + c * clock_bias_s.
    pub clock_bias_s: f64,
    /// Time derivative of `clock_bias_s`, s/s: af1 + 2 af2 dt + F e sqrt(A) cos(E) dE/dt.
    pub clock_drift_s_s: f64,
}

/// Upper bounds of URA (m) for index N = 0..14 (IS-GPS-200 20.3.3.3.1.3); N = 15 is "no
/// accuracy prediction available".
const URA_BOUNDS_M: [f64; 15] = [
    2.4, 3.4, 4.85, 6.85, 9.65, 13.65, 24.0, 48.0, 96.0, 192.0, 384.0, 768.0, 1536.0, 3072.0,
    6144.0,
];

/// URA index N (0-15) for a user range accuracy in metres, as RINEX files store it
/// (IS-GPS-200 20.3.3.3.1.3): the smallest N whose upper bound is not below `ura_m`.
/// Negative or non-finite values give 15 (no prediction).
pub fn ura_index_from_m(ura_m: f64) -> u8 {
    if ura_m.is_nan() || ura_m < 0.0 {
        return 15;
    }
    URA_BOUNDS_M
        .iter()
        .position(|&bound| ura_m <= bound)
        .map_or(15, |n| n as u8)
}

/// Nominal URA in metres for index N (upper bound of the range; 6144 m or more for N >= 14).
pub fn ura_m_from_index(ura_index: u8) -> f64 {
    URA_BOUNDS_M
        .get(usize::from(ura_index))
        .copied()
        .unwrap_or(f64::INFINITY)
}

/// Maximum number of Newton iterations for Kepler's equation.
const KEPLER_MAX_ITER: usize = 30;
/// Convergence threshold on the eccentric anomaly, rad.
const KEPLER_TOL_RAD: f64 = 1e-14;

/// Solves Kepler's equation M = E - e sin(E) for E by Newton iteration to 1e-14 rad
/// (IS-GPS-200 Table 20-IV, "may be solved by iteration").
pub fn eccentric_anomaly_rad(mean_anomaly_rad: f64, e: f64) -> f64 {
    // Solve for the mean anomaly reduced to [-pi, pi] (a good Newton start for any e < 1),
    // then restore the whole turns removed.
    let two_pi = 2.0 * std::f64::consts::PI;
    let turns = (mean_anomaly_rad / two_pi).round() * two_pi;
    let m = mean_anomaly_rad - turns;
    let mut ecc = if e > 0.8 {
        std::f64::consts::PI.copysign(m)
    } else {
        m
    };
    for _ in 0..KEPLER_MAX_ITER {
        let f = ecc - e * ecc.sin() - m;
        let step = f / (1.0 - e * ecc.cos());
        ecc -= step;
        if step.is_nan() || step.abs() < KEPLER_TOL_RAD {
            break;
        }
    }
    ecc + turns
}

impl Ephemeris {
    /// Semi-major axis A = (sqrt A)^2, m.
    pub fn semi_major_axis_m(&self) -> f64 {
        self.sqrt_a_sqrt_m * self.sqrt_a_sqrt_m
    }

    /// Curve-fit interval, s (IS-GPS-200 20.3.4.4, Table 20-XII): 4 h when the fit interval flag
    /// is 0, otherwise the interval implied by IODC (6 h if not listed).
    pub fn fit_interval_s(&self) -> f64 {
        if !self.fit_interval_flag {
            return 4.0 * 3600.0;
        }
        let hours = match self.iodc {
            240..=247 => 8.0,
            248..=255 | 496 => 14.0,
            497..=503 | 1021..=1023 => 26.0,
            504..=510 => 50.0,
            511 | 752..=756 => 74.0,
            757..=763 => 98.0,
            764..=767 | 1008..=1010 => 122.0,
            768..=774 | 1011..=1020 => 146.0,
            _ => 6.0,
        };
        hours * 3600.0
    }

    /// Position, velocity and L1 C/A clock correction at GPS time `t`.
    ///
    /// Implements IS-GPS-200 Table 20-IV: t_k = t - toe (a full-week difference, so the week
    /// crossover is handled without the +-302400 s rule), Kepler's equation by Newton iteration
    /// to 1e-14 rad, second-harmonic corrections, and rotation to ECEF with
    /// Omega_k = Omega_0 + (Omega_dot - Omega_e_dot) t_k - Omega_e_dot toe. The clock follows
    /// 20.3.3.3.3.1 with dt = t - toc and Delta t_r = F e sqrt(A) sin(E_k), minus T_GD
    /// (20.3.3.3.3.2, single-frequency L1 C/A user).
    ///
    /// Strictly `t` in the clock polynomial is the SV transmit time; the difference from using
    /// GPS system time is below 1e-15 s and the caller can iterate if it matters.
    pub fn sv_state(&self, t: GpsTime) -> SvState {
        let a = self.semi_major_axis_m();
        let n0 = (MU_M3_S2 / (a * a * a)).sqrt();
        let tk = t.diff_s(self.toe);
        let n = n0 + self.delta_n_rad_s;
        let mk = self.m0_rad + n * tk;
        let ek = eccentric_anomaly_rad(mk, self.e);
        let (sin_e, cos_e) = ek.sin_cos();
        let one_minus_ecos = 1.0 - self.e * cos_e;
        let sqrt_1me2 = (1.0 - self.e * self.e).sqrt();
        let vk = (sqrt_1me2 * sin_e).atan2(cos_e - self.e);
        let phik = vk + self.omega_rad;
        let (s2p, c2p) = (2.0 * phik).sin_cos();
        let du = self.cus_rad * s2p + self.cuc_rad * c2p;
        let dr = self.crs_m * s2p + self.crc_m * c2p;
        let di = self.cis_rad * s2p + self.cic_rad * c2p;
        let uk = phik + du;
        let rk = a * one_minus_ecos + dr;
        let ik = self.i0_rad + di + self.idot_rad_s * tk;
        let (su, cu) = uk.sin_cos();
        let xp = rk * cu;
        let yp = rk * su;
        let omega_dot_k = self.omega_dot_rad_s - OMEGA_E_DOT_RAD_S;
        let omk = self.omega0_rad + omega_dot_k * tk - OMEGA_E_DOT_RAD_S * self.toe.tow_s;
        let (so, co) = omk.sin_cos();
        let (si, ci) = ik.sin_cos();
        let pos_m = Vector3::new(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si);

        // Velocity: time derivatives of the equations above (Table 20-IV velocity block).
        let ek_dot = n / one_minus_ecos;
        let vk_dot = ek_dot * sqrt_1me2 / one_minus_ecos;
        let uk_dot = vk_dot * (1.0 + 2.0 * (self.cus_rad * c2p - self.cuc_rad * s2p));
        let rk_dot =
            a * self.e * sin_e * ek_dot + 2.0 * vk_dot * (self.crs_m * c2p - self.crc_m * s2p);
        let ik_dot = self.idot_rad_s + 2.0 * vk_dot * (self.cis_rad * c2p - self.cic_rad * s2p);
        let xp_dot = rk_dot * cu - rk * uk_dot * su;
        let yp_dot = rk_dot * su + rk * uk_dot * cu;
        let vel_mps = Vector3::new(
            xp_dot * co - yp_dot * ci * so + yp * si * ik_dot * so
                - (xp * so + yp * ci * co) * omega_dot_k,
            xp_dot * so + yp_dot * ci * co - yp * si * ik_dot * co
                + (xp * co - yp * ci * so) * omega_dot_k,
            yp_dot * si + yp * ci * ik_dot,
        );

        // Clock, 20.3.3.3.3.1.
        let dt = t.diff_s(self.toc);
        let rel_s = F_REL_S_PER_SQRT_M * self.e * self.sqrt_a_sqrt_m * sin_e;
        let rel_rate_s_s = F_REL_S_PER_SQRT_M * self.e * self.sqrt_a_sqrt_m * cos_e * ek_dot;
        let clock_bias_s =
            self.af0_s + self.af1_s_s * dt + self.af2_s_s2 * dt * dt + rel_s - self.tgd_s;
        let clock_drift_s_s = self.af1_s_s + 2.0 * self.af2_s_s2 * dt + rel_rate_s_s;
        SvState {
            pos_m,
            vel_mps,
            clock_bias_s,
            clock_drift_s_s,
        }
    }

    /// Relativistic clock correction Delta t_r = F e sqrt(A) sin(E_k) at `t`, s
    /// (IS-GPS-200 20.3.3.3.3.1). Included in [`SvState::clock_bias_s`]; exposed for tests and
    /// for users who model it separately.
    pub fn relativistic_correction_s(&self, t: GpsTime) -> f64 {
        let a = self.semi_major_axis_m();
        let n = (MU_M3_S2 / (a * a * a)).sqrt() + self.delta_n_rad_s;
        let ek = eccentric_anomaly_rad(self.m0_rad + n * t.diff_s(self.toe), self.e);
        F_REL_S_PER_SQRT_M * self.e * self.sqrt_a_sqrt_m * ek.sin()
    }

    /// Whether `t` is within `max_age_s` of toe, measured across week boundaries.
    pub fn is_within_s(&self, t: GpsTime, max_age_s: f64) -> bool {
        t.diff_s(self.toe).abs() <= max_age_s
    }

    /// The longest |t - toe| for which gpsrx uses this ephemeris, s:
    /// [`MAX_EPHEMERIS_AGE_S`] (4 h), or half the curve-fit interval
    /// ([`Self::fit_interval_s`], IS-GPS-200 20.3.4.4) when that is longer.
    pub fn max_age_s(&self) -> f64 {
        MAX_EPHEMERIS_AGE_S.max(self.fit_interval_s() / 2.0)
    }

    /// Whether the ephemeris may be used at `t`: |t - toe| <= [`Self::max_age_s`].
    pub fn is_valid_at(&self, t: GpsTime) -> bool {
        self.is_within_s(t, self.max_age_s())
    }

    /// The satellite seen at reception time `t_rx` from `rx_pos_m`: [`crate::frames::light_time`]
    /// with the state at transmit time `t_rx - tau` from this ephemeris, `iterations` passes from
    /// the flight-time guess `tau_guess_s` (0.075 s when nothing better is known).
    pub fn at_reception(
        &self,
        t_rx: GpsTime,
        rx_pos_m: &Vector3<f64>,
        tau_guess_s: f64,
        iterations: usize,
    ) -> SvAtReception {
        light_time(
            |tau| self.sv_state(t_rx.add_seconds(-tau)),
            rx_pos_m,
            tau_guess_s,
            iterations,
        )
    }
}

/// The standard validity limit of a broadcast ephemeris, |t - toe| in seconds: 4 h.
///
/// IS-GPS-200 20.3.4.4: with the fit interval flag 0 the ephemeris is a 4-hour curve fit (and
/// the control segment uploads a new one every 2 h, so a current one is never more than ~2 h
/// from toe). gpsrx accepts any |t - toe| up to the whole 4 h so that a RINEX file with gaps
/// still serves; the orbit error grows beyond the fit interval's ±2 h. An ephemeris with the fit
/// interval flag set is used up to half its longer fit interval ([`Ephemeris::max_age_s`]).
/// This is the one limit all of gpsrx uses ([`select_ephemeris`], [`Ephemeris::is_valid_at`]).
pub const MAX_EPHEMERIS_AGE_S: f64 = 4.0 * 3600.0;

/// How [`select_ephemeris`] treats the health word (IS-GPS-200 20.3.3.3.1.4, `sv_health`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HealthPolicy {
    /// Only ephemerides with `sv_health == 0` (for positioning).
    HealthyOnly,
    /// Healthy ones first; an unhealthy one only when no healthy one is valid (for searching
    /// and aiding: an unhealthy satellite usually still transmits).
    PreferHealthy,
    /// The health word does not matter (what the satellite transmits, for simulation).
    Ignore,
}

/// The ephemeris of `prn` among `candidates` to use at `t`: those valid at `t`
/// ([`Ephemeris::is_valid_at`]: |t - toe| <= 4 h or half the fit interval) and allowed by
/// `health`, the one with the toe nearest to `t` (healthy first under
/// [`HealthPolicy::PreferHealthy`]). Ties go to the first in `candidates`' order.
pub fn select_ephemeris<'a>(
    candidates: impl IntoIterator<Item = &'a Ephemeris>,
    prn: u8,
    t: GpsTime,
    health: HealthPolicy,
) -> Option<&'a Ephemeris> {
    candidates
        .into_iter()
        .filter(|e| e.prn == prn && e.is_valid_at(t))
        .filter(|e| health != HealthPolicy::HealthyOnly || e.sv_health == 0)
        .map(|e| {
            let rank = health == HealthPolicy::PreferHealthy && e.sv_health != 0;
            (e, rank, t.diff_s(e.toe).abs())
        })
        .min_by(|a, b| a.1.cmp(&b.1).then(a.2.total_cmp(&b.2)))
        .map(|(e, _, _)| e)
}

/// Half a GPS week, s: the IS-GPS-200 Table 20-IV limit on |t_k|.
pub const HALF_WEEK_S: f64 = SECONDS_PER_WEEK / 2.0;
