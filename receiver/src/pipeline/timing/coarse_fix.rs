//! The first fix from code phases alone (coarse time, van Diggelen ch. 4): with ephemerides
//! (`--nav`), an approximate time (`--time` or the SigMF `core:datetime`) and position
//! (`--approx-llh`), every satellite's full SV time comes from its code phase about a second
//! after the start, instead of from its navigation message 6-12 s later.
//!
//! # Observable
//!
//! A report of a channel starts at sample `k_i` with the replica `c_i` chips into code period
//! `m_i` (its `ms_count`) and runs at `r_i` chips/s. At the common sample `k` the replica
//! stands at
//!
//! ```text
//! c_i(k) = c_i + (k - k_i) / fs * r_i,   period m_i(k) = m_i + floor(c_i(k) / 1023),
//! phi_i = (c_i(k) mod 1023) / 1.023e6 s                (transmit time modulo 1 ms)
//! ```
//!
//! [`gpsrx_nav::pvt::solve_coarse_time`] turns the phi_i, the ephemerides, the a-priori time
//! `t_a = T_start + k / fs` and the a-priori position into each satellite's full transmit time
//! `T_i = N_i ms + phi_i`. The SV time at the start of period `m_i(k)` is `N_i ms`: the
//! decoder's time tag ([`crate::pipeline::navigation::navdata::NavDecoder::carry_time`]), whose
//! `sv_tow_s(m, c) = N_i ms + (m - m_i(k)) ms + c / 1.023e6` inverts the equations above.
//!
//! # Checks
//!
//! The differences of the `T_i` are exact but their common whole milliseconds only as good as
//! the coarse time (a few ms). The data-bit edges fix them: the SV time at a channel's bit
//! edge (period `b_i`) must be a whole 20 ms,
//!
//! ```text
//! o_i = (N_i - (m_i(k) - b_i)) mod 20 ms  in (-10, 10] ms,
//! ```
//!
//! and every bit-synchronised satellite must give the same `o_i` (its whole milliseconds are
//! then right modulo 20 ms); all `N_i` are moved by `-o`. A solution is used only if it
//! passed the chi-square test of its integers (6 or more satellites), or, with exactly 5 (no
//! redundancy), if all 5 have bit edges that agree; otherwise the receiver waits (for another
//! satellite, or for frame sync). Later, each satellite's first bit is checked against the
//! time again ([`crate::pipeline::navigation::navdata::NavEvent::BitEdgeMismatch`]) and its first HOW
//! against it ([`crate::pipeline::navigation::navdata::NavEvent::TowMismatch`]); the normal PVT's RAIM
//! checks every fix; a failure drops the times (the processor's part).

use crate::pipeline::navigation::observables::CODE_SETTLE_MS;
use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::frames::Llh;
use gpsrx_nav::pvt::{
    solve_coarse_time, CoarseApriori, CoarseIntegrity, CoarseMeasurement, PvtOptions,
};
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::{ChannelEpoch, ChannelState};
use std::collections::{BTreeMap, BTreeSet};

/// C/N0 a channel needs to take part, dB-Hz.
pub const MIN_CN0_DBHZ: f64 = 30.0;
/// Satellites needed (position, clock bias and time).
pub const MIN_SATELLITES: usize = gpsrx_nav::pvt::coarse_time::MIN_SATELLITES;
/// Bit-synchronised satellites whose edges must agree before the times are used.
pub const MIN_BIT_EDGES: usize = 3;
/// Reports older than this at the common sample are not used, s (a report covers 1-20 ms).
const MAX_REPORT_AGE_S: f64 = 0.025;
/// Stream time between two attempts, s.
pub const RETRY_S: f64 = 0.2;
/// Chips in a C/A code period.
const CODE_CHIPS: f64 = 1023.0;
/// Milliseconds in a GPS week.
const WEEK_MS: i64 = 604_800_000;

/// One satellite's SV time from the coarse fix: code period `ms_count` of its channel started
/// at SV time `sv_tow_s` (a whole millisecond).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseSvTime {
    /// PRN.
    pub prn: u8,
    /// `ms_count` of the channel's code period.
    pub ms_count: u64,
    /// SV time (TOW, s) at its start.
    pub sv_tow_s: f64,
}

/// A coarse-time fix that passed its checks.
#[derive(Debug, Clone, PartialEq)]
pub struct CoarseOutcome {
    /// Stream time of the common instant, s.
    pub t_s: f64,
    /// GPS time at it: the solver's, known to milliseconds, moved onto the time the SV times
    /// fit (by its sub-millisecond clock offset and the bit edges' whole milliseconds).
    pub time: GpsTime,
    /// Corrected minus approximate time, s.
    pub time_correction_s: f64,
    /// Distance of the coarse position from the approximate one, m.
    pub position_shift_m: f64,
    /// Every satellite's SV time.
    pub sv_times: Vec<CoarseSvTime>,
    /// How the integers were checked ("chi-square, 7 satellites", ...).
    pub check: String,
}

