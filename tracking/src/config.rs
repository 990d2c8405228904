//! Tracking-loop configuration: one plain, serde-readable struct, validated before use.
//!
//! Unknown keys are rejected (serde `deny_unknown_fields` lists the valid ones), and
//! [`LoopConfig::validate`] names the offending field and its valid range.

use serde::{Deserialize, Serialize};

use crate::loop_analysis;
use crate::loop_filter::LoopFilter;

/// Largest `Bn * T` accepted for any loop. Beyond it the digital loop's noise bandwidth exceeds the
/// design value by more than about 60 % (see `tracking/README.md`), and the loops go unstable
/// not far above (1st order at 0.50, 2nd at 0.44, 3rd at 0.56 for this implementation).
pub const MAX_BN_T: f64 = 0.2;

/// Valid range of the predetection integration time, seconds (whole C/A code periods up to one
/// navigation bit).
pub const T_COH_RANGE_S: (f64, f64) = (1.0e-3, 20.0e-3);

/// Valid range of the early-minus-late spacing, chips.
pub const EL_SPACING_RANGE_CHIPS: (f64, f64) = (0.1, 1.0);

/// PLL phase discriminator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PllDiscriminator {
    /// Costas `atan(Q/I)`: insensitive to data bits, range +-1/4 cycle (Kaplan Table 5.2).
    #[default]
    Costas,
    /// Four-quadrant `atan2(Q, I)` for a data-free (pilot) signal, range +-1/2 cycle.
    Atan2,
}

/// FLL frequency discriminator on consecutive prompts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FllDiscriminator {
    /// `atan2(cross * sign(dot), |dot|)`: insensitive to a data-bit flip between the two prompts,
    /// range +-1/(4T) Hz (Kaplan Table 5.4, ATAN2 with the sign of dot).
    #[default]
    DataInsensitive,
    /// `atan2(cross, dot)`: range +-1/(2T) Hz, for pilots or when no bit edge can fall between the
    /// two prompts.
    Atan2,
}

/// DLL discriminator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DllDiscriminator {
    /// Normalised early-minus-late envelope `(|E|-|L|)/(|E|+|L|)`, scaled to chips.
    #[default]
    NormalizedEnvelope,
    /// Dot product `Re((E-L) P*) / |P|^2`, scaled to chips.
    DotProduct,
}

/// Tracking-loop configuration (plain struct; TOML/JSON through serde).
///
/// Carrier loop modes (`pll_order`, `fll_order`):
/// - PLL alone: `(1|2|3, 0)`;
/// - FLL alone: `(0, 1|2)`;
/// - FLL-assisted PLL (Kaplan Fig. 5.20): `(2, 1)` or `(3, 2)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoopConfig {
    /// PLL order, 0 (no PLL: FLL only), 1, 2 or 3.
    pub pll_order: u8,
    /// PLL noise bandwidth Bn, Hz.
    pub pll_bw_hz: f64,
    /// FLL order, 0 (no FLL), 1 or 2.
    pub fll_order: u8,
    /// FLL noise bandwidth Bn, Hz.
    pub fll_bw_hz: f64,
    /// DLL order, 1 or 2.
    pub dll_order: u8,
    /// DLL noise bandwidth Bn, Hz.
    pub dll_bw_hz: f64,
    /// Predetection (coherent) integration time T, s: 1-20 ms in whole milliseconds.
    pub t_coh_s: f64,
    /// Early-minus-late correlator spacing d, chips (0.1-1).
    pub el_spacing_chips: f64,
    /// PLL discriminator.
    #[serde(default)]
    pub pll_discriminator: PllDiscriminator,
    /// FLL discriminator.
    #[serde(default)]
    pub fll_discriminator: FllDiscriminator,
    /// DLL discriminator.
    #[serde(default)]
    pub dll_discriminator: DllDiscriminator,
}

