//! The conclusions on the PLL phase jitter and the loops themselves: the Costas formula in its
//! region, why it fails at low prompt SNR and beyond `Bn T = 0.1`, the cells not run, and the
//! settling time.

use super::conclusions::{cell_label, range_of};
use super::formulas::lin;
use super::grid::cn0_t;
use super::table::note;
use super::{
    CellResult, CellStatus, BNT_LIMIT, HIGH_SNR_CN0_T, MAX_SETTLE_S, SETTLE_MARGIN_S,
    THRESHOLD_SIGMA_DEG, TOLERANCE,
};
use crate::steady_state::stability_limit_bn_t;
use gpsrx_tracking::carrier_loop::MIN_COSTAS_SLOPE;
use gpsrx_tracking::config::MAX_BN_T;
use gpsrx_tracking::loop_filter::{A3, B3};
use std::fmt::Write as _;

/// Checks the Costas formula `sigma_phi = (360/(2 pi)) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))` deg
/// (oracles.md "Noise") where it should hold (`Bn T <= 0.1`, formula sigma <= 15 deg: the `3 sigma
/// <= 45` deg rule of thumb), separately at high (`C/N0 T >= 3`) and low prompt SNR: how many
/// cells held lock, how many of those are within 20 % of the formula, and the measured / formula
/// and measured / linearised digital loop ranges. Empty when the grid has no such cell.
pub(super) fn formula_region(results: &[CellResult]) -> String {
    let region: Vec<&CellResult> = results.iter().filter(|r| r.in_formula_region()).collect();
    let mut s = String::new();
    for (title, high) in [
        (
            "C/N0 T >= 3 (35 dB-Hz and up at 1 ms, every C/N0 at 20 ms)",
            true,
        ),
        ("C/N0 T < 3 (25 and 30 dB-Hz at 1 ms)", false),
    ] {
        let cells: Vec<&CellResult> = region
            .iter()
            .copied()
            .filter(|r| (cn0_t(&r.cell) >= HIGH_SNR_CN0_T) == high)
            .collect();
        s += &formula_region_part(&cells, title);
    }
    s
}

/// [`formula_region`] for one prompt-SNR half (`cells`, described by `title`), with the locked
/// cells beyond 20 % of the formula (and what the digital loop predicts for them) and the cells
/// that lost lock or slipped.
fn formula_region_part(cells: &[&CellResult], title: &str) -> String {
    let mut s = String::new();
    if cells.is_empty() {
        return s;
    }
    let locked: Vec<&CellResult> = cells.iter().copied().filter(|r| r.locked()).collect();
    let within = locked
        .iter()
        .filter(|r| r.within_tolerance() == Some(true))
        .count();
    let (lo, hi) = range_of(locked.iter().map(|r| r.ratio()));
    let (llo, lhi) = range_of(
        locked
            .iter()
            .map(|r| r.measured.phase_deg / r.theory.phase_loop_deg),
    );
    let ranges = if lo <= hi {
        format!(
            " (measured / formula {lo:.2}-{hi:.2}; measured / linearised digital loop \
             {llo:.2}-{lhi:.2})"
        )
    } else {
        String::new()
    };
    let _ = writeln!(
        s,
        "- Formula region (Bn T <= {BNT_LIMIT}, formula sigma <= {THRESHOLD_SIGMA_DEG} deg), \
         {title}: {} cells, {} held lock, {within} of those within 20 % of the Costas \
         formula{ranges}.",
        cells.len(),
        locked.len(),
    );
    let out: Vec<String> = locked
        .iter()
        .filter(|r| r.within_tolerance() == Some(false))
        .map(|r| {
            format!(
                "{} at {:.2} (Bn T {:.3}; the digital loop predicts {:.2}, with the atan \
                 statistics {:.2})",
                cell_label(&r.cell),
                r.ratio(),
                r.cell.bn_t(),
                r.theory.phase_digital_ratio,
                r.theory.phase_loop_deg / r.theory.phase_formula_deg
            )
        })
        .collect();
    if !out.is_empty() {
        let _ = writeln!(s, "  - Beyond 20 %: {}.", out.join("; "));
    }
    let lost: Vec<String> = cells
        .iter()
        .filter(|r| !r.locked())
        .map(|r| format!("{} ({})", cell_label(&r.cell), note(r)))
        .collect();
    if !lost.is_empty() {
        let _ = writeln!(s, "  - Lost lock or slipped: {}.", lost.join("; "));
    }
    s
}

