//! `gpsrx study threshold`: the measured tracking threshold of the receiver's carrier loops
//! (the lowest C/N0 at which carrier lock is held at least 95 % of 30 s) for PLL orders 1-3,
//! noise bandwidths 0.4-18 Hz, integration times 1 and 20 ms, static and under stated dynamics
//! (unaided and INS-aided), against the theoretical threshold (the rule of thumb
//! `3 sigma + theta_e <= 45` deg for a Costas PLL, Kaplan & Hegarty 2nd ed. sec. 5.6).
//!
//! - theory ([`rule_threshold_dbhz`], [`rule_atan_dbhz`], [`detector_floor_dbhz`],
//!   [`stability_floor_dbhz`], [`rule_with_slope_dbhz`]): the rule of thumb (with Kaplan's
//!   thermal formula and with the receiver's own discriminator noise) and the floors, solved
//!   for C/N0.
//! - sim ([`run_once`]): one 30 s run at the level of 1 ms correlator outputs with the
//!   receiver's carrier loop, lock detector and fade detector; "lock held" is the channel's
//!   `pll_lock`.
//! - measure ([`measure_cell`]): the scan down in C/N0 (0.5 dB steps, [`RUNS_PER_STEP`] runs
//!   pooled per step, fixed seeds).
//! - grid ([`full_grid`], [`quick_grid`]) and [`Dynamics`]: the cells; [`CellResult`],
//!   [`build_table`], the plots and [`conclusions_md`]: the report. Besides `study.csv` the
//!   study writes the same table as `threshold.csv`.
//! - IF cross-check ([`if_cross_check`]): the receiver's whole channel on simulated IF samples
//!   2 dB above and below two cells' measured thresholds.
//! - DLL sweep ([`run_dll_sweep`]): code jitter of the carrier-aided DLL against theory,
//!   written to `dll.csv` and appended to the report.

mod conclusions;
mod dll;
mod dynamics;
mod grid;
mod if_check;
mod measure;
mod params;
mod plots;
mod result;
mod sim;
mod table;
mod theory;

pub use self::conclusions::conclusions_md;
pub use self::dll::{
    dll_md, dll_points, dll_table, dll_theory, run_dll, DllPoint, DllResult, DLL_SETTLE_S,
    DLL_SPACING_CHIPS, DLL_TOLERANCE,
};
pub use self::dynamics::Dynamics;
pub use self::grid::{full_grid, quick_grid, Cell, BN_HZ, DYNAMICS, T_COH_MS};
pub use self::if_check::{
    if_check_md, if_cross_check, if_lock_shares, IfCheckRow, IF_CHECK_CELLS, IF_CHECK_OFFSET_DB,
    IF_LEAD_S,
};
pub use self::measure::{measure_cell, run_seed, run_seed_raw, Measured};
pub use self::params::{
    AGREE_DB, HOLD_FRACTION, PRE_ROLL_S, RULE_LIMIT_DEG, RUNS_PER_STEP, SCAN_BOTTOM_DBHZ,
    SCAN_STEP_DB, SCAN_TOP_DBHZ, WINDOW_S,
};
pub use self::result::{cell_theory, Agreement, CellResult, CellTheory};
pub use self::sim::{run as run_once, steady_state_error_cycles, RunOutcome};
pub use self::table::{build_table, COLUMNS};
pub use self::theory::{
    allan_jitter_deg, atan_thermal_jitter_deg, detector_floor_dbhz, detector_relative_error,
    dynamic_stress_deg, loop_gain, rule_atan_dbhz, rule_threshold_dbhz, rule_with_slope_dbhz,
    stability_floor_dbhz, RuleInputs,
};

use super::report::{StudyReport, Table};
use super::{run_cases, CommonStudyArgs};
use std::time::Instant;

/// The CSV the issue asks for (the study's table), besides `study.csv`.
pub const CSV_NAME: &str = "threshold.csv";
/// The DLL sweep's CSV.
pub const DLL_CSV_NAME: &str = "dll.csv";

/// `gpsrx study` options of this study.
#[derive(Debug, Clone, clap::Args)]
pub struct ThresholdArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
}

/// Measures every cell of `cells` (rejected loops are listed, not run).
pub fn measure_cells(cells: &[Cell], seed: u64, progress: bool) -> anyhow::Result<Vec<CellResult>> {
    let outcomes = run_cases(cells, "threshold", progress, |c| {
        if c.rejected().is_some() {
            Ok(None)
        } else {
            measure_cell(c, seed).map(Some)
        }
    });
    cells
        .iter()
        .zip(outcomes)
        .map(|(c, m)| {
            Ok(CellResult {
                cell: *c,
                rejected: c.rejected(),
                theory: cell_theory(c),
                measured: m?,
            })
        })
        .collect()
}

