//! Per-satellite navigation-message decoding: the bit stream of a tracking channel ->
//! frame synchronisation -> parity-checked subframes -> ephemeris, ionosphere/UTC, and the SV
//! time of every code period.
//!
//! Frame sync (IS-GPS-200 20.3.2): a candidate is a position where the 8-bit preamble appears
//! in either polarity (the Costas loop's 180 deg ambiguity) and all ten words of the 300-bit
//! subframe pass parity; it is confirmed when the next subframe's TLM starts with the preamble
//! in the same polarity, 300 bits after the candidate's (160 ms after the candidate ends).
//! Only then are subframes used (including the candidate itself). Subframes that fail parity
//! afterwards are counted and never used; three in a row drop the sync.
//!
//! Time tag: the HOW of a subframe gives the TOW of its first bit, so the code period that
//! starts that bit left the satellite at `tow_start`; code period `m` later left it at
//! `tow_start + (m - m0) ms`, and a point `c` chips into that period at `+ c / 1.023e6 s`.

use crate::pipeline::navigation::frame_memory::FrameMemory;
use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_nav::atmosphere::{KlobucharParams, UtcParams};
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::lnav::{
    decode_subframe_any_polarity, decode_tlm_how, preamble_polarity, DecodedSubframe,
    EphemerisAssembler, Polarity, SubframePayload,
};
use gpsrx_nav::time::GpsTime;
use std::collections::VecDeque;

const SUBFRAME_BITS: usize = 300;

/// What a new bit produced.
#[derive(Debug, Clone, PartialEq)]
pub enum NavEvent {
    /// Frame synchronisation confirmed.
    FrameSync {
        /// TOW of the first confirmed subframe's start, s.
        tow_s: u32,
    },
    /// A subframe passed parity (after frame sync).
    Subframe {
        /// Subframe ID 1-5.
        id: u8,
        /// TOW of its start, s.
        tow_s: u32,
    },
    /// A complete, consistent ephemeris (subframes 1-3 with matching IODE/IODC).
    Ephemeris(Box<Ephemeris>),
    /// A subframe 4 or 5 page of the almanac (an almanac page or a page 25), for the
    /// almanac collected from all satellites.
    AlmanacPage(Box<DecodedSubframe>),
    /// A subframe failed parity.
    ParityFailure,
    /// A subframe's HOW disagrees with the SV time kept (a carried-over time, or the time of
    /// the previous subframes): the bit stream or the time is wrong (a gap in the samples?).
    /// The HOW's time is taken.
    TowMismatch {
        /// HOW time minus the time kept, ms.
        error_ms: f64,
    },
    /// While unsynchronised, with [`NavDecoder::report_tow_candidates`]: a telemetry word
    /// with the preamble and a hand-over word ending at the newest bit passed parity. Not yet
    /// trusted: [`NavDecoder::sync_at`] takes it once another satellite confirms it
    /// (`crate::pipeline::timing::quick_sync`).
    TowCandidate {
        /// `ms_count` of the TLM's first bit.
        first_ms: u64,
        /// The HOW's time of that subframe start, s.
        tow_s: u32,
    },
    /// The channel's data-bit edges disagree with a carried-over SV time (which is dropped).
    BitEdgeMismatch {
        /// SV time at the channel's bit edge modulo 20 ms, folded into [-10, 10), ms.
        offset_ms: f64,
    },
}

