//! `track.png`: the ground track in local east/north metres, each fix coloured by the number
//! of satellites it used.

use super::canvas::{linear_chart, plot_px, titled, with_legend_strip, MARGIN_PX};
use super::cn0::split_at_gaps;
use super::data::FixPoint;
use super::geometry::{equal_scale_ranges, median_position, LocalFrame};
use super::legend::{draw_legend, LegendEntry, Swatch};
use super::style::plot_err;
use super::PlotError;
use plotters::prelude::*;
use std::path::Path;

/// Size of `track.png`, px.
pub const TRACK_SIZE: (u32, u32) = (1000, 800);

/// The colour of a fix that used `n` satellites: red for 4 through the spectrum to violet
/// for 10 and more, grey for fewer than 4 (landmark-aided fixes).
pub fn sv_count_color(n: usize) -> RGBColor {
    match n {
        0..=3 => RGBColor(150, 150, 150),
        4 => RGBColor(214, 39, 40),
        5 => RGBColor(255, 127, 14),
        6 => RGBColor(188, 189, 34),
        7 => RGBColor(44, 160, 44),
        8 => RGBColor(23, 190, 207),
        9 => RGBColor(31, 119, 180),
        _ => RGBColor(148, 103, 189),
    }
}

fn sv_count_name(n: usize) -> String {
    match n {
        0..=3 => "< 4 satellites".to_string(),
        10.. => ">= 10 satellites".to_string(),
        n => format!("{n} satellites"),
    }
}

/// Draws the valid fixes of `fixes` as east/north offsets from `origin_ecef_m` (default: the
/// median fix), equal scale on both axes, coloured by satellites used, into `path`.
pub fn draw_track(
    fixes: &[FixPoint],
    origin_ecef_m: Option<[f64; 3]>,
    path: &Path,
) -> Result<(), PlotError> {
    let valid: Vec<&FixPoint> = fixes.iter().filter(|f| f.valid).collect();
    let (origin, origin_name) = match origin_ecef_m {
        Some(o) => (Some(o), "reference position"),
        None => (
            median_position(valid.iter().map(|f| f.ecef_m)),
            "median fix",
        ),
    };
    let frame = origin.map(LocalFrame::at);
    let en: Vec<(f64, f64, usize)> = match &frame {
        Some(frame) => valid
            .iter()
            .map(|f| {
                let [e, n, _] = frame.enu_m(f.ecef_m);
                (e, n, f.n_sv.clamp(3, 10))
            })
            .collect(),
        None => Vec::new(),
    };
    let mut counts: Vec<usize> = en.iter().map(|p| p.2).collect();
    counts.sort_unstable();
    counts.dedup();
    let mut entries: Vec<LegendEntry> = counts
        .iter()
        .map(|&n| LegendEntry {
            name: sv_count_name(n),
            color: sv_count_color(n),
            swatch: Swatch::Dot,
        })
        .collect();
    entries.push(LegendEntry {
        name: format!("origin: {origin_name}"),
        color: RGBColor(0, 0, 0),
        swatch: Swatch::Cross,
    });
    let title = format!("Ground track: {} valid fixes", en.len());
    let area = titled(path, TRACK_SIZE, &title)?;
    let (chart_area, side) = with_legend_strip(&area, &entries);
    let pts: Vec<(f64, f64)> = en.iter().map(|p| (p.0, p.1)).collect();
    let (er, nr) = equal_scale_ranges(&pts, plot_px(&chart_area), 2.0);
    let mut chart = linear_chart(&chart_area, er, nr, ("east (m)", "north (m)"), path)?;
    // Fixes joined in time order, broken where fixes are missing (a GNSS outage).
    let times: Vec<(f64, f64)> = valid
        .iter()
        .enumerate()
        .map(|(i, f)| (f.t_s, i as f64))
        .collect();
    for run in split_at_gaps(&times) {
        let (a, b) = (run[0].1 as usize, run[run.len() - 1].1 as usize);
        chart
            .draw_series(LineSeries::new(
                pts[a..=b].iter().copied(),
                RGBColor(170, 170, 170).stroke_width(1),
            ))
            .map_err(plot_err(path))?;
    }
    chart
        .draw_series(
            en.iter()
                .map(|&(e, n, k)| Circle::new((e, n), 3, sv_count_color(k).filled())),
        )
        .map_err(plot_err(path))?;
    if frame.is_some() {
        chart
            .draw_series(std::iter::once(Cross::new(
                (0.0, 0.0),
                8,
                BLACK.stroke_width(2),
            )))
            .map_err(plot_err(path))?;
    }
    draw_legend(&side, &entries, (0, (MARGIN_PX + 5) as i32)).map_err(plot_err(path))?;
    area.present().map_err(plot_err(path))?;
    Ok(())
}
