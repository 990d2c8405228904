//! The carrier loop a channel drives once per integration interval: discriminators, loop filter
//! and the aiding sum, as one small state machine-free object.

use num_complex::Complex64;

use crate::aiding;
use crate::config::{ConfigError, FllDiscriminator, LoopConfig, PllDiscriminator};
use crate::discriminator;
use crate::loop_filter::LoopFilter;

/// What one carrier-loop update produced.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CarrierOutput {
    /// Carrier NCO frequency (Doppler, Hz) to hold over the next interval:
    /// initial Doppler + feed-forward + loop filter output.
    pub nco_freq_hz: f64,
    /// The loop filter's share of it, Hz (the residual the loop itself tracks).
    pub loop_hz: f64,
    /// PLL discriminator output, cycles (reported even when no PLL is configured).
    pub phase_error_cycles: f64,
    /// FLL discriminator output, Hz (0 on the first update and without an FLL).
    pub freq_error_hz: f64,
}

/// PLL / FLL / FLL-assisted PLL carrier tracking loop with an aiding (feed-forward) port.
///
/// Per interval the channel calls [`CarrierLoop::update`] with the prompt of the interval just
/// dumped and the aid for the next one, and holds the returned `nco_freq_hz` over the next
/// interval (phase-continuous NCO). The timing this assumes is documented in
/// [`crate::loop_analysis`].
#[derive(Debug, Clone)]
pub struct CarrierLoop {
    cfg: LoopConfig,
    filter: LoopFilter,
    base_hz: f64,
    prev_prompt: Option<Complex64>,
    last: CarrierOutput,
    /// The signal's C/N0 (Hz) for the Costas gain normalisation, when known.
    cn0_hz: Option<f64>,
}

/// The smallest Costas slope the gain normalisation divides by: at most a 20-fold gain (the
/// slope of `1 - exp(-C/N0 T)` is 0.05 at 17.1 dB-Hz with T = 1 ms), so that a poor C/N0
/// estimate on a vanishing signal cannot blow the loop up.
pub const MIN_COSTAS_SLOPE: f64 = 0.05;

impl CarrierLoop {
    /// A carrier loop from a configuration, starting at `initial_doppler_hz` (e.g. from
    /// acquisition; 0 when all of the Doppler comes through the feed-forward).
    pub fn new(cfg: &LoopConfig, initial_doppler_hz: f64) -> Result<Self, ConfigError> {
        let filter = LoopFilter::carrier(cfg)?;
        if !initial_doppler_hz.is_finite() {
            return Err(ConfigError::OutOfRange {
                field: "initial_doppler_hz",
                value: initial_doppler_hz,
                valid: "a finite frequency in Hz".to_string(),
            });
        }
        Ok(Self {
            cfg: *cfg,
            filter,
            base_hz: initial_doppler_hz,
            prev_prompt: None,
            cn0_hz: None,
            last: CarrierOutput {
                nco_freq_hz: initial_doppler_hz,
                ..CarrierOutput::default()
            },
        })
    }

    /// One update with the prompt of the interval just dumped and the feed-forward Doppler (Hz,
    /// mean over the next interval, see [`aiding::DopplerAid::mean_over_hz`]; 0 when unaided).
    pub fn update(&mut self, prompt: Complex64, feedforward_hz: f64) -> CarrierOutput {
        let t = self.cfg.t_coh_s;
        let phase_error_cycles = match self.cfg.pll_discriminator {
            PllDiscriminator::Costas => discriminator::costas_atan(prompt),
            PllDiscriminator::Atan2 => discriminator::pll_atan2(prompt),
        };
        let freq_error_hz = match self.prev_prompt {
            Some(prev) if self.filter.assist_enabled() => match self.cfg.fll_discriminator {
                FllDiscriminator::DataInsensitive => {
                    discriminator::fll_data_insensitive(prev, prompt, t)
                }
                FllDiscriminator::Atan2 => discriminator::fll_atan2(prev, prompt, t),
            },
            _ => 0.0,
        };
        self.prev_prompt = Some(prompt);
        let primary = if self.filter.has_primary() {
            phase_error_cycles * self.costas_gain()
        } else {
            0.0
        };
        let loop_hz = self.filter.update(primary, freq_error_hz, t);
        let nco_freq_hz = aiding::carrier_nco_hz(feedforward_hz, self.base_hz + loop_hz);
        self.last = CarrierOutput {
            nco_freq_hz,
            loop_hz,
            phase_error_cycles,
            freq_error_hz,
        };
        self.last
    }