/// The navigation-message decoder of one satellite.
#[derive(Debug, Clone)]
pub struct NavDecoder {
    prn: u8,
    /// Recent bits (0/1 as received, before polarity correction) and the `ms_count` of their
    /// first code period.
    bits: VecDeque<(u8, u64)>,
    /// Index in `bits` where the next subframe starts, once synchronised.
    next_subframe: Option<usize>,
    /// A parity-checked candidate waiting for confirmation: its subframe, its first bit's ms and
    /// its polarity.
    candidate: Option<(DecodedSubframe, u64, Polarity)>,
    assembler: EphemerisAssembler,
    /// Latest ephemeris.
    pub ephemeris: Option<Ephemeris>,
    /// When the latest ephemeris's subframe 1 was sent: the HOW time of its start, s of the
    /// GPS week of the ephemeris's toe (RINEX 3.04 Table A6 "transmission time of message":
    /// negative when sent in the week before toe).
    pub ephemeris_transmission_tow_s: Option<f64>,
    /// Start (HOW time, s) and week of the latest subframe 1.
    last_sf1: Option<(u32, u32)>,
    /// Latest ionosphere parameters (subframe 4 page 18).
    pub iono: Option<KlobucharParams>,
    /// Latest GPS-UTC parameters (weeks resolved).
    pub utc: Option<UtcParams>,
    /// Latest GPS-UTC parameters as broadcast (8-bit weeks).
    utc_broadcast: Option<UtcParams>,
    /// Time tag: `ms_count` of a code period and the SV time (TOW, s) at its start: a
    /// subframe's first period and its HOW time, or a carried-over time
    /// ([`NavDecoder::carry_time`]).
    time_tag: Option<(u64, f64)>,
    /// The time tag was carried over (not read from a HOW), so the subframe boundaries are
    /// found from it rather than from a preamble.
    carried: bool,
    /// A rough SV time (`ms_count`, TOW s, tolerance s) while unsynchronised: a TLM and HOW
    /// that pass parity with a time within the tolerance give frame sync at once
    /// ([`NavDecoder::hint_time`]).
    hint: Option<(u64, f64, f64)>,
    /// Report TLM and HOW pairs found while unsynchronised ([`NavEvent::TowCandidate`]).
    tow_candidates: bool,
    reference_week: u32,
    /// Full transmission week from subframe 1 (10-bit week resolved with the reference week).
    week: Option<u32>,
    /// Subframes decoded, and subframes that failed parity after sync.
    pub subframes_ok: u32,
    /// Subframes that failed parity after frame sync.
    pub parity_failures: u32,
    consecutive_failures: u32,
    /// The bits of the frames before, by position (kept over losses of sync): the time of a
    /// bit stream after lost samples ([`NavDecoder::sv_time_from_frames`]).
    frames: FrameMemory,
}

impl NavDecoder {
    /// A decoder for `prn`; `reference_week` resolves the 10-bit week (the latest full week
    /// consistent with it is taken).
    pub fn new(prn: u8, reference_week: u32) -> Self {
        Self {
            prn,
            bits: VecDeque::with_capacity(2 * SUBFRAME_BITS + 8),
            next_subframe: None,
            candidate: None,
            assembler: EphemerisAssembler::new(prn, reference_week),
            ephemeris: None,
            ephemeris_transmission_tow_s: None,
            last_sf1: None,
            iono: None,
            utc: None,
            utc_broadcast: None,
            time_tag: None,
            carried: false,
            hint: None,
            tow_candidates: false,
            reference_week,
            week: None,
            subframes_ok: 0,
            parity_failures: 0,
            consecutive_failures: 0,
            frames: FrameMemory::default(),
        }
    }

    /// The satellite.
    pub fn prn(&self) -> u8 {
        self.prn
    }

    /// Whether frame sync is confirmed (and the SV time known).
    pub fn synced(&self) -> bool {
        self.time_tag.is_some()
    }

    /// The GPS week of the signal: from subframe 1 once decoded, else the reference week.
    pub fn week(&self) -> u32 {
        self.week.unwrap_or(self.reference_week)
    }

    /// The GPS week decoded from subframe 1, if any.
    pub fn decoded_week(&self) -> Option<u32> {
        self.week
    }

    /// Forgets the bit stream (after a loss of lock): frame sync must be found again.
    pub fn reset_sync(&mut self) {
        self.bits.clear();
        self.next_subframe = None;
        self.candidate = None;
        self.time_tag = None;
        self.carried = false;
        self.hint = None;
        self.consecutive_failures = 0;
    }

    /// Takes an SV time known from elsewhere (carried over an outage by the navigation
    /// processor): the code period `ms_count` started at SV time `sv_tow_s` (a whole 20 ms, a
    /// data-bit edge). The bit stream restarts; subframes are decoded from the next 6 s
    /// boundary of that time on, and the first HOW confirms it ([`NavEvent::TowMismatch`]
    /// otherwise). Every bit must start on a 20 ms boundary of this time, else it is dropped
    /// ([`NavEvent::BitEdgeMismatch`]).
    pub fn carry_time(&mut self, ms_count: u64, sv_tow_s: f64) {
        self.reset_sync();
        self.time_tag = Some((ms_count, sv_tow_s));
        self.carried = true;
    }

