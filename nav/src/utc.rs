//! GPS-to-UTC conversion parameters (IS-GPS-200 20.3.3.5.1.6, Table 20-IX; algorithm
//! 20.3.3.5.2.4).

use crate::time::{resolve_week_modulo, GpsTime};

/// UTC parameters broadcast in subframe 4 page 18.
///
/// `wnt` and `wn_lsf` are full week numbers when they come from a RINEX file. Decoded from the
/// LNAV message they are only known modulo 256; [`UtcParams::resolve_weeks`] makes them full.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UtcParams {
    /// Bias of GPS time relative to UTC(USNO), s.
    pub a0_s: f64,
    /// Drift of GPS time relative to UTC(USNO), s/s.
    pub a1_s_s: f64,
    /// Reference time of week for A0/A1, s (multiple of 4096 when broadcast).
    pub tot_s: u32,
    /// Reference week for A0/A1.
    pub wnt: u32,
    /// Current leap-second count GPS - UTC, s.
    pub dt_ls_s: i32,
    /// Week of the (past or future) leap-second event.
    pub wn_lsf: u32,
    /// Day number (1-7, 1 = Sunday) at the end of which the leap second takes effect.
    pub dn: u32,
    /// Leap-second count after the event, s.
    pub dt_lsf_s: i32,
}

impl UtcParams {
    /// Replaces the 8-bit WN_t and WN_LSF (as decoded from LNAV, 20.3.3.5.2.4) by the full
    /// weeks nearest `reference_week`.
    pub fn resolve_weeks(self, reference_week: u32) -> UtcParams {
        UtcParams {
            wnt: resolve_week_modulo(self.wnt, reference_week, 256),
            wn_lsf: resolve_week_modulo(self.wn_lsf, reference_week, 256),
            ..self
        }
    }

    /// GPS - UTC at GPS time `t`, s, away from a leap-second event (20.3.3.5.2.4 case a/c):
    /// Delta t_UTC = Delta t_LS + A0 + A1 (t - t_ot), with the weeks taken as full weeks.
    /// Uses Delta t_LSF once the event (end of day DN of week WN_LSF) is in the past.
    pub fn gps_minus_utc_s(&self, t: GpsTime) -> f64 {
        let t_ot = GpsTime::new(self.wnt, f64::from(self.tot_s));
        let event = GpsTime::new(self.wn_lsf, f64::from(self.dn) * 86_400.0);
        let leap = if t.diff_s(event) >= 0.0 {
            self.dt_lsf_s
        } else {
            self.dt_ls_s
        };
        f64::from(leap) + self.a0_s + self.a1_s_s * t.diff_s(t_ot)
    }
}

/// The leap seconds: from the start of each UTC date `(year, month)` (day 1, 00:00), GPS - UTC
/// was this many seconds (IERS Bulletin C; none announced after 2017-01-01 as of 2026).
const LEAP_SECONDS: [(i32, u32, i32); 18] = [
    (1981, 7, 1),
    (1982, 7, 2),
    (1983, 7, 3),
    (1985, 7, 4),
    (1988, 1, 5),
    (1990, 1, 6),
    (1991, 1, 7),
    (1992, 7, 8),
    (1993, 7, 9),
    (1994, 7, 10),
    (1996, 1, 11),
    (1997, 7, 12),
    (1999, 1, 13),
    (2006, 1, 14),
    (2009, 1, 15),
    (2012, 7, 16),
    (2015, 7, 17),
    (2017, 1, 18),
];

/// GPS - UTC, s, on the UTC date `year`-`month` (from the table of leap seconds: 0 before
/// July 1981, 18 since 1 January 2017).
pub fn leap_seconds_on(year: i32, month: u32) -> i32 {
    LEAP_SECONDS
        .iter()
        .rev()
        .find(|&&(y, m, _)| (year, month) >= (y, m))
        .map_or(0, |&(_, _, n)| n)
}

/// The GPS time of a UTC calendar date and time (leap seconds from [`leap_seconds_on`]).
pub fn gps_from_utc(year: i32, month: u32, day: u32, hour: u32, min: u32, sec: f64) -> GpsTime {
    GpsTime::from_calendar(year, month, day, hour, min, sec)
        .add_seconds(f64::from(leap_seconds_on(year, month)))
}

/// The UTC calendar date and time `(year, month, day, hour, minute, second)` of GPS time `t`
/// (leap seconds from [`leap_seconds_on`]; the inserted second 23:59:60 itself reads as the
/// next day's 00:00:00).
pub fn utc_from_gps(t: GpsTime) -> (i32, u32, u32, u32, u32, f64) {
    // The count in effect 18 s earlier decides, unless the day changed across a leap second.
    let (y, m, ..) = t.add_seconds(-18.0).to_calendar();
    let guess = t.add_seconds(-f64::from(leap_seconds_on(y, m)));
    let (y2, m2, ..) = guess.to_calendar();
    t.add_seconds(-f64::from(leap_seconds_on(y2, m2)))
        .to_calendar()
}
