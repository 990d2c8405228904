//! The conclusions on the Doppler (pseudorange-rate) and code errors, the choice of satellites
//! and the channels that were released.

use super::conclusions::{cell_label, range_of};
use super::grid::cn0_t;
use super::{
    CellResult, CellStatus, DLL_BN_HZ, EL_SPACING_CHIPS, FS_HZ, HIGH_SNR_CN0_T, LONG_INTERVAL_S,
    OBS_INTERVAL_S, PRNS,
};
use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use std::fmt::Write as _;

/// Checks the Doppler of the locked cells at `C/N0 T >= 3` against the linearised digital loop
/// (`LoopNoiseGains`: the PLL's Doppler has no standard closed form): the ranges of measured /
/// theory for the NCO frequency error, the 0.1 s and the 1 s carrier-phase pseudorange rate.
pub(super) fn doppler_error(results: &[CellResult]) -> String {
    let mut s = String::new();
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
    if high.is_empty() {
        return s;
    }
    // One-second differences per channel over the measurement window: the sampling uncertainty
    // of a std from n samples is about 1/sqrt(2n).
    let (nlo, nhi) = range_of(
        high.iter()
            .map(|r| r.measured.epochs as f64 * r.cell.t_s() / LONG_INTERVAL_S),
    );
    let _ = writeln!(
        s,
        "- Doppler (C/N0 T >= 3, locked): the NCO frequency error std is {dlo:.2}-{dhi:.2} x the \
         linearised digital loop's value, the {OBS_INTERVAL_S} s carrier-phase pseudorange rate \
         {plo:.2}-{phi:.2} x and the {LONG_INTERVAL_S} s one {qlo:.2}-{qhi:.2} x ({nlo:.0}-{nhi:.0} \
         one-second differences per satellite in this run: a std known to about +-{:.0} %). The \
         PLL's Doppler has no standard closed form; its std depends on what is output (NCO \
         frequency or a phase difference over tau).",
        100.0 / (2.0 * nlo.max(1.0)).sqrt()
    );
    s
}

/// Checks the code error of the locked cells against the linearised normalised-envelope DLL and
/// the oracle's E-L power formula `sqrt((Bn d/(2 CN0))(1 + 2/(T CN0 (2 - d))))` chips
/// (oracles.md), at `C/N0 T >= 10` and below, and explains why the power formula overstates the
/// envelope DLL's noise at low prompt SNR (half the squaring loss).
pub(super) fn code_error(results: &[CellResult]) -> String {
    let mut s = String::new();
    let ((a, b), (c, d)) = code_ratio_ranges(results, |x| x >= 10.0);
    let ((e, f), (g, h)) = code_ratio_ranges(results, |x| x < 10.0);
    let high = if a <= b {
        format!(
            "at C/N0 T >= 10 the measured std is {a:.2}-{b:.2} x the linearised envelope DLL and \
             {c:.2}-{d:.2} x the oracle's E-L *power* formula"
        )
    } else {
        "no locked cell at C/N0 T >= 10".to_string()
    };
    let low = if e <= f {
        // The power formula over the measurement, at its largest.
        let worst = results
            .iter()
            .filter(|r| r.locked() && cn0_t(&r.cell) < 10.0)
            .max_by(|x, y| {
                let q = |r: &&CellResult| r.theory.code_formula_chips / r.measured.code_chips;
                q(x).total_cmp(&q(y))
            });
        let over = worst.map_or(String::new(), |r| {
            let q = r.theory.code_formula_chips / r.measured.code_chips;
            format!(
                "; the power formula {} the channel's code noise, by up to {q:.1} x ({})",
                if q > 1.0 { "overstates" } else { "understates" },
                cell_label(&r.cell)
            )
        });
        format!(
            "Below (C/N0 T < 10) it is {e:.2}-{f:.2} x the envelope value and {g:.2}-{h:.2} x \
             the power formula{over}"
        )
    } else {
        "No locked cell below C/N0 T = 10".to_string()
    };
    let _ = writeln!(
        s,
        "- Code (DLL 1st order, Bn {DLL_BN_HZ} Hz, d = {EL_SPACING_CHIPS} chip, normalised \
         envelope): {high} (both tend to the coherent `Bn d/(2 C/N0)`). {low}. Theory: the \
         envelope discriminator's squaring loss is about half the power discriminator's \
         (`1 + 1/(T C/N0 (2 - d))` against `1 + 2/(T C/N0 (2 - d))` to first order) and its \
         gain drops with the noise-biased envelope sum."
    );
    s
}

/// Over the locked cells whose `C/N0 T` satisfies `pred`: the ranges of measured code error over
/// the envelope DLL's value and over the E-L power formula.
fn code_ratio_ranges(
    results: &[CellResult],
    pred: impl Fn(f64) -> bool,
) -> ((f64, f64), (f64, f64)) {
    let v: Vec<&CellResult> = results
        .iter()
        .filter(|r| r.locked() && pred(cn0_t(&r.cell)))
        .collect();
    let envelope = range_of(
        v.iter()
            .map(|r| r.measured.code_chips / r.theory.code_envelope_chips),
    );
    let formula = range_of(
        v.iter()
            .map(|r| r.measured.code_chips / r.theory.code_formula_chips),
    );
    (envelope, formula)
}

/// Explains the choice of satellites (G16, G25, G26): the ideal chips' correlation triangle,
/// sampled at `FS_HZ / 1.023 MHz` samples per chip, biases the code error of a satellite whose
/// code drifts slowly across the sample grid. A design note: nothing in it is measured by the
/// run.
pub(super) fn satellite_choice() -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "- Satellite choice (a design note, not measured in this run): the simulator's chips \
         are ideal (no front-end filter) and the correlation triangle is sampled at {:.2} \
         samples per chip; its E-L null moves with the code phase relative to the sample grid, \
         so a satellite whose code drifts slowly across the grid (near zero Doppler) would carry \
         that bias into the code error. The study uses {} whose Dopplers make the code drift \
         fast enough for the bias to average out within the DLL's time constant.",
        FS_HZ / CA_CHIP_RATE_HZ,
        PRNS.map(|p| format!("G{p:02}")).join(", ")
    );
    s
}

/// Lists the cells with channels released or never handed over to tracking (lost / channels),
/// with a possible cause (a wrong bit-synchronisation edge; not identified per channel). Empty
/// when none.
pub(super) fn released_channels(results: &[CellResult]) -> String {
    let mut s = String::new();
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
             lose lock at low prompt SNR (above), a possible cause at low C/N0 (not identified \
             per channel by this run) is a wrong bit-synchronisation edge: the C/N0 estimate over \
             20 ms blocks that straddle bit edges then falls below the release threshold.",
            lost.join(", ")
        );
    }
    s
}
