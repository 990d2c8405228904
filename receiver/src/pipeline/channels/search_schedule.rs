//! Which satellites are searched, when, and how hard: the background acquisition scheduler.
//!
//! Every wanted PRN without a live channel is searched again and again, escalating the
//! integration while it is not found ([`LEVELS`]): the configured search (1 ms x 10 by default,
//! about 36 dB-Hz), then 10 ms x 13 (about 31 dB-Hz) and 10 ms x 50 (about 28 dB-Hz), in one
//! pass of blocks (see [`LEVELS`] for why not the engine's half-shifted bit-edge pass).
//! Satellites come first in this order:
//!
//! 1. lost in the last [`HOT_FOR_S`]: around their last Doppler (and, when predicted visible,
//!    around the predicted one too), at the level their C/N0 needs, every [`HOT_INTERVAL_S`]
//!    at the configured level and less often at the deeper ones ([`hot_interval_s`]), free of
//!    the budget;
//! 2. predicted visible ([`Visibility::Visible`]: from `--nav` or decoded ephemerides and a
//!    position), in their predicted Doppler window, never left more than [`PREDICTED_WAIT_S`];
//! 3. the others over the whole Doppler range, the least recently searched first; once the
//!    most sensitive search has failed, only the cheap one (level 0) every `UNKNOWN_WAIT_S`,
//!    and the escalation again after `DEEP_WAIT_S`. Satellites predicted below
//!    the horizon are not searched, and while a prediction is about to come
//!    ([`Visibility::Pending`]: ephemerides at hand, no fix yet) the most sensitive search
//!    waits for it (most of the 32 PRNs are below the horizon).
//!
//! **CPU budget.** Searches spend a budget of modelled CPU time ([`SearchBudget`]: a bucket
//! that refills by a fixed amount per second of *signal*, so a post-processing run stays as
//! fast as the budget says, and a real-time one never stalls its tracking for long). The cost
//! of a search is modelled from its size, `samples x Doppler bins x passes x`
//! [`COST_S_PER_SAMPLE_BIN`] (measured on the development machine), not timed, so that runs are
//! deterministic.
//!
//! **False alarms.** A PRN searched `k` times would collect `k` false-alarm chances; its `k`-th
//! search gets `pfa 6 / (pi^2 k^2)` (the sum over all `k` is `pfa`): searching longer never
//! makes a false satellite more likely than one search at `pfa`.

