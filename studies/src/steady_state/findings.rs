//! The findings of the conclusions: each sentence that states a result is decided by the
//! measured cells (how many agree with their closed forms, the measured values and their sign);
//! the theory that explains them is labelled as such, and the seed's statements as the paper's.

use std::fmt::Write as _;

use super::text::{short, sig};
use super::{stability_limit_bn_t, Aiding, CellResult, Input, SteadyStateArgs};

/// (agreeing, total) over the cells that satisfy `pred`.
fn count(results: &[CellResult], pred: impl Fn(&CellResult) -> bool) -> (usize, usize) {
    let v: Vec<&CellResult> = results.iter().filter(|r| pred(r)).collect();
    (v.iter().filter(|r| r.agree).count(), v.len())
}

/// "12 of 12 cells agree" / "9 of 12 cells agree" / "no cell ran".
fn agree_text((k, n): (usize, usize)) -> String {
    if n == 0 {
        "no cell ran".into()
    } else {
        format!("{k} of {n} cells agree")
    }
}

/// Whether the cell is one of the main table's (the `--bn-hz` loop at T = 1 ms).
fn main_cell(args: &SteadyStateArgs, r: &CellResult) -> bool {
    r.cell.bn_hz == args.bn_hz && r.cell.t_coh_s == super::MAIN_T_COH_S
}

/// The DC-property argument (theory) and what the run measured of it: the other
/// configurations' agreement, the largest digital-loop noise bandwidth over the design Bn (from
/// `per_cfg`), and the stability limits.
pub(super) fn dc_property_md(
    args: &SteadyStateArgs,
    per_cfg: &[serde_json::Value],
    results: &[CellResult],
) -> String {
    let others = count(results, |r| !main_cell(args, r));
    let max_bn_t = results
        .iter()
        .filter(|r| !main_cell(args, r))
        .map(|r| r.cell.bn_hz * r.cell.t_coh_s)
        .fold(0.0, f64::max);
    let measured = if others.1 == 0 {
        format!(
            "This run has only Bn T = {} (without `--quick` the study adds other Bn and T)",
            short(args.bn_hz * super::MAIN_T_COH_S)
        )
    } else if others.0 == others.1 {
        format!(
            "Measured: all {} cells of the other configurations (Bn T up to {}) agree",
            others.1,
            short(max_bn_t)
        )
    } else {
        format!(
            "Measured: only {} of {} cells of the other configurations (Bn T up to {}) agree, \
so the argument does not hold for every one of them (see the table)",
            others.0,
            others.1,
            short(max_bn_t)
        )
    };
    let bn_ratio: f64 = per_cfg
        .iter()
        .flat_map(|c| {
            let bn = c["bn_hz"].as_f64().unwrap_or(f64::NAN);
            c["digital_noise_bandwidth_hz"]
                .as_array()
                .map(|a| {
                    a.iter()
                        .filter_map(|v| v.as_f64())
                        .map(|b| b / bn)
                        .collect::<Vec<_>>()
                })
                .unwrap_or_default()
        })
        .filter(|x| x.is_finite())
        .fold(f64::NAN, f64::max);
    let bandwidth = if bn_ratio.is_finite() {
        format!(
            " (the digital loop's integral of |H|^2: up to {} x the design Bn over this run's \
configurations)",
            sig(bn_ratio)
        )
    } else {
        String::new()
    };
    let limits: Vec<String> = (1..=3u8).map(|o| short(stability_limit_bn_t(o))).collect();
    format!(
        "- Theory: the steady-state error is a DC property of the digital loop: in steady state \
the integrators must ramp the NCO exactly as the residual does, which fixes the error by the \
integrator gains alone, so the closed forms, written with the implemented omega0, should hold \
for any *stable* Bn T, not only for Bn T << 1. {measured}. What departs from the analog design \
as Bn T grows is the loop's noise bandwidth{bandwidth}, its transients (the `max_abs_error_cycles` \
column) and its stability: this implementation's loops are stable for Bn T below {} (orders 1, \
2, 3; `loop_analysis::is_stable`, independent of T; `oracles.md` quotes 0.18 for a 3rd-order \
bilinear loop), and `LoopConfig` accepts Bn T <= {}. Stable loops beyond that limit are \
simulated with the loop filter and Costas discriminator directly (the computation of \
`CarrierLoop`).\n",
        limits.join(", "),
        short(gpsrx_tracking::config::MAX_BN_T),
    )
}

