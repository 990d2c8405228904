//! Seed 001 Figs. 3-3 to 3-5: availability, PDOP and HDOP against the number of satellites,
//! one curve per landmark count.

use super::params::LANDMARKS;
use super::summary::CellStats;
use crate::report::{LinePlot, Series};

fn per_landmarks(all: &[CellStats], value: impl Fn(&CellStats) -> f64) -> Vec<Series> {
    LANDMARKS
        .map(|n_lm| Series {
            name: format!("{n_lm} landmark(s)"),
            points: all
                .iter()
                .filter(|s| s.cell.n_lm == n_lm)
                .map(|s| (s.cell.n_sat as f64, value(s)))
                .collect(),
            reference: false,
        })
        .collect()
}

/// The three plots.
pub fn plots(all: &[CellStats]) -> Vec<LinePlot> {
    let plot = |file: &str, title: &str, y: &str, log_y: bool, series| LinePlot {
        file_name: file.into(),
        title: title.into(),
        x_label: "satellites".into(),
        y_label: y.into(),
        log_x: false,
        log_y,
        series,
    };
    vec![
        plot(
            "availability.png",
            "Fix availability (PDOP <= 10) with street-level landmarks",
            "fix available (%)",
            false,
            per_landmarks(all, |s| 100.0 * s.available),
        ),
        plot(
            "pdop.png",
            "Median PDOP with and without landmarks (seed 001 Figs. 3-3 to 3-5)",
            "median PDOP",
            true,
            per_landmarks(all, |s| s.median_pdop),
        ),
        plot(
            "hdop.png",
            "Median HDOP with and without landmarks",
            "median HDOP",
            true,
            per_landmarks(all, |s| s.median_hdop),
        ),
    ]
}