    /// Gives a rough SV time while unsynchronised: code period `ms_count` started near SV time
    /// `sv_tow_s`, within `tolerance_s`. Frame sync then needs only a telemetry word with the
    /// preamble and a hand-over word, both passing parity, whose time agrees (1.2 s after a
    /// subframe starts, instead of a whole subframe and the next preamble: 6-12 s). A false
    /// match needs 20 parity and preamble bits and the 17-bit TOW count to agree.
    pub fn hint_time(&mut self, ms_count: u64, sv_tow_s: f64, tolerance_s: f64) {
        if self.time_tag.is_none() {
            self.hint = Some((ms_count, sv_tow_s, tolerance_s));
        }
    }

    /// Reports every TLM and HOW that pass parity while unsynchronised
    /// ([`NavEvent::TowCandidate`]), for a frame sync 1.2 s into a subframe once another
    /// satellite confirms the time ([`NavDecoder::sync_at`]).
    pub fn report_tow_candidates(&mut self, on: bool) {
        self.tow_candidates = on;
    }

    /// Frame sync on the subframe whose first bit started code period `first_ms`, at SV time
    /// `tow_s` (a [`NavEvent::TowCandidate`] confirmed elsewhere). False when synchronised
    /// already or when that bit is no longer held.
    pub fn sync_at(&mut self, first_ms: u64, tow_s: u32) -> bool {
        if self.time_tag.is_some() {
            return false;
        }
        let Some(idx) = self.bits.iter().position(|&(_, ms)| ms == first_ms) else {
            return false;
        };
        self.bits.drain(..idx);
        self.hint = None;
        self.candidate = None;
        self.time_tag = Some((first_ms, f64::from(tow_s)));
        self.carried = false;
        self.next_subframe = Some(0);
        true
    }

    /// Whether a rough time is held ([`NavDecoder::hint_time`]).
    pub fn has_hint(&self) -> bool {
        self.hint.is_some()
    }

    /// Frame sync from the TLM and HOW ending at the newest bit, if they agree with the hint.
    fn sync_from_hint(&mut self, events: &mut Vec<NavEvent>) -> bool {
        let Some((m0, sv0, tol)) = self.hint else {
            return false;
        };
        let n = self.bits.len();
        if n < 60 {
            return false;
        }
        let head: Vec<u8> = self.bits.iter().skip(n - 60).map(|&(b, _)| b).collect();
        let Some((how, _)) = decode_tlm_how(&head) else {
            return false;
        };
        let first_ms = self.bits[n - 60].1;
        let tow = how.subframe_start_tow_s();
        let err = GpsTime::fold_tow_difference_s(
            f64::from(tow) - (sv0 + (first_ms as f64 - m0 as f64) * 1e-3),
        );
        if err.abs() > tol {
            return false;
        }
        self.hint = None;
        self.candidate = None;
        self.time_tag = Some((first_ms, f64::from(tow)));
        self.bits.drain(..n - 60);
        self.next_subframe = Some(0);
        events.push(NavEvent::FrameSync { tow_s: tow });
        true
    }

    /// Whether the SV time is a carried-over one not yet confirmed by a HOW.
    pub fn time_carried(&self) -> bool {
        self.carried
    }

    /// With a carried-over time and no subframe position yet: checks that the bit `ms` starts
    /// on a 20 ms boundary of SV time and starts the subframe at a 6 s boundary.
    fn align_from_time(&mut self, ms: u64, events: &mut Vec<NavEvent>) {
        let Some(sv) = self.sv_tow_s(ms, 0.0) else {
            return;
        };
        let sv_ms = sv * 1e3;
        let off = crate::pipeline::timing::modulo::nearest_remainder(sv_ms, 20.0);
        if off.abs() > 0.5 {
            events.push(NavEvent::BitEdgeMismatch { offset_ms: off });
            self.reset_sync();
            return;
        }
        let in_subframe = sv_ms.rem_euclid(6000.0);
        if !(0.5..=6000.0 - 0.5).contains(&in_subframe) {
            // This bit opens a subframe: keep it alone.
            let last = self.bits.len().saturating_sub(1);
            self.bits.drain(..last);
            self.next_subframe = Some(0);
        } else if self.bits.len() > SUBFRAME_BITS {
            self.bits.pop_front();
        }
    }

