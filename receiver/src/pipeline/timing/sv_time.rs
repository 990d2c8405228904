//! SV time kept across a loss of the signal and across lost samples.
//!
//! Per satellite an [`SvClock`] (where its code stood at the last usable report) predicts its
//! SV time at any later sample. After an outage (time intact) a new channel's first bit edge
//! takes the predicted time rounded to the 20 ms bit, so fixes resume without waiting for
//! frame sync. After lost samples ([`GapRecovery`]) the prediction is off by the gap: its
//! length is resolved from the new bit edges and the carrier-phase steps
//! ([`crate::pipeline::timing::gap_length`]) and every time moved over it, or, when that cannot be
//! done, the times become rough hints for a fast frame sync ([`NavDecoder::hint_time`]).

use crate::pipeline::navigation::navdata::NavDecoder;
use crate::pipeline::timing::modulo::nearest_remainder;
use gpsrx_dsp::constants::{F_L1_HZ, SPEED_OF_LIGHT_MPS};
use gpsrx_tracking::ChannelEpoch;
use std::collections::BTreeMap;

/// How long the length of lost samples is sought after the code offsets may be used, s.
pub const GAP_RESOLVE_S: f64 = 1.0;

/// Satellites whose data bits must give the same length of lost samples
/// ([`GapRecovery::note_bit_length`]).
pub const BIT_LENGTH_SATELLITES: usize = 2;

/// Longest gap sought in the data bits, ms (the bits after it are matched against the frames
/// before at every 20 ms edge from the kept time to this much later).
const BITS_GAP_MAX_MS: f64 = 3000.0;

/// Refused carried SV times that agree: per satellite `(PRN, offset of the kept SV time from
/// the new bit edge ms, SV time rate)`.
pub type EdgeOffsets = Vec<(u8, f64, f64)>;

/// What [`SvTimeKeeper::observe`] found that must be reported.
#[derive(Debug, Clone, Copy)]
pub enum CarryNote {
    /// A carried SV time fell this far (ms) off the new bit edge.
    Refused(f64),
    /// The length of lost samples was resolved.
    GapResolved {
        /// Stream time of the gap, s.
        t_s: f64,
        /// Its length, ms.
        length_ms: f64,
        /// Read from the data bits placed in the frames before (else from the carrier-phase
        /// steps and the code at the new bit edges).
        from_bits: bool,
    },
}

/// What is kept over a sample gap to measure it once the time is re-established.
#[derive(Debug, Clone)]
pub struct GapRecovery {
    /// Stream time of the gap, s.
    pub t_s: f64,
    /// The last fix before it: stream time (s), clock bias after any step (m), drift (m/s).
    pub before: Option<(f64, f64, f64)>,
    /// The carrier-phase steps at the gap: with them, the SV times
    /// are kept and carried over the gap once its length is resolved
    /// ([`crate::pipeline::timing::gap_length`]); without, the time comes from frame sync.
    pub steps: Vec<crate::pipeline::timing::carrier_step::PhaseStep>,
    /// Per PRN: how far the SV time kept falls off the channel's new bit edge (ms), and the
    /// satellite's SV time rate.
    pub edge_offsets: BTreeMap<u8, (f64, f64)>,
    /// Stream time from which the code offsets are settled enough to measure the length, s
    /// (`None`: they are not used).
    pub code_from_s: Option<f64>,
    /// Stream time after which an unresolved length is given up (the time then comes from
    /// frame sync), s.
    pub give_up_s: f64,
    /// The length resolved, ms.
    pub length_ms: Option<f64>,
    /// The length cannot be resolved: the time comes from frame sync.
    pub unresolved: bool,
    /// Receiver clock steps made while re-establishing the time, ms.
    pub stepped_ms: i64,
    /// Per PRN: the length (ms) read from its data bits, placed in the frames before
    /// ([`NavDecoder::sv_time_from_frames`]).
    pub bit_lengths: BTreeMap<u8, f64>,
}

