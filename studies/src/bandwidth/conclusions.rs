//! The report's conclusions: the section's order and the helpers its parts share. The parts
//! themselves live in [`super::phase_md`] (phase jitter and the loops), [`super::doppler_code_md`]
//! (Doppler, code, channels) and [`super::table_two_md`] (seed 004 Table 2).

use super::doppler_code_md::{code_error, doppler_error, released_channels, satellite_choice};
use super::phase_md::{beyond_bnt_limit, formula_region, low_snr_failure, rejected, settling};
use super::table_two_md::table_two;
use super::{Cell, CellResult, RunInfo, TableTwoRatio};
use std::fmt::Write as _;

/// A cell as the conclusions write it: C/N0/order/Bn/T (dB-Hz/-/Hz/ms).
pub(super) fn cell_label(c: &Cell) -> String {
    format!("{}/{}/{}/{}", c.cn0_dbhz, c.order, c.bn_hz, c.t_ms)
}

/// The smallest and largest finite value (`(inf, -inf)` when there is none).
pub(super) fn range_of(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        })
}

/// The "Conclusions" section of `study.md`: one bullet per conclusion (each empty when the grid
/// has no cell it speaks about), the seed 004 Table 2 comparison when the grid has both a locked
/// 1 Hz and 4 Hz cell of some (C/N0, order, T), and the run's size and wall time.
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
    s += &formula_region(results);
    s += &low_snr_failure(results);
    // 2. Beyond Bn T = 0.1.
    s += &beyond_bnt_limit(results);
    s += &rejected(results);
    // 3. Settling.
    s += &settling(results);
    // 4. Doppler and code.
    s += &doppler_error(results);
    s += &code_error(results);
    s += &satellite_choice();
    s += &released_channels(results);
    if !ratios.is_empty() {
        s += &table_two(ratios);
    }
    let _ = writeln!(
        s,
        "\nRun: {} recordings, {:.0} s of simulated signal, {:.1} s wall time.",
        info.recordings, info.recorded_s, info.wall_s
    );
    s
}
