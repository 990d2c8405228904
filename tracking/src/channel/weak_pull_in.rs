//! The weak-signal pull-in: how a channel whose acquisition C/N0 is below
//! [`WeakPullInConfig::enter_dbhz`] gets from the acquisition's Doppler to a bit-aligned phase
//! lock without ever running a loop on 1 ms prompts.
//!
//! # Why the normal pull-in fails at 28-30 dB-Hz
//!
//! The normal pull-in runs a 15 Hz PLL on 1 ms prompts. At `C/N0 = 28 dB-Hz` (631 Hz) the
//! prompt SNR is `C/N0 T = 0.63` (-2 dB): the Costas discriminator is mostly noise, the loop's
//! thermal jitter `sqrt(Bn/(C/N0) (1 + 1/(2 T C/N0)))` (Kaplan eq. 5.6) is 0.21 rad x 1.3
//! before the discriminator's non-linearity, and the loop slips cycles and then frequency:
//! the 20 ms NWPR blocks lose their coherence and the C/N0 estimate reads nothing, so the
//! channel is released.
//!
//! # Stages
//!
//! 1. **Frequency** ([`WeakPullInConfig::fll`]): a 1st-order FLL alone on 10 ms coherent sums
//!    (unaligned: the bit edges are unknown), data-insensitive discriminator
//!    `atan2(cross sign(dot), |dot|) / (2 pi T)` on consecutive sums (Kaplan Table 5.4), range
//!    `+-1/(4T)` = +-25 Hz. Its SNR per sum is `C/N0 T` = 6.3 (8 dB) at 28 dB-Hz; the
//!    discriminator's noise (differenced phase noise, `sqrt(2/(2 C/N0 T)) / (2 pi T)` = 6.3 Hz
//!    per sum) through a `Bn` = 2 Hz loop (`Bn T` = 0.02, variance factor `2 Bn T`) leaves about
//!    1.3 Hz rms, which costs nothing in the 20 ms sums of the next stages (`sinc^2(f T)`
//!    = 0.99 at 1.3 Hz). Meanwhile the histogram bit synchroniser ([`crate::bit_sync`]) runs
//!    on the 1 ms prompts: its statistic, the sign of `Re(P_k P_{k-1}^*)`, is phase-insensitive
//!    and needs only this frequency lock (a residual `f` scales it by `cos(2 pi f T)` = 0.9997
//!    at 3 Hz). Its lead threshold comes from the false-synchronisation probability
//!    [`WeakPullInConfig::p_false_sync`] at the design C/N0 [`WeakPullInConfig::bit_sync_dbhz`]
//!    (`lead >= ln(19/P) / ln((1-q)/q)`, `q = exp(-C/N0 T)/2`: 18 at 26 dB-Hz and 1e-4),
//!    which a 28 dB-Hz signal reaches in about 2.5 s (the true bin gains `1/2 - q` = 0.23 per
//!    bit on the others).
//! 2. **Phase** ([`WeakPullInConfig::pll`]), from the first bit edge after synchronisation:
//!    bit-aligned 20 ms sums, a 3rd-order Costas PLL at 5 Hz assisted by a 2nd-order FLL at
//!    2.5 Hz (`Bn T` = 0.1; this pair goes unstable at 0.37, `tracking/README.md`) for
//!    [`WeakPullInConfig::fll_assist_s`], then the PLL alone. The FLL discriminator on
//!    consecutive bit-aligned 20 ms sums is data-insensitive over +-12.5 Hz, ten times the
//!    frequency stage's residual. Third order: a constant line-of-sight acceleration leaves
//!    no phase error (a 2nd-order loop at 3 Hz would lag `(a/lambda)/wn^2` = 0.25 cycle at
//!    1.5 m/s^2, 7.9 Hz/s: measured, the weak satellites of an accelerating car slipped).
//!    Thermal jitter `sqrt(Bn/(C/N0) (1 + 1/(2 T C/N0)))` with the realised Bn (1.22 x 5 Hz at
//!    `Bn T` = 0.1) = 0.100 rad = 5.7 deg at 28 dB-Hz.
//! 3. **Hand-over** to the weak tracking loops ([`super::ChannelConfig::weak_track`]) once the
//!    PLL lock indicator (`cos 2 phi` of 20 ms sums, [`crate::lock_detector`]) says locked.
//!    It reads `cos(2 phi) rho/(rho + 1)` with `rho = 20 C/N0 T`: 0.93 cos(2 phi) at
//!    28 dB-Hz (0.90 with the 5.7 deg jitter), but at most 0.67 at 20 dB-Hz (`rho` = 2), below its 0.7 threshold: a signal
//!    too weak to track is never confirmed.
//!
//! # Loss of lock before bit synchronisation
//!
//! The channel's bit-aligned NWPR C/N0 estimate needs the bit edges. Until then a weak channel
//! estimates its C/N0 with the same NWPR statistic (`C/N0 = (mu - 1)/(T (M - mu))`, Van
//! Dierendonck) over unaligned blocks of `M` = 10 prompts of 1 ms; a block that holds a bit
//! transition loses part of its coherent power. With the edge at a uniformly unknown place in
//! the 10 ms grid, half the blocks hold an edge for 9 of the 10 offsets, and a block with the
//! edge `d` prompts in keeps `((10 - 2d)/10)^2` of its power when the bit changes
//! (half the time): the mean kept power is 0.835 (0 to -1.25 dB over the offsets). Near the
//! loss threshold (`rho = C/N0 T` << 1, `M - mu` ~ `M`) the estimate is proportional to the
//! kept power, so it is raised by [`PRESYNC_EDGE_LOSS_DB`] = 0.8 dB. Higher up the estimator
//! is not linear in it (`mu - 1` falls and `M - mu` grows): at 28 dB-Hz it reads 0.4 dB high
//! with the edge on the 10 ms grid and 1.6-2.0 dB low elsewhere (measured on the synthetic
//! signal of the tests; 1-2 dB low on the weak-mix recording too), which leaves 4 dB to the
//! threshold; it is replaced by the bit-aligned estimate at the first bit edge. For noise
//! (`mu` = 1 +- 1/sqrt(K) over `K` = 20 blocks in a 0.2 s window) it reads below 20 dB-Hz at
//! 3 sigma (after the correction). [`ChannelConfig::lost_estimates`](super::ChannelConfig::lost_estimates)
//! consecutive windows below [`WeakPullInConfig::lost_dbhz`] release the channel: pure noise
//! or a 20 dB-Hz signal in about 1 s. A channel still not confirmed after
//! [`WeakPullInConfig::patience_s`] is released too.

