//! The GPS almanac (IS-GPS-200 20.3.3.5.1.2, Table 20-VI): reduced-precision Keplerian orbits
//! and clocks of every satellite, transmitted by each one in subframes 4 and 5, and what a
//! receiver does with them before it has any ephemeris: predict which satellites are above the
//! horizon and at what Doppler to search for them.
//!
//! Satellite position follows the Table 20-IV user algorithm with the almanac's reductions
//! (20.3.3.5.2.1): the mean motion is the Keplerian `n0 = sqrt(mu / A^3)` (no delta n), all
//! harmonic corrections and IDOT are zero, `t_k = t - t_oa` and the inclination is
//! `i = 0.30 semicircles + delta_i`. The clock is `dt_sv = a_f0 + a_f1 t_k` (20.3.3.5.2.3).

use std::collections::BTreeMap;

use gpsrx_core::doppler::{los_doppler_hz, PosVel};

use crate::constants::{GPS_PI, MU_M3_S2, OMEGA_E_DOT_RAD_S, SECONDS_PER_WEEK};
use crate::ephemeris::{eccentric_anomaly_rad, Ephemeris, SvState};
use crate::frames::{azimuth_elevation, light_time, SvAtReception, Vector3};
use crate::time::GpsTime;

/// Reference inclination of the almanac, rad: 0.30 semicircles (Table 20-VI note: i_0 =
/// 0.30 semicircles, the transmitted delta_i is relative to it).
pub const ALMANAC_REF_INCLINATION_RAD: f64 = 0.30 * GPS_PI;

/// LSB of t_oa, s (Table 20-VI: 8 bits, scale factor 2^12 s).
pub const TOA_STEP_S: f64 = 4096.0;

/// The 6-bit page-25 health word "all ones": the SV with that ID is not available and its
/// almanac page may hold no data (20.3.3.5.1.3).
pub const HEALTH6_NOT_AVAILABLE: u8 = 0b11_1111;

/// One satellite's almanac in SI units (angles in radians, not semicircles).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Almanac {
    /// PRN (SV ID) 1-32.
    pub prn: u8,
    /// 8-bit SV health of the almanac page (20.3.3.5.1.3): 3 bits NAV data health (Table 20-VII)
    /// then 5 bits signal health (Table 20-VIII); 0 = all OK.
    pub health: u8,
    /// Eccentricity.
    pub e: f64,
    /// Almanac reference time: full week (WN_a resolved) and t_oa, s of week.
    pub toa: GpsTime,
    /// Inclination offset from 0.30 semicircles, rad.
    pub delta_i_rad: f64,
    /// Rate of right ascension, rad/s.
    pub omega_dot_rad_s: f64,
    /// Square root of the semi-major axis, sqrt(m).
    pub sqrt_a_sqrt_m: f64,
    /// Longitude of the ascending node at the weekly epoch, rad.
    pub omega0_rad: f64,
    /// Argument of perigee, rad.
    pub omega_rad: f64,
    /// Mean anomaly at t_oa, rad.
    pub m0_rad: f64,
    /// SV clock bias at t_oa, s.
    pub af0_s: f64,
    /// SV clock drift, s/s.
    pub af1_s_s: f64,
}

/// Wraps an angle into `[-pi, pi)`.
fn wrap_pi(x_rad: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    x_rad - two_pi * ((x_rad + std::f64::consts::PI) / two_pi).floor()
}

/// The allowed almanac reference time (a multiple of 4096 s within a week, Table 20-VI) nearest
/// to `t`: candidates are the multiples of 4096 s of `t`'s week up to 602112 s and TOW 0 of the
/// next week.
pub fn toa_near(t: GpsTime) -> GpsTime {
    let k = (t.tow_s / TOA_STEP_S).round().clamp(0.0, 147.0);
    let this_week = GpsTime::new(t.week, k * TOA_STEP_S);
    let next_week = GpsTime::new(t.week.saturating_add(1), 0.0);
    if next_week.diff_s(t).abs() < this_week.diff_s(t).abs() {
        next_week
    } else {
        this_week
    }
}

/// The 8-bit almanac health word of a 6-bit ephemeris/page-25 health word (20.3.3.3.1.4,
/// 20.3.3.5.1.3): the 5 signal bits are the same; the one-bit NAV data summary becomes the
/// 3-bit NAV data health 000 (all data OK) or 111 (all data bad, the worst of Table 20-VII).
pub fn health8_from_health6(health6: u8) -> u8 {
    let nav = if health6 & 0b10_0000 != 0 { 0b111 } else { 0 };
    (nav << 5) | (health6 & 0x1F)
}