/// Why an attempt gave nothing (the next one may).
#[derive(Debug, Clone, PartialEq)]
pub enum CoarseRefusal {
    /// Not enough satellites yet (not an error).
    Waiting,
    /// The solution or its checks failed: the message says why.
    Refused(String),
}

/// A channel's latest usable report.
#[derive(Debug, Clone, Copy)]
struct Snapshot {
    sample: u64,
    ms_count: u64,
    chips: f64,
    rate_chips_s: f64,
    cn0_dbhz: f64,
    /// `ms_count` of the latest bit edge of this channel.
    bit_edge_ms: Option<u64>,
}

/// Collects the channels' code phases and solves for the SV times once enough satellites are
/// tracked.
#[derive(Debug)]
pub struct CoarseFixer {
    fs_hz: f64,
    /// Approximate GPS time of sample 0.
    start: GpsTime,
    llh: Llh,
    latest: BTreeMap<u8, Snapshot>,
    next_attempt: u64,
    /// PRNs given a time.
    pub given: BTreeSet<u8>,
    /// An outcome was handed out (no more attempts).
    pub done: bool,
    /// Bound on the a-priori time error, s ([`CoarseApriori::time_uncertainty_s`]).
    time_uncertainty_s: f64,
    /// Smallest time correction accepted, s (`None`: any within the bound).
    min_correction_s: Option<f64>,
}

impl CoarseFixer {
    /// For samples at `fs_hz`, the first at approximately `start`, near `llh`.
    pub fn new(fs_hz: f64, start: GpsTime, llh: Llh) -> Self {
        Self {
            fs_hz,
            start,
            llh,
            latest: BTreeMap::new(),
            next_attempt: 0,
            given: BTreeSet::new(),
            done: false,
            time_uncertainty_s: gpsrx_nav::pvt::coarse_time::DEFAULT_TIME_UNCERTAINTY_S,
            min_correction_s: None,
        }
    }

    /// The a-priori time is only known to lie between `min_correction_s` and
    /// `uncertainty_s` before the true time (after lost samples of unknown length the
    /// receiver time, which counts samples, is late by the gap and never early): solutions
    /// correcting it by less than `min_correction_s` are refused, and the solver's bound is
    /// `uncertainty_s`.
    pub fn with_time_window(mut self, min_correction_s: f64, uncertainty_s: f64) -> Self {
        self.min_correction_s = Some(min_correction_s);
        self.time_uncertainty_s = uncertainty_s;
        self
    }

    /// Takes a channel report: kept while in phase lock, with C/N0 >= [`MIN_CN0_DBHZ`] and
    /// the code settled ([`CODE_SETTLE_MS`]).
    pub fn observe(&mut self, e: &ChannelEpoch) {
        let usable = e.pll_lock
            && e.state != ChannelState::Lost
            && e.cn0_dbhz >= MIN_CN0_DBHZ
            && e.ms_count >= CODE_SETTLE_MS;
        let before = self.latest.remove(&e.prn);
        if !usable {
            return;
        }
        // A new channel restarts its ms count: its old bit edge does not apply.
        let bit_edge_ms = if e.bit_edge {
            Some(e.ms_count)
        } else {
            before
                .filter(|b| b.ms_count <= e.ms_count)
                .and_then(|b| b.bit_edge_ms)
        };
        self.latest.insert(
            e.prn,
            Snapshot {
                sample: e.sample_index,
                ms_count: e.ms_count,
                chips: e.code_phase_chips,
                rate_chips_s: e.code_rate_chips_s,
                cn0_dbhz: e.cn0_dbhz,
                bit_edge_ms,
            },
        );
    }