use super::{Channel, TrackLoops};
use crate::bit_sync::{BitSyncConfig, MS_PER_BIT};
use crate::carrier_loop::CarrierLoop;
use crate::code_loop::CodeLoop;
use crate::config::{ConfigError, LoopConfig};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// The mean coherent power a 10 ms NWPR block loses to bit transitions before the bit edges
/// are known, dB (module documentation): added to the pre-synchronisation estimate.
pub const PRESYNC_EDGE_LOSS_DB: f64 = 0.8;

/// Prompts per NWPR block before bit synchronisation (unaligned blocks, 10 ms).
pub const PRESYNC_BLOCK_PROMPTS: u32 = 10;

/// Settings of the weak-signal pull-in (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WeakPullInConfig {
    /// Acquisition C/N0 below which a channel takes the weak pull-in, dB-Hz (0: never, as
    /// [`super::ChannelConfig::weak_pull_in`] `= None`; a start without a C/N0 never does).
    pub enter_dbhz: f64,
    /// Frequency stage: an FLL alone (`pll_order = 0`), unaligned sums.
    pub fll: LoopConfig,
    /// Phase stage, after bit synchronisation: bit-aligned, FLL-assisted PLL.
    pub pll: LoopConfig,
    /// Time after which the phase stage's FLL assist is switched off, s.
    pub fll_assist_s: f64,
    /// Design C/N0 of the bit synchroniser's lead threshold, dB-Hz.
    pub bit_sync_dbhz: f64,
    /// False bit-synchronisation probability the lead threshold is sized for.
    pub p_false_sync: f64,
    /// C/N0 (pre-synchronisation estimate) below which the pull-in counts as failing, dB-Hz.
    pub lost_dbhz: f64,
    /// Longest weak pull-in before the channel is released, s.
    pub patience_s: f64,
}

