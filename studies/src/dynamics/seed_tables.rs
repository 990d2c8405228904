//! Seed 004's Figs. 12/15 (satellites kept through the 10 g turn, unaided vs INS 1 vs INS 2) and
//! Table 3 (discriminator std of INS 1 and INS 2 and their ratio) at 0.4 Hz, as tables.

use super::aiding::Aiding;
use super::headline::{cn0s, ins1_biases, Trio};
use super::params::{HEADLINE_BN_HZ, MG_MPS2, NARROW_DEFAULT_BIAS_MG};
use super::result::CaseResult;
use crate::report::{fmt, Table};
use gpsrx_tracking::aiding::static_phase_offset_cycles;

/// Seed 004 Table 3: INS 2 / INS 1 phase error std of satellites 7, 8 and 13
/// (0.1013/0.09014, 0.09866/0.08450, 0.10061/0.09258).
pub(super) const PAPER_RATIO: (f64, f64) = (1.087, 1.168);

/// One row of Table 3: the INS 1 / INS 2 pair of one loop at one C/N0 and bias.
#[derive(Debug, Clone, Copy)]
pub(super) struct Table3Row<'a> {
    pub(super) cn0_dbhz: f64,
    pub(super) order: u8,
    /// INS 1 bias, m/s^2.
    pub(super) ins1_bias_mps2: f64,
    pub(super) ins1: &'a CaseResult,
    pub(super) ins2: &'a CaseResult,
}

impl Table3Row<'_> {
    /// INS 2 / INS 1 pooled discriminator std (Table 3's measure).
    pub(super) fn disc_ratio(&self) -> f64 {
        self.ins2.disc_std_cycles / self.ins1.disc_std_cycles
    }

    /// INS 2 / INS 1 phase std against the true carrier phase.
    pub(super) fn phase_ratio(&self) -> f64 {
        self.ins2.phase_std_cycles / self.ins1.phase_std_cycles
    }

    /// Smallest and largest per-satellite INS 2 / INS 1 discriminator std ratio (satellites
    /// with both stds; NaN when none).
    pub(super) fn sat_ratio_range(&self) -> (f64, f64) {
        let r: Vec<f64> = self
            .ins1
            .disc_std_per_sat
            .iter()
            .zip(&self.ins2.disc_std_per_sat)
            .map(|(a, b)| b / a)
            .filter(|x| x.is_finite())
            .collect();
        if r.is_empty() {
            return (f64::NAN, f64::NAN);
        }
        (
            r.iter().copied().fold(f64::INFINITY, f64::min),
            r.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }

    /// The largest static phase offset of the loop with INS `k` (1 or 2), cycles: the bias all
    /// on the line of sight, `B / (lambda w0^2)` at 2nd order, 0 at 3rd.
    pub(super) fn offset_bound_cycles(&self, k: f64) -> f64 {
        static_phase_offset_cycles(self.order, HEADLINE_BN_HZ, k * self.ins1_bias_mps2)
            .unwrap_or(f64::NAN)
    }
}

/// Every Table 3 row the results hold: C/N0, then order 2 and 3, then INS 1 bias, ascending.
pub(super) fn table3_rows(results: &[CaseResult]) -> Vec<Table3Row<'_>> {
    let mut out = Vec::new();
    for cn0 in cn0s(results) {
        for order in [2u8, 3] {
            for b in ins1_biases(results, HEADLINE_BN_HZ) {
                let t = Trio::new(results, cn0, order, HEADLINE_BN_HZ, b);
                if let (Some(ins1), Some(ins2)) = (t.ins1, t.ins2) {
                    out.push(Table3Row {
                        cn0_dbhz: cn0,
                        order,
                        ins1_bias_mps2: b,
                        ins1,
                        ins2,
                    });
                }
            }
        }
    }
    out
}

/// Table 3 as a table.
pub(super) fn table3(rows: &[Table3Row<'_>]) -> Table {
    let mut t = Table::new(&[
        "C/N0 (dB-Hz)",
        "order",
        "bias INS 1 / INS 2 (mg)",
        "largest offset INS 1 / INS 2 (cycle)",
        "kept INS 1 / INS 2",
        "disc. std INS 1 (cycle)",
        "disc. std INS 2 (cycle)",
        "ratio (paper 1.09-1.17)",
        "ratio per satellite",
        "phase std ratio (vs truth)",
    ]);
    for r in rows {
        let (lo, hi) = r.sat_ratio_range();
        let mg = r.ins1_bias_mps2 / MG_MPS2;
        t.push(vec![
            fmt(r.cn0_dbhz, 0),
            r.order.to_string(),
            format!("{} / {}", fmt(mg, 1), fmt(2.0 * mg, 1)),
            format!(
                "{} / {}",
                fmt(r.offset_bound_cycles(1.0), 3),
                fmt(r.offset_bound_cycles(2.0), 3)
            ),
            format!("{} / {} of {}", r.ins1.kept, r.ins2.kept, r.ins1.satellites),
            fmt(r.ins1.disc_std_cycles, 4),
            fmt(r.ins2.disc_std_cycles, 4),
            fmt(r.disc_ratio(), 3),
            format!("{}-{}", fmt(lo, 2), fmt(hi, 2)),
            fmt(r.phase_ratio(), 3),
        ]);
    }
    t
}

/// Figs. 12 and 15 as a table: satellites through the 10 g turn at 0.4 Hz, unaided and aided
/// by INS 1 and INS 2 (1 mg pair), per C/N0 and order.
pub(super) fn fig12_15(results: &[CaseResult]) -> Table {
    let mut t = Table::new(&[
        "C/N0 (dB-Hz)",
        "order",
        "aiding",
        "sats at start",
        "tracked min",
        "tracked mean",
        "kept",
        "lock drops",
    ]);
    for cn0 in cn0s(results) {
        for order in [2u8, 3] {
            let trio = Trio::new(
                results,
                cn0,
                order,
                HEADLINE_BN_HZ,
                NARROW_DEFAULT_BIAS_MG * MG_MPS2,
            );
            for (a, r) in [
                (Aiding::Unaided, trio.unaided),
                (Aiding::Ins1, trio.ins1),
                (Aiding::Ins2, trio.ins2),
            ] {
                let Some(r) = r else { continue };
                t.push(vec![
                    fmt(cn0, 0),
                    order.to_string(),
                    a.label().to_string(),
                    format!("{}/{}", r.tracked_at_start, r.satellites),
                    r.tracked_min.to_string(),
                    fmt(r.tracked_mean, 1),
                    r.kept.to_string(),
                    r.lock_drops.to_string(),
                ]);
            }
        }
    }
    t
}
