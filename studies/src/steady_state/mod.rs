//! `gpsrx study steady-state`: the steady-state phase error of PLLs of order 1, 2 and 3 under
//! step, ramp, parabola and cubic phase inputs, unaided and aided (perfect, band-limited, biased
//! INS), measured in closed loop and set against the closed forms (seed 004 Table 1, re-derived).
//!
//! # Closed forms
//!
//! Phase in cycles, frequency in Hz; `omega0` (1/s, "rad/s") is the implemented filter's
//! [`omega0`] = Bn/0.25, Bn/0.53, Bn/0.7845 (Kaplan Table 5.6; the implementation uses 0.53 where
//! the exact integral gives 0.5303). The loop `NCO = 1/s` (cycles per Hz) with the filters of
//! [`gpsrx_tracking::loop_filter`] is unit-free, so the error transfer function `E/R = 1 - H` is
//!
//! - order 1: `s / (s + omega0)`;
//! - order 2: `s^2 / (s^2 + a2 omega0 s + omega0^2)`;
//! - order 3: `s^3 / (s^3 + b3 omega0 s^2 + a3 omega0^2 s + omega0^3)`,
//!
//! i.e. `s^n/omega0^n` to leading order at `s = 0` for order `n`. `R` is the
//! *residual* phase the loop itself must track: the input minus what the feed-forward already put
//! into the NCO (seed 004 eq. 11, `f_NCO = f_ff + F(e)`). If the residual's polynomial part has
//! degree `m` with `d^m r/dt^m -> R` (cycles/s^m), the final-value theorem on
//! `E(s) ~ (s^n/omega0^n) R/s^(m+1)` gives
//!
//! - `m < n`: `e -> 0`;
//! - `m = n`: `e -> R / omega0^n` cycles (`(d^n theta/dt^n)/omega0^n`, `oracles.md`);
//! - `m > n`: unbounded, `d^(m-n) e/dt^(m-n) -> R / omega0^n` cycles/s^(m-n).
//!
//! The residual for each aiding (inputs: phase step `P` cycles; ramp = frequency offset `df` Hz;
//! parabola = Doppler rate `a` Hz/s; cubic = Doppler jerk `j` Hz/s^2):
//!
//! - unaided: the input itself, `m` = 0, 1, 2, 3 with `R` = `P`, `df`, `a`, `j`;
//! - perfect aid (`f_ff = f_true`): none, `e = 0` for every order (seed 004 eq. 7);
//! - band-limited aid (`f_ff = f_true alpha/(s + alpha)`, seed 004 eqs. 8-9): residual = input
//!   `* s/(s + alpha)`, whose polynomial part for an input of degree `m >= 2` has degree `m - 1`
//!   and `R/alpha`: parabola -> `a/alpha` Hz (order 1: `a/(alpha omega0)`; 2, 3: 0), cubic ->
//!   `j/alpha` Hz/s (order 1 grows at `j/(alpha omega0)` cycles/s; order 2: `j/(alpha omega0^2)`;
//!   order 3: 0). A step (Doppler impulse) or ramp (constant Doppler) leaves at most a decaying
//!   transient or a constant phase: 0 for every order;
//! - biased INS: perfect aid plus the Doppler error of a LOS accelerometer bias `B_V` (m/s^2):
//!   velocity error `B_V t`, aid error `+B_V t/lambda` Hz (seed 004 eqs. 12-16), residual a
//!   Doppler ramp `R = -B_V/lambda` (`m = 2`) whatever the input: order 1 grows at
//!   `-(B_V/lambda)/omega0` cycles/s, order 2 settles at `-(B_V/lambda)/omega0^2`, order 3: 0.
//!   (Sign: error = signal - NCO; an aid that is too high makes the NCO run ahead.)
//!
//! The digital loop has the same DC behaviour: in steady state the filter's integrators must
//! ramp the NCO exactly as the residual does, which fixes the error by the integrator gains alone
//! (e.g. order 2: `T omega0^2 e` per update = `a T`), so these values hold for any stable `Bn T`.
//!
//! # Measurement
//!
//! Each cell runs [`CarrierLoop`] (Costas atan discriminator, no FLL; beyond `LoopConfig`'s
//! `Bn T` limit, the same computation with the [`LoopFilter`] directly, if the digital loop is
//! stable) in the phase-domain simulator [`phase_sim`] without noise (the errors are deterministic; noise-free, the atan
//! discriminator is exact within +-1/4 cycle). Perfect aid is the true mean Doppler over the
//! interval the NCO will hold it; the band-limited aid is that Doppler through
//! [`BandLimiter`] (exact ZOH, 16 sub-steps per interval, started at the true Doppler), averaged
//! over the interval. The run lasts until the slowest closed-loop pole (and, for the
//! band-limited aid, `exp(-alpha t)`) has decayed to 1e-5, plus a window of `max(1 s, 50 T)`
//! (a bounded cell runs as long as the slowest order of its group and uses the last window)
//! over which a least-squares polynomial of the interval errors gives the mean (bounded cells) or
//! the growth rate (first or second derivative, unbounded cells). Input magnitudes are scaled per
//! cell so that bounded errors are about 0.03 cycle and growing ones reach about 0.05 cycle at
//! the end of the window: all far inside the discriminator's linear range.
//!
//! Agreement ([`agrees`]): `|measured - closed| <= 5 %` of `|closed|`, or `<= 0.005` cycle where
//! the closed form is 0; a bounded cell must meet it at both ends of its window (no drift), a
//! growing one with its rate.