    /// Tries a fix at the newest report's sample (at most every [`RETRY_S`]): `ephemeris`
    /// gives a satellite's ephemeris at a time, `opts` the PVT options.
    pub fn attempt(
        &mut self,
        ephemeris: &dyn Fn(u8, GpsTime) -> Option<Ephemeris>,
        opts: &PvtOptions,
    ) -> Result<CoarseOutcome, CoarseRefusal> {
        let Some(k) = self.latest.values().map(|s| s.sample).max() else {
            return Err(CoarseRefusal::Waiting);
        };
        let max_age = (MAX_REPORT_AGE_S * self.fs_hz) as u64;
        self.latest.retain(|_, s| s.sample + max_age >= k);
        if self.done || k < self.next_attempt || self.latest.len() < MIN_SATELLITES {
            return Err(CoarseRefusal::Waiting);
        }
        self.next_attempt = k + (RETRY_S * self.fs_hz) as u64;
        let t_a = self.start.add_seconds(k as f64 / self.fs_hz);
        // Each satellite at sample k: (PRN, period, phase s, snapshot, ephemeris).
        let sats: Vec<(u8, u64, f64, Snapshot, Ephemeris)> = self
            .latest
            .iter()
            .filter_map(|(&prn, s)| {
                let chips = s.chips + (k - s.sample) as f64 / self.fs_hz * s.rate_chips_s;
                let period = (chips / CODE_CHIPS).floor();
                let phase_s =
                    ((chips - period * CODE_CHIPS) / CA_CHIP_RATE_HZ).clamp(0.0, 0.999_999_999e-3);
                let m = s.ms_count.checked_add_signed(period as i64)?;
                Some((prn, m, phase_s, *s, ephemeris(prn, t_a)?))
            })
            .collect();
        if sats.len() < MIN_SATELLITES {
            return Err(CoarseRefusal::Waiting);
        }
        let meas: Vec<CoarseMeasurement<'_>> = sats
            .iter()
            .map(|(prn, _, phase_s, s, eph)| CoarseMeasurement {
                prn: *prn,
                tx_time_mod_1ms_s: *phase_s,
                cn0_dbhz: s.cn0_dbhz,
                ephemeris: eph,
            })
            .collect();
        let apriori = CoarseApriori {
            time_uncertainty_s: self.time_uncertainty_s,
            ..CoarseApriori::from_llh(t_a, &self.llh)
        };
        let sol = solve_coarse_time(&meas, &apriori, opts)
            .map_err(|e| CoarseRefusal::Refused(e.to_string()))?;
        if let Some(min) = self.min_correction_s.filter(|&m| sol.time_correction_s < m) {
            return Err(CoarseRefusal::Refused(format!(
                "the coarse time moves the receiver time back by {:.3} s (at most {:.3} s allowed)",
                -sol.time_correction_s, -min
            )));
        }
        // Whole milliseconds at the start of each satellite's period at k, and its bit edge.
        let mut used = Vec::new();
        for cs in sol
            .satellites
            .iter()
            .filter(|c| !sol.excluded_prns.contains(&c.prn))
        {
            let Some((prn, m, phase_s, s, _)) = sats.iter().find(|x| x.0 == cs.prn) else {
                continue;
            };
            let n_ms = ((cs.tx_time.tow_s - phase_s) * 1e3).round() as i64;
            used.push((*prn, *m, n_ms, s.bit_edge_ms));
        }
        let n = used.len();
        let edges: Vec<i64> = used
            .iter()
            .filter_map(|&(_, m, n_ms, b)| {
                let b = b?;
                let at_edge = n_ms - (m as i64 - b as i64);
                Some(at_edge - 20 * (at_edge as f64 / 20.0).round() as i64)
            })
            .collect();
        let check = match sol.integrity {
            CoarseIntegrity::Passed { .. } if n >= 6 => format!("chi-square test, {n} satellites"),
            CoarseIntegrity::Unverified if edges.len() == n => {
                format!("{n} satellites (no redundancy), all {n} bit edges agree")
            }
            // Five satellites without all their bit edges: wait for them, or a sixth.
            _ => return Err(CoarseRefusal::Waiting),
        };
        if edges.len() < MIN_BIT_EDGES.min(n) {
            return Err(CoarseRefusal::Waiting);
        }
        let offset = edges[0];
        if edges.iter().any(|&o| o != offset) {
            return Err(CoarseRefusal::Refused(format!(
                "the SV times fall on different offsets from the data-bit edges ({edges:?} ms modulo 20 ms): a code phase or an integer is wrong"
            )));
        }
        // The coarse time must be good to well within 10 ms for the bit edges to fix the
        // whole milliseconds.
        if 3.0 * sol.time_sigma_s > 0.009 {
            return Err(CoarseRefusal::Refused(format!(
                "the coarse time is known to {:.1} ms only (1 sigma): the bit edges cannot fix its milliseconds",
                sol.time_sigma_s * 1e3
            )));
        }
        // The solver's time is known to milliseconds only: the transmit times fit it with
        // the sub-millisecond clock offset `f = b / c + dt_c - u` (its clock-bias unknown
        // `b`, time correction `dt_c` and common shift `u`), and the bit edges moved them by
        // `offset` whole milliseconds. The time that fits them exactly is `t - f - offset`.
        let frac_s = sol.clock_bias_s + sol.time_correction_s - sol.common_ms_shift as f64 * 1e-3;
        let exact_s = frac_s + offset as f64 * 1e-3;
        let sv_times = used
            .iter()
            .map(|&(prn, m, n_ms, _)| CoarseSvTime {
                prn,
                ms_count: m,
                sv_tow_s: (n_ms - offset).rem_euclid(WEEK_MS) as f64 * 1e-3,
            })
            .collect::<Vec<_>>();
        self.done = true;
        self.given = sv_times.iter().map(|s| s.prn).collect();
        Ok(CoarseOutcome {
            t_s: k as f64 / self.fs_hz,
            time: sol.time.add_seconds(-exact_s),
            time_correction_s: sol.time_correction_s - exact_s,
            position_shift_m: (sol.pos_ecef_m - apriori.pos_ecef_m).norm(),
            sv_times,
            check: format!(
                "{check}, bit edges of {} satellites ({offset:+} ms)",
                edges.len()
            ),
        })
    }
}