impl GapRecovery {
    /// A gap at stream time `t_s`; `before`: the clock of the last fix; `steps`: the
    /// carrier-phase steps; `code_from_s`: from when the code offsets may be used.
    pub fn new(
        t_s: f64,
        before: Option<(f64, f64, f64)>,
        steps: Vec<crate::pipeline::timing::carrier_step::PhaseStep>,
        code_from_s: Option<f64>,
    ) -> Self {
        let unresolved =
            steps.len() < crate::pipeline::timing::gap_length::MIN_STEPS && code_from_s.is_none();
        Self {
            t_s,
            before,
            steps,
            edge_offsets: BTreeMap::new(),
            code_from_s,
            give_up_s: code_from_s.unwrap_or(t_s) + GAP_RESOLVE_S,
            length_ms: None,
            unresolved,
            stepped_ms: 0,
            bit_lengths: BTreeMap::new(),
        }
    }

    /// The length read from the data bits of `prn` (ms); once [`BIT_LENGTH_SATELLITES`]
    /// satellites agree (0.1 ms), it is the gap's length (the mean), whatever the carrier and
    /// the code say. Returns whether that resolved it.
    pub fn note_bit_length(&mut self, prn: u8, length_ms: f64) -> bool {
        self.bit_lengths.insert(prn, length_ms);
        let agreeing: Vec<f64> = self
            .bit_lengths
            .values()
            .copied()
            .filter(|l| (l - length_ms).abs() < 0.1)
            .collect();
        if agreeing.len() < BIT_LENGTH_SATELLITES || self.length_ms.is_some() {
            return false;
        }
        let length = agreeing.iter().sum::<f64>() / agreeing.len() as f64;
        tracing::debug!(
            "gap length {length:.4} ms from the data bits of {} satellites placed in the frames before",
            agreeing.len()
        );
        self.length_ms = Some(length);
        true
    }

    /// Takes the offset `off_ms` of `prn`'s kept SV time from its new bit edge and the
    /// satellite's SV time rate at stream time `now_s`; once
    /// [`crate::pipeline::timing::discontinuity::MIN_SATELLITES`] offsets agree (0.1 ms), resolves the
    /// length from the carrier-phase steps and, once settled, the code offsets
    /// ([`crate::pipeline::timing::gap_length::choose`]), or gives up after [`GAP_RESOLVE_S`].
    /// Returns whether the length was just resolved.
    pub fn add_edge_offset(&mut self, prn: u8, off_ms: f64, rate: f64, now_s: f64) -> bool {
        use crate::pipeline::timing::gap_length::{choose, estimate_from_code};
        self.edge_offsets.insert(prn, (off_ms, rate));
        let agreeing: Vec<(f64, f64)> = self
            .edge_offsets
            .values()
            .filter(|o| (o.0 - off_ms).abs() < 0.1)
            .copied()
            .collect();
        if agreeing.len() >= crate::pipeline::timing::discontinuity::MIN_SATELLITES {
            let mean = agreeing.iter().map(|o| o.0).sum::<f64>() / agreeing.len() as f64;
            // The kept time is g late: it falls -g (mod 20 ms) off the true bit edge.
            let offset = (-mean).rem_euclid(20.0);
            let by_code = self
                .code_from_s
                .filter(|&t| now_s >= t)
                .and_then(|_| estimate_from_code(&agreeing));
            self.length_ms =
                choose(offset, &self.steps, by_code).map(|l| refine_length_ms(l, &agreeing));
            tracing::debug!(
                "{now_s:.2} s: gap length: {offset:.3} ms modulo 20 ms from {} bit edges; by the code {by_code:?} (from {:?} s); with the carrier-phase steps: {:?}",
                agreeing.len(),
                self.code_from_s,
                self.length_ms
            );
        }
        if self.length_ms.is_none() && now_s >= self.give_up_s {
            self.unresolved = true;
        }
        self.length_ms.is_some()
    }
}