/// The low prompt-SNR cells (`C/N0 T < 3`): whether the Costas formula held there (cells above
/// the rule-of-thumb threshold that lost lock or left the 20 % band, counted), and the theory
/// that explains a failure: the `atan(Q/I)` discriminator's slope `1 - exp(-C/N0 T)` (computed
/// per C/N0) and the 3rd-order loop's conditional stability (Routh on
/// `s^3 + g(b3 w s^2 + a3 w^2 s + w^3)`: `g a3 b3 > 1`), with how many 3rd-order 1 ms cells held
/// lock at each C/N0. Empty when no cell below `C/N0 T = 3` ran.
pub(super) fn low_snr_failure(results: &[CellResult]) -> String {
    let mut s = String::new();
    let low: Vec<&CellResult> = results
        .iter()
        .filter(|r| r.status == CellStatus::Run && cn0_t(&r.cell) < HIGH_SNR_CN0_T)
        .collect();
    if low.is_empty() {
        return s;
    }
    // Cells the rule of thumb calls trackable (formula sigma <= 15 deg, Bn T <= 0.1) that lost
    // lock or are beyond 20 % of the formula.
    let region: Vec<&CellResult> = low
        .iter()
        .copied()
        .filter(|r| r.in_formula_region())
        .collect();
    let failed = region
        .iter()
        .filter(|r| r.within_tolerance() != Some(true))
        .count();
    let g_min = 1.0 / (A3 * B3);
    let mut cn0s: Vec<f64> = low.iter().map(|r| r.cell.cn0_dbhz).collect();
    cn0s.sort_by(f64::total_cmp);
    cn0s.dedup();
    let per_cn0: Vec<String> = cn0s
        .iter()
        .map(|&cn0| {
            let g = 1.0 - (-lin(cn0) * 1e-3).exp();
            // The loop gain after the receiver's slope normalisation.
            let k = g / g.max(MIN_COSTAS_SLOPE);
            let (l, n) = order3_t1_locked(results, cn0);
            let stability = if k > g_min {
                "linearly stable"
            } else {
                "linearly unstable"
            };
            if n == 0 {
                format!("{cn0} dB-Hz: g = {g:.2} (no 3rd-order 1 ms cell ran)")
            } else {
                format!(
                    "{cn0} dB-Hz: g = {g:.2}, loop gain {k:.2}, every 3rd-order 1 ms loop \
                     {stability}, {l} of {n} held lock"
                )
            }
        })
        .collect();
    let verdict = if region.is_empty() {
        "no cell at C/N0 T < 3 is inside the formula region, so the rule of thumb is not \
         tested there"
            .to_string()
    } else if failed == 0 {
        format!(
            "all {} cells at C/N0 T < 3 inside the formula region held lock within 20 % of the \
             formula: the rule of thumb held here",
            region.len()
        )
    } else {
        format!(
            "{failed} of {} cells at C/N0 T < 3 inside the formula region (where the rule of \
             thumb `3 sigma <= 45` deg calls them trackable) lost lock or are beyond 20 % of \
             the formula: the rule of thumb is optimistic at this prompt SNR",
            region.len()
        )
    };
    let _ = writeln!(
        s,
        "- Low prompt SNR (C/N0 T < 3): {verdict}. Theory (the loops' design, computed here): \
         the `atan(Q/I)` discriminator's mean slope is `g = 1 - exp(-C/N0 T)` and its output \
         saturates at +-90 deg, so the formula's squaring loss `1 + 1/(2 T C/N0)` no longer \
         describes it (`phase_jitter_loop_deg` uses the discriminator's own statistics); a \
         3rd-order loop's analog characteristic polynomial `s^3 + k(b3 w s^2 + a3 w^2 s + w^3)` \
         needs a loop gain `k a3 b3 > 1`, k > {g_min:.2} (Routh); the receiver divides the \
         discriminator by `g` down to {MIN_COSTAS_SLOPE} (`CarrierLoop::costas_gain`), so \
         `k = g / max(g, {MIN_COSTAS_SLOPE})`. At 1 ms: {}.",
        per_cn0.join("; ")
    );
    s
}

