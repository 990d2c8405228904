//! `gpsrx study dynamics`: high-dynamics tracking, unaided and INS-aided (seed 004, Sec. IV).
//!
//! Seed 004 flew a 10 g manoeuvre through a GPS signal simulator: an unaided 2nd-order PLL kept
//! as few as 4 satellites (Fig. 12), the INS-aided one kept all of them (Fig. 15), and with two
//! INS whose accelerometer biases differ by 2x the aided 2nd-order loop's phase error std was
//! the same (Table 3: 0.085-0.101 cycle). This study reproduces the experiment on simulated IF:
//!
//! - **Scenarios**: one per (manoeuvre, C/N0). A vehicle cruising at [`SPEED_MPS`] for
//!   [`LEAD_IN_S`] (channels started from truth pull in and hand over), then a jerk-limited
//!   manoeuvre (a level turn at `N g` for [`TURN_S`], or a longitudinal acceleration step at
//!   `N g` for [`STEP_S`]; acceleration ramped over [`RAMP_S`] in and out), then a cruise to
//!   [`DURATION_S`]. Every visible satellite at one C/N0, complex float samples at [`FS_HZ`]
//!   generated in memory by [`gpsrx_samples::sim`], a white-FM oscillator of Allan deviation
//!   [`ALLAN_DEVIATION_1S`] at 1 s. Each scenario is simulated once and tracked by every
//!   loop/aiding case (cases in parallel, [`super::run_cases`]).
//! - **Aiding**: the receiver's own feed-forward
//!   ([`gpsrx_receiver::pipeline::aiding::InsFeedForward`], the path of `gpsrx run --ins`) fed by an INS
//!   made from the truth trajectory by [`gpsrx_ins_aiding::simulate_ins`] with an accelerometer
//!   bias `B` (INS 1, magnitude [`INS1_BIAS_MPS2`]) or `2B` (INS 2), along `(1, 1, 1)/sqrt(3)` in
//!   east-north-up; the navigation data are the scenario's RINEX file; a fix at `t = 0` gives
//!   the feed-forward the receiver position and clock drift, as a navigation solution would.
//! - **Theory** (seed 004 eqs. 12-16, `oracles.md`): the bias makes a velocity error `B t`, a
//!   Doppler error ramp `B_V t / lambda` with `B_V = B . u` its line-of-sight part. A
//!   1st-order loop (`omega0 = Bn/0.25`) then lags by a growing
//!   `theta_1(t) = 360 B_V t / (lambda omega0)` deg; a 2nd-order loop (`omega0 = Bn/0.53`)
//!   settles at the constant `theta_2 = 360 B_V / (lambda omega0^2)` deg, which a mean removal
//!   takes out of the std, so the std does not depend on the bias; a 3rd-order loop has no
//!   error at all. (Seed 004 Table 1 writes the 1st-order, bias, "speed input" entry as the
//!   constant `(1 + B_V/lambda)/omega_n`; the derivation above, confirmed here by the
//!   measured growth, gives the ramp: the bias is a Doppler *ramp*, not a step.)
//!
//! Per case: satellites tracked (channel in `Track` with the PLL lock indicator on) every
//! [`TICK_S`] through the manoeuvre window (min, mean, kept throughout), loss-of-lock events,
//! the phase error std against the simulator's true carrier phase, the Costas discriminator's
//! std (what seed 004 Table 3 measured with `atan(Q/I)`), the mean discriminator error against
//! `theta_1`/`theta_2`, and the pseudorange-rate error std.

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
mod stats;
mod summary;
mod table;
mod track;

pub use aiding::Aiding;
pub use manoeuvre::Manoeuvre;
pub use params::{
    ALLAN_DEVIATION_1S, CLOCK_DRIFT_S_S, DURATION_S, FS_HZ, HEADLINE_BN_HZ, INS1_BIAS_MPS2,
    INS_RATE_HZ, LEAD_IN_S, ORDER1_BN_HZ, RAMP_S, SPEED_MPS, START_TOW_S, STEP_S, TICK_S, TURN_S,
};

use super::report::StudyReport;
use super::{run_cases, CommonStudyArgs};
use grid::grid;
use scenario::prepare;
use std::time::Instant;
use summary::build_report;
use track::run_case;

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
    let (scenarios, cases) = grid(args.common.quick);
    let mut results = Vec::new();
    for (k, spec) in scenarios.iter().enumerate() {
        let p = prepare(spec, args.common.seed)?;
        let what = format!(
            "dynamics {}/{}: {} at {} dB-Hz",
            k + 1,
            scenarios.len(),
            spec.manoeuvre.label(),
            spec.cn0_dbhz
        );
        for r in run_cases(&cases, &what, progress, |c| run_case(&p, c)) {
            results.push(r?);
        }
    }
    Ok(build_report(
        args,
        &results,
        started.elapsed().as_secs_f64(),
    ))
}
