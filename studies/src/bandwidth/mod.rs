//! `gpsrx study bandwidth`: carrier phase jitter, Doppler (pseudorange-rate) error and code error
//! of the implemented channels on simulated IF, over a grid of C/N0, PLL order, noise bandwidth
//! Bn and integration time T, against the thermal-noise formulas (oracles.md "Noise").
//!
//! # What is simulated
//!
//! A static receiver (Seoul) with a noiseless clock (Allan deviation 0) sees three satellites
//! (G16, G25, G26, see [`PRNS`]) at the same C/N0, in in-memory recordings
//! ([`super::if_sim::SimSource`], complex floats at 2.5 MHz, no quantisation) whose length each
//! cell's settling time sets. Every satellite is tracked by one channel per (order, Bn, T) cell
//! over the same samples, started from truth (code phase, Doppler) and, unless `--unaided`, with
//! the true Doppler fed forward (a perfect INS, seed 004 eq. 7), which removes the satellites'
//! own LOS dynamics so that only the thermal noise is left. Each channel pulls in with a PLL of
//! its Bn at T = 1 ms (order 2 for the 3rd-order cells, no FLL assist; [`cell_channel_config`]);
//! its own loop and T start at the hand-over to tracking (after bit synchronisation, on a bit
//! edge). Errors are measured against
//! the simulator's truth at every integration interval after the cell's settling time from the
//! hand-over ([`transient_decay_time_s`]: start-up transients down to [`SETTLE_FRACTION`]): the
//! replica (NCO) carrier phase at the interval's first sample against the true carrier phase
//! (offset and Costas half cycle removed), the NCO frequency held over the interval against the
//! true mean Doppler, the receiver's observable Doppler (carrier-phase change over 0.1 s, the
//! 10 Hz observable rate of `gpsrx run`; and over 1 s) against the true one, and the code phase
//! against the true one. Loss of lock (a released channel, a half-cycle slip against truth, a
//! code error beyond half a chip) is detected per channel and reported, never averaged in.
//!
//! # The formulas
//!
//! - PLL, Costas (oracles.md): `sigma_phi = (360/(2 pi)) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))` deg
//!   ([`pll_jitter_deg`]).
//! - DLL, non-coherent early-minus-late power, spacing d (oracles.md):
//!   `sigma = sqrt((Bn d/(2 CN0))(1 + 2/(T CN0 (2 - d))))` chips ([`dll_jitter_chips`]). The
//!   channel's DLL is the normalised early-minus-late *envelope* `(2-d)/2 (|E|-|L|)/(|E|+|L|)`
//!   with d = 1: the same coherent term `Bn d/(2 CN0)`, a smaller squaring loss; its own value
//!   ([`envelope_dll_stats`] in the linearised loop) is reported beside the formula.
//! - FLL (oracles.md): `sigma_f = (1/(2 pi T)) sqrt((4 F Bn/CN0)(1 + 1/(T CN0)))` Hz
//!   ([`fll_jitter_hz`]); for reference (the study's loops are PLLs).
//! - Doppler of a PLL: there is no standard closed form, so it is computed from the implemented
//!   digital loop ([`LoopNoiseGains`]): with white discriminator noise of variance
//!   `s^2 = (1/(2 T CN0))(1 + 1/(2 T CN0))/(2 pi)^2` cycles^2 per update (the variance that makes
//!   `2 Bn T s^2` the Costas formula), the NCO phase `phi_k` and frequency `u_k` are linear in
//!   the noise; their impulse responses `h_phi`, `h_u` give `var(phi) = s^2 sum h_phi^2`,
//!   `var(u) = s^2 sum h_u^2` and, for the Doppler from the phase change over `tau = m T`,
//!   `var = s^2 sum_j ((h_phi[j+m] - h_phi[j])/tau)^2`. The same sums give the digital loop's
//!   realised noise bandwidth `Bn' = sum (h_phi + h_u T/2)^2 / (2 T)` (on the interval-average
//!   phase, as in `gpsrx_tracking::loop_analysis`).
//! - "loop" columns: the same linearised digital loop with the discriminator's own statistics at
//!   the prompt SNR `rho = CN0 T` instead of the formula's: for `atan(Q/I)` the slope
//!   `1 - exp(-rho)` and the output variance from the phase distribution of a carrier in
//!   Gaussian noise ([`costas_atan_stats`]). This is what the measurement should match where the
//!   formula's assumptions (analog loop, small `Bn T`, high SNR) fail.

mod channel;
mod conclusions;
#[cfg(test)]
mod conclusions_tests;
mod discriminator;
mod doppler_code_md;
mod formulas;
mod grid;
mod intro;
mod loop_noise;
mod measure;
mod params;
mod phase_md;
mod plan;
mod plots;
mod ratios;
mod result;
mod table;
mod table_two_abs;
mod table_two_md;
mod theory;
mod track;