use gpsrx_dsp::acquisition::{AcqConfig, AcqResult, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;

/// Coherent integration (ms) and non-coherent blocks of the levels after the configured
/// search (level 0), searched in one pass of blocks from the first sample.
///
/// A 10 ms block holds a data-bit edge every other block; a bit change there cancels part of
/// it. The engine's bit-edge guard integrates a second pass of blocks shifted by 5 ms and keeps
/// the better (see `gpsrx_dsp::acquisition`): twice the inverse FFTs. More blocks in one pass
/// buy more for the same work. Simulated detection probability (random bits and edge phase,
/// blocks summed from 1 ms correlations, threshold for 1e-6 over 201 bins x 4000 lags per
/// pass, 1 dB of grid losses; 3000 trials): 10 ms x 10 in two passes 0.32 at 27 and 0.67 at
/// 28 dB-Hz, x 13 in one pass 0.49 and 0.81 (0.65 of the work); x 40 in two passes 0.75 at 24
/// and 0.975 at 25 dB-Hz, x 50 in one pass 0.84 and 0.984 (0.63 of the work; x 40 in one pass
/// 0.62 and 0.92).
pub const LEVELS: [(u32, u32); 2] = [(10, 13), (10, 50)];

/// Search lags per code period of the 10 ms x 13 level where a code period holds at least
/// `HALF_CHIP_FROM_SAMPLES_PER_MS` samples: half a chip between lags and +-1.024 MHz of the
/// spectrum kept (`AcqConfig::search_lags_per_ms`), with `HALF_CHIP_BLOCKS` times the blocks.
pub const HALF_CHIP_LAGS_PER_MS: usize = 2048;
/// Samples per code period from which the 10 ms x 13 level searches `HALF_CHIP_LAGS_PER_MS`
/// lags (3.072 MHz): its inverse FFTs, nearly all of its work, are then at least 1.5 times
/// shorter (4 MHz: 4096 -> 2048 points, 2.2 times less work per block), which more than pays
/// for the blocks added (0.61 of the work at 4 MHz, measured 0.6); below it (2.6 MHz:
/// 2688 -> 2048) the saving would not. The 10 ms x 50 level keeps its lags: 22 % more blocks
/// there would hold 3.5 MB more of block spectra at 4 MHz, and it sets the peak memory.
pub const HALF_CHIP_FROM_SAMPLES_PER_MS: f64 = 3072.0;
/// Blocks of a half-chip level per block of [`LEVELS`]: the 0.44 dB that half-chip lags and
/// the narrower band lose on average (`gpsrx_dsp::acquisition::AcqConfig::search_lags_per_ms`:
/// 90 % of the C/A power in +-1.024 MHz instead of 95 %, the peak up to a quarter chip from a
/// lag) is made up by `10^(2 x 0.044)` = 1.22 times the non-coherent blocks (the detection
/// statistic's SNR grows as the square root of the blocks): 10 ms x 16.
pub const HALF_CHIP_BLOCKS: f64 = 1.22;

/// The engine settings of background level `level` (1 or 2; 0 is `base` itself) at `fs_hz`:
/// `base` with the coherent integration and blocks of [`LEVELS`], in one pass (no bit-edge
/// pass); level 1 from `HALF_CHIP_FROM_SAMPLES_PER_MS` on at `HALF_CHIP_LAGS_PER_MS` lags
/// with `HALF_CHIP_BLOCKS` times the blocks (unless `base` asks for fewer lags still).
pub fn level_config(base: &AcqConfig, level: usize, fs_hz: f64) -> AcqConfig {
    match level.checked_sub(1).and_then(|i| LEVELS.get(i)) {
        Some(&(coherent_ms, noncoherent)) => {
            let half_chip = level == 1
                && fs_hz * 1e-3 >= HALF_CHIP_FROM_SAMPLES_PER_MS
                && base.search_lags_per_ms > HALF_CHIP_LAGS_PER_MS;
            let (lags, blocks) = if half_chip {
                let blocks = (f64::from(noncoherent) * HALF_CHIP_BLOCKS).round() as u32;
                (HALF_CHIP_LAGS_PER_MS, blocks)
            } else {
                (base.search_lags_per_ms, noncoherent)
            };
            AcqConfig {
                coherent_ms,
                noncoherent: blocks,
                bit_edge_offsets: Some(false),
                search_lags_per_ms: lags,
                ..base.clone()
            }
        }
        None => base.clone(),
    }
}
/// How long after a loss a satellite is searched in the narrow hot window, s.
pub const HOT_FOR_S: f64 = 60.0;
/// Seconds of signal between two hot searches of a satellite at the configured level (see
/// [`hot_interval_s`]).
pub const HOT_INTERVAL_S: f64 = 0.2;

/// Seconds of signal between two hot searches of a satellite at `level`: [`HOT_INTERVAL_S`]
/// at the configured level, 0.5 s at 10 ms x 13 and 1 s at 10 ms x 50. Hot searches are not
/// charged to the budget (re-acquiring a satellite just lost is worth more than any other
/// search: charged, a weak satellite lost in a manoeuvre waited for the 0.5 % refill, one
/// search in 10 s); at these intervals one lost satellite costs at most about 3 % (level 1)
/// and 5 % (level 2, its block spectra alone 35 ms at 2.6 MHz) of a core for [`HOT_FOR_S`].
pub fn hot_interval_s(level: usize) -> f64 {
    match level {
        0 => HOT_INTERVAL_S,
        1 => 0.5,
        _ => 1.0,
    }
}
/// Half width of the hot Doppler window: this much, Hz, plus [`HOT_DOPPLER_RATE_HZ_S`] per
/// second since the loss.
pub const HOT_DOPPLER_HZ: f64 = 250.0;
/// See [`HOT_DOPPLER_HZ`], Hz/s.
pub const HOT_DOPPLER_RATE_HZ_S: f64 = 25.0;
/// Longest wait between two searches of a satellite predicted visible, s.
pub const PREDICTED_WAIT_S: f64 = 2.0;
/// Wait between two cheap searches (level 0, about 36 dB-Hz) of a satellite nothing is
/// predicted of, once its most sensitive search failed, s: a satellite rising above the
/// horizon comes up at about 35-42 dB-Hz in open sky, and 32 of these searches cost about 1 %
/// of a full round.
pub const UNKNOWN_WAIT_S: f64 = 15.0;
/// Wait before a satellite nothing is predicted of is searched up to the most sensitive level
/// again, once that search failed, s. Between, it gets only the cheap search every
/// `UNKNOWN_WAIT_S`: at 4 MHz one most sensitive search of one PRN costs as much as about
/// 50 cheap ones, and most of the 32 PRNs are below the horizon.
pub const DEEP_WAIT_S: f64 = 300.0;
/// Wait of a satellite whose most sensitive search awaits a prediction
/// ([`Visibility::Pending`]), s.
pub const PENDING_WAIT_S: f64 = 1.0;
/// Seconds of signal between two scheduling decisions.
pub const TICK_S: f64 = 0.1;
/// Modelled CPU time of a search per sample, Doppler bin and pass, s, for 1 ms coherent
/// blocks, and divided by the coherent milliseconds for longer ones: the inverse FFTs, one per
/// block, bin and PRN. Fitted with [`COST_S_PER_SAMPLE_FFT`] to the process CPU time (every
/// thread of the pool) of batches of 1 and 8 PRNs over +-5 kHz at every level at 2.6 and
/// 4 MHz, on 8-bit noise held as ci8 (`cargo bench -p gpsrx-benches --bench search_cost`), on
/// the 2-core Intel Xeon (AVX-512) the project is measured on: within 17 % on all 12 (1 ms x 10
/// 2.1 ms per PRN at 4 MHz, 10 ms x 13 17 ms at 2.6 and 26 ms at 4 MHz at its full 4096 lags,
/// 10 ms x 50 65 ms and 100 ms). It was fitted to PRNs searched alone on the AMD EPYC of earlier sessions (1.9e-9),
/// which made a batch of 8 on the Xeon 1.2-1.3 times its model.
pub const COST_S_PER_SAMPLE_BIN: f64 = 2.5e-9;
/// Modelled CPU time of the block spectra of a search (the forward FFTs every search makes
/// whatever its targets, with the allocation of the spectra), s per sample and pass (10 ms x
/// 50: about 26 ms at 2.6 MHz, 40 ms at 4 MHz; see [`COST_S_PER_SAMPLE_BIN`]; 2.7e-8 on the
/// AMD).
pub const COST_S_PER_SAMPLE_FFT: f64 = 2.0e-8;
/// Largest modelled cost of one batch, s (a block waits for its search; 0.5 s under the
/// model fitted on the AMD, the same batches).
pub const MAX_BATCH_S: f64 = 0.65;
/// A charged batch waits until the budget can pay for this many of its level's due PRNs
/// (or all of them when fewer are due), so the block spectra every batch computes are
/// shared: the forward FFTs re-used across PRNs.
pub const MIN_BATCH_PRNS: usize = 4;

/// Capacity of the bucket, CPU s: a first round of searches at the start (every PRN up to
/// 10 ms x 13, most of them 10 ms x 50, at 2.6-4 MHz). It was 2 s with the two-pass levels,
/// whose searches cost 1/0.62 as much: the same round at the same sensitivity; then 1.25 s
/// under the cost model fitted on the AMD, which the Xeon's costs (the model now) make 1.6 s.
pub const BURST_S: f64 = 1.6;

/// Satellites tracked from which the first most sensitive search of a PRN nothing is
/// predicted of waits `DEEP_WAIT_S`, as its later ones do, instead of following its
/// 10 ms x 13 search at once (the cheap search goes on every `UNKNOWN_WAIT_S`).
///
/// That search (10 ms x 50) costs about four times the one before it (10 ms x 13, about
/// 31 dB-Hz), and a first round of it over the 20-odd PRNs that are not above the horizon is
/// most of a default run's CPU (a 60 s recording at 4 MHz with 12 satellites: 1.1 of the
/// 1.55 CPU s its searches were modelled to spend). With eight satellites tracked the
/// receiver fixes with margin for fault exclusion (which needs six) and a PDOP that a ninth
/// improves little; meanwhile the almanac the satellites send (a PRN per 30 s frame) and the
/// ephemerides predict which PRNs are up ([`Visibility`]): those are searched in their
/// predicted window at every level at once, the others not at all. The cost: a satellite at
/// 25-31 dB-Hz beside eight stronger ones, and not yet predicted, is found minutes later
/// instead of in the first second. A receiver tracking fewer (weak signals everywhere:
/// foliage, indoors), `--nav`, and satellites just lost are not affected.
pub const DEFER_DEEP_FROM_TRACKED: usize = 8;

/// The default refill, CPU s per second of signal: half a percent of a core. Once the first
/// round is done it pays for the cheap search of about 20 absent PRNs every
/// `UNKNOWN_WAIT_S` and their deep round every `DEEP_WAIT_S` (about 0.003 + 0.007 at
/// 4 MHz; the rounds come later than that when it runs short). It was 0.02, which spent 1.2 s
/// of CPU in a 60 s run on 10 ms x 50 searches of absent PRNs (half the searches' cost, a
/// third of the run's).
pub const DEFAULT_PER_SIGNAL_S: f64 = 0.005;

/// The CPU time searches may spend. Searches of a satellite lost in the last `HOT_FOR_S`
/// (re-acquisitions, see `hot_interval_s`) are not charged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchBudget {
    /// Refill per second of signal, CPU s (0.005: searching costs at most 0.5 % of a core
    /// after the first round).
    pub per_signal_s: f64,
    /// Capacity of the bucket, CPU s (spent at once at the start: a first full round).
    pub burst_s: f64,
    /// Satellites tracked from which the first most sensitive search of a PRN nothing is
    /// predicted of waits `DEEP_WAIT_S` ([`DEFER_DEEP_FROM_TRACKED`]; more than 32: never).
    pub defer_deep_from_tracked: usize,
}

