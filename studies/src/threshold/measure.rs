//! The measured threshold of a cell: a scan down in C/N0 until the loop no longer holds lock.

use super::params::{HOLD_FRACTION, RUNS_PER_STEP, SCAN_BOTTOM_DBHZ, SCAN_STEP_DB, SCAN_TOP_DBHZ};
use super::sim::{run, RunOutcome};
use super::Cell;

/// What the scan of a cell found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// The lowest C/N0 of the scan at which lock was held (dB-Hz); `None` when lock was not held
    /// even at the top of the scan.
    pub threshold_dbhz: Option<f64>,
    /// The run at the threshold.
    pub at_threshold: Option<RunOutcome>,
    /// The first run that failed (one step below the threshold), with its C/N0; `None` when the
    /// scan reached its bottom without a failure.
    pub first_failure: Option<(f64, RunOutcome)>,
    /// The same for the loop itself, by the truth ([`RunOutcome::slip_free_fraction`]): the
    /// lowest C/N0 of the scan at which the loop ran slip-free for the hold fraction of the
    /// window.
    pub loop_threshold_dbhz: Option<f64>,
    /// The first run whose loop slipped too early, with its C/N0.
    pub loop_first_failure: Option<(f64, RunOutcome)>,
    /// Runs made.
    pub runs: usize,
}

/// The noise seed of run `k` of `cell` at scan step `step` (SplitMix64 of the study seed, the
/// cell's key, the step and `k`: every run has its own noise, the same in every grid).
pub fn run_seed(seed: u64, cell: &Cell, step: usize, k: usize) -> u64 {
    let key = cell.key().rotate_left(17).wrapping_add(step as u64);
    run_seed_raw(seed, key.wrapping_add((k as u64).wrapping_mul(0x9e37_79b9)))
}

/// SplitMix64 of the study seed and a run's key.
pub fn run_seed_raw(seed: u64, key: u64) -> u64 {
    let mut z = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15).wrapping_add(key);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Scans `cell` from [`SCAN_TOP_DBHZ`] down in steps of [`SCAN_STEP_DB`], [`RUNS_PER_STEP`]
/// 30 s runs per step ([`run`], pooled by [`RunOutcome::pool`]): the threshold is the last
/// C/N0 before the first step whose runs hold lock less than [`HOLD_FRACTION`] of their
/// windows (a lucky step below the first failure cannot lower it). The loop's own threshold (slip-free for that share of the window) is found in the
/// same runs; the scan goes on until both have failed.
///
/// Errors: the receiver refuses the cell's loop.
pub fn measure_cell(cell: &Cell, seed: u64) -> anyhow::Result<Measured> {
    let steps = ((SCAN_TOP_DBHZ - SCAN_BOTTOM_DBHZ) / SCAN_STEP_DB).round() as usize;
    let mut m = Measured {
        threshold_dbhz: None,
        at_threshold: None,
        first_failure: None,
        loop_threshold_dbhz: None,
        loop_first_failure: None,
        runs: 0,
    };
    for step in 0..=steps {
        if m.first_failure.is_some() && m.loop_first_failure.is_some() {
            break;
        }
        let cn0 = SCAN_TOP_DBHZ - step as f64 * SCAN_STEP_DB;
        let runs = (0..RUNS_PER_STEP)
            .map(|k| run(cell, cn0, run_seed(seed, cell, step, k)))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let out = RunOutcome::pool(&runs);
        m.runs += runs.len();
        if m.first_failure.is_none() {
            if out.held_fraction >= HOLD_FRACTION {
                m.threshold_dbhz = Some(cn0);
                m.at_threshold = Some(out);
            } else {
                m.first_failure = Some((cn0, out));
            }
        }
        if m.loop_first_failure.is_none() {
            if out.slip_free_fraction >= HOLD_FRACTION {
                m.loop_threshold_dbhz = Some(cn0);
            } else {
                m.loop_first_failure = Some((cn0, out));
            }
        }
    }
    Ok(m)
}
