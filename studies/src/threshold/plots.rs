//! The plots: measured and theoretical thresholds against Bn.

use super::result::CellResult;
use super::Dynamics;
use crate::report::{LinePlot, Series};

/// Points `(Bn, threshold)` of the cells of `order`, `t_coh_ms` and `dynamics`, sorted by Bn.
fn points(
    results: &[CellResult],
    order: u8,
    t_coh_ms: u32,
    dynamics: Dynamics,
    value: impl Fn(&CellResult) -> Option<f64>,
) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = results
        .iter()
        .filter(|r| {
            r.rejected.is_none()
                && r.cell.order == order
                && r.cell.t_coh_ms == t_coh_ms
                && r.cell.dynamics == dynamics
        })
        .filter_map(|r| value(r).map(|v| (r.cell.bn_hz, v)))
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    p
}

/// One plot per integration time: every (dynamics, order) with at least one measured or
/// theoretical threshold, measured (dots) and rule of thumb (dashed), and the lock detector's
/// floor for static cells of the lowest order present.
pub fn plots(results: &[CellResult]) -> Vec<LinePlot> {
    let mut out = Vec::new();
    for t_coh_ms in super::grid::T_COH_MS {
        for static_only in [true, false] {
            let mut series = Vec::new();
            let mut floor_done = false;
            for dynamics in super::grid::DYNAMICS {
                if (dynamics == Dynamics::Static) != static_only {
                    continue;
                }
                for &order in dynamics.orders() {
                    let label = if static_only {
                        format!("order {order}")
                    } else {
                        format!("order {order}, {}", dynamics.name())
                    };
                    let m = points(
                        results,
                        order,
                        t_coh_ms,
                        dynamics,
                        CellResult::measured_dbhz,
                    );
                    let t = points(results, order, t_coh_ms, dynamics, |r| r.theory.rule_dbhz);
                    if m.is_empty() && t.is_empty() {
                        continue;
                    }
                    series.push(Series {
                        name: format!("{label} measured"),
                        points: m,
                        reference: false,
                    });
                    series.push(Series {
                        name: format!("{label} rule 3 sigma + theta_e = 45 deg"),
                        points: t,
                        reference: true,
                    });
                    if static_only && !floor_done {
                        let f = points(results, order, t_coh_ms, dynamics, |r| {
                            r.theory.detector_dbhz
                        });
                        if !f.is_empty() {
                            series.push(Series {
                                name: "lock detector floor".into(),
                                points: f,
                                reference: true,
                            });
                            floor_done = true;
                        }
                    }
                }
            }
            if series.iter().all(|s| s.points.is_empty()) {
                continue;
            }
            let what = if static_only { "static" } else { "dynamics" };
            out.push(LinePlot {
                file_name: format!("threshold_{what}_t{t_coh_ms}ms.png"),
                title: format!(
                    "Tracking threshold (lock held 95 % of 30 s), {what}, T = {t_coh_ms} ms"
                ),
                x_label: "Bn (Hz)".into(),
                y_label: "C/N0 threshold (dB-Hz)".into(),
                log_x: true,
                log_y: false,
                series,
            });
        }
    }
    out
}