    /// SV transmit time (TOW, s; may exceed a week's end by a fraction, which the caller's
    /// `GpsTime` normalises) of the point `code_phase_chips` into code period `ms_count`.
    pub fn sv_tow_s(&self, ms_count: u64, code_phase_chips: f64) -> Option<f64> {
        let (m0, tow0) = self.time_tag?;
        let dm = ms_count as f64 - m0 as f64;
        Some(tow0 + dm * 1e-3 + code_phase_chips / CA_CHIP_RATE_HZ)
    }

    /// Feeds one bit (+1/-1 as decided by the channel) whose first code period is `ms`.
    pub fn push_bit(&mut self, value: i8, ms: u64) -> Vec<NavEvent> {
        let mut events = Vec::new();
        if let Some(&(_, last_ms)) = self.bits.back() {
            if ms != last_ms + 20 {
                // A gap in the bit stream: the positions no longer line up.
                if self.carried {
                    self.bits.clear();
                    self.next_subframe = None;
                } else {
                    self.reset_sync();
                }
            }
        }
        self.bits.push_back((u8::from(value < 0), ms));
        self.remember(ms);
        if self.carried && self.next_subframe.is_none() {
            self.align_from_time(ms, &mut events);
            return events;
        }
        match self.next_subframe {
            Some(start) => {
                if self.bits.len() >= start + SUBFRAME_BITS {
                    let (decoded, first_ms) = self.decode_at(start);
                    match decoded {
                        Some((sf, _)) => self.accept(sf, first_ms, &mut events),
                        None => {
                            self.parity_failures += 1;
                            self.consecutive_failures += 1;
                            events.push(NavEvent::ParityFailure);
                        }
                    }
                    // Keep the last subframe's bits only (for the next decode).
                    self.bits.drain(..start + SUBFRAME_BITS);
                    self.next_subframe = Some(0);
                    if self.consecutive_failures >= 3 {
                        // Three bad subframes in a row: the sync (or the bit stream) is wrong.
                        self.reset_sync();
                    }
                }
            }
            None => self.search(&mut events),
        }
        events
    }

    /// Keeps the newest bit, starting code period `ms`, in the frame memory when its time was
    /// read from a HOW (not carried over a gap): bit number `TOW / 20 ms`.
    fn remember(&mut self, ms: u64) {
        if self.carried {
            return;
        }
        let (Some(sv), Some(&(raw, _))) = (self.sv_tow_s(ms, 0.0), self.bits.back()) else {
            return;
        };
        let n = (sv * 50.0).round();
        if (sv * 50.0 - n).abs() < 0.01 && n >= 0.0 {
            self.frames.record(n as u32, raw);
        }
    }

    /// The SV time (TOW, s) at the start of code period `ms_count` read from the bits held
    /// since the channel's bit sync, matched against the frames before
    /// (`FrameMemory::place`) among the 20 ms bit edges whose time falls in
    /// `[lo_s, hi_s]`: `None` until they match one edge and only one. For a time kept over
    /// lost samples of unknown length (IS-GPS-200 20.3.2: subframes 1-3 repeat every 30 s).
    pub fn sv_time_from_frames(&self, ms_count: u64, lo_s: f64, hi_s: f64) -> Option<f64> {
        // The newest 300 bits at most (a subframe: enough, and the cost bounded).
        let skip = self.bits.len().saturating_sub(SUBFRAME_BITS);
        let &(_, m_first) = self.bits.get(skip)?;
        let raw: Vec<u8> = self.bits.iter().skip(skip).map(|&(b, _)| b).collect();
        // The time at ms_count of the first held bit's candidate bit number c:
        // 20 ms c + (ms_count - m_first) ms.
        let since_s = (ms_count as f64 - m_first as f64) * 1e-3;
        let first = ((lo_s - since_s) * 50.0).ceil() as i64;
        let last = ((hi_s - since_s) * 50.0).floor() as i64;
        if last < first || last - first > 1000 {
            return None;
        }
        let n = self.frames.place(&raw, first, last)?;
        let tow_s = f64::from(n) * 0.02 + since_s;
        // Back into the window's week (a match across the week's end).
        Some(tow_s + ((lo_s - tow_s) / 604_800.0).ceil() * 604_800.0)
    }