impl SearchBudget {
    /// A budget of `per_signal_s` CPU s per second of signal, [`BURST_S`] of which may go at
    /// once (0: no background search, only the re-acquisition of satellites just lost).
    pub fn per_signal(per_signal_s: f64) -> Self {
        Self {
            per_signal_s,
            burst_s: if per_signal_s > 0.0 { BURST_S } else { 0.0 },
            defer_deep_from_tracked: DEFER_DEEP_FROM_TRACKED,
        }
    }
}

impl Default for SearchBudget {
    /// [`DEFAULT_PER_SIGNAL_S`] CPU s per second of signal, [`BURST_S`] at once.
    fn default() -> Self {
        Self::per_signal(DEFAULT_PER_SIGNAL_S)
    }
}

/// What is known of a satellite's visibility now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Visibility {
    /// Above the elevation mask, its Doppler within `doppler_hz +- half_width_hz`.
    Visible {
        /// Predicted Doppler, Hz (with the receiver clock drift when known).
        doppler_hz: f64,
        /// Uncertainty, Hz.
        half_width_hz: f64,
    },
    /// Below the horizon.
    Below,
    /// Not yet known, but soon (ephemerides are at hand; the receiver's position and time are
    /// not yet): the cheap searches go on, the most sensitive one waits for the prediction.
    Pending,
    /// Nothing known.
    Unknown,
}

/// A search the channel manager is to run: the level's engine, its samples and targets.
#[derive(Debug, Clone, PartialEq)]
pub struct Batch {
    /// Index of the engine (0: the configured search, then [`LEVELS`]).
    pub level: usize,
    /// First sample and number of samples searched.
    pub first: u64,
    /// Samples read.
    pub len: usize,
    /// The PRNs and their windows.
    pub targets: Vec<SearchTarget>,
    /// Per target: a hot search (a satellite just lost).
    pub hot: Vec<bool>,
}

/// Whether a satellite has a channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Liveness {
    /// A live channel tracks it.
    Live,
    /// Its last channel lost the signal at this sample index, holding this Doppler (Hz), with
    /// this C/N0 (dB-Hz) while it tracked.
    LostAt(u64, f64, f64),
    /// It never had a channel.
    Never,
}

#[derive(Debug, Clone, Copy, Default)]
struct PrnState {
    level: usize,
    searches: u32,
    /// Sample index before which it is not searched.
    not_before: u64,
    /// Sample index before which, unpredicted, it is not searched past level 0 again
    /// (`DEEP_WAIT_S`; 0: its first escalation is still to come).
    deep_not_before: u64,
}

/// A candidate for the next batch: priority (lower first), its level, target and cost.
struct Candidate {
    hot: bool,
    /// Not charged to the budget: a hot search (see [`hot_interval_s`]).
    free: bool,
    priority: (u8, u64),
    level: usize,
    target: SearchTarget,
    cost_s: f64,
}

/// The scheduler (see the module documentation).
#[derive(Debug, Clone)]
pub struct Scheduler {
    fs_hz: f64,
    budget: SearchBudget,
    tokens_s: f64,
    last_refill: u64,
    next_tick: u64,
    pfa: f64,
    wanted: Vec<Prn>,
    prns: [PrnState; 32],
}