/// The lost receiver time (ms) refined from `length_ms` (right to a few microseconds) and the
/// offsets `(off_i ms, r_i)` of the kept SV times from the new bit edges: the SV time of
/// satellite `i` ran `g r_i` over the gap, so `-off_i = g r_i - 20 m_i` for whole bits `m_i`,
/// and `g` is the mean of `(20 m_i - off_i) / r_i` (the offsets alone give `g r_i`, which
/// differs from `g` by up to `g 3e-6`: 1.5 us, 450 m of range, for half a second).
pub fn refine_length_ms(length_ms: f64, offsets: &[(f64, f64)]) -> f64 {
    if offsets.is_empty() {
        return length_ms;
    }
    offsets
        .iter()
        .map(|&(off, r)| {
            let m = ((length_ms * r + off) / 20.0).round();
            (20.0 * m - off) / r
        })
        .sum::<f64>()
        / offsets.len() as f64
}

impl GapRecovery {
    /// The gap's length (ms) from the clock bias `bias_m` of the first fix after it, at stream
    /// time `t_s`: the receiver counts samples, so lost samples make its time run late by the
    /// gap and the clock bias (receiver minus GPS time) drops by `c g` from its prediction
    /// `b0 + d (t - t0)`.
    pub fn length_from_bias_ms(&self, t_s: f64, bias_m: f64) -> Option<f64> {
        let (t0, b0, d) = self.before?;
        let predicted = b0 + d * (t_s - t0);
        Some(-(bias_m - predicted) / SPEED_OF_LIGHT_MPS * 1e3 + self.stepped_ms as f64)
    }
}

/// The longest outage an SV time is carried over, s. The carried time is a prediction with
/// the code rate at the loss; it must be right to well within 10 ms (half a data bit), which
/// holds for minutes (a Doppler change of 1 Hz/s costs 0.3 us over 30 s; a receiver moving
/// 300 m/s off the prediction costs 1 us per second).
const SV_CLOCK_CARRY_S: f64 = 120.0;

/// The longest a rough SV time serves as a frame-sync hint, s, and its tolerance, s (lost
/// samples of up to that much are then re-established 1.2 s after the next subframe starts).
const SV_CLOCK_HINT_S: f64 = 600.0;
const SV_CLOCK_HINT_TOLERANCE_S: f64 = 3.0;

/// A satellite's SV time at a sample, with its rate and the rate's rate: where the code of the
/// last usable report stood. After the channel has lost the signal, the SV time of a new
/// channel's bit edge is predicted from it, `sv(k) = sv_ref + r dt + r' dt^2 / 2` (the rate
/// held after [`RATE_RATE_HORIZON_S`]) with
/// `dt = (k - k_ref) / fs`, the SV time rate `r = 1 + f_D / f_L1` and its rate `r'` (the
/// Doppler rate over `f_L1`: under a 4.3 g acceleration along the line of sight the quadratic
/// term is 120 ns after 1.3 s, as much as the code offsets that measure a 31 ms gap), and
/// rounded to the 20 ms data bit (the bit edge the channel found): the satellite's time is
/// known again as soon as its new channel has bit sync, without waiting 6-12 s for frame sync.
#[derive(Debug, Clone, Copy)]
pub struct SvClock {
    /// Sample index of the reference point.
    sample: u64,
    /// SV time at it (TOW, s).
    sv_tow_s: f64,
    /// SV seconds per receiver second (`1 + f_D / f_L1`, filtered).
    pub rate: f64,
    /// Its rate, 1/s (the Doppler rate over `f_L1`, filtered).
    rate_rate: f64,
    /// Known only roughly (samples may have been lost since): not carried over, only a hint
    /// for frame sync ([`NavDecoder::hint_time`]).
    rough: bool,
}

impl SvClock {
    /// The predicted SV time at sample `k` for samples at `fs_hz`.
    fn at(&self, k: u64, fs_hz: f64) -> f64 {
        let dt = (k as f64 - self.sample as f64) / fs_hz;
        // The rate changes at most over the first seconds (a manoeuvre ends), then holds.
        let dq = dt.clamp(-RATE_RATE_HORIZON_S, RATE_RATE_HORIZON_S);
        self.sv_tow_s + dt * self.rate + (dq * dt - 0.5 * dq * dq) * self.rate_rate
    }
}

/// Longest time over which a predicted SV time follows the rate's rate, s.
const RATE_RATE_HORIZON_S: f64 = 5.0;