    /// Frame sync at a time read from the data bits ([`NavDecoder::sv_time_from_frames`]): code
    /// period `ms_count`, a bit edge just after the newest bit held, started at SV time
    /// `sv_tow_s`. The time counts as read from a HOW; the subframes are decoded from the
    /// start of the one in progress if its bits are held, else from the next.
    pub fn sync_from_frames(&mut self, ms_count: u64, sv_tow_s: f64) {
        let n = (sv_tow_s * 50.0).round().max(0.0) as u64;
        let into_subframe = (n % SUBFRAME_BITS as u64) as usize;
        let held = self.bits.len();
        let start = if into_subframe <= held {
            held - into_subframe
        } else {
            held + SUBFRAME_BITS - into_subframe
        };
        self.hint = None;
        self.candidate = None;
        self.time_tag = Some((ms_count, sv_tow_s));
        self.carried = false;
        self.next_subframe = Some(start);
    }

    /// Confirms a candidate with the next TLM preamble, or looks for a subframe ending at the
    /// newest bit.
    fn search(&mut self, events: &mut Vec<NavEvent>) {
        if self.sync_from_hint(events) {
            return;
        }
        // A hint the TLM and HOW disagree with (samples of unknown length lost since it was
        // taken) does not hold the candidate back: other satellites confirm it or not.
        if self.tow_candidates && self.bits.len() >= 60 {
            let n = self.bits.len();
            let head: Vec<u8> = self.bits.iter().skip(n - 60).map(|&(b, _)| b).collect();
            if let Some((how, _)) = decode_tlm_how(&head) {
                events.push(NavEvent::TowCandidate {
                    first_ms: self.bits[n - 60].1,
                    tow_s: how.subframe_start_tow_s(),
                });
            }
        }
        if let Some((sf, first_ms, polarity)) = self.candidate {
            // The next subframe starts 300 bits (6000 ms) after the candidate's first bit.
            let next_ms = first_ms + 6000;
            let Some(idx) = self.bits.iter().position(|&(_, ms)| ms == next_ms) else {
                return;
            };
            if self.bits.len() < idx + 8 {
                return;
            }
            let head: Vec<u8> = self
                .bits
                .iter()
                .skip(idx)
                .take(8)
                .map(|&(b, _)| b)
                .collect();
            self.candidate = None;
            if preamble_polarity(&head) == Some(polarity) {
                events.push(NavEvent::FrameSync {
                    tow_s: sf.how.subframe_start_tow_s(),
                });
                self.accept(sf, first_ms, events);
                self.bits.drain(..idx);
                self.next_subframe = Some(0);
                return;
            }
        }
        if self.bits.len() < SUBFRAME_BITS {
            return;
        }
        let start = self.bits.len() - SUBFRAME_BITS;
        match self.decode_at(start) {
            (Some((sf, polarity)), first_ms) => self.candidate = Some((sf, first_ms, polarity)),
            _ => {
                // Bound the buffer while searching.
                if self.bits.len() > 2 * SUBFRAME_BITS {
                    self.bits.pop_front();
                }
            }
        }
    }

    fn decode_at(&self, start: usize) -> (Option<(DecodedSubframe, Polarity)>, u64) {
        let mut bits = [0u8; SUBFRAME_BITS];
        for (i, b) in bits.iter_mut().enumerate() {
            *b = self.bits[start + i].0;
        }
        let first_ms = self.bits[start].1;
        (decode_subframe_any_polarity(&bits).ok(), first_ms)
    }

