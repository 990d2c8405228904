//! `gpsrx study landmarks`: street-level landmark ranges as extra observations (seed 001,
//! Park et al. 2011, section 3.3 and Figs. 3-3 to 3-5).
//!
//! For 3-9 satellites and 0-2 landmarks within 70 m (2 % range noise), Monte Carlo over
//! geometries ([`grid`]: random epochs of the broadcast day, random satellites in view, random
//! landmark bearings and ranges, fixed seeds): the share of geometries whose Jacobian at the
//! truth has rank 4 and PDOP <= 10, the share in which [`gpsrx_nav::pvt::solve`] (from the
//! previous fix) returns a fix with PDOP <= 10, and the median PDOP/HDOP ([`summary`]).
//! Conclusions are computed from these numbers ([`conclusions`]).

pub mod conclusions;
pub mod grid;
pub mod params;
mod plots;
pub mod summary;
mod table;

use super::report::StudyReport;
use super::{run_cases, CommonStudyArgs};
use anyhow::Context;
use grid::Cell;
use params::*;

/// `gpsrx study landmarks` options.
#[derive(Debug, Clone, clap::Args)]
pub struct LandmarksArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
}

/// The grid: every satellite count x landmark count.
pub fn cells() -> Vec<Cell> {
    SATELLITES
        .flat_map(|n_sat| LANDMARKS.map(move |n_lm| Cell { n_sat, n_lm }))
        .collect()
}

/// Runs the study (`trials` geometries per cell).
pub fn run_grid(
    seed: u64,
    trials: usize,
    progress: bool,
) -> anyhow::Result<Vec<summary::CellStats>> {
    let nav = gpsrx_nav::parse_rinex_nav(gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT)
        .context("the shipped brdc0010.22n does not parse")?;
    let cells = cells();
    Ok(run_cases(&cells, "landmarks", progress, |c| {
        summary::stats(*c, &grid::run_cell(&nav, *c, trials, seed))
    }))
}

/// Runs the study.
pub fn run(args: &LandmarksArgs, progress: bool) -> anyhow::Result<StudyReport> {
    let trials = if args.common.quick {
        TRIALS_QUICK
    } else {
        TRIALS
    };
    let all = run_grid(args.common.seed, trials, progress)?;
    let intro_md = format!(
        "Seed 001 (Park et al., 2011): ranges to street-level landmarks (bearing uniform, range \
         uniform in {}-{} m, sigma {} % of the range, at the antenna's height) added to {} - {} \
         satellites (elevation >= {} deg, pseudorange sigma {} m) at random epochs of \
         2022-01-01 over Seoul; {trials} geometries per cell, seed {}. \"Rank 4\" and \"PDOP <= \
         10 at truth\" are the geometry's; \"fix available\" is the solver's (from the previous \
         fix with all satellites, a fix with PDOP <= {USABLE_PDOP}). Medians over the rank-4 \
         geometries.",
        LANDMARK_RANGE_M.0,
        LANDMARK_RANGE_M.1,
        100.0 * LANDMARK_SIGMA_FRACTION,
        SATELLITES.start(),
        SATELLITES.end(),
        ELEVATION_MASK_DEG,
        PSEUDORANGE_SIGMA_M,
        args.common.seed
    );
    Ok(StudyReport {
        title: "Landmark ranges with few satellites (seed 001)".into(),
        intro_md,
        table: table::table(&all),
        conclusions_md: conclusions::conclusions_md(&all),
        summary: table::summary_json(&all, args.common.seed),
        plots: plots::plots(&all),
    })
}