/// Gains of the alpha-beta filter of the SV time rate over the reports (Benedict-Bordner:
/// `beta = alpha^2 / (2 - alpha)`): the rate averages about 50 reports against the PLL's
/// jitter and, with its rate, follows a Doppler ramp without lag.
const RATE_ALPHA: f64 = 0.02;
const RATE_BETA: f64 = RATE_ALPHA * RATE_ALPHA / (2.0 - RATE_ALPHA);

/// The satellites' SV times and the gap being recovered from: the one place that keeps them
/// (navigation asks and tells it, never edits its state).
#[derive(Debug, Default)]
pub struct SvTimeKeeper {
    /// Per PRN: its SV time, kept over a loss of the signal.
    clocks: BTreeMap<u8, SvClock>,
    /// A gap being recovered from.
    gap: Option<GapRecovery>,
    /// Carried SV times refused at the new bit edge: `(stream time s, PRN, offset ms)`.
    refused: Vec<(f64, u8, f64)>,
    /// Per PRN: the clock as it was, every [`SNAPSHOT_S`] over the last [`SNAPSHOTS`] of them
    /// (to go back to before lost samples found late, [`SvTimeKeeper::rewind`]).
    history: BTreeMap<u8, std::collections::VecDeque<SvClock>>,
}

/// Seconds between two kept snapshots of a satellite's clock.
const SNAPSHOT_S: f64 = 0.01;
/// Snapshots kept (0.3 s: a gap is found within a tenth of a second or two).
const SNAPSHOTS: usize = 30;

impl SvTimeKeeper {
    /// The gap being recovered from, if any.
    pub fn gap(&self) -> Option<&GapRecovery> {
        self.gap.as_ref()
    }

    /// Samples were lost at stream time `t_s` (samples at `fs_hz`): every clock goes back to
    /// a little before it (its instant is known to a few milliseconds), and the gap is kept
    /// to be measured ([`GapRecovery::new`] with the clock of the last fix `before`, the
    /// carrier-phase `steps` and `code_from_s`); a gap whose length cannot be resolved makes
    /// every SV time rough.
    pub fn start_gap(
        &mut self,
        t_s: f64,
        fs_hz: f64,
        before: Option<(f64, f64, f64)>,
        steps: Vec<crate::pipeline::timing::carrier_step::PhaseStep>,
        code_from_s: Option<f64>,
    ) {
        self.rewind(((t_s - 0.003) * fs_hz).max(0.0) as u64);
        let gap = GapRecovery::new(t_s, before, steps, code_from_s);
        if gap.unresolved {
            self.make_rough(None);
        }
        self.gap = Some(gap);
    }

    /// A gap at `t_s` (with the clock of the last fix `before`) unless one is being recovered
    /// from already: its length will come from the clock bias of the next valid fix.
    pub fn ensure_gap(&mut self, t_s: f64, before: Option<(f64, f64, f64)>) {
        self.gap
            .get_or_insert_with(|| GapRecovery::new(t_s, before, Vec::new(), None));
    }

    /// The carrier-phase steps over a code jump, measured once the phase loops hold again,
    /// for the gap being recovered from.
    pub fn set_gap_steps(&mut self, steps: Vec<crate::pipeline::timing::carrier_step::PhaseStep>) {
        if let Some(gap) = self.gap.as_mut() {
            gap.steps = steps;
        }
    }

    /// A receiver clock step of `step_ms` made while a gap is recovered from (counted in
    /// its length from the clock bias, [`GapRecovery::length_from_bias_ms`]).
    pub fn note_clock_step(&mut self, step_ms: i64) {
        if let Some(gap) = self.gap.as_mut() {
            gap.stepped_ms += step_ms;
        }
    }

    /// The gap being recovered from, taken once the receiver time is re-established (a valid
    /// fix), if its length was not resolved on the way.
    pub fn take_unmeasured_gap(&mut self) -> Option<GapRecovery> {
        self.gap.take().filter(|g| g.length_ms.is_none())
    }

