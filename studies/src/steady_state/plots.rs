//! The plots: error against time with the closed forms.

use super::fit::eval_fit;
use super::text::{closed_text, magnitude_text, short};
use super::{Aiding, CellResult, ClosedForm, Input, SteadyStateArgs};
use crate::report::{LinePlot, Series};

pub(super) fn plots(main: &[&CellResult], args: &SteadyStateArgs) -> Vec<LinePlot> {
    let pick = |input: Input, aiding: Aiding| -> Vec<&CellResult> {
        let mut v: Vec<&CellResult> = main
            .iter()
            .copied()
            .filter(|r| r.cell.input == input && r.cell.aiding == aiding)
            .collect();
        v.sort_by_key(|r| r.cell.order);
        v
    };
    vec![
        error_plot(
            "steady_state_parabola_unaided.png",
            &format!(
                "Parabola (constant Doppler rate), unaided, Bn {} Hz",
                short(args.bn_hz)
            ),
            &pick(Input::Parabola, Aiding::Unaided),
        ),
        error_plot(
            "steady_state_biased_ins.png",
            &format!(
                "Biased INS (B_V {} m/s^2), parabola input, Bn {} Hz",
                short(args.b_v_mps2),
                short(args.bn_hz)
            ),
            &pick(Input::Parabola, Aiding::BiasedIns),
        ),
        error_plot(
            "steady_state_cubic_band_limited.png",
            &format!(
                "Cubic (constant jerk), band-limited aid (alpha {} rad/s), Bn {} Hz",
                short(args.alpha_rad_s),
                short(args.bn_hz)
            ),
            &pick(Input::Cubic, Aiding::BandLimited),
        ),
    ]
}

/// Error against time for a few cells, with the closed forms dashed: the bounded value, or for a
/// growing error the predicted growth anchored at the fitted value (and slope, for `p = 2`) at
/// the window start.
fn error_plot(file: &str, title: &str, cells: &[&CellResult]) -> LinePlot {
    let mut series = Vec::new();
    for r in cells {
        series.push(Series {
            name: format!(
                "order {}, {} (measured)",
                r.cell.order,
                magnitude_text(r)
                    .split(" (")
                    .next()
                    .unwrap_or_default()
                    .split(';')
                    .next()
                    .unwrap_or_default()
            ),
            points: r.trace.clone(),
            reference: false,
        });
        let (t0, t1) = r.window;
        let points: Vec<(f64, f64)> = match r.closed {
            ClosedForm::Bounded(c) => vec![(0.0, c), (t1, c)],
            ClosedForm::Growing { p, rate } => {
                let e0 = eval_fit(&r.fit, t0);
                let slope0 = if p == 1 {
                    rate
                } else {
                    let x = t0 - r.fit.1;
                    r.fit.0[1] + 2.0 * r.fit.0[2] * x
                };
                (0..=50)
                    .map(|i| {
                        let dt = (t1 - t0) * f64::from(i) / 50.0;
                        let curv = if p == 2 { 0.5 * rate * dt * dt } else { 0.0 };
                        (t0 + dt, e0 + slope0 * dt + curv)
                    })
                    .collect()
            }
        };
        series.push(Series {
            name: format!(
                "order {}: closed form {}",
                r.cell.order,
                closed_text(r.closed)
            ),
            points,
            reference: true,
        });
    }
    LinePlot {
        file_name: file.into(),
        title: title.into(),
        x_label: "time (s)".into(),
        y_label: "phase error (cycles)".into(),
        log_x: false,
        log_y: false,
        series,
    }
}