/// Runs the DLL sweep ([`dll_points`]) in parallel.
pub fn run_dll_sweep(quick: bool, seed: u64, progress: bool) -> anyhow::Result<Vec<DllResult>> {
    let points = dll_points(quick);
    let out = run_cases(&points, "dll", progress, |p| {
        let key = (u64::from(p.order) << 32)
            ^ (((p.bn_hz * 10.0).round() as u64) << 16)
            ^ (u64::from(p.t_coh_ms) << 8)
            ^ (p.cn0_dbhz.round() as u64);
        run_dll(p, run_seed_raw(seed, key))
    });
    points
        .iter()
        .zip(out)
        .map(|(p, m)| {
            let (formula_chips, loop_chips, slope) = dll_theory(p);
            Ok(DllResult {
                point: *p,
                measured_chips: m?,
                formula_chips,
                loop_chips,
                slope,
            })
        })
        .collect()
}

/// Runs the study and the DLL sweep: the report (the DLL section appended to its
/// conclusions) and the DLL table (`dll.csv`).
pub fn run_with_dll(args: &ThresholdArgs, progress: bool) -> anyhow::Result<(StudyReport, Table)> {
    let (mut report, results) = run_cells(args, progress)?;
    let check = if_cross_check(&results, args.common.seed, progress)?;
    report.conclusions_md += &if_check_md(&check);
    let dll = run_dll_sweep(args.common.quick, args.common.seed, progress)?;
    report.conclusions_md += &dll_md(&dll);
    if let Some(obj) = report.summary.as_object_mut() {
        obj.insert(
            "dll_points_within_20pct".into(),
            serde_json::json!(dll.iter().filter(|r| r.agrees()).count()),
        );
        obj.insert("dll_points".into(), serde_json::json!(dll.len()));
    }
    Ok((report, dll_table(&dll)))
}

/// Runs the study's grid (no IF cross-check, no DLL sweep).
pub fn run(args: &ThresholdArgs, progress: bool) -> anyhow::Result<StudyReport> {
    Ok(run_cells(args, progress)?.0)
}

/// The grid's report and results.
fn run_cells(
    args: &ThresholdArgs,
    progress: bool,
) -> anyhow::Result<(StudyReport, Vec<CellResult>)> {
    let t0 = Instant::now();
    let quick = args.common.quick;
    let cells = if quick { quick_grid() } else { full_grid() };
    let results = measure_cells(&cells, args.common.seed, progress)?;
    let runs: usize = results
        .iter()
        .filter_map(|r| r.measured)
        .map(|m| m.runs)
        .sum();
    let wall_s = t0.elapsed().as_secs_f64();
    let n_run = results.iter().filter(|r| r.rejected.is_none()).count();
    let agree = results
        .iter()
        .filter(|r| r.vs_rule().is_some_and(|a| a.agrees()))
        .count();
    let summary = serde_json::json!({
        "study": "threshold",
        "quick": quick,
        "seed": args.common.seed,
        "cells_total": results.len(),
        "cells_run": n_run,
        "cells_within_3db_of_rule": agree,
        "share_within_3db_of_rule": agree as f64 / n_run.max(1) as f64,
        "runs": runs,
        "simulated_s": runs as f64 * (WINDOW_S + PRE_ROLL_S),
        "wall_s": wall_s,
    });
    let report = StudyReport {
        title: "Tracking threshold: measured against the rule of thumb".into(),
        intro_md: intro_md(quick, args.common.seed, runs, wall_s),
        table: build_table(&results),
        conclusions_md: conclusions_md(&results),
        summary,
        plots: plots::plots(&results),
    };
    Ok((report, results))
}