/// The 3rd-order, T = 1 ms cells at `cn0` dB-Hz that ran: (how many held lock, how many).
fn order3_t1_locked(results: &[CellResult], cn0: f64) -> (usize, usize) {
    let v: Vec<&CellResult> = results
        .iter()
        .filter(|r| {
            r.status == CellStatus::Run
                && r.cell.order == 3
                && r.cell.t_ms == 1
                && r.cell.cn0_dbhz == cn0
        })
        .collect();
    (v.iter().filter(|r| r.locked()).count(), v.len())
}

/// Checks the locked cells beyond `Bn T = 0.1`: how far the measured jitter departs from the
/// formula (range of measured / formula, "above"/"below" chosen by the values), whether it is
/// within 20 % of the linearised digital loop's prediction, and the digital loop's realised
/// noise bandwidth over the design value (computed for these cells). Empty when no such cell
/// held lock.
pub(super) fn beyond_bnt_limit(results: &[CellResult]) -> String {
    let mut s = String::new();
    let cells: Vec<&CellResult> = results
        .iter()
        .filter(|r| r.locked() && r.cell.bn_t() > BNT_LIMIT + 1e-12)
        .collect();
    if cells.is_empty() {
        return s;
    }
    let beyond: Vec<String> = cells
        .iter()
        .map(|r| {
            format!(
                "{}: {:.2} (digital loop {:.2})",
                cell_label(&r.cell),
                r.ratio(),
                r.theory.phase_loop_deg / r.theory.phase_formula_deg
            )
        })
        .collect();
    let mut bnts: Vec<String> = cells
        .iter()
        .map(|r| format!("{:.2}", r.cell.bn_t()))
        .collect();
    bnts.sort();
    bnts.dedup();
    let (lo, hi) = range_of(cells.iter().map(|r| r.ratio()));
    let (blo, bhi) = range_of(cells.iter().map(|r| r.theory.bn_realised_ratio));
    let (llo, lhi) = range_of(
        cells
            .iter()
            .map(|r| r.measured.phase_deg / r.theory.phase_loop_deg),
    );
    let departs = departure(lo, hi);
    let follows = if (1.0 - TOLERANCE..=1.0 + TOLERANCE).contains(&llo)
        && (1.0 - TOLERANCE..=1.0 + TOLERANCE).contains(&lhi)
    {
        "within 20 % of what the linearised digital loop predicts"
    } else {
        "not within 20 % of what the linearised digital loop predicts"
    };
    let _ = writeln!(
        s,
        "- Beyond Bn T = {BNT_LIMIT} (here Bn T = {}): the digital loop's noise bandwidth is \
         {blo:.2}-{bhi:.2} x the design value (on the interval-average phase, computed for \
         these loops), and the measured jitter {departs}, {follows} (measured / loop \
         {llo:.2}-{lhi:.2}). Measured / formula: {}.",
        bnts.join(", "),
        beyond.join("; ")
    );
    s
}

