//! `dr.png` (`gpsrx run --dr`): the GNSS/dead-reckoning fused track in local east/north
//! metres, the stretches the receiver had no GNSS fix (dead reckoning alone) marked in red.

use super::canvas::{linear_chart, plot_px, titled, with_legend_strip, MARGIN_PX};
use super::data::MAX_POINTS;
use super::geometry::{equal_scale_ranges, median_position, LocalFrame};
use super::legend::{draw_legend, LegendEntry, Swatch};
use super::style::plot_err;
use super::PlotError;
use crate::fusion::fuse::FusedFix;
use gpsrx_ins_aiding::FixSource;
use plotters::prelude::*;
use std::path::Path;

/// Size of `dr.png`, px.
pub const DR_SIZE: (u32, u32) = (1000, 800);
const FUSED: RGBColor = RGBColor(31, 119, 180);
const OUTAGE: RGBColor = RGBColor(214, 39, 40);

/// A stretch of consecutive rows with or without GNSS: (outage, east/north points in m,
/// duration in s).
type Stretch = (bool, Vec<(f64, f64)>, f64);

/// The rows of `fused` as east/north stretches split where dead reckoning alone starts or
/// ends (each stretch shares its first point with the previous one, so the line is
/// continuous); rows thinned to about [`MAX_POINTS`] in all.
fn stretches(fused: &[FusedFix], frame: &LocalFrame) -> Vec<Stretch> {
    let stride = fused.len().div_ceil(MAX_POINTS).max(1);
    let mut out: Vec<Stretch> = Vec::new();
    for (i, f) in fused.iter().enumerate() {
        let outage = f.source == FixSource::DrOnly;
        let changes = out.last().is_none_or(|s| s.0 != outage);
        if !i.is_multiple_of(stride) && !changes && i + 1 != fused.len() {
            continue;
        }
        let [e, n, _] = frame.enu_m([f.ecef_m.x, f.ecef_m.y, f.ecef_m.z]);
        if changes {
            let first = out.last().and_then(|s| s.1.last().copied());
            out.push((outage, first.into_iter().collect(), 0.0));
        }
        if let Some(s) = out.last_mut() {
            s.1.push((e, n));
        }
    }
    // Durations from the row times.
    let mut k = 0;
    for (i, f) in fused.iter().enumerate() {
        let outage = f.source == FixSource::DrOnly;
        if i > 0 && (fused[i - 1].source == FixSource::DrOnly) != outage {
            k += 1;
        }
        if let (Some(s), Some(prev)) = (out.get_mut(k), i.checked_sub(1).map(|j| &fused[j])) {
            s.2 += f.t_s - prev.t_s;
        }
    }
    out
}

/// Draws the fused track of `fused` (time order) into `path`.
pub fn draw_dr_track(fused: &[FusedFix], path: &Path) -> Result<(), PlotError> {
    let origin = median_position(fused.iter().map(|f| [f.ecef_m.x, f.ecef_m.y, f.ecef_m.z]));
    let parts = origin.map_or_else(Vec::new, |o| stretches(fused, &LocalFrame::at(o)));
    let outages: Vec<&Stretch> = parts.iter().filter(|s| s.0).collect();
    let outage_s: f64 = outages.iter().map(|s| s.2).sum();
    let entries = vec![
        LegendEntry {
            name: "GNSS or fused".into(),
            color: FUSED,
            swatch: Swatch::Line,
        },
        LegendEntry {
            name: match outages.len() {
                0 => "DR only (GNSS outage): none".to_string(),
                1 => format!("DR only (GNSS outage): 1, {outage_s:.0} s"),
                n => format!("DR only (GNSS outages): {n}, {outage_s:.0} s"),
            },
            color: OUTAGE,
            swatch: Swatch::Line,
        },
        LegendEntry {
            name: "start".into(),
            color: BLACK,
            swatch: Swatch::Dot,
        },
    ];
    let area = titled(path, DR_SIZE, "GNSS/dead-reckoning fused track")?;
    let (chart_area, side) = with_legend_strip(&area, &entries);
    let all: Vec<(f64, f64)> = parts.iter().flat_map(|s| s.1.iter().copied()).collect();
    let (er, nr) = equal_scale_ranges(&all, plot_px(&chart_area), 2.0);
    let mut chart = linear_chart(
        &chart_area,
        er,
        nr,
        ("east of the median position (m)", "north (m)"),
        path,
    )?;
    for (outage, pts, _) in &parts {
        let style = if *outage {
            OUTAGE.stroke_width(4)
        } else {
            FUSED.stroke_width(2)
        };
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), style))
            .map_err(plot_err(path))?;
    }
    if let Some(&start) = all.first() {
        chart
            .draw_series(std::iter::once(Circle::new(start, 6, BLACK.filled())))
            .map_err(plot_err(path))?;
    }
    draw_legend(&side, &entries, (0, (MARGIN_PX + 5) as i32)).map_err(plot_err(path))?;
    area.present().map_err(plot_err(path))?;
    Ok(())
}