/// The aided cells: perfect aiding (closed form 0), the band-limited aid and the biased INS, each
/// with how many cells agree; seed 004's conclusion (aided loops need order >= 2) is stated as
/// confirmed only when every biased-INS cell agrees.
pub(super) fn aiding_md(args: &SteadyStateArgs, results: &[CellResult]) -> String {
    let mut s = String::new();
    let perfect = count(results, |r| r.cell.aiding == Aiding::Perfect);
    let max_perfect = results
        .iter()
        .filter(|r| r.cell.aiding == Aiding::Perfect)
        .fold(0.0_f64, |m, r| m.max(r.measured.abs()));
    if perfect.1 > 0 {
        let verdict = if perfect.0 == perfect.1 {
            "it leaves no error for any order (seed 004 eq. 7)"
        } else {
            "it does *not* leave a negligible error in every cell (seed 004 eq. 7 predicts 0)"
        };
        let _ = writeln!(
            s,
            "- Perfect aiding (closed form 0 for every order): {}, so {verdict}; largest steady \
error {} cycle over all runs (not exactly 0 because the NCO holds one frequency \
per interval, so a curved phase leaves -theta'' T^2/12 inside each interval, which the loop \
sees and mostly removes).",
            agree_text(perfect),
            sig(max_perfect)
        );
    }
    let band = count(results, |r| r.cell.aiding == Aiding::BandLimited);
    let biased: Vec<(usize, usize)> = (1..=3u8)
        .map(|o| {
            count(results, |r| {
                r.cell.aiding == Aiding::BiasedIns && r.cell.order == o
            })
        })
        .collect();
    let measured: Vec<String> = (1..=3u8)
        .filter_map(|o| biased_measured(args, results, o))
        .collect();
    let o2 = if measured.is_empty() {
        String::new()
    } else {
        format!(" (main table, measured: {})", measured.join("; "))
    };
    let biased_all = biased.iter().all(|(k, n)| k == n) && biased.iter().any(|(_, n)| *n > 0);
    let conclusion = if biased_all {
        "as the closed forms say, aided loops need order >= 2, as seed 004 concludes (order 3 to \
remove the bias error entirely)"
    } else {
        "not every biased-INS cell agrees with its closed form, so this run does not confirm \
seed 004's conclusion that aided loops need order >= 2"
    };
    let _ = writeln!(
        s,
        "- Band-limited aid (theory: the residual is the input times s/(s + alpha), one order of \
dynamics removed): {}. Biased INS (theory: a Doppler ramp that a 1st-order loop cannot \
follow, a 2nd-order loop follows with a constant error -B_V/(lambda omega0^2) and a 3rd-order \
loop removes): order 1 {}, order 2 {}, order 3 {}{o2}: {conclusion}.",
        agree_text(band),
        agree_text(biased[0]),
        agree_text(biased[1]),
        agree_text(biased[2]),
    );
    s
}

/// The biased-INS cells of `order` in the main table, measured: "order 2 -0.0007381 cycles for
/// every input" or "order 1 -0.0066 to -0.0065 cycles/s over the inputs" (None when none ran).
fn biased_measured(args: &SteadyStateArgs, results: &[CellResult], order: u8) -> Option<String> {
    let v: Vec<&CellResult> = results
        .iter()
        .filter(|r| {
            main_cell(args, r) && r.cell.aiding == Aiding::BiasedIns && r.cell.order == order
        })
        .collect();
    let unit = v.first()?.closed.unit();
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| {
            (a.min(r.measured), b.max(r.measured))
        });
    Some(if sig(lo) == sig(hi) {
        format!("order {order} {} {unit} for every input", sig(lo))
    } else {
        format!(
            "order {order} {} to {} {unit} over the inputs",
            sig(lo),
            sig(hi)
        )
    })
}

