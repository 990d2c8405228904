//! The introduction and conclusions text of the report (the findings, each decided by the
//! measured cells, are in [`super::findings`]).

use gpsrx_tracking::loop_filter::omega0;
use gpsrx_tracking::phase_sim::LAMBDA_M;
use std::fmt::Write as _;

use super::findings::{aiding_md, dc_property_md, seed_differences_md};
use super::text::{short, sig};
use super::{
    CellResult, SteadyStateArgs, MAIN_T_COH_S, TARGET_END_ERROR_CYCLES, TARGET_ERROR_CYCLES,
};
use crate::report::Table;

pub(super) fn intro_md(args: &SteadyStateArgs) -> String {
    let w: Vec<String> = (1..=3u8).map(|o| sig(omega0(o, args.bn_hz))).collect();
    format!(
        "Seed 004 Table 1, re-derived and measured. Phase inputs (cycles) into PLLs of order 1-3 \
(Costas atan discriminator, `CarrierLoop`, no FLL), noise-free, in the phase-domain simulator \
`gpsrx_tracking::phase_sim`; main table Bn = {bn} Hz, T = 1 ms, so omega0 = {w1}, {w2}, {w3} \
rad/s (the implemented filter's omega0 = Bn/0.25, Bn/0.53, Bn/0.7845). Aiding: perfect = the \
true mean Doppler of each interval; band-limited = the true Doppler through alpha/(s + alpha), \
alpha = {alpha} rad/s (exact ZOH `BandLimiter`); biased INS = perfect + B_V t/lambda with \
B_V = {bv} m/s^2 on the line of sight. `--seed` has no effect (no noise).

**Closed forms.** With the loop's error transfer function `1 - H(s) ~ s^n/omega0^n` and the \
residual phase `r` the loop must track (input minus feed-forward, degree m, `d^m r/dt^m -> R`): \
m < n gives 0, m = n gives `R/omega0^n` cycles, m > n grows with `d^(m-n) e/dt^(m-n) -> \
R/omega0^n`. Residuals: unaided = the input; perfect = none; band-limited = input * \
s/(s + alpha) (degree m - 1, `R/alpha`); biased INS = `-B_V t^2/(2 lambda)` (m = 2) whatever the \
input. Symbolically (P step cycles, df Hz, a Hz/s, j Hz/s^2, r_B = B_V/lambda Hz/s):

| input | aiding | order 1 | order 2 | order 3 |
|---|---|---|---|---|
| step P | any | 0 | 0 | 0 |
| ramp df | unaided | df/omega0 | 0 | 0 |
| parabola a | unaided | grows at a/omega0 cycles/s | a/omega0^2 | 0 |
| cubic j | unaided | grows, d2e/dt2 = j/omega0 | grows at j/omega0^2 cycles/s | j/omega0^3 |
| any | perfect | 0 | 0 | 0 |
| ramp df | band-limited | 0 | 0 | 0 |
| parabola a | band-limited | a/(alpha omega0) | 0 | 0 |
| cubic j | band-limited | grows at j/(alpha omega0) cycles/s | j/(alpha omega0^2) | 0 |
| any | biased INS | grows at -r_B/omega0 cycles/s | -r_B/omega0^2 | 0 |

**Measurement.** Each cell runs until its slowest closed-loop pole (and the band limiter) has \
decayed to 1e-5, then a least-squares line (quadratic for d2e/dt2) over a window of max(1 s, \
50 T) gives the mean error (bounded) or the growth rate (unbounded). Magnitudes are scaled per \
cell: bounded errors about {tgt} cycle, growing ones about {tgt_end} cycle at the end of the \
window (inside the atan's linear range); LOS equivalents use lambda = {lam:.6} m. Agree: \
|measured - closed| <= 5 % of |closed|, or <= 0.005 cycle where the closed form is 0; bounded \
cells at both ends of the window. `max_abs_error_cycles` is over the whole run, transient \
included.",
        bn = short(args.bn_hz),
        w1 = w[0],
        w2 = w[1],
        w3 = w[2],
        alpha = short(args.alpha_rad_s),
        bv = short(args.b_v_mps2),
        tgt = TARGET_ERROR_CYCLES,
        tgt_end = TARGET_END_ERROR_CYCLES,
        lam = LAMBDA_M,
    )
}

pub(super) fn conclusions_md(
    args: &SteadyStateArgs,
    (total, agree): (usize, usize),
    per_cfg: &[serde_json::Value],
    results: &[CellResult],
) -> String {
    let mut s = format!(
        "**{agree} of {total} cells agree with their closed forms** at Bn = {} Hz, T = 1 ms \
(Bn T = {}).\n\n",
        short(args.bn_hz),
        short(args.bn_hz * MAIN_T_COH_S)
    );
    let mut cfg_table = Table::new(&[
        "Bn (Hz)",
        "T (ms)",
        "Bn T",
        "cells agree / run",
        "not run (unstable)",
        "LoopConfig accepts (orders 1 / 2 / 3)",
        "digital loop Bn (Hz), orders 1 / 2 / 3",
    ]);
    for c in per_cfg {
        let bn_d: Vec<String> = c["digital_noise_bandwidth_hz"]
            .as_array()
            .map(|a| {
                a.iter()
                    .map(|v| v.as_f64().map_or("unstable".to_string(), sig))
                    .collect()
            })
            .unwrap_or_default();
        let f = |k: &str| c[k].as_f64().unwrap_or(f64::NAN);
        cfg_table.push(vec![
            short(f("bn_hz")),
            short(f("t_coh_s") * 1e3),
            short(f("bn_t")),
            format!("{} / {}", c["cells_agree"], c["cells_total"]),
            c["cells_not_run"].to_string(),
            c["accepted_by_loop_config"]
                .as_array()
                .map(|a| {
                    a.iter()
                        .map(|v| if v == true { "yes" } else { "no" })
                        .collect::<Vec<_>>()
                        .join(" / ")
                })
                .unwrap_or_default(),
            bn_d.join(" / "),
        ]);
    }
    let others: Vec<&serde_json::Value> = per_cfg.iter().filter(|c| c["main"] == false).collect();
    let count = |k: &str| -> u64 { others.iter().map(|c| c[k].as_u64().unwrap_or(0)).sum() };
    if !others.is_empty() {
        s += "**Other loop configurations** (full run; their rows follow the main table):\n\n";
        s += &cfg_table.to_markdown();
        s += "\n";
        let max_bn_t = results
            .iter()
            .map(|r| r.cell.bn_hz * r.cell.t_coh_s)
            .fold(0.0, f64::max);
        let _ = writeln!(
            s,
            "- Other configurations: **{} of {} simulated cells agree** (Bn T up to {}); {} cells \
were not run because the digital loop is unstable there.",
            count("cells_agree"),
            count("cells_total"),
            short(max_bn_t),
            count("cells_not_run")
        );
    }
    s += &dc_property_md(args, per_cfg, results);
    s += &aiding_md(args, results);
    s += &seed_differences_md(args, results);
    s
}
