//! The headline cases: the 10 g turn (seed 004's manoeuvre) at 0.4 Hz, by C/N0, order and INS
//! bias, and the aided 1st-order loops.

use super::aiding::Aiding;
use super::manoeuvre::Manoeuvre;
use super::params::{HEADLINE_BN_HZ, MG_MPS2, NARROW_DEFAULT_BIAS_MG, ORDER1_BN_HZ};
use super::result::CaseResult;

/// Seed 004's manoeuvre.
pub(super) const TEN_G: Manoeuvre = Manoeuvre::Turn(10.0);

/// Which case to find.
#[derive(Debug, Clone, Copy)]
pub(super) struct Key {
    pub(super) manoeuvre: Manoeuvre,
    pub(super) cn0_dbhz: f64,
    pub(super) order: u8,
    pub(super) bn_hz: f64,
    pub(super) aiding: Aiding,
    /// INS 1 bias of the pair, m/s^2 (ignored unaided; None: any).
    pub(super) ins1_bias_mps2: Option<f64>,
}

/// The case of `key`, if it was run.
pub(super) fn find<'a>(results: &'a [CaseResult], key: &Key) -> Option<&'a CaseResult> {
    results.iter().find(|r| {
        r.spec.manoeuvre == key.manoeuvre
            && r.spec.cn0_dbhz == key.cn0_dbhz
            && r.case.order == key.order
            && r.case.bn_hz == key.bn_hz
            && r.case.aiding == key.aiding
            && (key.aiding == Aiding::Unaided
                || key
                    .ins1_bias_mps2
                    .is_none_or(|b| (r.case.ins1_bias_mps2 - b).abs() < 1e-12))
    })
}

/// The C/N0 values of the results, ascending.
pub(super) fn cn0s(results: &[CaseResult]) -> Vec<f64> {
    let mut v: Vec<f64> = results.iter().map(|r| r.spec.cn0_dbhz).collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// PRNs lost before the manoeuvre in every case at `cn0_dbhz`, whatever the loop or aiding
/// (a channel that never started, not a loop's doing).
pub(super) fn always_lost_before(results: &[CaseResult], cn0_dbhz: f64) -> Vec<u8> {
    let at: Vec<&CaseResult> = results
        .iter()
        .filter(|r| r.spec.cn0_dbhz == cn0_dbhz)
        .collect();
    at.first()
        .map(|r| r.lost_before_prns.clone())
        .unwrap_or_default()
        .into_iter()
        .filter(|p| at.iter().all(|r| r.lost_before_prns.contains(p)))
        .collect()
}

/// The INS 1 biases of the aided cases at `bn_hz`, ascending, m/s^2.
pub(super) fn ins1_biases(results: &[CaseResult], bn_hz: f64) -> Vec<f64> {
    let mut v: Vec<f64> = results
        .iter()
        .filter(|r| r.case.bn_hz == bn_hz && r.case.aiding != Aiding::Unaided)
        .map(|r| r.case.ins1_bias_mps2)
        .collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// Unaided, INS 1 and INS 2 cases of one loop at one C/N0 over the 10 g turn.
#[derive(Debug, Clone, Copy)]
pub(super) struct Trio<'a> {
    pub(super) unaided: Option<&'a CaseResult>,
    pub(super) ins1: Option<&'a CaseResult>,
    pub(super) ins2: Option<&'a CaseResult>,
}

impl<'a> Trio<'a> {
    /// The 10 g turn at `cn0_dbhz`, loop `order` at `bn_hz`, INS pair of `ins1_bias_mps2`.
    pub(super) fn new(
        results: &'a [CaseResult],
        cn0_dbhz: f64,
        order: u8,
        bn_hz: f64,
        ins1_bias_mps2: f64,
    ) -> Self {
        let f = |aiding| {
            find(
                results,
                &Key {
                    manoeuvre: TEN_G,
                    cn0_dbhz,
                    order,
                    bn_hz,
                    aiding,
                    ins1_bias_mps2: Some(ins1_bias_mps2),
                },
            )
        };
        Self {
            unaided: f(Aiding::Unaided),
            ins1: f(Aiding::Ins1),
            ins2: f(Aiding::Ins2),
        }
    }

    /// INS 2 / INS 1 of `f`, NaN when either case is missing.
    pub(super) fn ratio(&self, f: fn(&CaseResult) -> f64) -> f64 {
        match (self.ins1, self.ins2) {
            (Some(a), Some(b)) => f(b) / f(a),
            _ => f64::NAN,
        }
    }
}

/// The cases the summary and the conclusions single out: the 10 g turn at the highest C/N0,
/// orders 2 and 3 at 0.4 Hz with the default narrow bias, and the aided 1st-order loops.
pub(super) struct Headline<'a> {
    pub(super) cn0_dbhz: f64,
    pub(super) order2: Trio<'a>,
    pub(super) order3: Trio<'a>,
    pub(super) order1: Trio<'a>,
}

impl<'a> Headline<'a> {
    pub(super) fn new(results: &'a [CaseResult]) -> Self {
        Self::at(results, cn0s(results).last().copied().unwrap_or(f64::NAN))
    }

    /// The headline cases at `cn0_dbhz`.
    pub(super) fn at(results: &'a [CaseResult], cn0_dbhz: f64) -> Self {
        let b = NARROW_DEFAULT_BIAS_MG * MG_MPS2;
        let order1_bias = ins1_biases(results, ORDER1_BN_HZ)
            .first()
            .copied()
            .unwrap_or(f64::NAN);
        Self {
            cn0_dbhz,
            order2: Trio::new(results, cn0_dbhz, 2, HEADLINE_BN_HZ, b),
            order3: Trio::new(results, cn0_dbhz, 3, HEADLINE_BN_HZ, b),
            order1: Trio::new(results, cn0_dbhz, 1, ORDER1_BN_HZ, order1_bias),
        }
    }
}