    fn accept(&mut self, sf: DecodedSubframe, first_ms: u64, events: &mut Vec<NavEvent>) {
        self.subframes_ok += 1;
        self.consecutive_failures = 0;
        let tow_s = sf.how.subframe_start_tow_s();
        if let Some(kept) = self.sv_tow_s(first_ms, 0.0) {
            // The HOW against the time kept (week roll-over folded).
            let err = GpsTime::fold_tow_difference_s(f64::from(tow_s) - kept);
            if err.abs() > 1e-4 {
                events.push(NavEvent::TowMismatch {
                    error_ms: err * 1e3,
                });
            }
        }
        self.time_tag = Some((first_ms, f64::from(tow_s)));
        self.carried = false;
        events.push(NavEvent::Subframe {
            id: sf.how.subframe_id,
            tow_s,
        });
        if let SubframePayload::Subframe1(s1) = &sf.payload {
            let week = GpsTime::resolve_week_10bit(s1.week_mod_1024, self.reference_week);
            self.week = Some(week);
            self.last_sf1 = Some((tow_s, week));
        }
        match sf.payload {
            SubframePayload::Page18 { iono, utc } => {
                self.iono = Some(iono);
                self.utc_broadcast = Some(utc);
            }
            SubframePayload::Almanac(_)
            | SubframePayload::Sf5Page25(_)
            | SubframePayload::Sf4Page25(_) => {
                events.push(NavEvent::AlmanacPage(Box::new(sf)));
            }
            _ => {
                if let Some(eph) = self.assembler.push(&sf) {
                    // The assembler keeps the latest subframe 1: the one recorded here.
                    self.ephemeris_transmission_tow_s = self.last_sf1.map(|(tow, week)| {
                        f64::from(tow) + (f64::from(week) - f64::from(eph.toe.week)) * 604_800.0
                    });
                    self.ephemeris = Some(eph.clone());
                    events.push(NavEvent::Ephemeris(Box::new(eph)));
                }
            }
        }
        // The 8-bit WN_t and WN_LSF (IS-GPS-200 20.3.3.5.2.4) resolved against the decoded
        // 10-bit week once known (page 18 may come before subframe 1): against the reference
        // week alone, which may be years away, they can land 256 weeks off.
        if let Some(utc) = self.utc_broadcast {
            self.utc = Some(utc.resolve_weeks(self.week()));
        }
    }
}

