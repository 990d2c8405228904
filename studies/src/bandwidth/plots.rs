//! The study's plots: phase jitter and pseudorange-rate error against Bn, measured / formula
//! against `Bn T`, and code error against C/N0.

use super::grid::cn0_t;
use super::{CellResult, CellStatus, DLL_BN_HZ, EL_SPACING_CHIPS, HIGH_SNR_CN0_T};
use crate::if_sim;
use crate::report::{LinePlot, Series};

/// Every plot of the study, in the order `study.md` shows them.
pub(super) fn plots(results: &[CellResult]) -> Vec<LinePlot> {
    let cn0s = cn0_values(results);
    let pick = picked_cn0s(&cn0s);
    let mut out: Vec<LinePlot> = [1u32, 20]
        .into_iter()
        .filter_map(|t_ms| jitter_vs_bn_plot(results, &pick, t_ms))
        .collect();
    out.push(ratio_vs_bnt_plot(results));
    out.push(pr_rate_vs_bn_plot(results, &pick));
    out.push(code_vs_cn0_plot(results, &cn0s));
    out
}

/// The grid's C/N0 values, in the order they first appear.
fn cn0_values(results: &[CellResult]) -> Vec<f64> {
    let mut cn0s: Vec<f64> = Vec::new();
    for r in results {
        if !cn0s.contains(&r.cell.cn0_dbhz) {
            cn0s.push(r.cell.cn0_dbhz);
        }
    }
    cn0s
}

/// At most four C/N0 values, spread over the range (the curves of the plots against Bn).
fn picked_cn0s(cn0s: &[f64]) -> Vec<f64> {
    let mut pick: Vec<f64> = if cn0s.len() <= 4 {
        cn0s.to_vec()
    } else {
        let n = cn0s.len() - 1;
        (0..4).map(|i| cn0s[(i * n + 1) / 3]).collect::<Vec<_>>()
    };
    pick.dedup();
    pick
}

/// The cells that ran at this C/N0, PLL order and T, in grid order (ascending Bn).
fn run_cells(results: &[CellResult], cn0: f64, order: u8, t_ms: u32) -> Vec<&CellResult> {
    results
        .iter()
        .filter(|r| {
            r.cell.cn0_dbhz == cn0
                && r.cell.order == order
                && r.cell.t_ms == t_ms
                && r.status == CellStatus::Run
        })
        .collect()
}

/// Two curves against Bn for one C/N0: `measured` over the locked `cells` (named
/// `measured_name`) and the reference `theory` over all of them (named `theory_name`).
fn measured_and_theory_vs_bn(
    cells: &[&CellResult],
    measured_name: String,
    theory_name: String,
    measured: impl Fn(&CellResult) -> f64,
    theory: impl Fn(&CellResult) -> f64,
) -> [Series; 2] {
    [
        Series {
            name: measured_name,
            points: cells
                .iter()
                .filter(|r| r.locked())
                .map(|r| (r.cell.bn_hz, measured(r)))
                .collect(),
            reference: false,
        },
        Series {
            name: theory_name,
            points: cells.iter().map(|r| (r.cell.bn_hz, theory(r))).collect(),
            reference: true,
        },
    ]
}

/// `jitter_vs_bn_t{T}ms.png`: the 2nd-order loops' measured phase jitter against Bn at the
/// picked C/N0s, with the Costas formula (oracles.md). None when no cell of that T held lock.
fn jitter_vs_bn_plot(results: &[CellResult], pick: &[f64], t_ms: u32) -> Option<LinePlot> {
    let mut series = Vec::new();
    for &cn0 in pick {
        let cells = run_cells(results, cn0, 2, t_ms);
        if cells.is_empty() {
            continue;
        }
        series.extend(measured_and_theory_vs_bn(
            &cells,
            format!("{cn0} dB-Hz measured"),
            format!("{cn0} dB-Hz formula"),
            |r| r.measured.phase_deg,
            |r| r.theory.phase_formula_deg,
        ));
    }
    series
        .iter()
        .any(|s| !s.points.is_empty() && !s.reference)
        .then(|| LinePlot {
            file_name: format!("jitter_vs_bn_t{t_ms}ms.png"),
            title: format!("PLL phase jitter vs Bn (order 2, T = {t_ms} ms)"),
            x_label: "Bn (Hz)".into(),
            y_label: "phase jitter (deg)".into(),
            log_x: true,
            log_y: true,
            series,
        })
}

/// `ratio_vs_bnt.png`: measured / formula phase jitter against `Bn T` (the mean over C/N0 of
/// the locked cells at high prompt SNR, per order and T) with the linearised digital loop's
/// prediction per order: where the formula's small-`Bn T` assumption stops holding.
fn ratio_vs_bnt_plot(results: &[CellResult]) -> LinePlot {
    let mut series = Vec::new();
    for order in [2u8, 3] {
        for t_ms in [1u32, 20] {
            let pts = mean_ratio_vs_bnt(results, order, t_ms);
            if !pts.is_empty() {
                series.push(Series {
                    name: format!("order {order}, T {t_ms} ms (mean over C/N0)"),
                    points: pts,
                    reference: false,
                });
            }
        }
        series.push(Series {
            name: format!("digital loop / formula, order {order}"),
            points: digital_ratio_vs_bnt(results, order),
            reference: true,
        });
    }
    LinePlot {
        file_name: "ratio_vs_bnt.png".into(),
        title: "Measured / formula phase jitter vs Bn T (C/N0 T >= 3, locked)".into(),
        x_label: "Bn T".into(),
        y_label: "measured / formula".into(),
        log_x: true,
        log_y: false,
        series,
    }
}