pub use self::channel::{cell_channel_config, cell_status, CellStatus};
pub use self::discriminator::{
    carrier_phase_pdf, costas_atan_stats, envelope_dll_stats, gauss_hermite, DiscriminatorStats,
};
pub use self::formulas::{
    costas_formula_noise_var_cycles2, dll_jitter_chips, fll_jitter_hz, pll_jitter_deg,
};
pub use self::grid::{full_grid, quick_grid, Cell, HIGH_SNR_CN0_T};
pub use self::loop_noise::{stable_with_slope, transient_decay_time_s, LoopNoiseGains};
pub use self::measure::{measure_cell, CellMeasured};
pub use self::params::{
    BNT_LIMIT, DLL_BN_HZ, EL_SPACING_CHIPS, FS_HZ, LONG_INTERVAL_S, OBS_INTERVAL_S, PRNS,
    THRESHOLD_SIGMA_DEG, TOLERANCE,
};
pub use self::plan::cell_window_s;
pub use self::ratios::{table_two_ratios, TableTwoRatio};
pub use self::result::CellResult;
pub use self::theory::{cell_theory, CellTheory, MAX_SETTLE_S, SETTLE_FRACTION, SETTLE_MARGIN_S};

use self::plan::cases;
use self::table::build_report;
use self::track::run_case;
use super::report::StudyReport;
use super::{run_cases, CommonStudyArgs};
use std::time::Instant;

/// `gpsrx study` options of this study.
#[derive(Debug, Clone, clap::Args)]
pub struct BandwidthArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
    /// Measurement window after each cell's settling time, s [default: 24, or 12 with --quick];
    /// each recording lasts 2 s + the slowest settling time of its cells + this window.
    #[arg(long, value_name = "S")]
    pub window_s: Option<f64>,
    /// Track without the perfect (truth) Doppler feed-forward: the satellites' own LOS
    /// acceleration then loads narrow loops (a linear trend of the phase error is removed).
    #[arg(long)]
    pub unaided: bool,
}

/// Runs the study.
pub fn run(args: &BandwidthArgs, progress: bool) -> anyhow::Result<StudyReport> {
    use rayon::prelude::*;
    let t_start = Instant::now();
    let quick = args.common.quick;
    let grid = if quick { quick_grid() } else { full_grid() };
    let window_s = args.window_s.unwrap_or(if quick { 12.0 } else { 24.0 });
    if !(window_s.is_finite() && (2.0..=600.0).contains(&window_s)) {
        anyhow::bail!("--window-s {window_s} is out of range; valid: 2 ..= 600 s");
    }
    let aided = !args.unaided;
    let theories: Vec<CellTheory> = grid.par_iter().map(cell_theory).collect();
    let runnable: Vec<(Cell, f64)> = grid
        .iter()
        .zip(&theories)
        .filter(|(c, _)| cell_status(c) == CellStatus::Run)
        // A loop whose linearised form is unstable still runs (to show that it loses lock),
        // measured after the longest settling time.
        .map(|(c, t)| {
            (
                *c,
                if t.settle_s.is_finite() {
                    t.settle_s
                } else {
                    MAX_SETTLE_S
                },
            )
        })
        .collect();
    let cases = cases(&runnable, args.common.seed, window_s);
    let outcomes = run_cases(&cases, "bandwidth", progress, |c| {
        run_case(c, aided, &crate::if_sim::Oscillator::NONE)
    });
    let mut measured: Vec<(Cell, CellMeasured, f64)> = Vec::new();
    for (case, out) in cases.iter().zip(outcomes) {
        let out = out?;
        measured.extend(
            case.cells
                .iter()
                .zip(out)
                .map(|((c, _), m)| (*c, m, case.duration_s)),
        );
    }
    let results: Vec<CellResult> = grid
        .iter()
        .zip(theories)
        .map(|(cell, theory)| {
            let m = measured.iter().find(|(c, _, _)| c == cell);
            CellResult {
                cell: *cell,
                status: cell_status(cell),
                theory,
                measured: m.map(|(_, m, _)| m.clone()).unwrap_or_default(),
                duration_s: m.map(|(_, _, d)| *d).unwrap_or(f64::NAN),
            }
        })
        .collect();
    let recorded_s: f64 = cases.iter().map(|c| c.duration_s).sum();
    let wall_s = t_start.elapsed().as_secs_f64();
    let absolute = table_two_abs::run_absolute(args.common.seed, window_s, quick, progress)?;
    let mut report = build_report(
        &results,
        &RunInfo {
            window_s,
            aided,
            quick,
            seed: args.common.seed,
            recordings: cases.len(),
            recorded_s,
            wall_s,
        },
    );
    report.conclusions_md += &table_two_abs::absolute_md(&absolute);
    if let Some(obj) = report.summary.as_object_mut() {
        obj.insert(
            "table_two_absolute".into(),
            serde_json::to_value(&absolute).unwrap_or_default(),
        );
    }
    Ok(report)
}

/// How the study ran.
#[derive(Debug, Clone, Copy)]
struct RunInfo {
    window_s: f64,
    aided: bool,
    quick: bool,
    seed: u64,
    recordings: usize,
    recorded_s: f64,
    wall_s: f64,
}