/// The GPS week of the current date, to resolve 10-bit week numbers when nothing better is
/// known: GPS time from the system clock (leap seconds ignored: they do not move the week by
/// more than 18 s).
pub fn current_gps_week() -> u32 {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    // GPS epoch 1980-01-06 is 315,964,800 s after the Unix epoch.
    (((secs - 315_964_800.0) / 604_800.0).floor().max(0.0)) as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::navigation::frame_memory;
    use gpsrx_nav::lnav::LnavEncoder;
    use gpsrx_nav::rinex_nav::parse_rinex_nav;

    /// The transmitted bits (0/1) of PRN 7 from the subframe starting at `tow0_s` (a multiple of
    /// 6 s) for `n_subframes`, encoded from the project's broadcast file (IS-GPS-200 20.3.2).
    fn lnav_bits(tow0_s: u32, n_subframes: u32) -> Vec<u8> {
        let text = include_str!("../../../../samples/data/brdc0010.22n");
        let nav = parse_rinex_nav(text).expect("the shipped broadcast file");
        let eph = nav.ephemerides.iter().find(|e| e.prn == 7).expect("PRN 7");
        let enc = LnavEncoder::new(eph, nav.iono.as_ref(), nav.utc.as_ref()).expect("fits");
        (0..n_subframes)
            .flat_map(|k| enc.subframe_bits(tow0_s + 6 * k, 2190))
            .collect()
    }

    #[test]
    fn a_bit_stream_after_lost_samples_is_timed_from_the_frame_before() {
        // Frame sync on a stream starting at TOW 538 200 s (subframe 1 at 538 230 s).
        let tow0 = 538_200;
        let bits = lnav_bits(tow0, 15);
        let mut dec = NavDecoder::new(7, 2190);
        let ms0 = 1_000u64;
        let push = |dec: &mut NavDecoder, i: usize, ms: u64, invert: bool| {
            let b = bits[i] ^ u8::from(invert);
            dec.push_bit(if b == 1 { -1 } else { 1 }, ms)
        };
        for i in 0..1800 {
            push(&mut dec, i, ms0 + 20 * i as u64, false);
        }
        assert!(dec.synced());
        // 1234 bits (24.68 s) are lost and 31 ms of stream with them: the channel's code
        // periods go on counting, the decoder starts again, the polarity flipped.
        dec.reset_sync();
        let resume = 1800 + 1234; // bit 3034: the HOW of subframe 1, two frames on
        let ms_resume = ms0 + 20 * 1800 + 11;
        // The truth: bit `resume`; the time kept is 2.2 s off it (sought within 3 s).
        let true_s = f64::from(tow0) + resume as f64 * 0.02;
        let kept_s = true_s + 2.2;
        let mut found = None;
        for j in 0..120 {
            let ms = ms_resume + 20 * j as u64;
            push(&mut dec, resume + j, ms, true);
            // The time at the next bit edge, sought within 3 s of the kept one.
            let next = ms + 20;
            let kept = kept_s + 20.0 * (j + 1) as f64 * 1e-3;
            if let Some(t) = dec.sv_time_from_frames(next, kept - 3.0, kept + 3.0) {
                found = Some((j, t, next));
                break;
            }
        }
        let (j, t, next) = found.expect("placed in the frame before");
        let truth = true_s + 20.0 * (j + 1) as f64 * 1e-3;
        assert!((t - truth).abs() < 1e-9, "{t} against {truth}");
        assert!(
            j + 1 >= frame_memory::MIN_COMPARED as usize && j < 60,
            "after {} bits",
            j + 1
        );
        // Synchronised on it: the next subframe decodes and its HOW agrees.
        dec.sync_from_frames(next, t);
        let mut events = Vec::new();
        for k in (j + 1)..700 {
            events.extend(push(&mut dec, resume + k, ms_resume + 20 * k as u64, true));
        }
        assert!(events
            .iter()
            .any(|e| matches!(e, NavEvent::Subframe { .. })));
        assert!(!events
            .iter()
            .any(|e| matches!(e, NavEvent::TowMismatch { .. } | NavEvent::ParityFailure)));
    }

    #[test]
    fn a_stream_in_subframes_4_and_5_is_not_timed_from_its_data() {
        let tow0 = 538_200;
        let bits = lnav_bits(tow0, 15);
        let mut dec = NavDecoder::new(7, 2190);
        for (i, &b) in bits.iter().take(1800).enumerate() {
            dec.push_bit(if b == 1 { -1 } else { 1 }, 20 * i as u64);
        }
        dec.reset_sync();
        // Bits 2640-2699: subframe 4 of the next frame, past its TLM.
        let start = 2640;
        for (j, &b) in bits[start..start + 60].iter().enumerate() {
            dec.push_bit(if b == 1 { -1 } else { 1 }, 100_000 + 20 * j as u64);
        }
        let next = 100_000 + 20 * 60;
        let t = f64::from(tow0) + (start + 60) as f64 * 0.02;
        assert_eq!(dec.sv_time_from_frames(next, t - 3.0, t + 3.0), None);
    }

    #[test]
    fn the_hand_over_word_is_computed_from_the_frame_before() {
        let tow0 = 538_200;
        let bits = lnav_bits(tow0, 20);
        let n0 = tow0 * 50;
        // One frame received in inverted polarity.
        let mut mem = FrameMemory::default();
        for (j, &b) in bits.iter().take(1500).enumerate() {
            mem.record(n0 + j as u32, b ^ 1);
        }
        let word = |first: usize| -> u32 {
            bits[first..first + 30]
                .iter()
                .fold(0, |w, &b| (w << 1) | u32::from(b ^ 1))
        };
        // The HOWs the encoder sends one to three frames later, every subframe ID.
        for later in [5u32, 6, 7, 8, 9, 13, 19] {
            let s = n0 / 300 + later;
            let how = word(later as usize * 300 + 30);
            assert_eq!(mem.expected_how(s), Some(how), "subframe {later}");
        }
        // Five frames later: too old; a HOW that fails parity: none.
        assert_eq!(mem.expected_how(n0 / 300 + 25), None);
        mem.record(n0 + 40, bits[40]);
        assert_eq!(mem.expected_how(n0 / 300 + 5), None);
    }
}