    /// Starts a coast ([`CarrierLoop::coast`]) on a feed-forward that predicts the signal (its
    /// Doppler and Doppler rate): the loop's share of the NCO frequency and, in a 3rd-order
    /// loop, its rate memory go to zero, so the NCO follows the prediction alone, and the
    /// filter forgets its last input. What the loop held on top of the prediction was learned
    /// partly in the noise before the signal's loss was seen (the fade detector takes 40-60
    /// ms, the C/N0 test of a weak signal 0.3-0.5 s): at 18 Hz a rate memory wanders about
    /// 15 Hz/s in 40 ms, and a 6 Hz weak loop's frequency drifted 8 Hz in 0.4 s, from which
    /// it could not pull in when the signal came back.
    pub fn start_coast(&mut self) {
        self.filter.preset_rate(0.0);
        self.filter.forget_input();
        self.base_hz -= self.frequency_memory_hz();
    }

    /// One interval without a usable prompt (the signal is gone and an aid predicts it,
    /// [`aiding::DopplerAid::coast`]): the loop filter runs on zero error, so it holds its
    /// frequency (a 3rd-order loop its Doppler rate too) and the NCO is `f_ff + memory`; the
    /// FLL forgets its previous prompt.
    pub fn coast(&mut self, feedforward_hz: f64) -> CarrierOutput {
        let loop_hz = self.filter.update(0.0, 0.0, self.cfg.t_coh_s);
        self.prev_prompt = None;
        self.last = CarrierOutput {
            nco_freq_hz: aiding::carrier_nco_hz(feedforward_hz, self.base_hz + loop_hz),
            loop_hz,
            phase_error_cycles: 0.0,
            freq_error_hz: 0.0,
        };
        self.last
    }

    /// Sets the signal's C/N0 (Hz; `None` or a non-finite or negative value: unknown) for the
    /// Costas gain normalisation ([`CarrierLoop::costas_gain`]).
    pub fn set_cn0_hz(&mut self, cn0_hz: Option<f64>) {
        self.cn0_hz = cn0_hz.filter(|c| c.is_finite() && *c >= 0.0);
    }

    /// The gain the Costas discriminator's output is multiplied by before the loop filter:
    /// `1 / max(1 - exp(-C/N0 T), MIN_COSTAS_SLOPE)`, 1 with another discriminator or without
    /// a C/N0.
    ///
    /// The `atan(Q/I)` discriminator's mean output at a small phase error `phi` is
    /// `(1 - exp(-C/N0 T)) phi` (its slope falls with the prompt SNR as the fold at +-pi/2 takes
    /// more of the noise; derivation with `gpsrx_studies::bandwidth::costas_atan_stats`), so
    /// unnormalised a loop's gain, and with it its bandwidth, its dynamic stress error and (for
    /// a 3rd-order loop, conditionally stable: gain above 0.38 by Routh) its stability, depend
    /// on the C/N0: at 30 dB-Hz and T = 1 ms the loop runs at 63 % of its design gain. Divided
    /// by the slope it keeps its design (Kaplan & Hegarty sec. 5.3: the loop filter
    /// coefficients assume unit discriminator gain).
    pub fn costas_gain(&self) -> f64 {
        match (self.cfg.pll_discriminator, self.cn0_hz) {
            (PllDiscriminator::Costas, Some(c)) => {
                let slope = 1.0 - (-c * self.cfg.t_coh_s).exp();
                1.0 / slope.max(MIN_COSTAS_SLOPE)
            }
            _ => 1.0,
        }
    }

    /// The output of the last update (or the initial Doppler before the first).
    pub fn last(&self) -> CarrierOutput {
        self.last
    }

    /// The integration time the loop assumes, s.
    pub fn t_coh_s(&self) -> f64 {
        self.cfg.t_coh_s
    }

    /// The configuration the loop runs with.
    pub fn config(&self) -> &LoopConfig {
        &self.cfg
    }

    /// Changes the integration time (e.g. 1 ms -> 20 ms after bit synchronisation). The
    /// integrators keep their frequency; the FLL history is cleared because the next prompt
    /// spans a different interval. Rejects a `t_coh_s` outside 1-20 ms or one that would make
    /// `Bn T` too large for this loop.
    pub fn set_t_coh_s(&mut self, t_coh_s: f64) -> Result<(), ConfigError> {
        let new_cfg = LoopConfig {
            t_coh_s,
            ..self.cfg
        };
        new_cfg.validate()?;
        self.cfg = new_cfg;
        self.prev_prompt = None;
        Ok(())
    }

