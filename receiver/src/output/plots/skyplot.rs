//! `skyplot.png`: each satellite's track in azimuth and elevation (polar: zenith at the
//! centre, horizon on the outer circle, north up, east right), its PRN at the latest point.

use super::canvas::titled;
use super::data::SkyPoint;
use super::decimate::Decimated;
use super::geometry::sky_xy;
use super::style::{color, plot_err, LABEL_PX};
use super::PlotError;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// Size of `skyplot.png`, px.
pub const SKYPLOT_SIZE: (u32, u32) = (800, 840);
const EDGE: f64 = 1.13;

/// Draws the satellites' tracks of `sky` into `path`.
pub fn draw_skyplot(sky: &BTreeMap<u8, Decimated<SkyPoint>>, path: &Path) -> Result<(), PlotError> {
    let area = titled(
        path,
        SKYPLOT_SIZE,
        &format!("Skyplot: {} satellites in view", sky.len()),
    )?;
    let (w, h) = area.dim_in_pixel();
    let side = w.min(h).saturating_sub(20);
    let square = area
        .clone()
        .shrink(((w - side) / 2, (h - side) / 2), (side, side));
    let mut chart = ChartBuilder::on(&square)
        .build_cartesian_2d(-EDGE..EDGE, -EDGE..EDGE)
        .map_err(plot_err(path))?;
    let grid = RGBColor(190, 190, 190);
    for el in [0.0, 30.0, 60.0] {
        let ring: Vec<(f64, f64)> = (0..=360).map(|az| sky_xy(f64::from(az), el)).collect();
        let style = if el == 0.0 {
            BLACK.stroke_width(2)
        } else {
            grid.stroke_width(1)
        };
        chart
            .draw_series(LineSeries::new(ring, style))
            .map_err(plot_err(path))?;
    }
    for az in (0..360).step_by(30) {
        let az = f64::from(az);
        chart
            .draw_series(LineSeries::new(
                [sky_xy(az, 90.0), sky_xy(az, 0.0)],
                grid.stroke_width(1),
            ))
            .map_err(plot_err(path))?;
    }
    let font = ("sans-serif", LABEL_PX + 3).into_font();
    let small = ("sans-serif", LABEL_PX - 2)
        .into_font()
        .color(&RGBColor(110, 110, 110));
    let centred = |p: (f64, f64), s: &str| {
        EmptyElement::at(p) + Text::new(s.to_string(), (-5 * s.len() as i32, -9), font.clone())
    };
    let compass = [("N", 0.0), ("E", 90.0), ("S", 180.0), ("W", 270.0)];
    chart
        .draw_series(compass.iter().map(|&(s, az)| {
            let (x, y) = sky_xy(az, 0.0);
            centred((x * 1.07, y * 1.07), s)
        }))
        .map_err(plot_err(path))?;
    // Elevation labels along the 15 deg azimuth, clear of the north line.
    chart
        .draw_series([30.0, 60.0].iter().map(|&el| {
            EmptyElement::at(sky_xy(15.0, el))
                + Text::new(format!("{el:.0}°"), (3, -2), small.clone())
        }))
        .map_err(plot_err(path))?;
    for (i, (prn, track)) in sky.iter().enumerate() {
        let c = color(i);
        let pts: Vec<(f64, f64)> = track
            .values()
            .iter()
            .map(|p| sky_xy(p.az_deg, p.el_deg))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(3)))
            .map_err(plot_err(path))?;
        if let Some(&last) = pts.last() {
            let label = EmptyElement::at(last)
                + Circle::new((0, 0), 6, c.filled())
                + Text::new(format!("G{prn:02}"), (8, -20), font.clone().color(&c));
            chart
                .draw_series(std::iter::once(label))
                .map_err(plot_err(path))?;
        }
    }
    area.present().map_err(plot_err(path))?;
    Ok(())
}
