//! Detection of lost samples from the data-bit edges moving together on every satellite.
//!
//! Lost samples of length `g` leave each channel's code aligned (whole code periods) and its
//! millisecond count running on, but the navigation data bits now change sign `-g` modulo
//! 20 ms away from the bit edges the channel synchronised to: the same offset, in whole
//! milliseconds, on every satellite. The carrier-phase jump ([`super::discontinuity`]) is a
//! fraction of a cycle that depends on each Doppler: for some lengths and Dopplers it is too
//! small to see on enough satellites (31 ms lost at 2.6 MHz with five 1 ms channels showed a
//! clear step on two). The bit edges do not depend on the Doppler.
//!
//! A sign change of the prompt between consecutive 1 ms reports, `Re(P_k P*_(k-1)) < 0`
//! (differential, so independent of the residual carrier phase), is a *flip* at the report's
//! offset from the channel's bit edge. A flip followed by another 1 ms later is one report's
//! sign error, not data (bits last 20 ms), and is left out. Without lost samples the data
//! flip at offset 0 with probability about 1/2 per bit and noise flips any offset with a
//! probability below `p = 2 q (1 - q)`, `q = Q(sqrt(2 C/N0 T))` (BPSK at the 1 ms prompt SNR;
//! what is left after the pairs are removed needs two wrong signs in a row, about `q^2`),
//! taken as at least [`MIN_FLIP_PROB`]. With the edges
//! moved to offset `o`, the data flip at `o` and only noise at 0. Per channel-bit, a flip at
//! `o` and none at 0 has the log-likelihood ratio `w = ln((1 - p) / p)` for "moved" and the
//! opposite `-w` against it; both or neither carry none. Summed over every channel from the
//! first flip at `o` on, `L = sum w (flips at o) - sum w (flips at 0)`; a move is declared when
//! `L >= ` [`MIN_LLR`] with flips at `o` on at least [`MIN_CHANNELS`] channels. One channel
//! with a wrong bit sync cannot pass: the others keep flipping at their offset 0.

use gpsrx_tracking::{ChannelEpoch, ChannelState};
use num_complex::Complex64;
use std::collections::{BTreeMap, VecDeque};

/// Weakest C/N0 watched, dB-Hz (1 ms sign errors of a few per cent; the prompt power of the
/// signal three times that of noise, so that a collapse shows).
pub const MIN_CN0_DBHZ: f64 = 33.0;
/// Least noise flip probability assumed per report (so that no three flips suffice).
pub const MIN_FLIP_PROB: f64 = 0.005;
/// Log-likelihood ratio that declares the bit edges moved (four clean flips at 40 dB-Hz:
/// `4 ln(199) = 21`; three are 15.9).
pub const MIN_LLR: f64 = 18.0;
/// Channels that must flip at the new offset.
pub const MIN_CHANNELS: usize = 3;
/// Flips kept per channel, ms of signal.
pub const HISTORY_MS: u64 = 1000;
/// Reports that set the signal's level before flips count.
pub const SETTLE_REPORTS: u32 = 50;
/// Gains of the slow (signal level) and fast (latest reports) averages of the prompt power.
const REF_GAIN: f64 = 0.02;
const RECENT_GAIN: f64 = 0.05;
/// The signal's level follows the prompt power only while the latest reports are above this
/// fraction of it (noise after a collapse never becomes the level).
const REF_FOLLOW_RATIO: f64 = 0.7;
/// The prompt power has collapsed below this fraction of the signal's level: no flips count.
pub const FADE_RATIO: f64 = 0.5;
/// Milliseconds of a data bit.
const BIT_MS: u64 = 20;

/// The bit edges of several channels found moved by the same whole number of milliseconds.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeMove {
    /// The new edges' offset from the old ones, ms in 1..20: the lost time is `20 k - offset`
    /// ms (`k >= 1`).
    pub offset_ms: u64,
    /// A sample before the move: the last flip at an old edge before the first at the new
    /// offset (or a bit before that first flip when there is none).
    pub before_sample: u64,
    /// A sample after the move: the first flip at the new offset.
    pub after_sample: u64,
    /// Satellites whose data flipped at the new offset.
    pub prns: Vec<u8>,
    /// Satellites watched.
    pub watched: usize,
    /// The log-likelihood ratio of the move.
    pub llr: f64,
}

