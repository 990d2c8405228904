//! The study's plots.

use super::grid::cn0_t;
use super::{CellResult, CellStatus, DLL_BN_HZ, EL_SPACING_CHIPS, HIGH_SNR_CN0_T};
use crate::if_sim;
use crate::report::{LinePlot, Series};

pub(super) fn plots(results: &[CellResult]) -> Vec<LinePlot> {
    let mut cn0s: Vec<f64> = Vec::new();
    for r in results {
        if !cn0s.contains(&r.cell.cn0_dbhz) {
            cn0s.push(r.cell.cn0_dbhz);
        }
    }
    // At most four C/N0 values, spread over the range.
    let pick: Vec<f64> = if cn0s.len() <= 4 {
        cn0s.clone()
    } else {
        let n = cn0s.len() - 1;
        (0..4).map(|i| cn0s[(i * n + 1) / 3]).collect::<Vec<_>>()
    };
    let pick: Vec<f64> = {
        let mut p = pick;
        p.dedup();
        p
    };
    let sel = |cn0: f64, order: u8, t_ms: u32| -> Vec<&CellResult> {
        results
            .iter()
            .filter(|r| {
                r.cell.cn0_dbhz == cn0
                    && r.cell.order == order
                    && r.cell.t_ms == t_ms
                    && r.status == CellStatus::Run
            })
            .collect()
    };
    let mut out = Vec::new();
    for t_ms in [1u32, 20] {
        let mut series = Vec::new();
        for &cn0 in &pick {
            let cells = sel(cn0, 2, t_ms);
            if cells.is_empty() {
                continue;
            }
            series.push(Series {
                name: format!("{cn0} dB-Hz measured"),
                points: cells
                    .iter()
                    .filter(|r| r.locked())
                    .map(|r| (r.cell.bn_hz, r.measured.phase_deg))
                    .collect(),
                reference: false,
            });
            series.push(Series {
                name: format!("{cn0} dB-Hz formula"),
                points: cells
                    .iter()
                    .map(|r| (r.cell.bn_hz, r.theory.phase_formula_deg))
                    .collect(),
                reference: true,
            });
        }
        if series.iter().any(|s| !s.points.is_empty() && !s.reference) {
            out.push(LinePlot {
                file_name: format!("jitter_vs_bn_t{t_ms}ms.png"),
                title: format!("PLL phase jitter vs Bn (order 2, T = {t_ms} ms)"),
                x_label: "Bn (Hz)".into(),
                y_label: "phase jitter (deg)".into(),
                log_x: true,
                log_y: true,
                series,
            });
        }
    }
    // Measured / formula against Bn T: the mean over C/N0 of the locked cells at high prompt
    // SNR (C/N0 T >= 3) for each (order, T, Bn), with the digital loop's prediction.
    let mut series = Vec::new();
    for order in [2u8, 3] {
        for t_ms in [1u32, 20] {
            let mut pts: Vec<(f64, f64)> = Vec::new();
            for r in results.iter().filter(|r| {
                r.locked()
                    && r.cell.order == order
                    && r.cell.t_ms == t_ms
                    && r.above_threshold()
                    && cn0_t(&r.cell) >= HIGH_SNR_CN0_T
            }) {
                if pts.iter().any(|p| p.0 == r.cell.bn_t()) {
                    continue;
                }
                let same: Vec<f64> = results
                    .iter()
                    .filter(|q| {
                        q.locked()
                            && q.cell.order == order
                            && q.cell.t_ms == t_ms
                            && q.cell.bn_hz == r.cell.bn_hz
                            && q.above_threshold()
                            && cn0_t(&q.cell) >= HIGH_SNR_CN0_T
                    })
                    .map(|q| q.ratio())
                    .collect();
                pts.push((r.cell.bn_t(), if_sim::mean(&same)));
            }
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if !pts.is_empty() {
                series.push(Series {
                    name: format!("order {order}, T {t_ms} ms (mean over C/N0)"),
                    points: pts,
                    reference: false,
                });
            }
        }
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
        series.push(Series {
            name: format!("digital loop / formula, order {order}"),
            points: curve,
            reference: true,
        });
    }
    out.push(LinePlot {
        file_name: "ratio_vs_bnt.png".into(),
        title: "Measured / formula phase jitter vs Bn T (C/N0 T >= 3, locked)".into(),
        x_label: "Bn T".into(),
        y_label: "measured / formula".into(),
        log_x: true,
        log_y: false,
        series,
    });
    // Pseudorange-rate error vs Bn.
    let mut series = Vec::new();
    for &cn0 in &pick {
        let cells = sel(cn0, 2, 1);
        if cells.is_empty() {
            continue;
        }
        series.push(Series {
            name: format!("{cn0} dB-Hz, 0.1 s measured"),
            points: cells
                .iter()
                .filter(|r| r.locked())
                .map(|r| (r.cell.bn_hz, r.measured.pr_rate_mps))
                .collect(),
            reference: false,
        });
        series.push(Series {
            name: format!("{cn0} dB-Hz, 0.1 s theory"),
            points: cells
                .iter()
                .map(|r| (r.cell.bn_hz, r.theory.pr_rate_mps))
                .collect(),
            reference: true,
        });
    }
    out.push(LinePlot {
        file_name: "pr_rate_vs_bn.png".into(),
        title: "Pseudorange-rate error std (0.1 s carrier-phase Doppler) vs Bn (order 2, T 1 ms)"
            .into(),
        x_label: "Bn (Hz)".into(),
        y_label: "pseudorange-rate error std (m/s)".into(),
        log_x: true,
        log_y: true,
        series,
    });
    // Code error vs C/N0: the cells at the median Bn of each (C/N0, T) (the DLL is the same in
    // every cell of a row).
    let mut series = Vec::new();
    for t_ms in [1u32, 20] {
        let mut meas = Vec::new();
        let mut formula = Vec::new();
        let mut envelope = Vec::new();
        for &cn0 in &cn0s {
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
            continue;
        }
        series.push(Series {
            name: format!("T {t_ms} ms measured"),
            points: meas,
            reference: false,
        });
        series.push(Series {
            name: format!("T {t_ms} ms E-L power formula"),
            points: formula,
            reference: true,
        });
        series.push(Series {
            name: format!("T {t_ms} ms normalised envelope"),
            points: envelope,
            reference: true,
        });
    }
    out.push(LinePlot {
        file_name: "code_vs_cn0.png".into(),
        title: format!("DLL code error std vs C/N0 (Bn {DLL_BN_HZ} Hz, d {EL_SPACING_CHIPS} chip)"),
        x_label: "C/N0 (dB-Hz)".into(),
        y_label: "code error std (chips)".into(),
        log_x: false,
        log_y: true,
        series,
    });
    out
}
