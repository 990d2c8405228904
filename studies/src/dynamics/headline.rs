//! The headline cases: the 10 g turn at the highest C/N0 of the grid.

use super::aiding::Aiding;
use super::manoeuvre::Manoeuvre;
use super::params::{HEADLINE_BN_HZ, ORDER1_BN_HZ};
use super::result::CaseResult;

/// The headline configuration: 10 g turn at the highest C/N0 of the grid.
pub(super) fn headline(
    results: &[CaseResult],
    order: u8,
    bn_hz: f64,
    aiding: Aiding,
) -> Option<&CaseResult> {
    let cn0 = results
        .iter()
        .map(|r| r.spec.cn0_dbhz)
        .fold(f64::NEG_INFINITY, f64::max);
    results.iter().find(|r| {
        r.spec.manoeuvre == Manoeuvre::Turn(10.0)
            && r.spec.cn0_dbhz == cn0
            && r.case.order == order
            && r.case.bn_hz == bn_hz
            && r.case.aiding == aiding
    })
}

/// The cases the summary and the conclusions single out (10 g turn, highest C/N0).
pub(super) struct Headline<'a> {
    pub(super) unaided: Option<&'a CaseResult>,
    pub(super) ins1: Option<&'a CaseResult>,
    pub(super) ins2: Option<&'a CaseResult>,
    pub(super) order1_ins1: Option<&'a CaseResult>,
    pub(super) order1_ins2: Option<&'a CaseResult>,
}

impl<'a> Headline<'a> {
    pub(super) fn new(results: &'a [CaseResult]) -> Self {
        let h = |o, bn, a| headline(results, o, bn, a);
        Self {
            unaided: h(2, HEADLINE_BN_HZ, Aiding::Unaided),
            ins1: h(2, HEADLINE_BN_HZ, Aiding::Ins1),
            ins2: h(2, HEADLINE_BN_HZ, Aiding::Ins2),
            order1_ins1: h(1, ORDER1_BN_HZ, Aiding::Ins1),
            order1_ins2: h(1, ORDER1_BN_HZ, Aiding::Ins2),
        }
    }

    /// `f(b) / f(a)`, NaN when either case is missing.
    fn ratio(a: Option<&CaseResult>, b: Option<&CaseResult>, f: fn(&CaseResult) -> f64) -> f64 {
        match (a, b) {
            (Some(a), Some(b)) => f(b) / f(a),
            _ => f64::NAN,
        }
    }

    /// INS 2 / INS 1 phase error std of the 2nd-order loop.
    pub(super) fn std_ratio(&self) -> f64 {
        Self::ratio(self.ins1, self.ins2, |r| r.phase_std_cycles)
    }

    /// INS 2 / INS 1 mean |phase error| of the 1st-order loop.
    pub(super) fn order1_mean_ratio(&self) -> f64 {
        Self::ratio(self.order1_ins1, self.order1_ins2, |r| r.disc_mean_abs_deg)
    }

    /// INS 2 / INS 1 phase error growth of the 1st-order loop.
    pub(super) fn order1_growth_ratio(&self) -> f64 {
        Self::ratio(self.order1_ins1, self.order1_ins2, |r| r.growth_abs_deg_s)
    }
}