/// The main-table cell of (input, order, aiding), if it ran.
fn find<'a>(
    args: &SteadyStateArgs,
    results: &'a [CellResult],
    input: Input,
    order: u8,
    aiding: Aiding,
) -> Option<&'a CellResult> {
    results.iter().find(|r| {
        main_cell(args, r)
            && r.cell.input == input
            && r.cell.order == order
            && r.cell.aiding == aiding
    })
}

/// "agrees (measured -0.000738 cycle, closed form -0.000738)" for one cell, or "did not run".
fn cell_verdict(r: Option<&CellResult>) -> String {
    r.map_or("did not run".into(), |r| {
        format!(
            "{} (measured {}, closed form {})",
            if r.agree { "agrees" } else { "does not agree" },
            sig(r.measured),
            sig(r.closed.value())
        )
    })
}

/// Where the derivation differs from seed 004 Table 1 (the paper's entries are background), and
/// what this run's cells say about each difference.
pub(super) fn seed_differences_md(args: &SteadyStateArgs, results: &[CellResult]) -> String {
    let main_biased = |o: u8| {
        count(results, |r| {
            main_cell(args, r) && r.cell.aiding == Aiding::BiasedIns && r.cell.order == o
        })
    };
    let (b1, b2) = (main_biased(1), main_biased(2));
    let jerk2 = find(args, results, Input::Cubic, 2, Aiding::BandLimited);
    let par1 = find(args, results, Input::Parabola, 1, Aiding::BandLimited);
    let signs: Vec<f64> = results
        .iter()
        .filter(|r| main_cell(args, r) && r.cell.aiding == Aiding::BiasedIns && r.cell.order == 2)
        .map(|r| r.measured)
        .collect();
    let sign = if signs.is_empty() {
        "was not measured in this run".to_string()
    } else if signs.iter().all(|&m| m < 0.0) {
        "is negative here (every input)".to_string()
    } else if signs.iter().all(|&m| m > 0.0) {
        "is positive here (every input), against the sign derived below".to_string()
    } else {
        "changes sign with the input here".to_string()
    };
    format!(
        "- Differences from seed 004 Table 1 (the paper's entries are quoted, not measured): (1) \
the bias columns. Seed eq. 16 writes the Doppler error as `B_V/(s lambda)`, a frequency *step*, \
although the velocity error of a constant bias is `B_V t` (eq. 13), whose transform is \
`B_V/s^2`: a frequency *ramp*. The seed's entries B_V/(lambda omega_n) (order 1, step input) and \
0 (order 2) are what a constant velocity error gives; with the ramp, order 1 grows without bound \
and order 2 settles at -B_V/(lambda omega0^2) for every input (this run's main table: order 1 \
{}, order 2 {}; the seed's -1/omega_n^2 for order 2 under an acceleration input is this value \
for a unit Doppler ramp, and its order-1 'infinity' matches). Its order-1 velocity entry \
(1 + B_V/lambda)/omega_n adds an unaided unit-ramp error that perfect aiding removes; not \
reproduced. (2) Band-limited jerk, order 2: the seed's text gives 6/(alpha omega_n) for \
theta = t^3; the dimensions give j/(alpha omega0^2) (j = 6), and this run's cell {}. Its order-1 \
acceleration entry 2/(alpha omega_n) for theta = t^2 (a = 2): this run's cell {}. (3) The \
biased-INS 2nd-order error {sign}: error = signal - NCO and an aid that is too high makes the NCO \
run ahead (`oracles.md` quotes its magnitude, 360 B_V/(lambda omega0^2) deg).\n",
        agree_text(b1),
        agree_text(b2),
        cell_verdict(jerk2),
        cell_verdict(par1),
    )
}