    /// A carried SV time of `prn` refused at `t_s`, `off_ms` off its new bit edge. When
    /// [`crate::pipeline::timing::discontinuity::MIN_SATELLITES`] satellites were refused
    /// within 2 s by the same offset (0.1 ms), samples were lost during the outage: returns how
    /// many agree and their `(PRN, offset ms, SV time rate)` (and forgets the refusals).
    pub fn note_refusal(&mut self, t_s: f64, prn: u8, off_ms: f64) -> Option<(usize, EdgeOffsets)> {
        self.refused.retain(|r| t_s - r.0 < 2.0 && r.1 != prn);
        self.refused.push((t_s, prn, off_ms));
        let agreeing = self
            .refused
            .iter()
            .filter(|r| (r.2 - off_ms).abs() < 0.1)
            .count();
        if agreeing < crate::pipeline::timing::discontinuity::MIN_SATELLITES {
            return None;
        }
        let offsets: Vec<(u8, f64, f64)> = self
            .refused
            .iter()
            .filter(|r| (r.2 - off_ms).abs() < 0.1)
            .filter_map(|r| self.clocks.get(&r.1).map(|c| (r.1, r.2, c.rate)))
            .collect();
        self.refused.clear();
        Some((agreeing, offsets))
    }

    /// The offsets `(PRN, offset ms, rate)` of refused carried times handed to the gap being
    /// recovered from at `t_s` ([`GapRecovery::add_edge_offset`]): its length, if that
    /// resolved it.
    pub fn add_edge_offsets(&mut self, offsets: EdgeOffsets, t_s: f64) -> Option<f64> {
        let mut resolved = None;
        if let Some(gap) = self.gap.as_mut() {
            for (p, o, r) in offsets {
                if gap.add_edge_offset(p, o, r, t_s) {
                    resolved = gap.length_ms;
                }
            }
        }
        resolved
    }

    /// Moves every kept SV time over a gap of `length_ms` of receiver time (once its length is
    /// known): each satellite's SV time ran `length r` meanwhile; they are exact again.
    pub fn move_over_gap(&mut self, length_ms: f64) {
        let g = length_ms * 1e-3;
        for c in self.clocks.values_mut() {
            c.sv_tow_s += g * c.rate + 0.5 * g * g * c.rate_rate;
            c.rate += g * c.rate_rate;
            c.rough = false;
        }
    }

    /// Every clock back to where it stood before sample `sample` (lost samples found after
    /// the fact: the reports since then may have read a shifted code, the loops following it).
    pub fn rewind(&mut self, sample: u64) {
        for (prn, snaps) in self.history.iter_mut() {
            while snaps.back().is_some_and(|c| c.sample >= sample) {
                snaps.pop_back();
            }
            match snaps.back() {
                Some(c) => {
                    self.clocks.insert(*prn, *c);
                }
                None => {
                    self.clocks.remove(prn);
                }
            }
        }
    }

    /// Where the SV time of `prn` stood at its last usable report, `(sample, TOW s)`, unless
    /// it is known only roughly.
    pub fn last_known(&self, prn: u8) -> Option<(u64, f64)> {
        self.clocks
            .get(&prn)
            .filter(|c| !c.rough)
            .map(|c| (c.sample, c.sv_tow_s))
    }

    /// Whether an SV time of `prn` was ever kept (roughly or not).
    pub fn ever_known(&self, prn: u8) -> bool {
        self.clocks.contains_key(&prn)
    }

    /// Marks the SV time of `prn` (all with `None`) as rough: samples may have been lost.
    pub fn make_rough(&mut self, prn: Option<u8>) {
        for (p, c) in self.clocks.iter_mut() {
            if prn.is_none_or(|q| q == *p) {
                c.rough = true;
            }
        }
    }