    /// Switches the FLL assist off (or on again) without disturbing the frequency memory. For a
    /// pure FLL (`pll_order = 0`) switching it off freezes the NCO frequency.
    pub fn set_fll_assist(&mut self, on: bool) {
        self.filter.set_assist_enabled(on);
        if !on {
            self.prev_prompt = None;
        }
    }

    /// The same loop with the settings `cfg` (another bandwidth or order): the frequency it
    /// holds and, from a 3rd-order loop to a 3rd-order loop, the Doppler rate it holds carry
    /// over, so that the switch itself moves the NCO by nothing (a bumpless transfer). The
    /// FLL history restarts.
    ///
    /// Errors: `cfg` out of range.
    pub fn retuned(&self, cfg: &LoopConfig) -> Result<Self, ConfigError> {
        let mut next = Self::new(cfg, self.frequency_memory_hz())?;
        if let Some(rate) = self.filter.rate_memory() {
            next.preset_doppler_rate(rate);
        }
        Ok(next)
    }

    /// Moves the Doppler-rate memory of a 3rd-order loop by `delta_hz_s` (see
    /// [`LoopFilter::shift_rate`]), as [`CarrierLoop::shift_base_hz`] moves its frequency.
    pub fn shift_doppler_rate(&mut self, delta_hz_s: f64) {
        self.filter.shift_rate(delta_hz_s);
    }

    /// Presets the Doppler-rate memory of a 3rd-order loop (Hz/s); see
    /// [`LoopFilter::preset_rate`].
    pub fn preset_doppler_rate(&mut self, rate_hz_s: f64) {
        self.filter.preset_rate(rate_hz_s);
    }

    /// Moves the loop's base frequency by `delta_hz` (when a feed-forward is switched on or off,
    /// so that the NCO frequency stays continuous: base - ff_new + ff_new = base).
    pub fn shift_base_hz(&mut self, delta_hz: f64) {
        if delta_hz.is_finite() {
            self.base_hz += delta_hz;
        }
    }

    /// Forgets the previous prompt (call after a gap in the correlations).
    pub fn reset_history(&mut self) {
        self.prev_prompt = None;
    }

    /// The loop's frequency memory, Hz, without the feed-forward: the base frequency plus the
    /// last integrator (for a loop with one; else the last NCO frequency less the feed-forward is
    /// not available here, so the base plus the last loop output). Unlike the NCO frequency it
    /// carries no proportional-path noise (`a2 omega0 e` of every interval, 2.5 Hz rms for a
    /// 15 Hz loop at 35 dB-Hz), so it is the frequency to hand over to another loop.
    pub fn frequency_memory_hz(&self) -> f64 {
        if self.filter.has_integrator() {
            self.base_hz + self.filter.integrator()
        } else {
            self.base_hz + self.last.loop_hz
        }
    }

    /// The loop filter.
    pub fn filter(&self) -> &LoopFilter {
        &self.filter
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_initial_doppler_and_adds_feedforward() {
        let cfg = LoopConfig {
            fll_order: 0,
            ..LoopConfig::default()
        };
        let mut l = CarrierLoop::new(&cfg, 1234.0).ok();
        let out = l
            .as_mut()
            .map(|l| l.update(Complex64::new(1.0, 0.0), 10.0))
            .unwrap_or_default();
        assert!((out.nco_freq_hz - 1244.0).abs() < 1e-12);
        assert_eq!(out.loop_hz, 0.0);
        assert!(CarrierLoop::new(&cfg, f64::INFINITY).is_err());
    }

    #[test]
    fn changing_t_coh_is_validated() {
        let cfg = LoopConfig {
            fll_order: 0,
            pll_bw_hz: 15.0,
            ..LoopConfig::default()
        };
        let Ok(mut l) = CarrierLoop::new(&cfg, 0.0) else {
            panic!("default config must be valid")
        };
        assert!(l.set_t_coh_s(0.02).is_err()); // 15 Hz * 20 ms = 0.3
        assert!(l.set_t_coh_s(0.01).is_ok());
        assert_eq!(l.t_coh_s(), 0.01);
    }
}
