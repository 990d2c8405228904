//! Navigation-bit synchronisation by a histogram of sign changes, then bit decisions.
//!
//! A C/A data bit lasts 20 code periods and its edges coincide with code-period starts, so with
//! 1 ms prompts an edge can sit at one of 20 positions. Each time consecutive prompts disagree in
//! sign (`Re(P_k P_{k-1}*) < 0`, which needs frequency lock only, not phase lock), the bin `k mod
//! 20` is incremented (Kaplan Sec. 5.12, histogram method).
//!
//! # Confidence test
//!
//! Per 20 ms, the true edge bin sees a change with probability `p1 = 1/2` (random data), any other
//! bin with `q`, the probability that noise flips the comparison. For the differential comparison
//! `q = exp(-C/N0 T)/2` (DPSK error rate with `Eb/N0 = C/N0 T`). After `n` bit periods with counts
//! `c_i`, `c_j` the log-likelihood ratio of "edge at i" against "edge at j" is
//! `(c_i - c_j) ln((1 - q)/q)` for `p1 = 1/2`. Requiring it to exceed `ln(19 / P_false)` against
//! the runner-up bin gives the lead needed:
//!
//! `lead >= ln(19 / P_false) / ln((1 - q)/q)`
//!
//! e.g. 4 at 35 dB-Hz and 9 at 30 dB-Hz for `P_false = 1e-4` ([`BitSyncConfig::for_cn0`]). A floor on
//! the best bin's count (`min_transitions`) guards against a model that is too optimistic (cycle
//! slips, non-random data). Each transition takes 40 ms on average (random data), so the time to
//! synchronise is about `40 ms * min_transitions` at high C/N0.
//!
//! # Bits
//!
//! Once synchronised, every 20 prompts starting at an edge are summed; the bit is the sign of the
//! real part of the sum (phase-locked, Costas: polarity still ambiguous until the preamble), and
//! its receive time is the `t_s` given with the first prompt of the bit.

use num_complex::Complex64;

/// Code periods per navigation bit.
pub const MS_PER_BIT: usize = 20;

/// Bit-synchroniser settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BitSyncConfig {
    /// Minimum number of sign changes in the winning bin.
    pub min_transitions: u32,
    /// Minimum lead of the winning bin over the runner-up.
    pub min_lead: u32,
    /// Give up after this many prompts without synchronisation.
    pub max_prompts: u32,
}

impl Default for BitSyncConfig {
    /// Sized for 30 dB-Hz at a false-synchronisation probability of 1e-4, giving up after 10 s.
    fn default() -> Self {
        Self::for_cn0(30.0, 1e-4)
    }
}

impl BitSyncConfig {
    /// Settings for a weakest expected C/N0 (dB-Hz) and a false-synchronisation probability
    /// (module docs): `min_lead = ceil(ln(19/P)/ln((1-q)/q))`, `q = exp(-C/N0 T)/2`,
    /// `T` = 1 ms; at least 2 and at most 200. `min_transitions = max(min_lead, 8)`.
    pub fn for_cn0(cn0_dbhz: f64, p_false: f64) -> Self {
        let cn0 = 10f64.powf(cn0_dbhz / 10.0);
        let q = (0.5 * (-cn0 * 1e-3).exp()).clamp(1e-300, 0.49);
        let p = if p_false.is_finite() && p_false > 0.0 && p_false < 1.0 {
            p_false
        } else {
            1e-4
        };
        let lead = ((19.0 / p).ln() / ((1.0 - q) / q).ln()).ceil();
        let min_lead = if lead.is_finite() {
            lead.clamp(2.0, 200.0) as u32
        } else {
            200
        };
        Self {
            min_transitions: min_lead.max(8),
            min_lead,
            max_prompts: 10_000,
        }
    }
}

/// State of the synchroniser.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BitSyncState {
    /// Collecting sign changes.
    Searching,
    /// Bit edges are at prompts with index `k mod 20 == edge`.
    Synced {
        /// Edge position, 0-19, counted from the first prompt pushed.
        edge: usize,
    },
    /// No decision within `max_prompts`; reset and try again (or the signal is too weak).
    Failed,
}

/// One navigation bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bit {
    /// +1 or -1 (sign of the real part of the sum; Costas polarity ambiguity remains).
    pub value: i8,
    /// The coherent sum of the 20 prompts.
    pub sum: Complex64,
    /// Receive time of the bit's leading edge (the `t_s` of its first prompt), s.
    pub t_s: f64,
}

/// Histogram bit synchroniser and bit stream.
#[derive(Debug, Clone)]
pub struct BitSync {
    cfg: BitSyncConfig,
    hist: [u32; MS_PER_BIT],
    k: u64,
    prev: Option<Complex64>,
    state: BitSyncState,
    acc: Complex64,
    acc_n: usize,
    acc_t_s: f64,
}

