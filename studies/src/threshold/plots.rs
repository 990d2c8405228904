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

/// One plot per integration time for the static cells (the receiver's lock and the loop's own
/// slip-free threshold per order, the rule once: it is the same for every order without
/// stress, the lock detector's floor and the 3rd-order stability floor) and one for the other
/// dynamics (measured and rule per dynamics and order).
pub fn plots(results: &[CellResult]) -> Vec<LinePlot> {
    let mut out = Vec::new();
    for t_coh_ms in super::grid::T_COH_MS {
        for static_only in [true, false] {
            let series = if static_only {
                static_series(results, t_coh_ms)
            } else {
                dynamics_series(results, t_coh_ms)
            };
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

fn static_series(results: &[CellResult], t_coh_ms: u32) -> Vec<Series> {
    let d = Dynamics::Static;
    let mut series = Vec::new();
    for order in 1..=3u8 {
        series.push(Series {
            name: format!("order {order}, receiver lock"),
            points: points(results, order, t_coh_ms, d, CellResult::measured_dbhz),
            reference: false,
        });
    }
    for order in 1..=3u8 {
        series.push(Series {
            name: format!("order {order}, loop slip-free"),
            points: points(results, order, t_coh_ms, d, CellResult::loop_dbhz),
            reference: false,
        });
    }
    let lowest = (1..=3u8)
        .find(|&o| !points(results, o, t_coh_ms, d, |r| r.theory.rule_dbhz).is_empty())
        .unwrap_or(1);
    series.push(Series {
        name: "rule 3 sigma = 45 deg".into(),
        points: points(results, lowest, t_coh_ms, d, |r| r.theory.rule_dbhz),
        reference: true,
    });
    series.push(Series {
        name: format!("rule with atan noise (order {lowest})"),
        points: points(results, lowest, t_coh_ms, d, |r| r.theory.rule_atan_dbhz),
        reference: true,
    });
    series.push(Series {
        name: "lock detector floor".into(),
        points: points(results, lowest, t_coh_ms, d, |r| r.theory.detector_dbhz),
        reference: true,
    });
    series.push(Series {
        name: "order 3 stability floor".into(),
        points: points(results, 3, t_coh_ms, d, |r| r.theory.stable_dbhz),
        reference: true,
    });
    series.retain(|s| !s.points.is_empty());
    series
}

fn dynamics_series(results: &[CellResult], t_coh_ms: u32) -> Vec<Series> {
    let mut series = Vec::new();
    for dynamics in super::grid::DYNAMICS {
        if dynamics == Dynamics::Static {
            continue;
        }
        for &order in dynamics.orders() {
            let label = format!("order {order}, {}", dynamics.name());
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
                name: format!("{label} rule"),
                points: t,
                reference: true,
            });
            series.push(Series {
                name: format!("{label} rule, atan noise"),
                points: points(results, order, t_coh_ms, dynamics, |r| {
                    r.theory.rule_atan_dbhz
                }),
                reference: true,
            });
        }
    }
    series
}