/// A cell that enters the mean of [`mean_ratio_vs_bnt`]: locked, of this order and T, above
/// threshold and at high prompt SNR (`C/N0 T >= 3`).
fn in_ratio_mean(r: &CellResult, order: u8, t_ms: u32) -> bool {
    r.locked()
        && r.cell.order == order
        && r.cell.t_ms == t_ms
        && r.above_threshold()
        && cn0_t(&r.cell) >= HIGH_SNR_CN0_T
}

/// (`Bn T`, mean over C/N0 of measured / formula) of the [`in_ratio_mean`] cells of this order
/// and T, one point per Bn, by ascending `Bn T`.
fn mean_ratio_vs_bnt(results: &[CellResult], order: u8, t_ms: u32) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for r in results.iter().filter(|r| in_ratio_mean(r, order, t_ms)) {
        if pts.iter().any(|p| p.0 == r.cell.bn_t()) {
            continue;
        }
        let same: Vec<f64> = results
            .iter()
            .filter(|q| in_ratio_mean(q, order, t_ms) && q.cell.bn_hz == r.cell.bn_hz)
            .map(|q| q.ratio())
            .collect();
        pts.push((r.cell.bn_t(), if_sim::mean(&same)));
    }
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts
}

/// (`Bn T`, digital loop / formula) of the cells of this order that ran, one point per `Bn T`,
/// by ascending `Bn T`.
fn digital_ratio_vs_bnt(results: &[CellResult], order: u8) -> Vec<(f64, f64)> {
    let mut curve: Vec<(f64, f64)> = results
        .iter()
        .filter(|r| {
            r.cell.order == order
                && r.status == CellStatus::Run
                && r.theory.phase_digital_ratio.is_finite()
        })
        .map(|r| (r.cell.bn_t(), r.theory.phase_digital_ratio))
        .collect();
    curve.sort_by(|a, b| a.0.total_cmp(&b.0));
    curve.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-12);
    curve
}

/// `pr_rate_vs_bn.png`: the 0.1 s carrier-phase pseudorange-rate error std of the 2nd-order,
/// T = 1 ms loops against Bn at the picked C/N0s, with the linearised digital loop's value.
fn pr_rate_vs_bn_plot(results: &[CellResult], pick: &[f64]) -> LinePlot {
    let mut series = Vec::new();
    for &cn0 in pick {
        let cells = run_cells(results, cn0, 2, 1);
        if cells.is_empty() {
            continue;
        }
        series.extend(measured_and_theory_vs_bn(
            &cells,
            format!("{cn0} dB-Hz, 0.1 s measured"),
            format!("{cn0} dB-Hz, 0.1 s theory"),
            |r| r.measured.pr_rate_mps,
            |r| r.theory.pr_rate_mps,
        ));
    }
    LinePlot {
        file_name: "pr_rate_vs_bn.png".into(),
        title: "Pseudorange-rate error std (0.1 s carrier-phase Doppler) vs Bn (order 2, T 1 ms)"
            .into(),
        x_label: "Bn (Hz)".into(),
        y_label: "pseudorange-rate error std (m/s)".into(),
        log_x: true,
        log_y: true,
        series,
    }
}

/// `code_vs_cn0.png`: the DLL code error std against C/N0 per T, with the oracle's E-L power
/// formula and the linearised normalised-envelope DLL.
fn code_vs_cn0_plot(results: &[CellResult], cn0s: &[f64]) -> LinePlot {
    let series = [1u32, 20]
        .into_iter()
        .flat_map(|t_ms| code_vs_cn0_series(results, cn0s, t_ms))
        .collect();
    LinePlot {
        file_name: "code_vs_cn0.png".into(),
        title: format!("DLL code error std vs C/N0 (Bn {DLL_BN_HZ} Hz, d {EL_SPACING_CHIPS} chip)"),
        x_label: "C/N0 (dB-Hz)".into(),
        y_label: "code error std (chips)".into(),
        log_x: false,
        log_y: true,
        series,
    }
}

/// The three curves of [`code_vs_cn0_plot`] at one T (none when no cell of that T held lock):
/// per C/N0 the median measured code error over the locked cells of every order and Bn (the
/// DLL is the same in every cell of a row), and the two theories of the first of them.
fn code_vs_cn0_series(results: &[CellResult], cn0s: &[f64], t_ms: u32) -> Vec<Series> {
    let mut meas = Vec::new();
    let mut formula = Vec::new();
    let mut envelope = Vec::new();
    for &cn0 in cn0s {
        let cells: Vec<&CellResult> = results
            .iter()
            .filter(|r| r.cell.cn0_dbhz == cn0 && r.cell.t_ms == t_ms && r.locked())
            .collect();
        if cells.is_empty() {
            continue;
        }
        let mut v: Vec<f64> = cells.iter().map(|r| r.measured.code_chips).collect();
        v.sort_by(f64::total_cmp);
        meas.push((cn0, v[v.len() / 2]));
        formula.push((cn0, cells[0].theory.code_formula_chips));
        envelope.push((cn0, cells[0].theory.code_envelope_chips));
    }
    if meas.is_empty() {
        return Vec::new();
    }
    vec![
        Series {
            name: format!("T {t_ms} ms measured"),
            points: meas,
            reference: false,
        },
        Series {
            name: format!("T {t_ms} ms E-L power formula"),
            points: formula,
            reference: true,
        },
        Series {
            name: format!("T {t_ms} ms normalised envelope"),
            points: envelope,
            reference: true,
        },
    ]
}