impl Scheduler {
    /// A scheduler for samples at `fs_hz` searching `wanted` (all 32 if empty) with the
    /// false-alarm probability `pfa` per PRN over the whole run, starting at sample `start`.
    pub fn new(fs_hz: f64, budget: SearchBudget, pfa: f64, wanted: &[Prn], start: u64) -> Self {
        Self {
            fs_hz,
            budget,
            tokens_s: budget.burst_s,
            last_refill: start,
            next_tick: start,
            pfa,
            wanted: if wanted.is_empty() {
                Prn::all().collect()
            } else {
                wanted.to_vec()
            },
            prns: [PrnState::default(); 32],
        }
    }

    /// The modelled CPU time left, s.
    #[cfg(test)]
    pub fn tokens_s(&self) -> f64 {
        self.tokens_s
    }

    /// Counts the cold start's search of `searched` (made at [`search_pfa`]`(pfa, 1)`): their
    /// next search is their second.
    pub fn with_searched(mut self, searched: &[Prn]) -> Self {
        for p in searched {
            self.prns[p.index()].searches = self.prns[p.index()].searches.max(1);
        }
        self
    }

    /// The false-alarm probability of the next search of `prn`.
    fn pfa_of(&self, prn: Prn) -> f64 {
        search_pfa(self.pfa, self.prns[prn.index()].searches + 1)
    }

    /// The batch due at sample `now`, if any: `engines` are the levels' engines, `window` the
    /// samples held (`now - window` is the oldest), `live` whether a PRN has a channel,
    /// `visibility` what is predicted of it.
    pub fn due(
        &mut self,
        now: u64,
        window: u64,
        engines: &[AcquisitionEngine],
        live: &dyn Fn(Prn) -> Liveness,
        visibility: &dyn Fn(Prn) -> Visibility,
    ) -> Option<Batch> {
        let elapsed = now.saturating_sub(self.last_refill) as f64 / self.fs_hz;
        self.tokens_s =
            (self.tokens_s + elapsed * self.budget.per_signal_s).min(self.budget.burst_s);
        self.last_refill = now;
        if now < self.next_tick {
            return None;
        }
        self.next_tick = now + (TICK_S * self.fs_hz) as u64;
        let due: Vec<Prn> = self
            .wanted
            .iter()
            .copied()
            .filter(|&p| live(p) != Liveness::Live && now >= self.prns[p.index()].not_before)
            .collect();
        let mut candidates: Vec<Candidate> = due
            .into_iter()
            .filter_map(|p| self.candidate(p, now, engines, live(p), visibility(p)))
            .collect();
        candidates.sort_by_key(|c| c.priority);
        let (level, free, hot_first) = candidates.first().map(|c| (c.level, c.free, c.hot))?;
        let engine = engines.get(level)?;
        let len = engine.samples_wanted() as u64;
        if window < len {
            return None;
        }
        let mut spent = if free { 0.0 } else { fixed_cost_s(engine) };
        if !free && !hot_first {
            // Wait until the batch can hold a few PRNs: each batch pays for its block
            // spectra, which a batch of one at 10 ms x 50 spends 40 % of its cost on (a
            // satellite just lost does not wait).
            let least: f64 = candidates
                .iter()
                .filter(|c| c.level == level && !c.free)
                .take(MIN_BATCH_PRNS)
                .map(|c| c.cost_s)
                .sum();
            // (A full bucket is enough, however expensive the PRNs at a high rate.)
            if (spent + least).min(self.budget.burst_s) > self.tokens_s {
                return None;
            }
        }
        let mut targets = Vec::new();
        let mut hot = Vec::new();
        for c in candidates.into_iter().filter(|c| c.level == level) {
            if free {
                // A batch of re-acquisitions alone (they come first).
                if c.free {
                    hot.push(true);
                    targets.push(c.target.with_pfa(self.pfa_of(c.target.prn)));
                }
                continue;
            }
            if spent + c.cost_s > self.tokens_s.min(MAX_BATCH_S) && !targets.is_empty() {
                break;
            }
            if spent + c.cost_s > self.tokens_s {
                break;
            }
            spent += c.cost_s;
            hot.push(c.hot);
            targets.push(c.target.with_pfa(self.pfa_of(c.target.prn)));
        }
        if targets.is_empty() {
            return None;
        }
        self.tokens_s -= spent;
        Some(Batch {
            level,
            first: now - len,
            len: len as usize,
            targets,
            hot,
        })
    }

    /// The candidate search of `p` at sample `now`, or `None` when it is not to be searched
    /// (predicted below the horizon: looked at again in `UNKNOWN_WAIT_S`).
    fn candidate(
        &mut self,
        p: Prn,
        now: u64,
        engines: &[AcquisitionEngine],
        live: Liveness,
        vis: Visibility,
    ) -> Option<Candidate> {
        let s = self.prns[p.index()];
        let hot = match live {
            Liveness::LostAt(at, doppler, cn0) => {
                let since_s = now.saturating_sub(at) as f64 / self.fs_hz;
                (since_s < HOT_FOR_S).then(|| {
                    let w = HOT_DOPPLER_HZ + HOT_DOPPLER_RATE_HZ_S * since_s;
                    (doppler, w, level_for_cn0(cn0))
                })
            }
            _ => None,
        };
        let (rank, level, target) = match (hot, vis) {
            (
                Some((d, w, l)),
                Visibility::Visible {
                    doppler_hz,
                    half_width_hz,
                },
            ) => {
                // Where it was lost and where the last fix predicts it now: under dynamics
                // the Doppler a channel held when it let go is stale (a 10 g turn moves it by
                // 500 Hz/s) or the loop's own runaway.
                let (lo, hi) = (
                    (d - w).min(doppler_hz - half_width_hz),
                    (d + w).max(doppler_hz + half_width_hz),
                );
                (
                    0,
                    l,
                    SearchTarget::around(p, 0.5 * (lo + hi), 0.5 * (hi - lo)),
                )
            }
            (Some((d, w, l)), _) => (0, l, SearchTarget::around(p, d, w)),
            (None, Visibility::Below) => {
                self.prns[p.index()].not_before = now + (UNKNOWN_WAIT_S * self.fs_hz) as u64;
                return None;
            }
            (
                None,
                Visibility::Visible {
                    doppler_hz,
                    half_width_hz,
                },
            ) => (
                1,
                s.level,
                SearchTarget::around(p, doppler_hz, half_width_hz),
            ),
            (None, Visibility::Pending) if s.level >= LEVELS.len() => {
                self.prns[p.index()].not_before = now + (PENDING_WAIT_S * self.fs_hz) as u64;
                return None;
            }
            (None, Visibility::Pending | Visibility::Unknown) => {
                (2, s.level, SearchTarget::full(p))
            }
        };
        let level = level.min(engines.len().saturating_sub(1));
        let engine = engines.get(level)?;
        Some(Candidate {
            hot: rank == 0,
            free: rank == 0,
            priority: (rank, s.not_before),
            level,
            cost_s: cost_s(engine, &target),
            target,
        })
    }

