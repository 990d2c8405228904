//! `dop.png`: the number of satellites used (upper panel) and PDOP and HDOP (lower panel)
//! against time.

use super::canvas::{linear_chart, titled, with_legend_strip, MARGIN_PX, X_AREA_PX, Y_AREA_PX};
use super::data::FixPoint;
use super::legend::{draw_legend, LegendEntry, Swatch};
use super::style::{color, plot_err, AXIS_DESC_PX, LABEL_PX};
use super::ticks::{padded_range, tick_label};
use super::PlotError;
use plotters::prelude::*;
use std::path::Path;

/// Size of `dop.png`, px.
pub const DOP_SIZE: (u32, u32) = (1000, 700);
/// DOP values above this are drawn at the top of the panel (flagged fixes reach hundreds).
const DOP_CEILING: f64 = 20.0;

/// Draws satellites used, PDOP and HDOP of `fixes` against time into `path`.
pub fn draw_dop(fixes: &[FixPoint], path: &Path) -> Result<(), PlotError> {
    let entries = vec![
        LegendEntry {
            name: "satellites used".into(),
            color: BLACK,
            swatch: Swatch::Line,
        },
        LegendEntry {
            name: "PDOP".into(),
            color: color(0),
            swatch: Swatch::Line,
        },
        LegendEntry {
            name: "HDOP".into(),
            color: color(1),
            swatch: Swatch::Line,
        },
    ];
    let area = titled(path, DOP_SIZE, "Satellites used and dilution of precision")?;
    let (charts, side) = with_legend_strip(&area, &entries);
    let (upper, lower) = charts.split_vertically(charts.dim_in_pixel().1 / 2);
    let (_, t1) = padded_range(fixes.iter().map(|f| f.t_s), false);
    let t0 = 0.0;
    let n_max = fixes.iter().map(|f| f.n_sv).max().unwrap_or(4).max(4) as i32;
    let mut top = ChartBuilder::on(&upper)
        .margin(MARGIN_PX)
        .x_label_area_size(X_AREA_PX)
        .y_label_area_size(Y_AREA_PX)
        .build_cartesian_2d(t0..t1, 0..n_max + 1)
        .map_err(plot_err(path))?;
    top.configure_mesh()
        .light_line_style(TRANSPARENT)
        .y_desc("satellites used")
        .x_label_formatter(&|v| tick_label(*v))
        .y_labels((n_max + 2) as usize)
        .label_style(("sans-serif", LABEL_PX))
        .axis_desc_style(("sans-serif", AXIS_DESC_PX))
        .draw()
        .map_err(plot_err(path))?;
    let steps = fixes.windows(2).flat_map(|w| {
        let n = w[0].n_sv as i32;
        [(w[0].t_s, n), (w[1].t_s, n)]
    });
    top.draw_series(LineSeries::new(steps, BLACK.stroke_width(2)))
        .map_err(plot_err(path))?;
    let dops = || fixes.iter().flat_map(|f| [f.pdop, f.hdop]);
    let (_, d1) = padded_range(dops().map(|v| v.min(DOP_CEILING)), false);
    let mut bottom = linear_chart(
        &lower,
        t0..t1,
        0.0..d1.max(1.0),
        (
            "time from the start of the recording (s)",
            "dilution of precision",
        ),
        path,
    )?;
    type Pick = fn(&FixPoint) -> f64;
    for (i, pick) in [(|f: &FixPoint| f.pdop) as Pick, |f: &FixPoint| f.hdop]
        .into_iter()
        .enumerate()
    {
        let pts = fixes
            .iter()
            .map(|f| (f.t_s, pick(f)))
            .filter(|p| p.1.is_finite())
            .map(|(t, v)| (t, v.min(DOP_CEILING)));
        bottom
            .draw_series(LineSeries::new(pts, color(i).stroke_width(2)))
            .map_err(plot_err(path))?;
    }
    draw_legend(&side, &entries, (0, (MARGIN_PX + 5) as i32)).map_err(plot_err(path))?;
    area.present().map_err(plot_err(path))?;
    Ok(())
}