/// The 6-bit summary of an 8-bit almanac health word: MSB set when any NAV data health bit is,
/// then the 5 signal bits (20.3.3.5.1.3).
pub fn health6_from_health8(health8: u8) -> u8 {
    (u8::from(health8 >> 5 != 0) << 5) | (health8 & 0x1F)
}

impl Almanac {
    /// Semi-major axis A = (sqrt A)^2, m.
    pub fn semi_major_axis_m(&self) -> f64 {
        self.sqrt_a_sqrt_m * self.sqrt_a_sqrt_m
    }

    /// Inclination i = 0.30 semicircles + delta_i, rad (Table 20-VI note).
    pub fn inclination_rad(&self) -> f64 {
        ALMANAC_REF_INCLINATION_RAD + self.delta_i_rad
    }

    /// Whether the 8-bit health word is 0 (all NAV data and signals OK).
    pub fn is_healthy(&self) -> bool {
        self.health == 0
    }

    /// Position, velocity and clock at GPS time `t` from the almanac (IS-GPS-200 Table 20-IV
    /// with the almanac reductions of 20.3.3.5.2.1):
    ///
    /// ```text
    /// n0 = sqrt(mu / A^3)            t_k = t - t_oa (full weeks)    M_k = M_0 + n0 t_k
    /// M_k = E_k - e sin E_k          nu_k = atan2(sqrt(1 - e^2) sin E_k, cos E_k - e)
    /// u_k = nu_k + omega             r_k = A (1 - e cos E_k)        i = 0.30 pi + delta_i
    /// OMEGA_k = OMEGA_0 + (OMEGADOT - OMEGAEDOT_e) t_k - OMEGAEDOT_e t_oa
    /// ```
    ///
    /// and the velocity as the time derivative of these equations. The clock is
    /// `a_f0 + a_f1 t_k` (20.3.3.5.2.3): no relativistic term and no T_GD, so `clock_bias_s` is
    /// good to the almanac's few microseconds only.
    pub fn sv_state(&self, t: GpsTime) -> SvState {
        let a = self.semi_major_axis_m();
        let n0 = (MU_M3_S2 / (a * a * a)).sqrt();
        let tk = t.diff_s(self.toa);
        let ek = eccentric_anomaly_rad(self.m0_rad + n0 * tk, self.e);
        let (sin_e, cos_e) = ek.sin_cos();
        let one_minus_ecos = 1.0 - self.e * cos_e;
        let sqrt_1me2 = (1.0 - self.e * self.e).sqrt();
        let uk = (sqrt_1me2 * sin_e).atan2(cos_e - self.e) + self.omega_rad;
        let rk = a * one_minus_ecos;
        let (su, cu) = uk.sin_cos();
        let (xp, yp) = (rk * cu, rk * su);
        let omega_dot_k = self.omega_dot_rad_s - OMEGA_E_DOT_RAD_S;
        let omk = self.omega0_rad + omega_dot_k * tk - OMEGA_E_DOT_RAD_S * self.toa.tow_s;
        let (so, co) = omk.sin_cos();
        let (si, ci) = self.inclination_rad().sin_cos();
        let pos_m = Vector3::new(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si);

        let ek_dot = n0 / one_minus_ecos;
        let uk_dot = ek_dot * sqrt_1me2 / one_minus_ecos;
        let rk_dot = a * self.e * sin_e * ek_dot;
        let xp_dot = rk_dot * cu - rk * uk_dot * su;
        let yp_dot = rk_dot * su + rk * uk_dot * cu;
        let vel_mps = Vector3::new(
            xp_dot * co - yp_dot * ci * so - (xp * so + yp * ci * co) * omega_dot_k,
            xp_dot * so + yp_dot * ci * co + (xp * co - yp * ci * so) * omega_dot_k,
            yp_dot * si,
        );
        SvState {
            pos_m,
            vel_mps,
            clock_bias_s: self.af0_s + self.af1_s_s * tk,
            clock_drift_s_s: self.af1_s_s,
        }
    }

    /// The satellite seen at reception time `t_rx` from `rx_pos_m` ([`light_time`] with two
    /// passes from a 75 ms flight time: far more precise than the almanac itself).
    pub fn at_reception(&self, t_rx: GpsTime, rx_pos_m: &Vector3<f64>) -> SvAtReception {
        light_time(
            |tau| self.sv_state(t_rx.add_seconds(-tau)),
            rx_pos_m,
            0.075,
            2,
        )
    }