impl Default for WeakPullInConfig {
    fn default() -> Self {
        Self {
            enter_dbhz: 33.0,
            fll: LoopConfig {
                pll_order: 0,
                pll_bw_hz: 1.0,
                fll_order: 1,
                fll_bw_hz: 2.0,
                dll_order: 1,
                dll_bw_hz: 1.0,
                t_coh_s: 10.0e-3,
                el_spacing_chips: 1.0,
                ..LoopConfig::default()
            },
            pll: LoopConfig {
                pll_order: 3,
                pll_bw_hz: 5.0,
                fll_order: 2,
                fll_bw_hz: 2.5,
                dll_order: 1,
                dll_bw_hz: 0.5,
                t_coh_s: 20.0e-3,
                el_spacing_chips: 1.0,
                ..LoopConfig::default()
            },
            fll_assist_s: 1.0,
            bit_sync_dbhz: 26.0,
            p_false_sync: 1e-4,
            lost_dbhz: 22.0,
            patience_s: 15.0,
        }
    }
}

impl WeakPullInConfig {
    /// Checks the loops (integration times divisors of the 20 ms bit, the frequency stage an
    /// FLL alone) and the numbers.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for l in [&self.fll, &self.pll] {
            l.validate()?;
            let ms = (l.t_coh_s * 1e3).round() as usize;
            if ms == 0 || !MS_PER_BIT.is_multiple_of(ms) {
                return Err(ConfigError::OutOfRange {
                    field: "t_coh_s",
                    value: l.t_coh_s,
                    valid: "1, 2, 4, 5, 10 or 20 ms (a divisor of the 20 ms data bit)".into(),
                });
            }
        }
        if self.fll.pll_order != 0 {
            return Err(ConfigError::BadOrder {
                field: "weak_pull_in.fll.pll_order",
                value: self.fll.pll_order,
                valid: "0 (the frequency stage is an FLL alone)",
            });
        }
        let checks: [(&'static str, f64, bool); 6] = [
            ("enter_dbhz", self.enter_dbhz, self.enter_dbhz.is_finite()),
            (
                "fll_assist_s",
                self.fll_assist_s,
                self.fll_assist_s.is_finite() && self.fll_assist_s >= 0.0,
            ),
            (
                "bit_sync_dbhz",
                self.bit_sync_dbhz,
                self.bit_sync_dbhz.is_finite() && self.bit_sync_dbhz > 0.0,
            ),
            (
                "p_false_sync",
                self.p_false_sync,
                self.p_false_sync > 0.0 && self.p_false_sync < 1.0,
            ),
            ("lost_dbhz", self.lost_dbhz, self.lost_dbhz.is_finite()),
            (
                "patience_s",
                self.patience_s,
                self.patience_s.is_finite() && self.patience_s >= 1.0 && self.patience_s <= 600.0,
            ),
        ];
        for (field, value, ok) in checks {
            if !ok {
                return Err(ConfigError::OutOfRange {
                    field,
                    value,
                    valid: "see the defaults of [tracking.weak_pull_in]: a finite \
                            C/N0 in dB-Hz, times >= 0 s (patience 1 to 600 s), 0 < p < 1"
                        .into(),
                });
            }
        }
        Ok(())
    }

    /// The bit synchroniser of the weak pull-in: the lead for [`Self::bit_sync_dbhz`] and
    /// [`Self::p_false_sync`], giving up after [`Self::patience_s`].
    pub fn bit_sync_config(&self) -> BitSyncConfig {
        BitSyncConfig {
            max_prompts: (self.patience_s * 1e3).round() as u32,
            ..BitSyncConfig::for_cn0(self.bit_sync_dbhz, self.p_false_sync)
        }
    }
}

/// Where a weak pull-in stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum WeakStage {
    /// FLL alone on unaligned sums, bit synchronisation running.
    Frequency,
    /// Bit-aligned FLL-assisted PLL; the count of code periods since it started.
    Phase {
        /// Code periods in this stage.
        ms: u64,
    },
}

impl Channel {
    /// The weak pull-in's settings, when this channel runs one.
    fn weak_cfg(&self) -> Option<WeakPullInConfig> {
        self.weak_stage.and(self.cfg.weak_pull_in)
    }