    /// Takes the results of `batch`, searched at sample `now`, with `visibility` as in
    /// [`Scheduler::due`] and `tracked` satellites tracked (those found by the batch
    /// included): a PRN not found searches harder next time, or waits once the hardest search
    /// failed (or before its first one, see [`DEFER_DEEP_FROM_TRACKED`]).
    pub fn record(
        &mut self,
        batch: &Batch,
        results: &[AcqResult],
        now: u64,
        tracked: usize,
        visibility: &dyn Fn(Prn) -> Visibility,
    ) {
        let max_level = LEVELS.len();
        for (i, (t, r)) in batch.targets.iter().zip(results).enumerate() {
            let s = &mut self.prns[t.prn.index()];
            s.searches += 1;
            if r.detected {
                s.level = 0;
                continue;
            }
            let hot = batch.hot.get(i).copied().unwrap_or(false);
            let predicted = matches!(visibility(t.prn), Visibility::Visible { .. });
            if !hot
                && !predicted
                && batch.level + 1 == max_level
                && s.deep_not_before == 0
                && tracked >= self.budget.defer_deep_from_tracked
            {
                // Its first deepest search waits, as its later ones do.
                s.deep_not_before = now + (DEEP_WAIT_S * self.fs_hz) as u64;
            }
            let wait_s = if hot {
                hot_interval_s(batch.level)
            } else if batch.level < max_level && (predicted || now >= s.deep_not_before) {
                s.level = batch.level + 1;
                0.0
            } else if predicted {
                PREDICTED_WAIT_S
            } else {
                // Unpredicted: the cheap search now and then, the deep ones rarely.
                if batch.level == max_level {
                    s.deep_not_before = now + (DEEP_WAIT_S * self.fs_hz) as u64;
                }
                s.level = 0;
                UNKNOWN_WAIT_S
            };
            s.not_before = now + (wait_s * self.fs_hz) as u64;
        }
    }
}

/// The false-alarm probability of the `k`-th search (from 1) of a PRN when the whole run may
/// spend `pfa` on it: `pfa 6 / (pi^2 k^2)`, whose sum over all `k` is `pfa`.
pub fn search_pfa(pfa: f64, k: u32) -> f64 {
    let k = f64::from(k.max(1));
    pfa * 6.0 / (std::f64::consts::PI.powi(2) * k * k)
}

/// The least sensitive level that finds a satellite of `cn0_dbhz` (the C/N0 its channel
/// measured): 1 ms x 10 from 37 dB-Hz, 10 ms x 10 from 31 dB-Hz, else 10 ms x 40.
pub fn level_for_cn0(cn0_dbhz: f64) -> usize {
    if !cn0_dbhz.is_finite() || cn0_dbhz >= 37.0 {
        0
    } else if cn0_dbhz >= 31.0 {
        1
    } else {
        2
    }
}

/// The modelled CPU time every search with `engine` spends whatever its targets (the block
/// spectra), s.
pub fn fixed_cost_s(engine: &AcquisitionEngine) -> f64 {
    engine.samples_needed() as f64 * passes(engine) * COST_S_PER_SAMPLE_FFT
}

/// Passes of blocks a search with `engine` makes (2 with the bit-edge pass).
fn passes(engine: &AcquisitionEngine) -> f64 {
    if engine.config().uses_bit_edge_offsets() {
        2.0
    } else {
        1.0
    }
}