// One concept a file: the inputs and aidings (`inputs`), the closed forms and the agreement rule
// (`closed_form`), a cell (`cell`), loop stability (`stability`), the feed-forward (`aid`), the
// closed-loop run and its measurement (`sim`, `fit`), the configurations of a run (`plan`) and
// the report (`table`, `text`, `conclusions`, `plots`).
mod aid;
mod cell;
mod closed_form;
mod conclusions;
mod findings;
#[cfg(test)]
mod findings_tests;
mod fit;
mod inputs;
mod plan;
mod plots;
mod sim;
mod stability;
mod table;
mod text;

pub use self::cell::{Cell, TARGET_END_ERROR_CYCLES, TARGET_ERROR_CYCLES};
pub use self::closed_form::{agrees, closed_form, residual, ClosedForm, ABS_TOL_CYCLES, REL_TOL};
pub use self::inputs::{AidParams, Aiding, Input};
pub use self::sim::{simulate, CellResult};
pub use self::stability::stability_limit_bn_t;

use self::plan::{configs, plan, Planned};
use self::table::build_report;
use crate::report::StudyReport;
use crate::{run_cases, CommonStudyArgs};

// Targets of the intra-doc links in the module docs.
#[cfg(doc)]
use gpsrx_ins_aiding::BandLimiter;
#[cfg(doc)]
use gpsrx_tracking::loop_filter::{omega0, LoopFilter};
#[cfg(doc)]
use gpsrx_tracking::{phase_sim, CarrierLoop};

/// Default noise bandwidth of the main table, Hz.
pub const DEFAULT_BN_HZ: f64 = 10.0;
/// Default band-limiter corner alpha, rad/s.
pub const DEFAULT_ALPHA_RAD_S: f64 = 5.0;
/// Default LOS accelerometer bias B_V, m/s^2 (`oracles.md`: 3.0 deg at Bn = 3 Hz, 2nd order).
pub const DEFAULT_B_V_MPS2: f64 = 0.05;
/// Integration time of the main table, s.
pub const MAIN_T_COH_S: f64 = 1.0e-3;

/// `gpsrx study` options of this study.
#[derive(Debug, Clone, clap::Args)]
pub struct SteadyStateArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
    /// Noise bandwidth Bn of the main table (T = 1 ms), Hz.
    #[arg(long, default_value_t = DEFAULT_BN_HZ)]
    pub bn_hz: f64,
    /// Corner alpha of the band-limited aid alpha/(s + alpha), rad/s (seed 004 eq. 8).
    #[arg(long, default_value_t = DEFAULT_ALPHA_RAD_S)]
    pub alpha_rad_s: f64,
    /// LOS accelerometer bias B_V of the biased INS, m/s^2 (seed 004 eqs. 12-16).
    #[arg(long, default_value_t = DEFAULT_B_V_MPS2)]
    pub b_v_mps2: f64,
}

impl SteadyStateArgs {
    /// The defaults with these common options.
    pub fn new(common: CommonStudyArgs) -> Self {
        Self {
            common,
            bn_hz: DEFAULT_BN_HZ,
            alpha_rad_s: DEFAULT_ALPHA_RAD_S,
            b_v_mps2: DEFAULT_B_V_MPS2,
        }
    }
}

fn check_args(args: &SteadyStateArgs) -> anyhow::Result<()> {
    for (name, v) in [("--bn-hz", args.bn_hz), ("--alpha-rad-s", args.alpha_rad_s)] {
        if !(v.is_finite() && v > 0.0) {
            anyhow::bail!("{name} = {v}: must be a finite value > 0");
        }
    }
    if !(args.b_v_mps2.is_finite() && args.b_v_mps2 != 0.0) {
        anyhow::bail!(
            "--b-v-mps2 = {}: must be finite and non-zero",
            args.b_v_mps2
        );
    }
    Ok(())
}

/// The cells the study runs, in order, and the (Bn, T, order) groups it does not run (an
/// unstable digital loop).
#[allow(clippy::type_complexity)]
pub fn cells(
    args: &SteadyStateArgs,
) -> anyhow::Result<(Vec<(f64, f64)>, Vec<Cell>, Vec<(f64, f64, u8, String)>)> {
    check_args(args)?;
    let aid = AidParams {
        alpha_rad_s: args.alpha_rad_s,
        b_v_mps2: args.b_v_mps2,
    };
    let cfgs = configs(args);
    let mut cells = Vec::new();
    let mut not_run = Vec::new();
    for &(bn, t) in &cfgs {
        for order in 1..=3u8 {
            match plan(bn, t, order, aid) {
                Planned::Cells(c) => cells.extend(c),
                Planned::NotRun(why) => not_run.push((bn, t, order, why)),
            }
        }
    }
    Ok((cfgs, cells, not_run))
}

/// Runs the study: the 48 cells at `--bn-hz` and T = 1 ms (`--quick`: only these), and in the
/// full run the same cells at Bn = 2 and 18 Hz and at T = 20 ms, where the loop is accepted.
pub fn run(args: &SteadyStateArgs, progress: bool) -> anyhow::Result<StudyReport> {
    let (cfgs, cells, not_run) = cells(args)?;
    let results = run_cases(&cells, "steady-state", progress, simulate)
        .into_iter()
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(build_report(args, &cfgs, &results, &not_run))
}