impl Default for LoopConfig {
    /// A pull-in configuration: 2nd-order PLL at 15 Hz assisted by a 1st-order FLL at 10 Hz,
    /// 1st-order DLL at 2 Hz, T = 1 ms, d = 1 chip.
    fn default() -> Self {
        Self {
            pll_order: 2,
            pll_bw_hz: 15.0,
            fll_order: 1,
            fll_bw_hz: 10.0,
            dll_order: 1,
            dll_bw_hz: 2.0,
            t_coh_s: 1.0e-3,
            el_spacing_chips: 1.0,
            pll_discriminator: PllDiscriminator::default(),
            fll_discriminator: FllDiscriminator::default(),
            dll_discriminator: DllDiscriminator::default(),
        }
    }
}

/// A configuration value that cannot be used, with the field and what would be valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// A numeric field outside its valid range.
    #[error("{field} = {value} is out of range; valid: {valid}")]
    OutOfRange {
        /// Field name as in [`LoopConfig`].
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// The valid range, in words.
        valid: String,
    },
    /// A loop order that does not exist.
    #[error("{field} = {value} is not a supported loop order; valid: {valid}")]
    BadOrder {
        /// Field name as in [`LoopConfig`].
        field: &'static str,
        /// The rejected order.
        value: u8,
        /// The valid orders.
        valid: &'static str,
    },
    /// A PLL/FLL order pair that is not one of the supported carrier loops.
    #[error("pll_order = {pll_order} with fll_order = {fll_order} is not a supported carrier loop; valid (pll_order, fll_order): PLL alone (1|2|3, 0), FLL alone (0, 1|2), FLL-assisted PLL (2, 1) or (3, 2)")]
    Combination {
        /// The requested PLL order.
        pll_order: u8,
        /// The requested FLL order.
        fll_order: u8,
    },
    /// The digital closed loop has a pole on or outside the unit circle.
    #[error("the {which} loop is unstable as a digital loop at t_coh_s = {t_coh_s}; reduce its bandwidth(s) or t_coh_s")]
    Unstable {
        /// `carrier` or `code`.
        which: &'static str,
        /// The integration time used.
        t_coh_s: f64,
    },
}

fn check_range(
    field: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    valid: impl Fn() -> String,
) -> Result<(), ConfigError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            field,
            value,
            valid: valid(),
        })
    }
}

/// Checks `t_coh_s`: 1-20 ms in whole milliseconds.
pub fn validate_t_coh_s(t_coh_s: f64) -> Result<(), ConfigError> {
    let (lo, hi) = T_COH_RANGE_S;
    let valid = || "0.001 ..= 0.020 s in whole milliseconds (whole C/A code periods)".to_string();
    check_range("t_coh_s", t_coh_s, lo - 1e-12, hi + 1e-12, valid)?;
    let ms = t_coh_s * 1.0e3;
    if (ms - ms.round()).abs() > 1.0e-6 {
        return Err(ConfigError::OutOfRange {
            field: "t_coh_s",
            value: t_coh_s,
            valid: valid(),
        });
    }
    Ok(())
}

/// Checks a loop bandwidth: positive, finite, and `Bn * T <= MAX_BN_T`.
pub fn validate_bandwidth(
    field: &'static str,
    bw_hz: f64,
    t_coh_s: f64,
) -> Result<(), ConfigError> {
    let hi = MAX_BN_T / t_coh_s;
    check_range(field, bw_hz, f64::MIN_POSITIVE, hi, || {
        format!("0 < {field} <= {hi} Hz (Bn * t_coh_s <= {MAX_BN_T} at t_coh_s = {t_coh_s} s)")
    })
}

