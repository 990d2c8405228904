//! The report's conclusions.

use super::grid::cn0_t;
use super::table::note;
use super::{
    Cell, CellResult, CellStatus, RunInfo, TableTwoRatio, BNT_LIMIT, DLL_BN_HZ, EL_SPACING_CHIPS,
    HIGH_SNR_CN0_T, THRESHOLD_SIGMA_DEG,
};
use gpsrx_tracking::config::MAX_BN_T;
use std::fmt::Write as _;

fn cell_label(c: &Cell) -> String {
    format!("{}/{}/{}/{}", c.cn0_dbhz, c.order, c.bn_hz, c.t_ms)
}

pub(super) fn range_of(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        })
}

pub(super) fn conclusions(
    results: &[CellResult],
    ratios: &[TableTwoRatio],
    info: &RunInfo,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Conclusions\n\nCells are written C/N0/order/Bn/T (dB-Hz/-/Hz/ms).\n"
    );
    // 1. The formula region, split by prompt SNR.
    let region: Vec<&CellResult> = results.iter().filter(|r| r.in_formula_region()).collect();
    for (title, high) in [
        (
            "C/N0 T >= 3 (35 dB-Hz and up at 1 ms, every C/N0 at 20 ms)",
            true,
        ),
        ("C/N0 T < 3 (25 and 30 dB-Hz at 1 ms)", false),
    ] {
        let cells: Vec<&&CellResult> = region
            .iter()
            .filter(|r| (cn0_t(&r.cell) >= HIGH_SNR_CN0_T) == high)
            .collect();
        if cells.is_empty() {
            continue;
        }
        let locked: Vec<&&&CellResult> = cells.iter().filter(|r| r.locked()).collect();
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
    }
    let low_run = results
        .iter()
        .any(|r| r.status == CellStatus::Run && cn0_t(&r.cell) < HIGH_SNR_CN0_T);
    if low_run {
        let order3 = |cn0: f64| {
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
        };
        let (l25, n25) = order3(25.0);
        let (l30, n30) = order3(30.0);
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
    }
    // 2. Beyond Bn T = 0.1.
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
    // 3. Settling.
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
    // 4. Doppler and code.
    let high: Vec<&CellResult> = results
        .iter()
        .filter(|r| r.locked() && cn0_t(&r.cell) >= HIGH_SNR_CN0_T)
        .collect();
    let (dlo, dhi) = range_of(
        high.iter()
            .map(|r| r.measured.doppler_hz / r.theory.doppler_hz),
    );
    let (plo, phi) = range_of(
        high.iter()
            .map(|r| r.measured.pr_rate_mps / r.theory.pr_rate_mps),
    );
    let (qlo, qhi) = range_of(
        high.iter()
            .map(|r| r.measured.pr_rate_1s_mps / r.theory.pr_rate_1s_mps),
    );
    let _ = writeln!(
        s,
        "- Doppler (C/N0 T >= 3, locked): the NCO frequency error std is {dlo:.2}-{dhi:.2} x the \
         linearised digital loop's value, the 0.1 s carrier-phase pseudorange rate \
         {plo:.2}-{phi:.2} x and the 1 s one {qlo:.2}-{qhi:.2} x (about 24-48 one-second \
         differences per satellite: +-15 %). The PLL's Doppler has no standard closed form; its \
         std depends on what is output (NCO frequency or a phase difference over tau)."
    );
    let code_rows = |pred: &dyn Fn(f64) -> bool| -> (f64, f64, f64, f64) {
        let v: Vec<&CellResult> = results
            .iter()
            .filter(|r| r.locked() && pred(cn0_t(&r.cell)))
            .collect();
        let (a, b) = range_of(
            v.iter()
                .map(|r| r.measured.code_chips / r.theory.code_envelope_chips),
        );
        let (c, d) = range_of(
            v.iter()
                .map(|r| r.measured.code_chips / r.theory.code_formula_chips),
        );
        (a, b, c, d)
    };
    let (a, b, c, d) = code_rows(&|x| x >= 10.0);
    let (e, f, g, h) = code_rows(&|x| x < 10.0);
    let _ = writeln!(
        s,
        "- Code (DLL 1st order, Bn {DLL_BN_HZ} Hz, d = {EL_SPACING_CHIPS} chip, normalised \
         envelope): at C/N0 T >= 10 the measured std is {a:.2}-{b:.2} x the linearised \
         envelope DLL and {c:.2}-{d:.2} x the oracle's E-L *power* formula (both tend to the \
         coherent `Bn d/(2 C/N0)`). Below (C/N0 T < 10) it is {e:.2}-{f:.2} x the envelope \
         value and {g:.2}-{h:.2} x the power formula: the envelope discriminator's squaring \
         loss is about half the power discriminator's (`1 + 1/(T C/N0 (2 - d))` against \
         `1 + 2/(T C/N0 (2 - d))` to first order) and its gain drops with the noise-biased \
         envelope sum, so the power formula overstates the channel's code noise up to \
         threefold at 25 dB-Hz and 1 ms."
    );
    let _ = writeln!(
        s,
        "- Satellite choice: the simulator's chips are ideal (no front-end filter) and the \
         correlation triangle is sampled at 2.44 samples per chip; its E-L null moves with the \
         code phase relative to the sample grid. A satellite whose code drifts slowly across \
         the grid (G31, +201 Hz Doppler: 0.13 chip/s, a 3 s period) carries that bias into the \
         code error: in a separate run at 50 dB-Hz (Bn 10 Hz, T 1 ms) G31 read 0.0043 chip \
         against 0.0024 chip for G16 (+3672 Hz) and the 0.00225 chip theory. The study uses \
         G16, G25 and G26 (1.3-2.4 chip/s) so that the bias averages out within the DLL's time \
         constant."
    );
    let lost: Vec<String> = results
        .iter()
        .filter(|r| r.status == CellStatus::Run && r.measured.lost > 0)
        .map(|r| {
            format!(
                "{} ({}/{})",
                cell_label(&r.cell),
                r.measured.lost,
                r.measured.channels
            )
        })
        .collect();
    if !lost.is_empty() {
        let _ = writeln!(
            s,
            "- Channels released or never handed over to tracking: {}. Besides the loops that \
             lose lock at low prompt SNR (above), a channel at 25 dB-Hz can be released a few \
             seconds after start when its bit synchronisation (sized for 30 dB-Hz at a \
             false-sync probability of 1e-4) picks a wrong edge: its C/N0 estimate over 20 ms \
             blocks that straddle bit edges then falls below 20 dB-Hz (G25 in the 40 s \
             recording at 25 dB-Hz: edge 7 ms off, C/N0 read 2-16 dB-Hz, released at 3.3 s, in \
             every configuration tracked on it).",
            lost.join(", ")
        );
    }
    if !ratios.is_empty() {
        let _ = writeln!(
            s,
            "\n### Seed 004 Table 2: pseudorange-rate error std at Bn = 4 Hz over Bn = 1 Hz\n\n\
             Seed 004 measured 1.65, 1.72 and 1.81 (static, 2nd-order PLL, real front end and \
             oscillator, averaging interval not stated).\n\n\
             | C/N0 | order | T ms | NCO Doppler measured | theory | 0.1 s measured | theory | \
             1 s measured | theory |\n|---|---|---|---|---|---|---|---|---|"
        );
        for r in ratios {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
                r.cn0_dbhz,
                r.order,
                r.t_ms,
                r.nco_measured,
                r.nco_theory,
                r.obs_0p1s_measured,
                r.obs_0p1s_theory,
                r.obs_1s_measured,
                r.obs_1s_theory
            );
        }
        let o2: Vec<&TableTwoRatio> = ratios.iter().filter(|r| r.order == 2).collect();
        let (a, b) = range_of(o2.iter().map(|r| r.obs_1s_measured));
        let (c, d) = range_of(o2.iter().map(|r| r.obs_0p1s_measured));
        let (e, f) = range_of(o2.iter().map(|r| r.nco_measured));
        let _ = writeln!(
            s,
            "\nWhich ratio one gets depends on what is called the Doppler. The NCO frequency \
             carries the loop filter's proportional path, which passes the white discriminator \
             noise straight through (`u ~ a2 omega0 e`): its std grows as Bn (order 2 measured \
             {e:.2}-{f:.2}; theory 4.0 at 1 ms, 4.3 at 20 ms where Bn T = 0.08 widens the 4 Hz \
             loop). The Doppler a receiver outputs is a carrier-phase \
             difference over its observable interval tau. For tau much longer than the loop's \
             time constant (`1/omega0` = 0.53 s at 1 Hz, 0.13 s at 4 Hz) it is \
             `sqrt(2) sigma_phi / tau` and the ratio is `sqrt(4) = 2` because the thermal \
             jitter grows as `sqrt(Bn)` (1 s: measured {a:.2}-{b:.2}); for tau = 0.1 s, shorter \
             than the 1 Hz loop's time constant, the narrow loop's phase is still correlated \
             over tau and the ratio is larger (measured {c:.2}-{d:.2}). The often-quoted `Bn^1.5` \
             (8x) applies to the low-frequency part of the loop's frequency error alone, not to \
             either output. Seed 004's 1.65-1.81 is therefore consistent with a Doppler averaged \
             over about a second plus a noise share that does not grow with Bn: in a real receiver the oscillator's Allan \
             term grows as 1/Bn and pulls the ratio below 2, and this simulation has no \
             oscillator noise."
        );
    }
    let _ = writeln!(
        s,
        "\nRun: {} recordings, {:.0} s of simulated signal, {:.1} s wall time.",
        info.recordings, info.recorded_s, info.wall_s
    );
    s
}
