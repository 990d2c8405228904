//! The carrier-aided code loop (DLL) a channel drives once per integration interval.

use num_complex::Complex64;

use crate::aiding;
use crate::config::{ConfigError, DllDiscriminator, LoopConfig};
use crate::discriminator;
use crate::loop_filter::LoopFilter;

/// What one code-loop update produced.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CodeOutput {
    /// Code NCO rate to hold over the next interval, chips/s:
    /// `1.023e6 + carrier aid + DLL output`.
    pub code_rate_chips_s: f64,
    /// The DLL filter's share, chips/s.
    pub dll_chips_s: f64,
    /// DLL discriminator output, chips (signal minus replica code phase).
    pub code_error_chips: f64,
}

/// Carrier-aided DLL of order 1 or 2 with a normalised E-L envelope or dot-product discriminator.
#[derive(Debug, Clone)]
pub struct CodeLoop {
    cfg: LoopConfig,
    filter: LoopFilter,
}

impl CodeLoop {
    /// A code loop from a configuration (validated).
    pub fn new(cfg: &LoopConfig) -> Result<Self, ConfigError> {
        Ok(Self {
            cfg: *cfg,
            filter: LoopFilter::code(cfg)?,
        })
    }

    /// One update with the early, prompt and late correlations of the interval just dumped and the
    /// carrier aid in chips/s (the code Doppler implied by the carrier NCO, see
    /// [`aiding::code_doppler_chips_s`]; 0 for an unaided DLL).
    pub fn update(
        &mut self,
        early: Complex64,
        prompt: Complex64,
        late: Complex64,
        carrier_aid_chips_s: f64,
    ) -> CodeOutput {
        let code_error_chips = match self.cfg.dll_discriminator {
            DllDiscriminator::NormalizedEnvelope => {
                discriminator::dll_normalized_envelope(early, late, self.cfg.el_spacing_chips)
            }
            DllDiscriminator::DotProduct => discriminator::dll_dot_product(early, prompt, late),
        };
        let dll_chips_s = self.filter.update(code_error_chips, 0.0, self.cfg.t_coh_s);
        output(dll_chips_s, code_error_chips, carrier_aid_chips_s)
    }

    /// Starts a coast ([`CodeLoop::coast`]): the filter forgets its last input.
    pub fn start_coast(&mut self) {
        self.filter.forget_input();
    }

    /// One interval without a usable prompt (the signal is gone and an aid predicts it): the
    /// DLL runs on zero error (a 1st-order DLL adds nothing, a 2nd-order one holds its rate), so
    /// the code follows the carrier aid `carrier_aid_chips_s` alone.
    pub fn coast(&mut self, carrier_aid_chips_s: f64) -> CodeOutput {
        let dll_chips_s = self.filter.update(0.0, 0.0, self.cfg.t_coh_s);
        output(dll_chips_s, 0.0, carrier_aid_chips_s)
    }

    /// Changes the integration time (validated like [`LoopConfig::validate`]).
    pub fn set_t_coh_s(&mut self, t_coh_s: f64) -> Result<(), ConfigError> {
        let new_cfg = LoopConfig {
            t_coh_s,
            ..self.cfg
        };
        new_cfg.validate()?;
        self.cfg = new_cfg;
        Ok(())
    }

    /// The configuration the loop runs with.
    pub fn config(&self) -> &LoopConfig {
        &self.cfg
    }

    /// The loop filter.
    pub fn filter(&self) -> &LoopFilter {
        &self.filter
    }
}

/// The code NCO rate from the DLL's correction and the carrier aid (chips/s; a non-finite
/// aid counts as none).
fn output(dll_chips_s: f64, code_error_chips: f64, carrier_aid_chips_s: f64) -> CodeOutput {
    let aid = if carrier_aid_chips_s.is_finite() {
        carrier_aid_chips_s
    } else {
        0.0
    };
    CodeOutput {
        code_rate_chips_s: aiding::code_rate_chips_s(0.0, aid + dll_chips_s),
        dll_chips_s,
        code_error_chips,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;

    #[test]
    fn nominal_rate_plus_aid() {
        let cfg = LoopConfig::default();
        let Ok(mut c) = CodeLoop::new(&cfg) else {
            panic!("default config must be valid")
        };
        let p = Complex64::new(10.0, 0.0);
        let out = c.update(p * 0.5, p, p * 0.5, 2.5);
        assert!((out.code_rate_chips_s - (CA_CHIP_RATE_HZ + 2.5)).abs() < 1e-9);
        assert_eq!(out.code_error_chips, 0.0);
    }
}