/// One sign change of a channel's prompt.
#[derive(Debug, Clone, Copy)]
struct Flip {
    ms: u64,
    sample: u64,
    offset_ms: u64,
    weight: f64,
}

#[derive(Debug, Default)]
struct EdgeWatch {
    /// `ms_count` and prompt of the previous report.
    last: Option<(u64, Complex64)>,
    /// `ms_count` of the latest bit edge.
    edge_ms: Option<u64>,
    /// The latest flip, kept until the next report shows it was not one report's sign error.
    pending: Option<Flip>,
    /// Prompt power: the signal's level (slow average, never lowered by a collapse) and the
    /// latest reports' (fast average); reports since the watch began.
    ref_power: f64,
    recent_power: f64,
    reports: u32,
    flips: VecDeque<Flip>,
}

/// Watches every channel's data-bit flips for a common move of the bit edges.
#[derive(Debug, Default)]
pub struct BitEdgeMonitor {
    watches: BTreeMap<u8, EdgeWatch>,
}

/// `Q(x)`, the standard normal tail, from `erfc` (Abramowitz and Stegun 7.1.26, |error| <
/// 1.5e-7).
fn q_function(x: f64) -> f64 {
    let z = x / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z.abs());
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erfc = poly * (-z * z).exp();
    0.5 * if z >= 0.0 { erfc } else { 2.0 - erfc }
}

/// Probability that noise flips the sign between two 1 ms reports at `cn0_dbhz`.
pub fn noise_flip_prob(cn0_dbhz: f64, t_coh_s: f64) -> f64 {
    let q = q_function((2.0 * 10f64.powf(cn0_dbhz / 10.0) * t_coh_s).sqrt());
    (2.0 * q * (1.0 - q)).max(MIN_FLIP_PROB)
}

impl BitEdgeMonitor {
    /// An empty monitor.
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes one channel report.
    pub fn push(&mut self, e: &ChannelEpoch) {
        let w = self.watches.entry(e.prn).or_default();
        let watched = e.state == ChannelState::Track
            && e.code_lock
            && (e.t_coh_s - 1e-3).abs() < 1e-4
            && e.cn0_dbhz >= MIN_CN0_DBHZ
            && e.prompt.norm_sqr() > 0.0;
        // A new channel of the same satellite counts its milliseconds from 0 again.
        let restarted = w.last.is_some_and(|(ms, _)| e.ms_count <= ms);
        if !watched || restarted {
            *w = EdgeWatch::default();
            if !watched {
                return;
            }
        }
        if e.bit_edge {
            w.edge_ms = Some(e.ms_count);
        }
        // Flips count only while the signal is there: after a collapse of the prompt power
        // (samples lost past the code, a blockage) the prompts are noise and flip anywhere.
        let power = e.prompt.norm_sqr();
        w.reports = w.reports.saturating_add(1);
        if w.reports == 1 {
            (w.ref_power, w.recent_power) = (power, power);
        }
        w.recent_power += RECENT_GAIN * (power - w.recent_power);
        let faded = w.recent_power < FADE_RATIO * w.ref_power;
        if w.recent_power >= REF_FOLLOW_RATIO * w.ref_power {
            let gain = if w.reports < SETTLE_REPORTS {
                1.0 / f64::from(w.reports)
            } else {
                REF_GAIN
            };
            w.ref_power += gain * (power - w.ref_power);
        }
        if faded || w.reports < SETTLE_REPORTS {
            // The flips since the power began to fall (the average takes tens of reports to
            // show it) were noise's: a collapsed channel supports no move.
            if faded {
                w.flips.clear();
            }
            w.pending = None;
            w.last = Some((e.ms_count, e.prompt));
            return;
        }
        let consecutive = matches!(w.last, Some((ms, _)) if ms + 1 == e.ms_count);
        if !consecutive {
            w.pending = None;
        }
        let since_edge = w.edge_ms.and_then(|edge| e.ms_count.checked_sub(edge));
        if let (true, Some((_, prev)), Some(since_edge)) = (consecutive, w.last, since_edge) {
            if (e.prompt * prev.conj()).re < 0.0 {
                let p = noise_flip_prob(e.cn0_dbhz, e.t_coh_s);
                let flip = Flip {
                    ms: e.ms_count,
                    sample: e.sample_index,
                    offset_ms: since_edge % BIT_MS,
                    weight: ((1.0 - p) / p).ln(),
                };
                match w.pending.take() {
                    // Flips 1 ms apart: one report's sign was wrong, no data changed.
                    Some(prev) if prev.ms + 1 == flip.ms => {}
                    Some(prev) => {
                        w.flips.push_back(prev);
                        w.pending = Some(flip);
                    }
                    None => w.pending = Some(flip),
                }
            } else if let Some(prev) = w.pending.take() {
                w.flips.push_back(prev);
            }
        }
        w.last = Some((e.ms_count, e.prompt));
        while w
            .flips
            .front()
            .is_some_and(|f| f.ms + HISTORY_MS < e.ms_count)
        {
            w.flips.pop_front();
        }
    }

