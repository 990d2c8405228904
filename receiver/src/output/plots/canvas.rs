//! The frame of the run plots: a white PNG with a title, and a strip on the right for the
//! legend so it never covers data.

use super::legend::{legend_size_px, LegendEntry};
use super::style::{plot_err, register_font, AXIS_DESC_PX, LABEL_PX, TITLE_PX};
use super::ticks::tick_label;
use super::PlotError;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::ops::Range;
use std::path::Path;

/// Margin around a chart, px.
pub const MARGIN_PX: u32 = 15;
/// Height of the x tick labels and description, px.
pub const X_AREA_PX: u32 = 45;
/// Width of the y tick labels and description, px.
pub const Y_AREA_PX: u32 = 70;

/// A bitmap drawing area.
pub type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// A white `size` PNG at `path` with `title` on top; returns the area under the title.
pub fn titled<'a>(path: &'a Path, size: (u32, u32), title: &str) -> Result<Area<'a>, PlotError> {
    register_font();
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err(path))?;
    root.titled(title, ("sans-serif", TITLE_PX))
        .map_err(plot_err(path))
}

/// A chart with linear axes over `x` and `y`.
pub type LinearChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A chart on `area` with linear axes over `x` and `y` and the standard margin and label
/// areas, its mesh drawn: no minor lines, plain tick labels, `desc` = (x, y) descriptions.
pub fn linear_chart<'a, 'b>(
    area: &'a Area<'b>,
    x: Range<f64>,
    y: Range<f64>,
    desc: (&str, &str),
    path: &Path,
) -> Result<LinearChart<'a, 'b>, PlotError> {
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN_PX)
        .x_label_area_size(X_AREA_PX)
        .y_label_area_size(Y_AREA_PX)
        .build_cartesian_2d(x, y)
        .map_err(plot_err(path))?;
    chart
        .configure_mesh()
        .light_line_style(TRANSPARENT)
        .x_desc(desc.0)
        .y_desc(desc.1)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style(("sans-serif", LABEL_PX))
        .axis_desc_style(("sans-serif", AXIS_DESC_PX))
        .draw()
        .map_err(plot_err(path))?;
    Ok(chart)
}

/// `area` split into the chart (left) and a legend strip (right) wide enough for `entries`.
pub fn with_legend_strip<'a>(area: &Area<'a>, entries: &[LegendEntry]) -> (Area<'a>, Area<'a>) {
    let (w, _) = area.dim_in_pixel();
    let (lw, _) = legend_size_px(entries);
    area.split_horizontally(w.saturating_sub(lw + MARGIN_PX))
}

/// The plotting area (px) a chart on `area` gets with the standard margin and label areas.
pub fn plot_px(area: &Area<'_>) -> (u32, u32) {
    let (w, h) = area.dim_in_pixel();
    (
        w.saturating_sub(2 * MARGIN_PX + Y_AREA_PX),
        h.saturating_sub(2 * MARGIN_PX + X_AREA_PX),
    )
}
