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