    /// Forgets every channel's flips and bit edges (the channels were told to find their
    /// bit edges again, or a gap was found otherwise).
    pub fn reset(&mut self) {
        self.watches.clear();
    }

    /// The common move of the bit edges, if the flips so far show one (then the monitor is
    /// reset).
    pub fn evaluate(&mut self) -> Option<EdgeMove> {
        let mut best: Option<EdgeMove> = None;
        for offset in 1..BIT_MS {
            // Every flip at this offset may be the first after the move.
            for w in self.watches.values() {
                for first in w.flips.iter().filter(|f| f.offset_ms == offset) {
                    let m = self.score(offset, first.sample);
                    if m.llr >= MIN_LLR
                        && m.prns.len() >= MIN_CHANNELS
                        && best.as_ref().is_none_or(|b| m.llr > b.llr)
                    {
                        best = Some(m);
                    }
                }
            }
        }
        if best.is_some() {
            self.reset();
        }
        best
    }

    /// The move to `offset` from sample `from` on, scored over every channel.
    fn score(&self, offset: u64, from: u64) -> EdgeMove {
        let mut llr = 0.0;
        let mut prns = Vec::new();
        let mut before = None::<u64>;
        for (&prn, w) in &self.watches {
            let mut moved = false;
            for f in &w.flips {
                if f.sample < from {
                    if f.offset_ms == 0 {
                        before = Some(before.map_or(f.sample, |b| b.max(f.sample)));
                    }
                    continue;
                }
                if f.offset_ms == offset {
                    llr += f.weight;
                    moved = true;
                } else if f.offset_ms == 0 {
                    llr -= f.weight;
                }
            }
            if moved {
                prns.push(prn);
            }
        }
        // Without a flip at an old edge before, the move is within the bit before.
        let bit_samples = self.bit_samples();
        EdgeMove {
            offset_ms: offset,
            before_sample: before.unwrap_or(from.saturating_sub(bit_samples)),
            after_sample: from,
            prns,
            watched: self.watches.values().filter(|w| w.last.is_some()).count(),
            llr,
        }
    }