    /// Per code period of a weak pull-in: counts the phase stage (switching its FLL assist off
    /// after [`WeakPullInConfig::fll_assist_s`]), releases the channel after
    /// [`WeakPullInConfig::patience_s`], and moves from the frequency stage to the phase stage
    /// at the first bit edge after synchronisation (`next_is_edge`): the partial sum is
    /// dropped so that the 20 ms sums start on the edge. Returns whether it switched (no
    /// report for this period then).
    pub(super) fn weak_pull_in_step(&mut self, next_is_edge: bool) -> bool {
        let Some(cfg) = self.weak_cfg() else {
            return false;
        };
        if self.pull_in_ms as f64 > cfg.patience_s * 1e3 {
            self.state = super::ChannelState::Lost;
            return false;
        }
        match self.weak_stage {
            Some(WeakStage::Phase { ms }) => {
                let ms = ms + 1;
                self.weak_stage = Some(WeakStage::Phase { ms });
                if ms == (cfg.fll_assist_s * 1e3).round() as u64 {
                    self.carrier.set_fll_assist(false);
                }
                false
            }
            Some(WeakStage::Frequency) if next_is_edge => {
                self.set_weak_loops(&cfg.pll);
                self.weak_stage = Some(WeakStage::Phase { ms: 0 });
                self.acc = [Complex64::new(0.0, 0.0); 3];
                self.acc_ms = 0;
                true
            }
            _ => false,
        }
    }

    /// Back to the frequency stage (the bit edges were forgotten: samples lost).
    pub(super) fn weak_restart_frequency_stage(&mut self) {
        if let (Some(WeakStage::Phase { .. }), Some(cfg)) = (self.weak_stage, self.weak_cfg()) {
            self.set_weak_loops(&cfg.fll);
            self.weak_stage = Some(WeakStage::Frequency);
        }
    }

    /// Whether the hand-over of a weak pull-in may happen: the phase stage has run without its
    /// FLL assist (true for a channel without a weak pull-in).
    pub(super) fn weak_ready_for_hand_over(&self) -> bool {
        match (self.weak_stage, self.weak_cfg()) {
            (Some(WeakStage::Phase { ms }), Some(cfg)) => {
                ms >= (cfg.fll_assist_s * 1e3).round() as u64
            }
            (Some(WeakStage::Frequency), _) => false,
            _ => true,
        }
    }

    /// Carrier and code loops of `loops`, from the carrier loop's frequency memory.
    pub(super) fn set_weak_loops(&mut self, loops: &LoopConfig) {
        if let (Ok(carrier), Ok(code_loop)) = (
            CarrierLoop::new(loops, self.carrier.frequency_memory_hz()),
            CodeLoop::new(loops),
        ) {
            self.carrier = carrier;
            self.code_loop = code_loop;
            let d = loops.el_spacing_chips;
            self.taps = [d / 2.0, 0.0, -d / 2.0];
            self.loops = TrackLoops::Normal;
        }
    }

    /// A C/N0 estimate of the pre-synchronisation NWPR (unaligned 10 ms blocks), dB-Hz before
    /// the [`PRESYNC_EDGE_LOSS_DB`] correction: reported, and once per estimation window tested
    /// against [`WeakPullInConfig::lost_dbhz`]; [`super::ChannelConfig::lost_estimates`]
    /// consecutive low ones release the channel.
    pub(super) fn on_presync_estimate(&mut self, c: f64) {
        let Some(cfg) = self.weak_cfg() else {
            return;
        };
        let c = if c > crate::cn0::CN0_MIN_DBHZ {
            c + PRESYNC_EDGE_LOSS_DB
        } else {
            c
        };
        self.cn0_dbhz = c;
        let window = 2 * self.cn0_window_blocks;
        if self.presync_cn0.blocks().is_multiple_of(window) {
            self.low_cn0_count = if c < cfg.lost_dbhz {
                self.low_cn0_count + 1
            } else {
                0
            };
            if self.low_cn0_count >= self.cfg.lost_estimates {
                self.state = super::ChannelState::Lost;
            }
        }
    }

    /// Whether the channel is in the frequency stage of a weak pull-in (unaligned sums).
    pub(super) fn weak_frequency_stage(&self) -> bool {
        self.weak_stage == Some(WeakStage::Frequency)
    }

    /// Whether the channel runs (or ran until its hand-over) a weak pull-in.
    pub fn weak_pull_in(&self) -> bool {
        self.weak_stage.is_some()
    }
}

#[cfg(test)]
mod tests;
