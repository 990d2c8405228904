//! [`LinePlot`]: named curves on linear or logarithmic axes (the studies' plots), with 1-2-5
//! tick labels on log axes and the legend in a corner free of data (or beside the plot).

use super::legend::{
    draw_legend, draw_legend_in_corner, free_corner, legend_size_px, LegendEntry, Swatch,
};
use super::style::{color, plot_err, register_font, AXIS_DESC_PX, LABEL_PX, TITLE_PX};
use super::ticks::{log_ticks, padded_range, tick_label};
use super::PlotError;
use plotters::coord::combinators::BindKeyPoints;
use plotters::prelude::*;
use std::path::Path;

/// Size of a line plot, px.
pub const LINE_PLOT_SIZE: (u32, u32) = (1000, 640);
const MARGIN_PX: u32 = 15;
const X_AREA_PX: u32 = 45;
const Y_AREA_PX: u32 = 70;
const TITLE_AREA_PX: u32 = 40;

/// One named curve of a line plot.
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// Legend text (an empty name has no legend entry).
    pub name: String,
    /// (x, y) points, drawn in order; non-finite points (and non-positive ones on a log
    /// axis) are skipped.
    pub points: Vec<(f64, f64)>,
    /// Draw as a dashed reference line (e.g. a closed form) rather than a measured curve.
    pub reference: bool,
}

/// A line plot.
#[derive(Debug, Clone, Default)]
pub struct LinePlot {
    /// File name inside the output directory (`.png`).
    pub file_name: String,
    /// Title.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// The curves.
    pub series: Vec<Series>,
}

/// Position of `v` on an axis `[lo, hi]` as a fraction (log axes in log10).
fn axis_fraction(v: f64, lo: f64, hi: f64, log: bool) -> f64 {
    if log {
        (v.log10() - lo.log10()) / (hi.log10() - lo.log10())
    } else {
        (v - lo) / (hi - lo)
    }
}

impl LinePlot {
    /// The drawable points of each series.
    fn clean_points(&self) -> Vec<Vec<(f64, f64)>> {
        self.series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .copied()
                    .filter(|(x, y)| {
                        x.is_finite()
                            && y.is_finite()
                            && (!self.log_x || *x > 0.0)
                            && (!self.log_y || *y > 0.0)
                    })
                    .collect()
            })
            .collect()
    }

    fn legend(&self) -> Vec<LegendEntry> {
        self.series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.name.is_empty())
            .map(|(i, s)| LegendEntry {
                name: s.name.clone(),
                color: color(i),
                swatch: if s.reference {
                    Swatch::Dashed
                } else {
                    Swatch::Line
                },
            })
            .collect()
    }
}

/// Draws `plot` into a [`LINE_PLOT_SIZE`] PNG at `path`.
pub fn draw_line_plot(plot: &LinePlot, path: &Path) -> Result<(), PlotError> {
    register_font();
    let (w, h) = LINE_PLOT_SIZE;
    let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err(path))?;
    let root = root
        .titled(&plot.title, ("sans-serif", TITLE_PX))
        .map_err(plot_err(path))?;
    let points = plot.clean_points();
    let (x0, x1) = padded_range(points.iter().flatten().map(|p| p.0), plot.log_x);
    let (y0, y1) = padded_range(points.iter().flatten().map(|p| p.1), plot.log_y);
    let entries = plot.legend();
    let (lw, lh) = legend_size_px(&entries);
    let area_w = f64::from(w - 2 * MARGIN_PX - Y_AREA_PX);
    let area_h = f64::from(h - TITLE_AREA_PX - 2 * MARGIN_PX - X_AREA_PX);
    let normalised: Vec<Vec<(f64, f64)>> = points
        .iter()
        .map(|s| {
            s.iter()
                .map(|&(x, y)| {
                    (
                        axis_fraction(x, x0, x1, plot.log_x),
                        axis_fraction(y, y0, y1, plot.log_y),
                    )
                })
                .collect()
        })
        .collect();
    let corner = free_corner(
        &normalised,
        (f64::from(lw) / area_w, f64::from(lh) / area_h),
    );
    let (chart_area, side) = match (corner, entries.is_empty()) {
        (None, false) => {
            let (a, b) = root.split_horizontally(w.saturating_sub(lw + 2 * MARGIN_PX));
            (a, Some(b))
        }
        _ => (root.clone(), None),
    };
    let mut builder = ChartBuilder::on(&chart_area);
    builder
        .margin(MARGIN_PX)
        .x_label_area_size(X_AREA_PX)
        .y_label_area_size(Y_AREA_PX);
    // The four axis combinations have different coordinate types.
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart.map_err(plot_err(path))?;
            chart
                .configure_mesh()
                .light_line_style(TRANSPARENT)
                .x_desc(plot.x_label.as_str())
                .y_desc(plot.y_label.as_str())
                .x_label_formatter(&|v| tick_label(*v))
                .y_label_formatter(&|v| tick_label(*v))
                .label_style(("sans-serif", LABEL_PX))
                .axis_desc_style(("sans-serif", AXIS_DESC_PX))
                .draw()
                .map_err(plot_err(path))?;
            for (i, (s, pts)) in plot.series.iter().zip(&points).enumerate() {
                let c = color(i);
                let style = ShapeStyle::from(&c).stroke_width(2);
                if s.reference {
                    chart.draw_series(DashedLineSeries::new(pts.clone(), 8, 5, style))
                } else {
                    chart.draw_series(LineSeries::new(pts.clone(), style))
                }
                .map_err(plot_err(path))?;
                if !s.reference {
                    chart
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                        .map_err(plot_err(path))?;
                }
            }
            if let Some(corner) = corner {
                let area = chart.plotting_area().strip_coord_spec();
                draw_legend_in_corner(&area, &entries, corner).map_err(plot_err(path))?;
            }
        }};
    }
    let (xr, yr) = (x0..x1, y0..y1);
    match (plot.log_x, plot.log_y) {
        (false, false) => draw!(builder.build_cartesian_2d(xr, yr)),
        (true, false) => {
            draw!(builder.build_cartesian_2d(xr.log_scale().with_key_points(log_ticks(x0, x1)), yr))
        }
        (false, true) => {
            draw!(builder.build_cartesian_2d(xr, yr.log_scale().with_key_points(log_ticks(y0, y1))))
        }
        (true, true) => draw!(builder.build_cartesian_2d(
            xr.log_scale().with_key_points(log_ticks(x0, x1)),
            yr.log_scale().with_key_points(log_ticks(y0, y1))
        )),
    }
    if let Some(side) = side {
        draw_legend(&side, &entries, (0, (MARGIN_PX + 5) as i32)).map_err(plot_err(path))?;
    }
    root.present().map_err(plot_err(path))?;
    Ok(())
}
