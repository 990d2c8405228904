//! `gpsrx study dynamics`: high-dynamics tracking, unaided and INS-aided (seed 004, Sec. IV).
//!
//! Seed 004 flew a 10 g manoeuvre through a GPS signal simulator: an unaided 2nd-order PLL at
//! Bn = 0.4 Hz kept as few as 4 satellites (Fig. 12), the INS-aided one at least 8 (Fig. 15),
//! and with two INS whose accelerometer biases differ by 2x the aided loop's phase error std
//! was 0.085-0.101 cycle, INS 2's 9-17 % above INS 1's (Table 3). This study reproduces the
//! experiment on simulated IF:
//!
//! - **Scenarios** (`grid.rs`): one per (manoeuvre, C/N0, lead-in). A vehicle cruising at
//!   [`SPEED_MPS`] for the lead-in ([`LEAD_IN_S`], longer for loops narrower than
//!   [`HEADLINE_BN_HZ`]: [`lead_in_s`]), long enough for the channels to hand over
//!   from pull-in and narrow in stages to their loop, then a jerk-limited manoeuvre (a level
//!   turn at `N g` for [`TURN_S`], or a longitudinal acceleration step at `N g` for [`STEP_S`];
//!   acceleration ramped over [`RAMP_S`] in and out), then [`TAIL_S`] of cruise. Every visible
//!   satellite at one C/N0 (33 dB-Hz, where the Costas discriminator's std is Table 3's, and
//!   45), complex float samples at [`FS_HZ`] generated in memory by [`gpsrx_samples::sim`],
//!   the receiver oscillator [`OSCILLATOR`] (two-state clock). Each scenario is simulated once
//!   and tracked by each of its loop/aiding cases (in parallel, [`super::run_cases`]).
//! - **Channels** are configured as `gpsrx run` configures them (`track::case_config`):
//!   unaided, the case's PLL is the tracking loop; aided, it is the `aided_track` loop, which
//!   the channel takes once the feed-forward is on. Either way the channel's own staged
//!   narrowing takes it from the pull-in loop to a narrow loop.
//! - **Aiding**: the receiver's own feed-forward
//!   ([`gpsrx_receiver::pipeline::aiding::InsFeedForward`], the path of `gpsrx run --ins`) fed by
//!   an INS made from the truth trajectory by [`gpsrx_ins_aiding::simulate_ins`] with an
//!   accelerometer bias `B` (INS 1: 0.5, 1 or 2 mg for the narrow loops, [`NARROW_INS1_BIAS_MG`];
//!   [`WIDE_INS1_BIAS_MPS2`] for the 2-18 Hz and 1st-order loops) or `2B` (INS 2), along
//!   `(1, 1, 1)/sqrt(3)` in east-north-up; the navigation data are the scenario's RINEX file; a
//!   fix at `t = 0` gives the feed-forward the receiver position and clock drift, as a
//!   navigation solution would.
//! - **Theory** (seed 004 eqs. 12-16, `oracles.md`): the bias makes a velocity error `B t`, a
//!   Doppler error ramp `B_V t / lambda` with `B_V = B . u` its line-of-sight part. A
//!   1st-order loop (`omega0 = Bn/0.25`) then lags by a growing
//!   `theta_1(t) = 360 B_V t / (lambda omega0)` deg; a 2nd-order loop (`omega0 = Bn/0.53`)
//!   settles at the constant `theta_2 = 360 B_V / (lambda omega0^2)` deg, which a mean removal
//!   takes out of the std as long as the loop stays linear; a 3rd-order loop has no error at
//!   all. (Seed 004 Table 1 writes the 1st-order, bias, "speed input" entry as the constant
//!   `(1 + B_V/lambda)/omega_n`; the derivation above, confirmed here by the measured growth,
//!   gives the ramp: the bias is a Doppler *ramp*, not a step.)
//!
//! Per case: satellites tracked (channel in `Track` with the PLL lock indicator on) every
//! [`TICK_S`] through the manoeuvre window (min, mean, kept throughout), loss-of-lock events,
//! the phase error std against the simulator's true carrier phase, the Costas discriminator's
//! std (what seed 004 Table 3 measured with `atan(Q/I)`), pooled and per satellite, the mean
//! discriminator error against `theta_1`/`theta_2`, and the pseudorange-rate error std. The
//! report (`summary.rs`) gives Figs. 12/15 and Table 3 at 0.4 Hz, and conclusions computed from
//! the results (`conclusions.rs`, `grid_md.rs`).

mod aiding;
mod bias;
mod conclusions;
mod grid;
mod grid_md;
mod headline;
mod ins;
mod intro;
mod manoeuvre;
mod mem_source;
mod params;
mod plots;
mod result;
mod scenario;
mod seed_tables;
mod stats;
mod summary;
mod table;
mod table3_md;
mod track;

pub use aiding::Aiding;
pub use manoeuvre::Manoeuvre;
pub use params::{
    lead_in_s, narrowing_s, CLOCK_DRIFT_S_S, FS_HZ, HAND_OVER_S, HEADLINE_BN_HZ, INS_RATE_HZ,
    LEAD_IN_S, MG_MPS2, NARROW_BN_HZ, NARROW_DEFAULT_BIAS_MG, NARROW_INS1_BIAS_MG, NARROW_RATIO,
    ORDER1_BN_HZ, OSCILLATOR, PULL_IN_BN_HZ, RAMP_S, SETTLE_BN_S, SPEED_MPS, STAGE_BN_S,
    START_TOW_S, STEP_S, TAIL_S, TICK_S, TURN_S, WIDE_BN_HZ, WIDE_INS1_BIAS_MPS2,
};

use super::report::StudyReport;
use super::{run_cases, CommonStudyArgs};
use grid::grid;
use result::NotRun;
use scenario::prepare;
use std::time::Instant;
use summary::build_report;
use track::{case_config, run_case};

/// `gpsrx study dynamics` options.
#[derive(Debug, Clone, clap::Args)]
pub struct DynamicsArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
}

/// Runs the study.
pub fn run(args: &DynamicsArgs, progress: bool) -> anyhow::Result<StudyReport> {
    let started = Instant::now();
    let scenarios = grid(args.common.quick);
    let mut results = Vec::new();
    let mut not_run = Vec::new();
    for (k, (spec, all)) in scenarios.iter().enumerate() {
        // Cases whose loops the receiver rejects (ChannelConfig::validate) are reported, not run.
        let mut cases = Vec::new();
        for c in all {
            match case_config(c).validate() {
                Ok(()) => cases.push(*c),
                Err(e) => not_run.push(NotRun {
                    spec: *spec,
                    case: *c,
                    why: e.to_string(),
                }),
            }
        }
        if cases.is_empty() {
            continue;
        }
        let p = prepare(spec, &cases, args.common.seed)?;
        let what = format!(
            "dynamics {}/{}: {} at {} dB-Hz, {} s lead-in",
            k + 1,
            scenarios.len(),
            spec.manoeuvre.label(),
            spec.cn0_dbhz,
            spec.lead_in_s
        );
        for r in run_cases(&cases, &what, progress, |c| run_case(&p, c)) {
            results.push(r?);
        }
    }
    Ok(build_report(
        args,
        &results,
        &not_run,
        started.elapsed().as_secs_f64(),
    ))
}
