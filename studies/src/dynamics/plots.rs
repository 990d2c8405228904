//! The plots: satellites tracked through the 10 g turn, phase error std and fewest satellites
//! tracked against the turn acceleration.

use super::aiding::Aiding;
use super::headline::headline;
use super::manoeuvre::Manoeuvre;
use super::params::{HEADLINE_BN_HZ, ORDER1_BN_HZ, TICK_S};
use super::result::CaseResult;
use crate::report::{LinePlot, Series};

pub(super) fn plots(results: &[CaseResult]) -> Vec<LinePlot> {
    let mut out = Vec::new();
    // The 2nd-order aided curves last, so that they are drawn on top.
    let cases = [
        (1u8, ORDER1_BN_HZ, Aiding::Ins1),
        (1, ORDER1_BN_HZ, Aiding::Ins2),
        (2, HEADLINE_BN_HZ, Aiding::Unaided),
        (2, HEADLINE_BN_HZ, Aiding::Ins1),
        (2, HEADLINE_BN_HZ, Aiding::Ins2),
    ];
    let series: Vec<Series> = cases
        .iter()
        .filter_map(|&(o, bn, a)| headline(results, o, bn, a))
        .map(|r| Series {
            name: format!(
                "order {} Bn {} Hz {}",
                r.case.order,
                r.case.bn_hz,
                r.case.aiding.label()
            ),
            points: r
                .tracked_per_tick
                .iter()
                .enumerate()
                .map(|(k, &n)| ((k + 1) as f64 * TICK_S, n as f64))
                .collect(),
            reference: false,
        })
        .collect();
    let cn0 = results
        .iter()
        .map(|r| r.spec.cn0_dbhz)
        .fold(f64::NEG_INFINITY, f64::max);
    let (w0, w1) = Manoeuvre::Turn(10.0).window_s();
    out.push(LinePlot {
        file_name: "tracked_10g.png".into(),
        title: format!(
            "Satellites tracked, 10 g turn {w0}-{w1} s, {cn0} dB-Hz (overlapping curves hide each other)"
        ),
        x_label: "time (s)".into(),
        y_label: "satellites in Track with PLL lock".into(),
        series,
        ..LinePlot::default()
    });
    let turn_g = |r: &CaseResult| match r.spec.manoeuvre {
        Manoeuvre::Turn(g) => Some(g),
        Manoeuvre::Step(_) => None,
    };
    let by_g = |order: u8, bn: f64, a: Aiding, y: &dyn Fn(&CaseResult) -> f64| Series {
        name: format!("order {order} Bn {bn} Hz {}", a.label()),
        points: results
            .iter()
            .filter(|r| {
                r.spec.cn0_dbhz == cn0
                    && r.case.order == order
                    && r.case.bn_hz == bn
                    && r.case.aiding == a
            })
            .filter_map(|r| turn_g(r).map(|g| (g, y(r))))
            .collect(),
        reference: false,
    };
    let modes = [Aiding::Unaided, Aiding::Ins1, Aiding::Ins2];
    out.push(LinePlot {
        file_name: "phase_std_vs_g.png".into(),
        title: format!(
            "Phase error std vs turn acceleration (order 2, Bn {HEADLINE_BN_HZ} Hz, {cn0} dB-Hz; INS 1 and 2 coincide)"
        ),
        x_label: "turn acceleration (g)".into(),
        y_label: "phase error std over locked intervals (cycle)".into(),
        log_y: true,
        series: modes
            .iter()
            .map(|&a| by_g(2, HEADLINE_BN_HZ, a, &|r| r.phase_std_cycles))
            .collect(),
        ..LinePlot::default()
    });
    out.push(LinePlot {
        file_name: "min_tracked_vs_g.png".into(),
        title: format!("Fewest satellites tracked in the turn, {cn0} dB-Hz"),
        x_label: "turn acceleration (g)".into(),
        y_label: "min satellites tracked".into(),
        series: min_tracked_series(results, cn0),
        ..LinePlot::default()
    });
    out
}

/// Fewest satellites tracked in the turns vs g: unaided loops of order 2 and 3 at the wider
/// bandwidths of the grid, and the fewest over the aided cases of order >= 2 that were tracking
/// every satellite when the manoeuvre began.
fn min_tracked_series(results: &[CaseResult], cn0: f64) -> Vec<Series> {
    let turns =
        |r: &&CaseResult| r.spec.cn0_dbhz == cn0 && matches!(r.spec.manoeuvre, Manoeuvre::Turn(_));
    let mut out = Vec::new();
    for order in [2u8, 3] {
        for bn in [5.0, 10.0, 18.0] {
            let points: Vec<(f64, f64)> = results
                .iter()
                .filter(turns)
                .filter(|r| {
                    r.case.aiding == Aiding::Unaided && r.case.order == order && r.case.bn_hz == bn
                })
                .map(|r| (r.spec.manoeuvre.g(), r.tracked_min as f64))
                .collect();
            if !points.is_empty() {
                out.push(Series {
                    name: format!("unaided, order {order}, Bn {bn} Hz"),
                    points,
                    reference: false,
                });
            }
        }
    }
    let mut gs: Vec<f64> = results
        .iter()
        .filter(turns)
        .map(|r| r.spec.manoeuvre.g())
        .collect();
    gs.sort_by(f64::total_cmp);
    gs.dedup();
    out.push(Series {
        name: "aided (INS 1 or 2, order >= 2, every Bn tracking all at the start): fewest".into(),
        points: gs
            .iter()
            .map(|&g| {
                let min = results
                    .iter()
                    .filter(turns)
                    .filter(|r| {
                        r.spec.manoeuvre.g() == g
                            && r.case.aiding != Aiding::Unaided
                            && r.case.order >= 2
                            && r.tracked_at_start == r.satellites
                    })
                    .map(|r| r.tracked_min)
                    .min()
                    .unwrap_or(0);
                (g, min as f64)
            })
            .collect(),
        reference: false,
    });
    out
}