    /// The almanac a control segment would upload for the orbit and clock of `eph`, referred to
    /// `toa` (full week = WN_a, and t_oa; use [`toa_near`] for an ICD-valid one). The ephemeris'
    /// Kepler elements are propagated from t_oe to t_oa, its harmonic corrections dropped:
    ///
    /// ```text
    /// dt = t_oa - t_oe                      n = sqrt(mu / A_e^3) + delta n
    /// A = (mu / n^2)^(1/3)    (the almanac has no delta n: keep the mean motion, not A_e)
    /// M_0,a = M_0 + n dt      delta_i = i_0 + IDOT dt - 0.30 pi
    /// OMEGA_0,a = OMEGA_0 + OMEGADOT dt - OMEGAEDOT_e 604800 (WN_a - WN_oe)
    /// a_f0,a = a_f0 + a_f1 dt_c + a_f2 dt_c^2,   a_f1,a = a_f1 + 2 a_f2 dt_c,   dt_c = t_oa - t_oc
    /// ```
    ///
    /// The OMEGA_0 term makes `OMEGA_k` of both models agree at every t (each counts the Earth
    /// rotation from the start of its own reference week). Keeping the mean motion instead of A
    /// trades a constant radial offset of (2/3) (delta n / n) A (~0.5 km) for no along-track
    /// drift (delta n t, ~9 km per day). The 6-bit ephemeris health becomes the 8-bit almanac
    /// word by [`health8_from_health6`]. Angles are wrapped into [-pi, pi).
    pub fn from_ephemeris(eph: &Ephemeris, toa: GpsTime) -> Almanac {
        let a_e = eph.semi_major_axis_m();
        let n = (MU_M3_S2 / (a_e * a_e * a_e)).sqrt() + eph.delta_n_rad_s;
        let a = (MU_M3_S2 / (n * n)).cbrt();
        let dt = toa.diff_s(eph.toe);
        let dtc = toa.diff_s(eph.toc);
        let dweek = f64::from(toa.week) - f64::from(eph.toe.week);
        Almanac {
            prn: eph.prn,
            health: health8_from_health6(eph.sv_health),
            e: eph.e,
            toa,
            delta_i_rad: eph.i0_rad + eph.idot_rad_s * dt - ALMANAC_REF_INCLINATION_RAD,
            omega_dot_rad_s: eph.omega_dot_rad_s,
            sqrt_a_sqrt_m: a.sqrt(),
            omega0_rad: wrap_pi(
                eph.omega0_rad + eph.omega_dot_rad_s * dt
                    - OMEGA_E_DOT_RAD_S * SECONDS_PER_WEEK * dweek,
            ),
            omega_rad: wrap_pi(eph.omega_rad),
            m0_rad: wrap_pi(eph.m0_rad + n * dt),
            af0_s: eph.af0_s + eph.af1_s_s * dtc + eph.af2_s_s2 * dtc * dtc,
            af1_s_s: eph.af1_s_s + 2.0 * eph.af2_s_s2 * dtc,
        }
    }
}

/// What the almanac predicts for one satellite seen from a receiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlmanacPrediction {
    /// PRN.
    pub prn: u8,
    /// Azimuth, rad, clockwise from north in [0, 2 pi).
    pub azimuth_rad: f64,
    /// Elevation, rad.
    pub elevation_rad: f64,
    /// Geometric range, m.
    pub range_m: f64,
    /// L1 carrier Doppler, Hz, positive when the range shrinks, including the satellite's
    /// almanac clock drift a_f1 and the receiver clock drift given
    /// ([`gpsrx_core::doppler::los_doppler_hz`]).
    pub doppler_hz: f64,
    /// The almanac's 8-bit health word is 0.
    pub healthy: bool,
}

