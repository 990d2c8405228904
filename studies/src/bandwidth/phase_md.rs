//! The conclusions on the PLL phase jitter and the loops themselves: the Costas formula in its
//! region, why it fails at low prompt SNR and beyond `Bn T = 0.1`, the cells not run, and the
//! settling time.

use super::conclusions::{cell_label, range_of};
use super::grid::cn0_t;
use super::table::note;
use super::{CellResult, CellStatus, BNT_LIMIT, HIGH_SNR_CN0_T, THRESHOLD_SIGMA_DEG};
use gpsrx_tracking::config::MAX_BN_T;
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
    let _ = writeln!(
        s,
        "- Formula region (Bn T <= {BNT_LIMIT}, formula sigma <= {THRESHOLD_SIGMA_DEG} deg), \
         {title}: {} cells, {} held lock, {within} of those within 20 % of the Costas \
         formula (measured / formula {lo:.2}-{hi:.2}; measured / linearised digital loop \
         {llo:.2}-{lhi:.2}).",
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

/// Explains why the formula fails near `C/N0 T = 1`: the `atan(Q/I)` discriminator's slope
/// `1 - exp(-C/N0 T)` and its saturation, and the 3rd-order loop's conditional stability (Routh
/// on `s^3 + g(b3 w s^2 + a3 w^2 s + w^3)`: `g a3 b3 > 1`), with how many 3rd-order 1 ms cells
/// held lock at 25 and 30 dB-Hz. Empty when no cell below `C/N0 T = 3` ran.
pub(super) fn low_snr_failure(results: &[CellResult]) -> String {
    let mut s = String::new();
    let low_run = results
        .iter()
        .any(|r| r.status == CellStatus::Run && cn0_t(&r.cell) < HIGH_SNR_CN0_T);
    if !low_run {
        return s;
    }
    let (l25, n25) = order3_t1_locked(results, 25.0);
    let (l30, n30) = order3_t1_locked(results, 30.0);
    let _ = writeln!(
        s,
        "- Why the formula fails near C/N0 T = 1: the `atan(Q/I)` discriminator's mean slope \
         is `1 - exp(-C/N0 T)` (0.27 at 25 dB-Hz, 0.63 at 30 dB-Hz, 1 ms) and its output \
         saturates at +-90 deg, so the formula's squaring loss `1 + 1/(2 T C/N0)` no longer \
         describes it (`phase_jitter_loop_deg` uses the discriminator's own statistics). A \
         3rd-order loop is only conditionally stable: with discriminator gain g its analog \
         characteristic polynomial `s^3 + g(b3 w s^2 + a3 w^2 s + w^3)` needs \
         `g a3 b3 > 1`, g > 0.38 (Routh); at 25 dB-Hz and 1 ms every 3rd-order loop is \
         linearly unstable ({l25} of {n25} held lock), and at 30 dB-Hz (g = 0.63, little \
         margin) {l30} of {n30} held lock. The oracle's rule of thumb (`3 sigma <= 45` deg \
         with the formula's sigma) is optimistic at this prompt SNR."
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

/// Checks the locked cells beyond `Bn T = 0.1`: measured / formula against the linearised
/// digital loop's prediction (the digital loop's noise bandwidth, 1.82 x for order 2 and 1.57 x
/// for order 3 at `Bn T = 0.2`, tracking/README.md). Empty when no such cell held lock.
pub(super) fn beyond_bnt_limit(results: &[CellResult]) -> String {
    let mut s = String::new();
    let beyond: Vec<String> = results
        .iter()
        .filter(|r| r.locked() && r.cell.bn_t() > BNT_LIMIT + 1e-12)
        .map(|r| {
            format!(
                "{}: {:.2} (digital loop {:.2})",
                cell_label(&r.cell),
                r.ratio(),
                r.theory.phase_loop_deg / r.theory.phase_formula_deg
            )
        })
        .collect();
    if !beyond.is_empty() {
        let _ = writeln!(
            s,
            "- Beyond Bn T = {BNT_LIMIT} (here Bn T = 0.2: 10 Hz at 20 ms) the digital loop's \
             noise bandwidth is well above the design value (1.82 x for order 2, 1.57 x for \
             order 3, on the interval-average phase: tracking/README.md), and the NCO phase at \
             the interval start carries more: the measured jitter departs from the formula by \
             40-55 %, as the linearised digital loop predicts. Measured / formula: {}.",
            beyond.join("; ")
        );
    }
    s
}

/// Lists the (order, Bn, T) not run at any C/N0 because `LoopConfig::validate` rejects
/// `Bn T > MAX_BN_T`, each with whether its digital loop is stable (unstable from `Bn T` = 0.44
/// for order 2, 0.56 for order 3, tracking/README.md). Empty when every cell ran.
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
             2nd-order digital loop becomes unstable at Bn T = 0.44, the 3rd-order at 0.56 \
             (tracking/README.md).",
            rejected.join("; ")
        );
    }
    s
}

/// States when each cell is measured (`settle_s` after the hand-over to tracking) and, when a
/// 3rd-order cell ran, why the Kaplan 3rd-order loop (a3 = 1.1, b3 = 2.4) needs about 43/Bn s
/// against 6.3/Bn s for the 2nd-order loop (its lightly damped pole pair, excited by the
/// hand-over's frequency step).
pub(super) fn settling(results: &[CellResult]) -> String {
    let mut s = String::new();
    let order3_run = results
        .iter()
        .any(|r| r.status == CellStatus::Run && r.cell.order == 3);
    let _ = writeln!(
        s,
        "- Settling: every cell is measured from `settle_s` after its hand-over to tracking{}",
        if order3_run {
            ":"
        } else {
            " (1 s + 6.3/Bn s for the 2nd-order loops)."
        }
    );
    if order3_run {
        let _ = writeln!(
            s,
            "  - The Kaplan 3rd-order loop (a3 = 1.1, b3 = 2.4) has a lightly damped pair of \
             closed-loop poles (damping ratio 0.22, decay rate 0.148 omega0). The hand-over to \
             tracking moves the pull-in loop's last output, proportional term included, into \
             the new loop's base frequency: a frequency step of the size of the NCO's frequency \
             noise, which excites that pair; it takes about 43/Bn s to decay to 3e-4 (90 s at \
             0.5 Hz) against 6.3/Bn s for the 2nd-order loop. In a first version of this study \
             (3rd-order pull-in from the random initial carrier phase, errors measured from \
             `1 + 5/Bn` s) the 0.5 Hz 3rd-order loops read up to 9.7 deg at 50 dB-Hz against \
             0.13 deg thermal, and at 35 dB-Hz one satellite fell into a slipping limit cycle \
             (its phase swung by tens of cycles over 140 s). Handing over only the integrator \
             state would remove the hand-over step."
        );
    }
    s
}