impl LoopConfig {
    /// Checks every field and the stability of the resulting digital loops.
    ///
    /// Bandwidths of loops that are switched off (order 0) are not checked.
    pub fn validate(&self) -> Result<(), ConfigError> {
        validate_t_coh_s(self.t_coh_s)?;
        if self.pll_order > 3 {
            return Err(ConfigError::BadOrder {
                field: "pll_order",
                value: self.pll_order,
                valid: "0 (no PLL), 1, 2, 3",
            });
        }
        if self.fll_order > 2 {
            return Err(ConfigError::BadOrder {
                field: "fll_order",
                value: self.fll_order,
                valid: "0 (no FLL), 1, 2",
            });
        }
        if !(1..=2).contains(&self.dll_order) {
            return Err(ConfigError::BadOrder {
                field: "dll_order",
                value: self.dll_order,
                valid: "1, 2",
            });
        }
        let supported = matches!(
            (self.pll_order, self.fll_order),
            (1..=3, 0) | (0, 1..=2) | (2, 1) | (3, 2)
        );
        if !supported {
            return Err(ConfigError::Combination {
                pll_order: self.pll_order,
                fll_order: self.fll_order,
            });
        }
        if self.pll_order > 0 {
            validate_bandwidth("pll_bw_hz", self.pll_bw_hz, self.t_coh_s)?;
        }
        if self.fll_order > 0 {
            validate_bandwidth("fll_bw_hz", self.fll_bw_hz, self.t_coh_s)?;
        }
        validate_bandwidth("dll_bw_hz", self.dll_bw_hz, self.t_coh_s)?;
        let (lo, hi) = EL_SPACING_RANGE_CHIPS;
        check_range("el_spacing_chips", self.el_spacing_chips, lo, hi, || {
            format!("{lo} ..= {hi} chips")
        })?;
        let carrier = LoopFilter::carrier_unchecked(self);
        if !loop_analysis::is_stable(&carrier, self.t_coh_s) {
            return Err(ConfigError::Unstable {
                which: "carrier",
                t_coh_s: self.t_coh_s,
            });
        }
        let code = LoopFilter::standard_unchecked(self.dll_order, self.dll_bw_hz);
        if !loop_analysis::is_stable(&code, self.t_coh_s) {
            return Err(ConfigError::Unstable {
                which: "code",
                t_coh_s: self.t_coh_s,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_valid() {
        assert_eq!(LoopConfig::default().validate(), Ok(()));
    }

    #[test]
    fn errors_name_the_field_and_range() {
        let mut c = LoopConfig {
            el_spacing_chips: 1.5,
            ..LoopConfig::default()
        };
        let msg = c
            .validate()
            .map_err(|e| e.to_string())
            .err()
            .unwrap_or_default();
        assert!(
            msg.contains("el_spacing_chips = 1.5") && msg.contains("0.1 ..= 1"),
            "{msg}"
        );
        c.el_spacing_chips = 0.5;
        c.t_coh_s = 0.0015;
        let msg = c
            .validate()
            .map_err(|e| e.to_string())
            .err()
            .unwrap_or_default();
        assert!(
            msg.contains("t_coh_s") && msg.contains("whole milliseconds"),
            "{msg}"
        );
        c.t_coh_s = 0.02;
        c.pll_bw_hz = 15.0; // 15 Hz * 20 ms = 0.3 > 0.2
        let msg = c
            .validate()
            .map_err(|e| e.to_string())
            .err()
            .unwrap_or_default();
        assert!(msg.contains("pll_bw_hz") && msg.contains("<= 10"), "{msg}");
        c.pll_bw_hz = f64::NAN;
        assert!(c.validate().is_err());
        c.pll_bw_hz = 5.0;
        c.fll_bw_hz = 2.0;
        c.fll_order = 2;
        let msg = c
            .validate()
            .map_err(|e| e.to_string())
            .err()
            .unwrap_or_default();
        assert!(msg.contains("(2, 1) or (3, 2)"), "{msg}");
        c.pll_order = 4;
        assert!(matches!(
            c.validate(),
            Err(ConfigError::BadOrder {
                field: "pll_order",
                ..
            })
        ));
    }

    #[test]
    fn unknown_keys_are_rejected_with_the_valid_list() {
        let text = "pll_order = 2\npll_bw_hz = 10.0\nfll_order = 0\nfll_bw_hz = 0.0\n\
                    dll_order = 1\ndll_bw_hz = 1.0\nt_coh_s = 0.001\nel_spacing_chips = 1.0\n\
                    pll_bandwidth = 3.0\n";
        let err = toml::from_str::<LoopConfig>(text)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            err.contains("pll_bandwidth") && err.contains("pll_bw_hz"),
            "{err}"
        );
        let ok: Result<LoopConfig, _> = toml::from_str(&text.replace("pll_bandwidth = 3.0\n", ""));
        assert!(ok.is_ok_and(|c| c.validate().is_ok()));
    }
}