/// Predicts azimuth, elevation, range and L1 Doppler of every almanac in `almanacs` for a
/// receiver at `rx` (ECEF position and velocity) at GPS time `t`, with receiver clock drift
/// `rx_clock_drift_s_s` (s/s; 0 if unknown). The satellite state is taken at transmit time
/// with the Earth's rotation during the flight ([`Almanac::at_reception`]); a satellite whose
/// range rate is undefined (receiver at the satellite) is skipped. Output in input order.
pub fn predict<'a>(
    almanacs: impl IntoIterator<Item = &'a Almanac>,
    rx: &PosVel,
    t: GpsTime,
    rx_clock_drift_s_s: f64,
) -> Vec<AlmanacPrediction> {
    almanacs
        .into_iter()
        .filter_map(|alm| {
            let seen = alm.at_reception(t, &rx.pos_m);
            let sv = PosVel {
                pos_m: seen.sv.pos_m,
                vel_mps: seen.sv.vel_mps,
            };
            let doppler_hz = los_doppler_hz(&sv, rx, seen.sv.clock_drift_s_s, rx_clock_drift_s_s)?;
            let (azimuth_rad, elevation_rad) = azimuth_elevation(&rx.pos_m, &seen.sv.pos_m);
            Some(AlmanacPrediction {
                prn: alm.prn,
                azimuth_rad,
                elevation_rad,
                range_m: seen.range_m,
                doppler_hz,
                healthy: alm.is_healthy(),
            })
        })
        .collect()
}

/// A constellation almanac as subframes 4 and 5 carry it: one [`Almanac`] per PRN, the
/// reference time of subframe 5 page 25 (t_oa and WN_a) and the page-25 6-bit health and 4-bit
/// A-S/configuration words of all 32 SVs.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AlmanacSet {
    /// t_oa and full WN_a of subframe 5 page 25.
    pub toa: GpsTime,
    /// Almanac per PRN.
    pub almanacs: BTreeMap<u8, Almanac>,
    /// 6-bit health of SV 1-32 (index PRN - 1) as pages 25 carry it;
    /// [`HEALTH6_NOT_AVAILABLE`] for an SV without almanac.
    pub health6: [u8; 32],
    /// 4-bit A-S flag (MSB) and SV configuration code (3 LSBs) of SV 1-32 (20.3.3.5.1.4).
    pub sv_config: [u8; 32],
}

impl AlmanacSet {
    /// An empty set referred to `toa`: every SV "not available", configuration 0.
    pub fn new(toa: GpsTime) -> AlmanacSet {
        AlmanacSet {
            toa,
            almanacs: BTreeMap::new(),
            health6: [HEALTH6_NOT_AVAILABLE; 32],
            sv_config: [0; 32],
        }
    }

    /// Adds (or replaces) the almanac of `alm.prn` and sets its page-25 health from the
    /// almanac's 8-bit word. PRNs outside 1-32 are ignored.
    pub fn insert(&mut self, alm: Almanac) {
        let Some(slot) = usize::from(alm.prn).checked_sub(1).filter(|&i| i < 32) else {
            return;
        };
        self.health6[slot] = health6_from_health8(alm.health);
        self.almanacs.insert(alm.prn, alm);
    }

    /// The almanac of every PRN among `ephemerides` (the first one of each PRN, in order)
    /// derived with [`Almanac::from_ephemeris`] at `toa`.
    pub fn from_ephemerides<'a>(
        ephemerides: impl IntoIterator<Item = &'a Ephemeris>,
        toa: GpsTime,
    ) -> AlmanacSet {
        let mut set = AlmanacSet::new(toa);
        for eph in ephemerides {
            if !set.almanacs.contains_key(&eph.prn) {
                set.insert(Almanac::from_ephemeris(eph, toa));
            }
        }
        set
    }

    /// The almanac of `prn`.
    pub fn get(&self, prn: u8) -> Option<&Almanac> {
        self.almanacs.get(&prn)
    }

    /// [`predict`] for every almanac of the set, ascending PRN.
    pub fn predict(
        &self,
        rx: &PosVel,
        t: GpsTime,
        rx_clock_drift_s_s: f64,
    ) -> Vec<AlmanacPrediction> {
        predict(self.almanacs.values(), rx, t, rx_clock_drift_s_s)
    }

    /// The healthy satellites at or above `mask_rad` elevation, highest first: the search list
    /// of a warm start.
    pub fn visible(
        &self,
        rx: &PosVel,
        t: GpsTime,
        rx_clock_drift_s_s: f64,
        mask_rad: f64,
    ) -> Vec<AlmanacPrediction> {
        let mut list: Vec<AlmanacPrediction> = self
            .predict(rx, t, rx_clock_drift_s_s)
            .into_iter()
            .filter(|p| p.healthy && p.elevation_rad >= mask_rad)
            .collect();
        list.sort_by(|a, b| b.elevation_rad.total_cmp(&a.elevation_rad));
        list
    }
}