    /// Samples of a data bit, from the reports seen (0 before any).
    fn bit_samples(&self) -> u64 {
        self.watches
            .values()
            .flat_map(|w| w.flips.iter().zip(w.flips.iter().skip(1)))
            .find(|(a, b)| b.ms > a.ms)
            .map_or(0, |(a, b)| (b.sample - a.sample) / (b.ms - a.ms) * BIT_MS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::pipeline::test_support::Noise;

    /// Channels at `cn0` dB-Hz (one per entry), 1 ms reports at 2.048 MHz whose bits (random,
    /// per satellite) have edges at `ms % 20 == phase` of each; from `cut_ms` on, `lost_ms`
    /// of signal are missing (the data run on by that much), and `wrong_sync` channels
    /// believe an edge 7 ms off the true one; with `collapse` the signal is gone from the
    /// cut on (noise alone). Returns the first move found and when.
    fn run(
        cn0: &[f64],
        cut_ms: u64,
        lost_ms: u64,
        wrong_sync: &[usize],
        collapse: bool,
        seed: u64,
    ) -> Option<(u64, EdgeMove)> {
        let mut m = BitEdgeMonitor::new();
        let mut noise = Noise(seed);
        let bits: Vec<Vec<f64>> = (0..cn0.len())
            .map(|_| {
                (0..200)
                    .map(|_| if noise.uniform() < 0.5 { 1.0 } else { -1.0 })
                    .collect()
            })
            .collect();
        for k in 0..3000u64 {
            for (i, &c) in cn0.iter().enumerate() {
                let phase = (i as u64 * 3) % 20;
                let t = if k >= cut_ms { k + lost_ms } else { k };
                let bit = bits[i][((t + 20 - phase) / 20) as usize % 200];
                let on = !(collapse && k >= cut_ms);
                let amp = if on {
                    (2.0 * 10f64.powf(c / 10.0) * 1e-3).sqrt()
                } else {
                    0.0
                };
                let prompt = Complex64::new(amp * bit + noise.normal(), noise.normal());
                let mut e =
                    crate::pipeline::test_support::report(i as u8 + 1, k, prompt, 1000.0, 0.0, c);
                let believed = if wrong_sync.contains(&i) {
                    (phase + 7) % 20
                } else {
                    phase
                };
                e.bit_edge = k % 20 == believed;
                m.push(&e);
            }
            if k % 10 == 9 {
                if let Some(d) = m.evaluate() {
                    return Some((k, d));
                }
            }
        }
        None
    }

    #[test]
    fn flip_probability_follows_bpsk_theory() {
        // 40 dB-Hz at 1 ms: q = Q(sqrt(20)) = 3.9e-6, below the floor.
        assert_eq!(noise_flip_prob(40.0, 1e-3), MIN_FLIP_PROB);
        // 32 dB-Hz: q = Q(sqrt(3.17)) = Q(1.781) = 0.0375, p = 2 q (1 - q) = 0.0721.
        assert!((noise_flip_prob(32.0, 1e-3) - 0.0721).abs() < 5e-4);
        assert!((q_function(1.0) - 0.158_655).abs() < 1e-6);
    }

    #[test]
    fn a_31_ms_cut_moves_every_edge_by_9_ms_and_is_found_within_a_few_bits() {
        let cn0 = [35.0, 36.5, 41.0, 42.0, 43.0];
        for seed in 1..=20u64 {
            let (at, d) = run(&cn0, 1500, 31, &[], false, seed).expect("the move is found");
            // g = 31 ms: the data run 31 ms ahead, the edges come 11 ms earlier, i.e. at
            // offset 9 of the old bit.
            assert_eq!(d.offset_ms, 9, "seed {seed}: {d:?}");
            assert!(d.before_sample <= 1500 * 2048, "seed {seed}: {d:?}");
            assert!(d.after_sample >= 1500 * 2048, "seed {seed}: {d:?}");
            assert!(at < 1500 + 200, "seed {seed}: found {} ms late", at - 1500);
            assert!(d.prns.len() >= MIN_CHANNELS);
        }
    }

    #[test]
    fn noise_whole_bit_cuts_a_wrong_bit_sync_and_a_collapse_are_not_a_move() {
        let cn0 = [32.0, 33.0, 35.0, 41.0, 43.0];
        for seed in 1..=20u64 {
            assert_eq!(run(&cn0, 1500, 0, &[], false, seed), None, "seed {seed}");
            // 40 ms lost: the edges stay where they were.
            assert_eq!(run(&cn0, 1500, 40, &[], false, seed), None, "seed {seed}");
            // One channel synchronised 7 ms off from the start.
            assert_eq!(run(&cn0, 3000, 0, &[2], false, seed), None, "seed {seed}");
            // Every signal gone (the code moved away, a blockage): the prompts are noise.
            assert_eq!(run(&cn0, 1000, 0, &[], true, seed), None, "seed {seed}");
        }
    }
}