/// The modelled CPU time of searching `target` with `engine`, s (beside the fixed cost).
pub fn cost_s(engine: &AcquisitionEngine, target: &SearchTarget) -> f64 {
    let step = engine.doppler_step_hz();
    let (lo, hi) = engine.doppler_range_hz();
    let (a, b) = target.doppler_window_hz.unwrap_or((lo, hi));
    let bins = ((b.min(hi) - a.max(lo)) / step).max(0.0) + 1.0;
    let coherent_ms = engine.config().coherent_ms.max(1);
    // The spectrum bins each inverse FFT reads per code period: the samples of a period, or
    // fewer when the search keeps only the lowest frequencies, with an FFT's n log n per
    // point counted from the 4096 points the constant was fitted at (2048: 11/12).
    let per_ms = engine.fs_hz() * 1e-3;
    let lags = engine.search_lags() as f64;
    let kept = if lags < per_ms {
        lags / per_ms * lags.log2() / 12.0
    } else {
        1.0
    };
    engine.samples_needed() as f64 * kept * bins * passes(engine) * COST_S_PER_SAMPLE_BIN
        / f64::from(coherent_ms)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FS: f64 = 2.6e6;

    fn engines() -> Vec<AcquisitionEngine> {
        let base = AcqConfig::default();
        (0..=LEVELS.len())
            .map(|level| {
                AcquisitionEngine::new(FS, level_config(&base, level, FS)).expect("engine")
            })
            .collect()
    }

    fn result(prn: Prn, detected: bool) -> AcqResult {
        AcqResult {
            prn,
            detected,
            code_phase_samples: 0.0,
            code_phase_chips: 0.0,
            doppler_hz: 0.0,
            doppler_coarse_hz: 0.0,
            cn0_dbhz: None,
            metric: 1.0,
            threshold: 2.0,
            peak_ratio: 1.0,
            bit_offset_ms: 0,
            refine_ms: 0,
            cross_correlation_of: None,
        }
    }

    /// Runs the scheduler for `seconds` of signal with nothing ever found; returns per PRN
    /// the levels searched and the sample of each search.
    fn run(
        seconds: f64,
        vis: &dyn Fn(Prn) -> Visibility,
        budget: SearchBudget,
    ) -> Vec<Vec<(usize, u64)>> {
        run_for(seconds, vis, budget, &[])
    }

    /// [`run`] searching only `wanted` (all 32 if empty).
    fn run_for(
        seconds: f64,
        vis: &dyn Fn(Prn) -> Visibility,
        budget: SearchBudget,
        wanted: &[Prn],
    ) -> Vec<Vec<(usize, u64)>> {
        run_tracking(seconds, vis, budget, wanted, 0)
    }

    /// [`run_for`] with `tracked` satellites tracked (PRNs not wanted).
    fn run_tracking(
        seconds: f64,
        vis: &dyn Fn(Prn) -> Visibility,
        budget: SearchBudget,
        wanted: &[Prn],
        tracked: usize,
    ) -> Vec<Vec<(usize, u64)>> {
        let engines = engines();
        let mut s = Scheduler::new(FS, budget, 1e-3, wanted, 0);
        let mut log = vec![Vec::new(); 32];
        let block = (0.01 * FS) as u64;
        let mut now = block;
        while (now as f64) < seconds * FS {
            if let Some(b) = s.due(now, now, &engines, &|_| Liveness::Never, vis) {
                for t in &b.targets {
                    log[t.prn.index()].push((b.level, now));
                    assert!(t
                        .pfa
                        .is_some_and(|p| p <= 1e-3 * 6.0 / std::f64::consts::PI.powi(2) + 1e-12));
                }
                let results: Vec<AcqResult> =
                    b.targets.iter().map(|t| result(t.prn, false)).collect();
                s.record(&b, &results, now, tracked, vis);
            }
            now += block;
        }
        log
    }

    #[test]
    fn the_middle_level_searches_half_the_lags_with_more_blocks_from_3_mhz() {
        let base = AcqConfig::default();
        for (fs, lags, blocks) in [(2.6e6, 4096, 13), (4.0e6, 2048, 16), (16.368e6, 2048, 16)] {
            let c = level_config(&base, 1, fs);
            assert_eq!(
                (c.search_lags_per_ms, c.noncoherent),
                (lags, blocks),
                "{fs}"
            );
            // The deepest level keeps its lags and blocks everywhere.
            let deep = level_config(&base, 2, fs);
            assert_eq!((deep.search_lags_per_ms, deep.noncoherent), (4096, 50));
        }
        // Fewer lags asked for stay so.
        let few = AcqConfig {
            search_lags_per_ms: 1024,
            ..AcqConfig::default()
        };
        assert_eq!(level_config(&few, 1, 4e6).search_lags_per_ms, 1024);
        assert_eq!(level_config(&few, 1, 4e6).noncoherent, 13);
        // The model charges the inverse FFTs' length: 16 blocks of 2048 lags cost 0.58 of
        // 13 blocks of 4000 samples per period at 4 MHz (0.63 in points, 11/12 per point).
        let at = |c: AcqConfig| {
            let e = AcquisitionEngine::new(4e6, c).expect("engine");
            cost_s(&e, &SearchTarget::full(Prn::new(1).expect("prn")))
        };
        let native = AcqConfig {
            search_lags_per_ms: 4096,
            ..level_config(&base, 1, 2.6e6)
        };
        let ratio = at(level_config(&base, 1, 4e6)) / at(native);
        let want = 16.0 * 2048.0 / (13.0 * 4000.0) * 11.0 / 12.0;
        assert!((ratio - want).abs() < 1e-9, "{ratio} {want}");
    }

    #[test]
    fn beside_eight_tracked_satellites_the_first_deep_search_of_an_unknown_prn_waits() {
        // PRNs 9-12 nothing is known of, 13 predicted visible; 8 (then 7) satellites tracked.
        let wanted: Vec<Prn> = (9..=13).filter_map(|p| Prn::new(p).ok()).collect();
        let vis = |p: Prn| {
            if p.get() == 13 {
                Visibility::Visible {
                    doppler_hz: 1000.0,
                    half_width_hz: 300.0,
                }
            } else {
                Visibility::Unknown
            }
        };
        let seconds = 1.2 * DEEP_WAIT_S;
        let budget = SearchBudget::per_signal(1.0);
        let log = run_tracking(seconds, &vis, budget, &wanted, DEFER_DEEP_FROM_TRACKED);
        for (i, l) in log.iter().enumerate().skip(8).take(4) {
            let levels: Vec<usize> = l.iter().map(|x| x.0).collect();
            assert_eq!(&levels[..3], &[0, 1, 0], "PRN {}: {levels:?}", i + 1);
            // The cheap search every UNKNOWN_WAIT_S, the deep one once DEEP_WAIT_S is over.
            let first_deep = l.iter().find(|x| x.0 == 2).map(|x| x.1 as f64 / FS);
            let after_s = first_deep.expect("a deep search after the wait") - l[1].1 as f64 / FS;
            assert!(
                (DEEP_WAIT_S..DEEP_WAIT_S + UNKNOWN_WAIT_S + 1.0).contains(&after_s),
                "PRN {}: {after_s} s",
                i + 1
            );
            let cheap = l.iter().filter(|x| x.0 == 0).count() as f64;
            assert!(cheap + 2.0 >= DEEP_WAIT_S / UNKNOWN_WAIT_S, "PRN {}", i + 1);
        }
        // The predicted one goes on to the deep search at once.
        let predicted: Vec<usize> = log[12].iter().map(|x| x.0).collect();
        assert_eq!(&predicted[..3], &[0, 1, 2], "{predicted:?}");
        // One satellite fewer, or the deferral turned off (33): the round as before.
        let never = SearchBudget {
            defer_deep_from_tracked: 33,
            ..budget
        };
        for (budget, tracked) in [(budget, DEFER_DEEP_FROM_TRACKED - 1), (never, 12)] {
            let log = run_tracking(5.0, &vis, budget, &wanted, tracked);
            for l in log.iter().skip(8).take(5) {
                let levels: Vec<usize> = l.iter().map(|x| x.0).collect();
                assert_eq!(&levels[..3], &[0, 1, 2], "{levels:?}");
            }
        }
    }

    #[test]
    fn without_a_budget_only_satellites_just_lost_are_searched_again_free_of_charge() {
        let engines = engines();
        let mut s = Scheduler::new(FS, SearchBudget::per_signal(0.0), 1e-3, &[], 0);
        let block = (0.01 * FS) as u64;
        // G05 was lost at 0.5 s, tracked strong (45 dB-Hz); the others were never seen.
        let lost = (0.5 * FS) as u64;
        let live = |p: Prn| {
            if p.get() == 5 {
                Liveness::LostAt(lost, 1000.0, 45.0)
            } else {
                Liveness::Never
            }
        };
        let vis = |_: Prn| Visibility::Unknown;
        let mut searched = Vec::new();
        let mut now = lost + block;
        while (now as f64) < 5.5 * FS {
            if let Some(b) = s.due(now, now, &engines, &live, &vis) {
                searched.extend(b.targets.iter().map(|t| (b.level, t.prn.get(), now)));
                let results: Vec<AcqResult> =
                    b.targets.iter().map(|t| result(t.prn, false)).collect();
                s.record(&b, &results, now, 0, &vis);
            }
            now += block;
        }
        assert!(
            searched
                .iter()
                .all(|&(level, prn, _)| level == 0 && prn == 5),
            "{searched:?}"
        );
        // Every HOT_INTERVAL_S over the 5 s.
        let want = (5.0 / HOT_INTERVAL_S) as usize;
        assert!(searched.len() + 1 >= want, "{} searches", searched.len());
        assert_eq!(s.tokens_s(), 0.0);
    }

    #[test]
    fn unfound_satellites_are_searched_ever_harder_within_the_budget() {
        // Eight satellites tracked, the 24 other PRNs searched with nothing known of them.
        let wanted: Vec<Prn> = (9..=32).filter_map(|p| Prn::new(p).ok()).collect();
        let seconds = 120.0;
        let log = run_for(
            seconds,
            &|_| Visibility::Unknown,
            SearchBudget::default(),
            &wanted,
        );
        for (i, l) in log.iter().enumerate().skip(8) {
            let levels: Vec<usize> = l.iter().map(|x| x.0).collect();
            // Every PRN reaches the most sensitive search within two minutes, in order (the
            // burst pays for most of the round, the refill for the rest).
            assert!(levels.len() >= 3, "PRN {}: {levels:?}", i + 1);
            assert_eq!(&levels[..3], &[0, 1, 2], "PRN {}", i + 1);
            // Then only the cheap search, every UNKNOWN_WAIT_S, until DEEP_WAIT_S is over.
            let deep_at = l[2].1;
            for w in l[2..].windows(2) {
                assert_eq!(w[1].0, 0, "PRN {}: {levels:?}", i + 1);
                let gap_s = (w[1].1 - w[0].1) as f64 / FS;
                assert!(gap_s >= UNKNOWN_WAIT_S - 0.01, "PRN {}: {gap_s} s", i + 1);
            }
            assert!(((seconds * FS) as u64) < deep_at + (DEEP_WAIT_S * FS) as u64);
        }
        // The modelled CPU time spent stays within the budget: the burst + the refill.
        let engines = engines();
        let spent: f64 = log
            .iter()
            .enumerate()
            .flat_map(|(i, l)| {
                let prn = Prn::new(i as u8 + 1).expect("prn");
                l.iter().map(move |&(lvl, _)| (lvl, prn))
            })
            .map(|(lvl, prn)| cost_s(&engines[lvl], &SearchTarget::full(prn)))
            .sum();
        // Plus each batch's block spectra.
        let mut batches: Vec<(usize, u64)> = log.iter().flatten().copied().collect();
        batches.sort_unstable();
        batches.dedup();
        let fixed: f64 = batches
            .iter()
            .map(|&(lvl, _)| fixed_cost_s(&engines[lvl]))
            .sum();
        let spent = spent + fixed;
        let allowed = BURST_S + DEFAULT_PER_SIGNAL_S * seconds;
        assert!(spent <= allowed + 1e-9, "spent {spent} s of {allowed} s");
    }

    #[test]
    fn an_absent_satellite_is_searched_deep_again_only_after_the_deep_wait() {
        // Four PRNs nothing is known of, never found, over 1.5 DEEP_WAIT_S with a budget
        // that never runs short: per PRN the round 0, 1, 2, then level 0 alone every
        // UNKNOWN_WAIT_S, then the round again once DEEP_WAIT_S has passed since the first
        // deep search failed.
        let wanted: Vec<Prn> = (1..=4).filter_map(|p| Prn::new(p).ok()).collect();
        let seconds = 1.5 * DEEP_WAIT_S;
        let log = run_for(
            seconds,
            &|_| Visibility::Unknown,
            SearchBudget::per_signal(1.0),
            &wanted,
        );
        for (i, l) in log.iter().enumerate().take(4) {
            let levels: Vec<usize> = l.iter().map(|x| x.0).collect();
            let deep: Vec<u64> = l.iter().filter(|x| x.0 == 2).map(|x| x.1).collect();
            assert_eq!(deep.len(), 2, "PRN {}: {levels:?}", i + 1);
            let apart_s = (deep[1] - deep[0]) as f64 / FS;
            assert!(
                (DEEP_WAIT_S..DEEP_WAIT_S + UNKNOWN_WAIT_S + 1.0).contains(&apart_s),
                "PRN {}: deep searches {apart_s} s apart",
                i + 1
            );
            // Between them: cheap searches only, every UNKNOWN_WAIT_S.
            let between = l.iter().filter(|x| x.1 > deep[0] && x.1 < deep[1]);
            let cheap: Vec<usize> = between.map(|x| x.0).collect();
            let want = (DEEP_WAIT_S / UNKNOWN_WAIT_S) as usize;
            assert!(
                cheap.len() + 2 >= want && cheap.len() <= want + 2,
                "PRN {}: {cheap:?}",
                i + 1
            );
            assert_eq!(&cheap[cheap.len() - 2..], &[0, 1], "PRN {}", i + 1);
            assert!(cheap[..cheap.len() - 1].iter().all(|&x| x == 0));
        }
    }

    #[test]
    fn predicted_satellites_come_first_and_never_wait_long_and_hidden_ones_are_skipped() {
        let vis = |p: Prn| match p.get() {
            1..=4 => Visibility::Visible {
                doppler_hz: 1000.0,
                half_width_hz: 300.0,
            },
            5..=8 => Visibility::Unknown,
            _ => Visibility::Below,
        };
        let log = run(40.0, &vis, SearchBudget::default());
        for l in &log[8..] {
            assert!(
                l.is_empty(),
                "a satellite below the horizon was searched: {l:?}"
            );
        }
        for (i, l) in log[..4].iter().enumerate() {
            // First, as soon as the window holds a search (0.11 s).
            let first = l.first().map(|x| x.1 as f64 / FS);
            assert!(first.is_some_and(|t| t <= 0.15), "PRN {}: {first:?}", i + 1);
            let longest = l.windows(2).map(|w| w[1].1 - w[0].1).max().unwrap_or(0) as f64 / FS;
            assert!(
                longest <= PREDICTED_WAIT_S + 0.2,
                "PRN {}: waited {longest} s",
                i + 1
            );
        }
    }

    #[test]
    fn a_lost_satellite_is_searched_in_its_hot_window_every_fifth_of_a_second() {
        let engines = engines();
        let mut s = Scheduler::new(FS, SearchBudget::default(), 1e-3, &[], 0);
        let prn = Prn::new(7).expect("prn");
        let lost_at = (5.0 * FS) as u64;
        let mut times = Vec::new();
        let block = (0.01 * FS) as u64;
        let mut now = (5.0 * FS) as u64;
        while (now as f64) < 7.0 * FS {
            let live = |p: Prn| {
                if p == prn {
                    Liveness::LostAt(lost_at, -1234.0, 45.0)
                } else {
                    Liveness::Live
                }
            };
            if let Some(b) = s.due(now, now, &engines, &live, &|_| Visibility::Unknown) {
                let t = b.targets[0];
                assert_eq!(b.level, 0);
                let (lo, hi) = t.doppler_window_hz.expect("narrow");
                assert!(lo < -1234.0 && hi > -1234.0 && hi - lo < 700.0, "{lo} {hi}");
                times.push(now);
                let r = vec![result(prn, false)];
                s.record(&b, &r, now, 0, &|_| Visibility::Unknown);
            }
            now += block;
        }
        assert!(times.len() >= 9, "{} hot searches in 2 s", times.len());
    }

    /// A satellite lost in a turn whose last fix predicts it 900 Hz from where its channel let
    /// go: the hot window covers both, at the level of the C/N0 it was tracked at.
    #[test]
    fn a_lost_satellite_predicted_elsewhere_is_searched_where_it_was_and_where_it_is() {
        let engines = engines();
        let mut s = Scheduler::new(FS, SearchBudget::default(), 1e-3, &[], 0);
        let prn = Prn::new(7).expect("prn");
        let lost_at = (5.0 * FS) as u64;
        let now = lost_at + (0.2 * FS) as u64;
        let live = |p: Prn| {
            if p == prn {
                Liveness::LostAt(lost_at, -1234.0, 45.0)
            } else {
                Liveness::Live
            }
        };
        let vis = |_: Prn| Visibility::Visible {
            doppler_hz: -334.0,
            half_width_hz: 100.0,
        };
        let b = s
            .due(now, now, &engines, &live, &vis)
            .expect("a hot search");
        assert_eq!((b.level, b.hot.as_slice()), (0, &[true][..]));
        let (lo, hi) = b.targets[0].doppler_window_hz.expect("a window");
        assert!(lo < -1234.0 - 250.0 && hi >= -334.0 + 100.0, "{lo} {hi}");
        assert!(hi - lo < 1500.0, "not the whole range: {lo} {hi}");
    }

    /// A weak satellite just lost (tracked at 33 dB-Hz) is searched again at the level its
    /// C/N0 needs, free of the budget (none here), every half second: before, its searches
    /// were charged and a lost satellite waited for the refill.
    #[test]
    fn a_weak_satellite_just_lost_is_searched_deep_enough_free_of_charge() {
        let engines = engines();
        let mut s = Scheduler::new(FS, SearchBudget::per_signal(0.0), 1e-3, &[], 0);
        let prn = Prn::new(9).expect("prn");
        let lost = (2.0 * FS) as u64;
        let live = |p: Prn| {
            if p == prn {
                Liveness::LostAt(lost, 800.0, 33.0)
            } else {
                Liveness::Live
            }
        };
        let vis = |_: Prn| Visibility::Unknown;
        let block = (0.01 * FS) as u64;
        let mut times = Vec::new();
        let mut now = lost + block;
        while (now as f64) < 7.0 * FS {
            if let Some(b) = s.due(now, now, &engines, &live, &vis) {
                assert_eq!((b.level, b.targets.len()), (level_for_cn0(33.0), 1));
                times.push(now);
                s.record(&b, &[result(prn, false)], now, 0, &vis);
            }
            now += block;
        }
        let want = (5.0 / hot_interval_s(1)) as usize;
        assert!(
            times.len() + 1 >= want && times.len() <= want + 1,
            "{} searches in 5 s",
            times.len()
        );
        assert_eq!(s.tokens_s(), 0.0);
    }
}
