//! A cell's theory and measurement side by side, and how they compare.

use super::measure::Measured;
use super::params::{AGREE_DB, F_L1_HZ};
use super::theory::{
    allan_jitter_deg, detector_floor_dbhz, dynamic_stress_deg, rule_atan_dbhz, rule_threshold_dbhz,
    rule_with_slope_dbhz, stability_floor_dbhz, RuleInputs,
};
use super::Cell;
use crate::bandwidth::LoopNoiseGains;
use gpsrx_tracking::LoopFilter;

/// The theoretical thresholds of a cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellTheory {
    /// Dynamic stress error `theta_e`, deg (infinite: unbounded).
    pub stress_deg: f64,
    /// The rule of thumb `3 sigma + theta_e <= 45` deg with the design Bn, dB-Hz.
    pub rule_dbhz: Option<f64>,
    /// The rule with the stress divided by the Costas discriminator's slope, dB-Hz.
    pub rule_slope_dbhz: Option<f64>,
    /// The digital loop's realised noise bandwidth (linearised, discriminator slope 1), Hz.
    pub realised_bn_hz: f64,
    /// The rule of thumb with the realised Bn, dB-Hz.
    pub rule_realised_dbhz: Option<f64>,
    /// The rule with the receiver's own (`atan`) discriminator noise through the digital loop
    /// and the stress over the normalised gain, dB-Hz (`theory::rule_atan_dbhz`).
    pub rule_atan_dbhz: Option<f64>,
    /// The receiver's lock-detector floor with the rule's jitter, dB-Hz.
    pub detector_dbhz: Option<f64>,
    /// The C/N0 below which the linearised loop with the Costas slope is unstable, dB-Hz
    /// (`None`: stable at every C/N0).
    pub stable_dbhz: Option<f64>,
}

impl CellTheory {
    /// What the receiver can at best report: the highest of the rule, the detector floor and
    /// the stability floor (`None` if the rule or the detector has no threshold).
    pub fn expected_dbhz(&self) -> Option<f64> {
        Some(self.loop_expected_dbhz()?.max(self.detector_dbhz?))
    }

    /// What the loop itself can at best hold: the higher of the rule (with the stress over the
    /// discriminator's slope) and the stability floor.
    pub fn loop_expected_dbhz(&self) -> Option<f64> {
        Some(
            self.rule_slope_dbhz?
                .max(self.stable_dbhz.unwrap_or(f64::NEG_INFINITY)),
        )
    }
}

/// The theory of `cell` with a perfect clock (Allan deviation 0) and no vibration.
pub fn cell_theory(cell: &Cell) -> CellTheory {
    let stress_deg = dynamic_stress_deg(cell.order, cell.bn_hz, &cell.dynamics);
    let inputs = RuleInputs {
        bn_hz: cell.bn_hz,
        t_coh_s: cell.t_coh_s(),
        allan_deg: allan_jitter_deg(cell.order, cell.bn_hz, 0.0, F_L1_HZ).unwrap_or(0.0),
        vibration_deg: 0.0,
        stress_deg,
    };
    let realised_bn_hz = LoopFilter::pll(cell.order, cell.bn_hz)
        .map(|f| LoopNoiseGains::new(f, cell.bn_hz, cell.t_coh_s(), 1.0).noise_bandwidth_hz())
        .unwrap_or(f64::NAN);
    let phase_gain = LoopFilter::pll(cell.order, cell.bn_hz)
        .map(|f| LoopNoiseGains::phase_gain_of(f, cell.bn_hz, cell.t_coh_s(), 1.0))
        .unwrap_or(f64::NAN);
    CellTheory {
        stress_deg,
        rule_dbhz: rule_threshold_dbhz(&inputs),
        rule_slope_dbhz: rule_with_slope_dbhz(&inputs),
        realised_bn_hz,
        rule_realised_dbhz: rule_threshold_dbhz(&RuleInputs {
            bn_hz: realised_bn_hz,
            ..inputs
        }),
        rule_atan_dbhz: rule_atan_dbhz(&inputs, phase_gain),
        detector_dbhz: detector_floor_dbhz(&inputs),
        stable_dbhz: stability_floor_dbhz(cell.order, cell.bn_hz, cell.t_coh_s()),
    }
}

/// A cell's result.
#[derive(Debug, Clone, PartialEq)]
pub struct CellResult {
    /// The cell.
    pub cell: Cell,
    /// Why the receiver refuses its loop (then it is not run).
    pub rejected: Option<String>,
    /// Its theory.
    pub theory: CellTheory,
    /// Its measurement (`None` when rejected).
    pub measured: Option<Measured>,
}

/// How a measured threshold compares with a theoretical one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Agreement {
    /// Both have a threshold; measured minus theory, dB.
    Delta(f64),
    /// Neither has a threshold (the stress is too large for both).
    BothNone,
    /// Theory has a threshold, the loop never held.
    MeasuredNone,
    /// The loop held, theory has no threshold.
    TheoryNone,
}

impl Agreement {
    /// Compares `measured` with `theory`.
    pub fn of(measured: Option<f64>, theory: Option<f64>) -> Self {
        match (measured, theory) {
            (Some(m), Some(t)) => Self::Delta(m - t),
            (None, None) => Self::BothNone,
            (None, Some(_)) => Self::MeasuredNone,
            (Some(_), None) => Self::TheoryNone,
        }
    }

    /// Within [`AGREE_DB`] (or both without a threshold).
    pub fn agrees(&self) -> bool {
        match self {
            Self::Delta(d) => d.abs() <= AGREE_DB,
            Self::BothNone => true,
            _ => false,
        }
    }
}

impl CellResult {
    /// The measured threshold, dB-Hz.
    pub fn measured_dbhz(&self) -> Option<f64> {
        self.measured.and_then(|m| m.threshold_dbhz)
    }

    /// Measured against the rule of thumb (`None` for a rejected cell).
    pub fn vs_rule(&self) -> Option<Agreement> {
        self.measured
            .map(|m| Agreement::of(m.threshold_dbhz, self.theory.rule_dbhz))
    }

    /// The loop's own (slip-free) threshold, dB-Hz.
    pub fn loop_dbhz(&self) -> Option<f64> {
        self.measured.and_then(|m| m.loop_threshold_dbhz)
    }

    /// Measured against the rule with the receiver's own discriminator noise.
    pub fn vs_atan_rule(&self) -> Option<Agreement> {
        self.measured
            .map(|m| Agreement::of(m.threshold_dbhz, self.theory.rule_atan_dbhz))
    }

    /// The loop's own threshold against the rule of thumb.
    pub fn loop_vs_rule(&self) -> Option<Agreement> {
        self.measured
            .map(|m| Agreement::of(m.loop_threshold_dbhz, self.theory.rule_dbhz))
    }

    /// Measured against the expected threshold (rule and detector floor).
    pub fn vs_expected(&self) -> Option<Agreement> {
        self.measured
            .map(|m| Agreement::of(m.threshold_dbhz, self.theory.expected_dbhz()))
    }
}