/// How a range `lo..=hi` of measured / formula departs from 1, in words: "is 40-55 % above the
/// formula", "is 10-20 % below the formula" or "is within -5 % to +8 % of the formula".
pub(super) fn departure(lo: f64, hi: f64) -> String {
    let (a, b) = (100.0 * (lo - 1.0), 100.0 * (hi - 1.0));
    if a > 0.0 {
        format!("is {a:.0}-{b:.0} % above the formula")
    } else if b < 0.0 {
        format!("is {:.0}-{:.0} % below the formula", -b, -a)
    } else {
        format!("is {a:+.0} % to {b:+.0} % of the formula")
    }
}

/// Lists the (order, Bn, T) not run at any C/N0 because `LoopConfig::validate` rejects
/// `Bn T > MAX_BN_T`, each with whether its digital loop is stable, and the stability limits
/// ([`stability_limit_bn_t`]). Empty when every cell ran.
pub(super) fn rejected(results: &[CellResult]) -> String {
    let mut s = String::new();
    let rejected: Vec<String> = results
        .iter()
        .filter_map(|r| match &r.status {
            CellStatus::Rejected { stable, .. } => Some(format!(
                "order {} Bn {} Hz T {} ms (Bn T {:.2}, digital loop {})",
                r.cell.order,
                r.cell.bn_hz,
                r.cell.t_ms,
                r.cell.bn_t(),
                if *stable { "stable" } else { "unstable" }
            )),
            CellStatus::Run => None,
        })
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    if !rejected.is_empty() {
        let _ = writeln!(
            s,
            "- Not run (every C/N0): {}. `LoopConfig::validate` rejects Bn T > {MAX_BN_T}; the \
             2nd-order digital loop becomes unstable at Bn T = {:.2}, the 3rd-order at {:.2} \
             (`loop_analysis::is_stable`, computed here).",
            rejected.join("; "),
            stability_limit_bn_t(2),
            stability_limit_bn_t(3)
        );
    }
    s
}

/// States when each cell is measured (`settle_s` after the hand-over to tracking), with the
/// settling times `settle_s - 1 s` in units of `1/Bn` of the cells that ran, per order (from
/// [`super::transient_decay_time_s`]), and, when a 3rd-order cell ran, why the Kaplan 3rd-order
/// loop needs longer (its lightly damped pole pair, excited by the hand-over's frequency step).
pub(super) fn settling(results: &[CellResult]) -> String {
    let mut s = String::new();
    let per_order: Vec<String> = [2u8, 3]
        .iter()
        .filter_map(|&order| {
            let (lo, hi) = range_of(
                results
                    .iter()
                    .filter(|r| r.status == CellStatus::Run && r.cell.order == order)
                    .map(|r| (r.theory.settle_s - SETTLE_MARGIN_S) * r.cell.bn_hz),
            );
            (lo <= hi).then(|| {
                if hi - lo < 0.05 * hi {
                    format!("{lo:.1}/Bn s for order {order}")
                } else {
                    format!("{lo:.1}/Bn-{hi:.1}/Bn s for order {order}")
                }
            })
        })
        .collect();
    let order3_run = results
        .iter()
        .any(|r| r.status == CellStatus::Run && r.cell.order == 3);
    let _ = writeln!(
        s,
        "- Settling: every cell is measured from `settle_s` after its hand-over to tracking \
         ({SETTLE_MARGIN_S} s + {}, at most {MAX_SETTLE_S} s).",
        if per_order.is_empty() {
            "the linearised loop's decay time".to_string()
        } else {
            per_order.join(", ")
        }
    );
    if order3_run {
        let _ = writeln!(
            s,
            "  - Theory (the loop's design, not a measurement): the Kaplan 3rd-order loop \
             (a3 = {A3}, b3 = {B3}) has a lightly damped pair of closed-loop poles (damping ratio \
             0.22, decay rate 0.148 omega0, against 0.707 omega0 for order 2). The hand-over to \
             tracking moves the pull-in loop's last output, proportional term included, into \
             the new loop's base frequency: a frequency step of the size of the NCO's frequency \
             noise, which excites that pair. Handing over only the integrator state would \
             remove the hand-over step."
        );
    }
    s
}
