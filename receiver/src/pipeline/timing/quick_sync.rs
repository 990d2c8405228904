//! Frame sync 1.2 s into a subframe, confirmed across satellites.
//!
//! The normal frame sync ([`crate::pipeline::navigation::navdata`]) waits for a whole parity-checked
//! subframe and the next preamble: 6-12 s. A telemetry word (preamble) and a hand-over word
//! that both pass parity give the time of week 1.2 s after a subframe starts, but alone they
//! could be a chance match (20 preamble and parity bits). Two satellites whose candidate
//! times agree cannot both be one: all satellites start their subframes together by GPS time,
//! so at a common sample `k` their SV times differ only by their travel-time differences,
//! under 25 ms (ranges 20 000-26 000 km), while a false candidate is off by anything. The SV
//! time of a candidate at the sample `k_c` of its report is
//!
//! ```text
//! sv_c(k_c) = TOW_c + (m_c - m0_c) ms + chips_c / 1.023e6
//! ```
//!
//! (`m_c`, `chips_c`: the report's `ms_count` and code phase, `m0_c` the TLM's first code
//! period), and two candidates agree when `|sv_a(k_a) + (k_b - k_a) / fs - sv_b(k_b)|` is below
//! [`AGREEMENT_S`]. A candidate also agrees with a satellite whose time is known already.
//! The PVT's RAIM then checks every fix as usual, and the next subframe's HOW each time.

use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_nav::time::GpsTime;
use gpsrx_tracking::ChannelEpoch;

/// Largest difference of two satellites' SV times at a common instant, s (travel-time
/// differences under 25 ms, plus the report's length).
pub const AGREEMENT_S: f64 = 0.05;
/// A candidate waits this long for a confirmation, s of stream time.
const KEEP_S: f64 = 1.0;

/// A TLM and HOW found by a satellite's decoder, with its SV time at the report's sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TowCandidate {
    /// PRN.
    pub prn: u8,
    /// `ms_count` of the TLM's first bit.
    pub first_ms: u64,
    /// The HOW's time of that subframe start, s.
    pub tow_s: u32,
    /// Sample index of the report.
    pub sample: u64,
    /// SV time (TOW, s) at that sample.
    pub sv_tow_s: f64,
}

impl TowCandidate {
    /// The candidate of decoder event (`first_ms`, `tow_s`) for report `e`.
    pub fn new(e: &ChannelEpoch, first_ms: u64, tow_s: u32) -> Self {
        let sv_tow_s = f64::from(tow_s)
            + (e.ms_count as f64 - first_ms as f64) * 1e-3
            + e.code_phase_chips / CA_CHIP_RATE_HZ;
        Self {
            prn: e.prn,
            first_ms,
            tow_s,
            sample: e.sample_index,
            sv_tow_s,
        }
    }

    /// Whether SV time `sv_tow_s` at `sample` agrees with this candidate.
    pub fn agrees(&self, sample: u64, sv_tow_s: f64, fs_hz: f64) -> bool {
        let predicted = self.sv_tow_s + (sample as f64 - self.sample as f64) / fs_hz;
        GpsTime::fold_tow_difference_s(sv_tow_s - predicted).abs() < AGREEMENT_S
    }
}

/// The candidates waiting for a confirmation.
#[derive(Debug, Default)]
pub struct QuickSync {
    pending: Vec<TowCandidate>,
}

impl QuickSync {
    /// Takes a candidate; `known` gives the SV time at a sample of satellites whose time is
    /// known (PRN, sample, SV time). Returns the candidates to synchronise on: the new one
    /// and the waiting ones that agree with each other, or the new one alone when it agrees
    /// with a known time; none otherwise (it waits).
    pub fn offer(
        &mut self,
        c: TowCandidate,
        known: &[(u8, u64, f64)],
        fs_hz: f64,
    ) -> Vec<TowCandidate> {
        let keep = (KEEP_S * fs_hz) as u64;
        self.pending
            .retain(|p| p.prn != c.prn && p.sample + keep >= c.sample);
        if known
            .iter()
            .any(|&(prn, k, sv)| prn != c.prn && c.agrees(k, sv, fs_hz))
        {
            return vec![c];
        }
        let (agreeing, rest): (Vec<_>, Vec<_>) = self
            .pending
            .iter()
            .partition(|p| p.agrees(c.sample, c.sv_tow_s, fs_hz));
        if agreeing.is_empty() {
            self.pending.push(c);
            return Vec::new();
        }
        self.pending = rest;
        let mut out = agreeing;
        out.push(c);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(prn: u8, sample: u64, sv: f64) -> TowCandidate {
        TowCandidate {
            prn,
            first_ms: 0,
            tow_s: 0,
            sample,
            sv_tow_s: sv,
        }
    }

    #[test]
    fn two_agreeing_candidates_confirm_each_other_and_a_stray_one_waits() {
        let fs = 1e6;
        let mut q = QuickSync::default();
        assert!(q.offer(cand(1, 1000, 100.070), &[], fs).is_empty());
        // 6 s off (another subframe's TOW): waits.
        assert!(q.offer(cand(2, 2000, 106.071), &[], fs).is_empty());
        // 18 ms of travel-time difference, 5 ms later: confirms PRN 1.
        let out = q.offer(cand(3, 6000, 100.057), &[], fs);
        let prns: Vec<u8> = out.iter().map(|c| c.prn).collect();
        assert_eq!(prns, vec![1, 3]);
        // A known time confirms a new candidate.
        let out = q.offer(cand(4, 9000, 100.080), &[(1, 9000, 100.078)], fs);
        assert_eq!(out.len(), 1);
        // PRN 2 expired after a second.
        assert!(q
            .offer(cand(5, 2_500_000, 106.071 + 2.498), &[], fs)
            .is_empty());
    }
}