fn intro_md(quick: bool, seed: u64, runs: usize, wall_s: f64) -> String {
    format!(
        "The lowest C/N0 at which the receiver's carrier loop holds lock for at least \
         {hold:.0} % of {window:.0} s, for PLL orders 1-3, Bn {bns} Hz and T {ts} ms \
         ({grid} grid), against the rule of thumb for a Costas PLL, `3 sigma + theta_e <= 45` \
         deg (Kaplan & Hegarty 2nd ed. sec. 5.6): `sigma^2 = sigma_t^2 + sigma_v^2 + sigma_A^2`, \
         thermal `sigma_t = (360/2 pi) sqrt((Bn/CN0)(1 + 1/(2 T CN0)))` deg, a perfect clock \
         (`sigma_A = 0`; the theory takes 144 or 160 `sigma_y f_L / Bn` deg for a real one), no \
         vibration, and the dynamic stress `theta_e = 360 (d^n theta/dt^n)/omega0^n` deg of an \
         order-n loop (omega0 = Bn/0.25, Bn/0.53, Bn/0.7845), solved for C/N0 by bisection \
         (`theory_dbhz`). Kaplan's squaring loss `1 + 1/(2 T CN0)` is that of the product \
         (`I Q`) discriminator; the receiver's is `atan(Q/I)`, whose output folds into \
         (-90, 90] deg and is noisier below about 0 dB of prompt SNR (2.0x the formula's \
         variance per unit slope at C/N0 T = 0.5, 3.0x at 0.06), so `theory_atan_dbhz` is the \
         same rule with `sigma_t` from the atan's exact variance and slope (numerical integration \
         over the prompt phase density, checked against a Monte Carlo run of the receiver's \
         discriminator) through the linearised digital loop's phase noise gain, and the stress \
         over the normalised loop gain.\n\n\
         **Dynamics** (what the loop must follow after the feed-forward): `static`; `accel 1 g` \
         (unaided, constant LOS acceleration, orders 2-3); `jerk 10 g/s` (unaided, constant LOS \
         jerk, the entry of a turn that reaches 10 g in 1 s, order 3); `INS bias 1 mg` (aided \
         through any manoeuvre by an INS whose LOS accelerometer bias is 1 mg: a Doppler ramp of \
         0.05 Hz/s, orders 2-3); `INS vel 0.05 m/s` (aided by an INS with a constant 0.05 m/s LOS \
         velocity error, order 1). A loop of lower order than the residual's degree has an \
         unbounded error and is not run.\n\n\
         **Measurement**: at the level of 1 ms correlator outputs (prompt `A d sinc exp(j 2 pi e) \
         + n`, unit noise per component, `A = sqrt(2 CN0 1 ms)`, random data bits), the \
         receiver's own carrier loop (`CarrierLoop`: Costas atan divided by its slope \
         `1 - exp(-C/N0 T)` down to 0.05, from the lock detector's C/N0, the cell's filter, NCO \
         held over bit-aligned intervals of T), started in its steady state. **Lock held** is \
         the channel's `pll_lock` in each 1 ms period: its `PllLockDetector` (default settings: \
         bit-aligned 20-prompt coherent blocks, steadiness `|LPF(S^2)|/s >= 0.7` with `s` the \
         block's signal power estimated without the noise bias, a low-pass adapted to the block \
         SNR, steady offset <= 0.2 cycle, 10-test hysteresis) locked and its fade detector \
         quiet. \
         Each C/N0 is {per} runs of {pre:.0} s + {window:.0} s with their held shares pooled \
         (fixed seeds from `--seed {seed}`); the scan goes down from {top:.0} dB-Hz in {step} dB \
         steps and stops at the first C/N0 that holds lock less than {hold:.0} % of the window: `measured_dbhz` is the last that \
         held (`none`: not even at the top). {runs} runs in {wall_s:.0} s.\n\n\
         **Other columns**: `stress_deg` theta_e; `detector_dbhz` the lock detector's floor \
         (where `exp(-2 sigma^2) - 1.645 eps/sqrt(2)` reaches 0.7, `eps` the relative error of \
         its estimate at the block SNR `rho` = 20 ms of C/N0); `theory_slope_dbhz` the rule with \
         the stress divided by the loop gain the normalised Costas slope leaves (below 0.05: \
         slope/0.05; a lower loop gain leaves a larger steady-state error); `stable_dbhz` the \
         C/N0 below which that gain leaves a \
         3rd-order loop (only conditionally stable) linearly unstable; `expected_dbhz` the \
         highest of `theory_slope_dbhz`, `stable_dbhz` and `detector_dbhz`; `loop_dbhz` the \
         loop's own threshold by the truth (no half-cycle slip, a 3/8-cycle excursion, in the \
         first 95 % of the window), whatever the lock detector reports; `bn_real_hz` the digital loop's realised noise bandwidth and `theory_real_dbhz` \
         the rule with it; `below_threshold` the first failing run.\n",
        hold = 100.0 * HOLD_FRACTION,
        window = WINDOW_S,
        bns = BN_HZ.map(|b| b.to_string()).join(", "),
        ts = T_COH_MS.map(|t| t.to_string()).join(" and "),
        grid = if quick { "quick" } else { "full" },
        pre = PRE_ROLL_S,
        per = RUNS_PER_STEP,
        top = SCAN_TOP_DBHZ,
        step = SCAN_STEP_DB,
    )
}
