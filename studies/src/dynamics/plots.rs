//! The plots: satellites tracked through the 10 g turn at 0.4 Hz (seed 004 Figs. 12/15), phase
//! error std and fewest satellites tracked against the turn acceleration.

use super::aiding::Aiding;
use super::headline::{cn0s, Trio};
use super::manoeuvre::Manoeuvre;
use super::params::{HEADLINE_BN_HZ, MG_MPS2, NARROW_DEFAULT_BIAS_MG, TICK_S};
use super::result::CaseResult;
use crate::report::{LinePlot, Series};

/// Satellites tracked against time: one series per case.
fn tracked_series(r: &CaseResult) -> Series {
    Series {
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
    }
}

/// Seed 004 Figs. 12/15 at one C/N0: satellites tracked through the 10 g turn, orders 2 and 3
/// at 0.4 Hz, unaided and aided (None when none of these cases ran).
fn figs_plot(results: &[CaseResult], cn0: f64) -> Option<LinePlot> {
    let b = NARROW_DEFAULT_BIAS_MG * MG_MPS2;
    let mut series = Vec::new();
    let mut window = None;
    for order in [2u8, 3] {
        let t = Trio::new(results, cn0, order, HEADLINE_BN_HZ, b);
        for r in [t.unaided, t.ins1, t.ins2].into_iter().flatten() {
            window = Some(r.spec.window_s());
            series.push(tracked_series(r));
        }
    }
    let (w0, w1) = window?;
    Some(LinePlot {
        file_name: format!("tracked_10g_{cn0}dbhz.png"),
        title: format!(
            "Satellites tracked, 10 g turn {w0}-{w1} s, {cn0} dB-Hz, Bn {HEADLINE_BN_HZ} Hz (Figs. 12/15)"
        ),
        x_label: "time (s)".into(),
        y_label: "satellites in Track with PLL lock".into(),
        series,
        ..LinePlot::default()
    })
}

pub(super) fn plots(results: &[CaseResult]) -> Vec<LinePlot> {
    let all_cn0 = cn0s(results);
    let mut out: Vec<LinePlot> = all_cn0
        .iter()
        .filter_map(|&c| figs_plot(results, c))
        .collect();
    let cn0 = all_cn0.last().copied().unwrap_or(f64::NAN);
    let turn_g = |r: &CaseResult| match r.spec.manoeuvre {
        Manoeuvre::Turn(g) => Some(g),
        Manoeuvre::Step(_) => None,
    };
    let bias = NARROW_DEFAULT_BIAS_MG * MG_MPS2;
    let by_g = |order: u8, bn: f64, a: Aiding, y: &dyn Fn(&CaseResult) -> f64| Series {
        name: format!("order {order} Bn {bn} Hz {}", a.label()),
        points: results
            .iter()
            .filter(|r| {
                r.spec.cn0_dbhz == cn0
                    && r.case.order == order
                    && r.case.bn_hz == bn
                    && r.case.aiding == a
                    && (a == Aiding::Unaided || r.case.ins1_bias_mps2 == bias)
            })
            .filter_map(|r| turn_g(r).map(|g| (g, y(r))))
            .collect(),
        reference: false,
    };
    let modes = [Aiding::Unaided, Aiding::Ins1, Aiding::Ins2];
    out.push(LinePlot {
        file_name: "phase_std_vs_g.png".into(),
        title: format!(
            "Phase error std vs turn acceleration (Bn {HEADLINE_BN_HZ} Hz, {cn0} dB-Hz, INS 1 {NARROW_DEFAULT_BIAS_MG} mg)"
        ),
        x_label: "turn acceleration (g)".into(),
        y_label: "phase error std over locked intervals (cycle)".into(),
        log_y: true,
        series: [2u8, 3]
            .iter()
            .flat_map(|&o| {
                modes
                    .iter()
                    .map(move |&a| (o, a))
            })
            .map(|(o, a)| by_g(o, HEADLINE_BN_HZ, a, &|r| r.phase_std_cycles))
            .filter(|s| !s.points.is_empty())
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
        for bn in [HEADLINE_BN_HZ, 5.0, 10.0, 18.0] {
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
