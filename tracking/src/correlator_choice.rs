//! Which correlator kernel the channels run: `[tracking] correlator` (the widest instruction
//! set allowed) and `correlator_arithmetic`, overridden by `gpsrx run/track --correlator`.
//!
//! The instruction set is a ceiling, not a demand: `"avx2"` runs the AVX2 kernel on an
//! AVX-512 machine (to time what an AVX2-only CPU would do) and the scalar one on a CPU
//! without AVX2; `"auto"` takes the widest this CPU has.

use gpsrx_dsp::correlator::{Arithmetic, Correlator, Isa};
use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// The widest instruction set the channels' correlator may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CorrelatorIsa {
    /// The widest this CPU runs (AVX-512, else AVX2+FMA, else scalar).
    #[default]
    Auto,
    /// At most AVX-512.
    Avx512,
    /// At most AVX2+FMA.
    Avx2,
    /// The portable scalar kernel.
    Scalar,
}

/// The arithmetic of the channels' correlator.
///
/// `auto` takes, per block format, the faster one ([`Arithmetic::Auto`]): int16 on ci8 and
/// ci16 blocks where the CPU has AVX2 (the int16-lane kernels, 16 samples per step with AVX2,
/// 32 with AVX-512 VNNI: about twice the f32 kernels' speed), f32 on cf32. An I16 correlator
/// runs the F32 kernel on cf32 blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CorrelatorArithmetic {
    /// The faster per block format.
    #[default]
    Auto,
    /// f32 wipe-off and accumulation.
    F32,
    /// Integer samples, Q14 carrier, exact integer sums ([`Arithmetic::I16`]).
    I16,
}

/// A `--correlator` value: `ISA` or `ISA/ARITHMETIC`, e.g. `avx2` or `avx2/i16`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CorrelatorChoice {
    /// The instruction-set ceiling.
    pub isa: CorrelatorIsa,
    /// The arithmetic (`None`: keep the configured one).
    pub arithmetic: Option<CorrelatorArithmetic>,
}

/// A correlator name that is not one of the valid ones.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown correlator {given:?}: valid are {valid}")]
pub struct UnknownCorrelator {
    /// What was given.
    pub given: String,
    /// The valid values, in words.
    pub valid: &'static str,
}

const ISA_NAMES: &str =
    "auto, avx512, avx2, scalar (optionally /auto, /f32 or /i16, e.g. avx2/i16)";
const ARITHMETIC_NAMES: &str = "auto, f32, i16";

impl CorrelatorIsa {
    /// The [`Isa`] ceiling.
    pub fn max_isa(self) -> Isa {
        match self {
            CorrelatorIsa::Auto | CorrelatorIsa::Avx512 => Isa::Avx512,
            CorrelatorIsa::Avx2 => Isa::Avx2Fma,
            CorrelatorIsa::Scalar => Isa::Scalar,
        }
    }

    /// The fastest kernel of `arithmetic` within the ceiling that this CPU runs.
    pub fn correlator(self, arithmetic: CorrelatorArithmetic) -> Correlator {
        Correlator::best_up_to(self.max_isa(), arithmetic.into())
    }
}

impl From<CorrelatorArithmetic> for Arithmetic {
    fn from(a: CorrelatorArithmetic) -> Self {
        match a {
            CorrelatorArithmetic::F32 => Arithmetic::F32,
            CorrelatorArithmetic::I16 => Arithmetic::I16,
            CorrelatorArithmetic::Auto => Arithmetic::Auto,
        }
    }
}

impl FromStr for CorrelatorIsa {
    type Err = UnknownCorrelator;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "avx512" | "avx-512" => Ok(Self::Avx512),
            "avx2" | "avx2+fma" => Ok(Self::Avx2),
            "scalar" => Ok(Self::Scalar),
            _ => Err(UnknownCorrelator {
                given: s.into(),
                valid: ISA_NAMES,
            }),
        }
    }
}

impl FromStr for CorrelatorArithmetic {
    type Err = UnknownCorrelator;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "f32" => Ok(Self::F32),
            "i16" => Ok(Self::I16),
            _ => Err(UnknownCorrelator {
                given: s.into(),
                valid: ARITHMETIC_NAMES,
            }),
        }
    }
}

impl FromStr for CorrelatorChoice {
    type Err = UnknownCorrelator;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || UnknownCorrelator {
            given: s.into(),
            valid: ISA_NAMES,
        };
        let (isa, arithmetic) = match s.split_once('/') {
            Some((isa, a)) => (isa, Some(a.parse().map_err(|_| bad())?)),
            None => (s, None),
        };
        Ok(Self {
            isa: isa.parse().map_err(|_| bad())?,
            arithmetic,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_bad_ones_say_what_is_valid() {
        let c: CorrelatorChoice = "avx2/i16".parse().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(c.isa, CorrelatorIsa::Avx2);
        assert_eq!(c.arithmetic, Some(CorrelatorArithmetic::I16));
        let c: CorrelatorChoice = "AVX512".parse().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((c.isa, c.arithmetic), (CorrelatorIsa::Avx512, None));
        for bad in ["avx3", "avx2/f64", "", "/i16"] {
            let e = bad
                .parse::<CorrelatorChoice>()
                .err()
                .unwrap_or_else(|| panic!("{bad:?} parsed"));
            let msg = e.to_string();
            assert!(msg.contains("auto, avx512, avx2, scalar"), "{msg}");
        }
    }

    #[test]
    fn the_ceiling_is_respected_and_auto_takes_the_widest() {
        for isa in [
            CorrelatorIsa::Auto,
            CorrelatorIsa::Avx512,
            CorrelatorIsa::Avx2,
            CorrelatorIsa::Scalar,
        ] {
            for a in [
                CorrelatorArithmetic::Auto,
                CorrelatorArithmetic::F32,
                CorrelatorArithmetic::I16,
            ] {
                let c = isa.correlator(a);
                assert!(c.isa() <= isa.max_isa(), "{isa:?}: {}", c.name());
                assert_eq!(c.arithmetic(), Arithmetic::from(a));
                // Nothing wider within the ceiling was available.
                for wider in Isa::ALL.into_iter().filter(|&w| w > c.isa()) {
                    assert!(wider > isa.max_isa() || !wider.is_available());
                }
            }
        }
        assert_eq!(
            CorrelatorIsa::Auto
                .correlator(CorrelatorArithmetic::F32)
                .name(),
            Correlator::best().name()
        );
        // The default: the widest ISA, the arithmetic chosen per block format.
        let d = CorrelatorIsa::default().correlator(CorrelatorArithmetic::default());
        assert_eq!(d.isa(), Correlator::best().isa());
        assert_eq!(d.arithmetic(), Arithmetic::Auto);
    }

    #[test]
    fn toml_values_are_lowercase_names() {
        #[derive(Deserialize)]
        struct T {
            correlator: CorrelatorIsa,
            correlator_arithmetic: CorrelatorArithmetic,
        }
        let t: T = toml::from_str("correlator = \"avx2\"\ncorrelator_arithmetic = \"i16\"")
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(t.correlator, CorrelatorIsa::Avx2);
        assert_eq!(t.correlator_arithmetic, CorrelatorArithmetic::I16);
        let e = toml::from_str::<T>("correlator = \"sse\"\ncorrelator_arithmetic = \"f32\"")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("avx2"), "{e}");
    }
}
