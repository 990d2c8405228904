//! `cn0.png`: each satellite's C/N0 against time, the legend beside the data.

use super::canvas::{linear_chart, titled, with_legend_strip, MARGIN_PX};
use super::decimate::Decimated;
use super::legend::{draw_legend, LegendEntry, Swatch};
use super::style::{color, plot_err};
use super::ticks::padded_range;
use super::PlotError;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// Size of `cn0.png`, px.
pub const CN0_SIZE: (u32, u32) = (1000, 600);
/// Lowest C/N0 on the axis, dB-Hz.
const CN0_FLOOR_DBHZ: f64 = 15.0;

/// The stretches of `points` (time order) without a gap longer than three times the median
/// step: a satellite lost and found again is drawn as separate lines.
pub fn split_at_gaps(points: &[(f64, f64)]) -> Vec<&[(f64, f64)]> {
    let mut steps: Vec<f64> = points.windows(2).map(|w| w[1].0 - w[0].0).collect();
    if steps.is_empty() {
        return if points.is_empty() {
            Vec::new()
        } else {
            vec![points]
        };
    }
    steps.sort_by(f64::total_cmp);
    let limit = 3.0 * steps[steps.len() / 2];
    let mut runs = Vec::new();
    let mut start = 0;
    for i in 1..points.len() {
        if points[i].0 - points[i - 1].0 > limit {
            runs.push(&points[start..i]);
            start = i;
        }
    }
    runs.push(&points[start..]);
    runs
}

/// Draws each satellite's C/N0 (s, dB-Hz) of `cn0` into `path`.
pub fn draw_cn0(cn0: &BTreeMap<u8, Decimated<(f64, f64)>>, path: &Path) -> Result<(), PlotError> {
    let entries: Vec<LegendEntry> = cn0
        .keys()
        .enumerate()
        .map(|(i, prn)| LegendEntry {
            name: format!("G{prn:02}"),
            color: color(i),
            swatch: Swatch::Line,
        })
        .collect();
    let area = titled(path, CN0_SIZE, "C/N0 of each satellite")?;
    let (chart_area, side) = with_legend_strip(&area, &entries);
    let all = || cn0.values().flat_map(|d| d.values().iter().copied());
    let (t0, t1) = padded_range(all().map(|p| p.0), false);
    // A lost signal's estimate collapses towards 0 dB-Hz: the axis stops at 15 dB-Hz so the
    // tracked levels stay readable (the plunge leaves through the bottom).
    let (y0, y1) = padded_range(all().map(|p| p.1), false);
    let y0 = y0.max(CN0_FLOOR_DBHZ.min(y1 - 1.0));
    let mut chart = linear_chart(
        &chart_area,
        t0.max(0.0)..t1,
        y0..y1,
        ("time from the start of the recording (s)", "C/N0 (dB-Hz)"),
        path,
    )?;
    for (i, series) in cn0.values().enumerate() {
        for run in split_at_gaps(series.values()) {
            chart
                .draw_series(LineSeries::new(
                    run.iter().copied(),
                    color(i).stroke_width(2),
                ))
                .map_err(plot_err(path))?;
        }
    }
    draw_legend(&side, &entries, (0, (MARGIN_PX + 5) as i32)).map_err(plot_err(path))?;
    area.present().map_err(plot_err(path))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_split_the_line() {
        let pts = [(0.0, 1.0), (0.1, 1.0), (0.2, 1.0), (5.0, 1.0), (5.1, 1.0)];
        let runs = split_at_gaps(&pts);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0].len(), 3);
        assert_eq!(runs[1], &pts[3..]);
        assert_eq!(split_at_gaps(&pts[..1]).len(), 1);
        assert!(split_at_gaps(&[]).is_empty());
    }
}