    /// Keeps the satellite's SV time from every usable report, and carries it over to a new
    /// channel of the same satellite after a loss ([`SvClock`]): at the new channel's first
    /// bit edge in phase lock, the predicted SV time is rounded to the 20 ms bit; a prediction
    /// more than 1 ms off a bit boundary (samples lost, or a wrong bit edge) is not used.
    /// Returns what the caller must report: a refused carried time, or the length of lost
    /// samples just resolved. `dec` is the satellite's decoder, `usable` whether the report is
    /// in phase lock with signal.
    pub fn observe(
        &mut self,
        e: &ChannelEpoch,
        dec: &mut NavDecoder,
        fs_hz: f64,
        usable: bool,
    ) -> Option<CarryNote> {
        if !usable {
            return None;
        }
        if let Some(sv) = dec.sv_tow_s(e.ms_count, e.code_phase_chips) {
            // The rate from the carrier (the code NCO's rate carries the DLL's corrections,
            // tenths of a chip per second, which would grow to a tenth of a microsecond over a
            // second), filtered with its rate.
            let measured = 1.0 + e.doppler_hz / F_L1_HZ;
            let (rate, rate_rate) = match self.clocks.get(&e.prn) {
                Some(c) if !c.rough && e.sample_index > c.sample => {
                    let dt = (e.sample_index - c.sample) as f64 / fs_hz;
                    let predicted = c.rate + c.rate_rate * dt;
                    let residual = measured - predicted;
                    (
                        predicted + RATE_ALPHA * residual,
                        c.rate_rate + RATE_BETA * residual / dt,
                    )
                }
                _ => (measured, 0.0),
            };
            let clock = SvClock {
                sample: e.sample_index,
                sv_tow_s: sv,
                rate,
                rate_rate,
                rough: false,
            };
            self.clocks.insert(e.prn, clock);
            let snaps = self.history.entry(e.prn).or_default();
            let due = snaps.back().is_none_or(|c| {
                (e.sample_index.saturating_sub(c.sample)) as f64 >= SNAPSHOT_S * fs_hz
            });
            if due {
                snaps.push_back(clock);
                if snaps.len() > SNAPSHOTS {
                    snaps.pop_front();
                }
            }
            return None;
        }
        let clock = self.clocks.get(&e.prn)?;
        let elapsed_s = (e.sample_index as f64 - clock.sample as f64) / fs_hz;
        let unresolved_gap = self.gap.as_ref().is_some_and(|g| g.unresolved);
        if clock.rough || unresolved_gap {
            // Known roughly (samples may have been lost): frame sync from the data bits placed
            // in the frames before, or from the first TLM and HOW whose time agrees with it.
            if elapsed_s <= SV_CLOCK_HINT_S {
                let sv = clock.at(e.sample_index, fs_hz)
                    - e.code_phase_chips / gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
                if e.bit_edge && (e.ms_count / 20).is_multiple_of(5) {
                    let tol = SV_CLOCK_HINT_TOLERANCE_S;
                    if let Some(tow) = dec.sv_time_from_frames(e.ms_count, sv - tol, sv + tol) {
                        tracing::info!(
                            "G{:02}: SV time read from its data bits (matched in the frames before): {:+.1} ms from the time kept",
                            e.prn,
                            (tow - sv) * 1e3
                        );
                        dec.sync_from_frames(e.ms_count, tow);
                        return None;
                    }
                }
                if !dec.has_hint() {
                    dec.hint_time(e.ms_count, sv, SV_CLOCK_HINT_TOLERANCE_S);
                }
            }
            return None;
        }
        if !e.bit_edge || !(0.0..=SV_CLOCK_CARRY_S).contains(&elapsed_s) {
            return None;
        }
        // SV time at the start of the code period that opens this interval (a bit edge).
        let mut edge_ms = (clock.at(e.sample_index, fs_hz)
            - e.code_phase_chips / gpsrx_dsp::constants::CA_CHIP_RATE_HZ)
            * 1e3;
        let mut note = None;
        match self.gap.as_mut() {
            Some(gap) if !gap.unresolved && gap.length_ms.is_none() => {
                // Across lost samples: first their length, from the offsets of the kept time
                // from the new bit edges and the carrier-phase steps.
                let off = nearest_remainder(edge_ms, 20.0);
                // The data bits since the new bit sync, placed in the frames before: the SV
                // time ran g r over the gap.
                let by_bits = dec
                    .sv_time_from_frames(
                        e.ms_count,
                        (edge_ms - 1.0) * 1e-3,
                        (edge_ms + BITS_GAP_MAX_MS) * 1e-3,
                    )
                    .is_some_and(|sv_s| {
                        gap.note_bit_length(e.prn, (sv_s * 1e3 - edge_ms) / clock.rate)
                    });
                if by_bits || gap.add_edge_offset(e.prn, off, clock.rate, e.t_rx_s) {
                    let length_ms = gap.length_ms.unwrap_or(0.0);
                    note = Some(CarryNote::GapResolved {
                        t_s: gap.t_s,
                        length_ms,
                        from_bits: by_bits,
                    });
                    self.move_over_gap(length_ms);
                    edge_ms += length_ms;
                } else if gap.unresolved {
                    tracing::warn!(
                        "the length of the samples lost at {:.3} s cannot be resolved from the carrier-phase steps, the code or the data bits yet: waiting for frame sync",
                        gap.t_s
                    );
                    self.make_rough(None);
                }
                note?;
            }
            Some(gap) if gap.length_ms.is_none() => return None,
            _ => {}
        }
        let off_ms = nearest_remainder(edge_ms, 20.0);
        let bit_ms = edge_ms - off_ms;
        if off_ms.abs() > 1.0 {
            tracing::info!(
                "G{:02}: the SV time carried over {elapsed_s:.1} s falls {off_ms:+.3} ms off the new bit edge (samples lost?): waiting for frame sync",
                e.prn
            );
            self.make_rough(Some(e.prn));
            return self.gap.is_none().then_some(CarryNote::Refused(off_ms));
        }
        dec.carry_time(e.ms_count, bit_ms * 1e-3);
        tracing::info!(
            "G{:02}: SV time carried over {elapsed_s:.1} s (bit edge {off_ms:+.3} ms from the prediction)",
            e.prn
        );
        note
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusals_by_one_offset_on_three_satellites_within_two_seconds_are_a_gap() {
        let mut k = SvTimeKeeper::default();
        // Two satellites refused by about -9 ms, one by another offset: not yet.
        assert!(k.note_refusal(10.0, 3, -9.00,).is_none());
        assert!(k.note_refusal(10.5, 16, -9.05).is_none());
        assert!(k.note_refusal(10.6, 22, -4.00).is_none());
        // A third agreeing within 0.1 ms and 2 s: samples lost (no clocks kept: no offsets).
        let (agreeing, offsets) = k.note_refusal(11.0, 25, -8.99).expect("a gap");
        assert_eq!(agreeing, 3);
        assert!(offsets.is_empty());
        // The refusals are forgotten once reported.
        assert!(k.note_refusal(11.1, 26, -9.0).is_none());
        // Refusals older than 2 s do not count.
        assert!(k.note_refusal(14.0, 29, -9.0).is_none());
        assert!(k.note_refusal(14.5, 31, -9.0).is_none());
        assert!(k.note_refusal(16.6, 32, -9.0).is_none());
    }

    #[test]
    fn clock_steps_while_recovering_count_in_the_length_from_the_clock_bias() {
        let mut k = SvTimeKeeper::default();
        // Last fix at 5 s: bias 300 m, drift 3 m/s.
        k.start_gap(10.0, 2.6e6, Some((5.0, 300.0, 3.0)), Vec::new(), None);
        let gap = k.gap().expect("a gap");
        assert!(
            gap.unresolved,
            "no steps, no code: the length comes from the clock bias"
        );
        // The receiver time is 31 ms late after the gap: the bias drops by c 31 ms from its
        // prediction b0 + d (t - t0).
        let c = SPEED_OF_LIGHT_MPS;
        let bias = 300.0 + 3.0 * (12.0 - 5.0) - 0.031 * c;
        let length = gap.length_from_bias_ms(12.0, bias).expect("a length");
        assert!((length - 31.0).abs() < 1e-6, "{length}");
        // A 31 ms clock step made meanwhile moves the bias back by as much: still 31 ms.
        k.note_clock_step(31);
        let gap = k.take_unmeasured_gap().expect("unmeasured");
        let length = gap
            .length_from_bias_ms(12.0, bias + 0.031 * c)
            .expect("a length");
        assert!((length - 31.0).abs() < 1e-6, "{length}");
        assert!(k.gap().is_none());
    }
}