impl BitSync {
    /// A synchroniser with the given settings.
    pub fn new(cfg: BitSyncConfig) -> Self {
        Self {
            cfg,
            hist: [0; MS_PER_BIT],
            k: 0,
            prev: None,
            state: BitSyncState::Searching,
            acc: Complex64::new(0.0, 0.0),
            acc_n: 0,
            acc_t_s: 0.0,
        }
    }

    /// Feeds the 1 ms prompt of one code period that started at receive time `t_s`; prompts must
    /// come for consecutive code periods (after a gap, call [`Self::reset`]). Returns a bit when
    /// one is complete.
    pub fn push(&mut self, prompt: Complex64, t_s: f64) -> Option<Bit> {
        let p = if prompt.re.is_finite() && prompt.im.is_finite() {
            prompt
        } else {
            Complex64::new(0.0, 0.0)
        };
        let pos = (self.k % MS_PER_BIT as u64) as usize;
        self.k += 1;
        match self.state {
            BitSyncState::Searching => {
                if let Some(prev) = self.prev {
                    if (p * prev.conj()).re < 0.0 {
                        self.hist[pos] += 1;
                    }
                }
                self.prev = Some(p);
                if let Some(edge) = self.decide() {
                    self.state = BitSyncState::Synced { edge };
                } else if self.k >= u64::from(self.cfg.max_prompts) {
                    self.state = BitSyncState::Failed;
                }
                None
            }
            BitSyncState::Synced { edge } => {
                if pos == edge {
                    self.acc = Complex64::new(0.0, 0.0);
                    self.acc_n = 0;
                    self.acc_t_s = t_s;
                }
                self.acc += p;
                self.acc_n += 1;
                if self.acc_n == MS_PER_BIT && (pos + 1) % MS_PER_BIT == edge {
                    self.acc_n = 0;
                    Some(Bit {
                        value: if self.acc.re < 0.0 { -1 } else { 1 },
                        sum: self.acc,
                        t_s: self.acc_t_s,
                    })
                } else {
                    None
                }
            }
            BitSyncState::Failed => None,
        }
    }

    fn decide(&self) -> Option<usize> {
        let (mut best, mut second) = (0usize, None::<usize>);
        for i in 1..MS_PER_BIT {
            if self.hist[i] > self.hist[best] {
                second = Some(best);
                best = i;
            } else if second.is_none_or(|s| self.hist[i] > self.hist[s]) {
                second = Some(i);
            }
        }
        let c_best = self.hist[best];
        let c_second = second.map_or(0, |s| self.hist[s]);
        (c_best >= self.cfg.min_transitions && c_best - c_second >= self.cfg.min_lead)
            .then_some(best)
    }

    /// The state.
    pub fn state(&self) -> BitSyncState {
        self.state
    }

    /// The sign-change histogram (bin = edge position counted from the first prompt).
    pub fn histogram(&self) -> &[u32; MS_PER_BIT] {
        &self.hist
    }

    /// Prompts pushed since the last reset.
    pub fn prompts(&self) -> u64 {
        self.k
    }

    /// Takes the data-bit edges from outside while still searching: a bit starts at every
    /// prompt whose position (counted from the first prompt since the last reset) is `edge`
    /// modulo 20, as if the histogram had decided on it. The first bit is reported from the
    /// next edge on. Ignored once synchronised or failed.
    pub fn assume_edge(&mut self, edge: usize) {
        if self.state == BitSyncState::Searching {
            self.state = BitSyncState::Synced {
                edge: edge % MS_PER_BIT,
            };
            self.acc = Complex64::new(0.0, 0.0);
            self.acc_n = 0;
        }
    }

    /// Starts over.
    pub fn reset(&mut self) {
        *self = Self::new(self.cfg);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lead_formula() {
        assert_eq!(BitSyncConfig::for_cn0(35.0, 1e-4).min_lead, 4);
        assert_eq!(BitSyncConfig::for_cn0(30.0, 1e-4).min_lead, 9);
        assert_eq!(BitSyncConfig::for_cn0(50.0, 1e-4).min_lead, 2);
    }

    #[test]
    fn noise_free_sync_and_bits() {
        let bits: Vec<f64> = (0..60)
            .map(|i| if (i * 7 + i / 3) % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let offset = 13; // first edge at prompt 13 -> bin 13
        let mut bs = BitSync::new(BitSyncConfig {
            min_transitions: 5,
            min_lead: 3,
            max_prompts: 5000,
        });
        let mut out = Vec::new();
        for k in 0..1100usize {
            let b = if k < offset {
                -bits[0]
            } else {
                bits[(k - offset) / 20 + 1]
            };
            if let Some(bit) = bs.push(Complex64::new(b, 0.0), k as f64 * 1e-3) {
                out.push(bit);
            }
        }
        assert_eq!(bs.state(), BitSyncState::Synced { edge: 13 });
        assert!(!out.is_empty());
        for bit in &out {
            let k0 = (bit.t_s * 1e3).round() as usize;
            assert_eq!((k0 + 20 - offset) % 20, 0);
            assert_eq!(f64::from(bit.value), bits[(k0 - offset) / 20 + 1]);
        }
    }
}
