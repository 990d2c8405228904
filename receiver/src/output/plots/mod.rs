//! PNG plots: those of every `gpsrx run` and the line plots of the studies.
//!
//! A run's [`crate::output::FileSink`] gathers [`RunPlotData`] in bounded memory and, at the
//! end, [`write_run_plots`] draws into the output directory:
//!
//! - `track.png` ([`track`]): the ground track in east/north metres from the median fix,
//!   coloured by the number of satellites used;
//! - `skyplot.png` ([`skyplot`]): azimuth/elevation tracks, north up, east right, zenith at the
//!   centre, each PRN at its latest point;
//! - `cn0.png` ([`cn0`]): C/N0 of each satellite against time;
//! - `dop.png` ([`dop`]): satellites used, PDOP and HDOP against time;
//! - `dr.png` ([`dr`], `gpsrx run --dr`): the fused track, GNSS outages in red.
//!
//! [`LinePlot`] and [`draw_line_plot`] are the studies' plots. Everything is drawn with
//! plotters' bitmap backend and the embedded DejaVu Sans font ([`register_font`]). A plot that
//! cannot be drawn is a warning in a run, never a failed run.

pub mod canvas;
pub mod cn0;
pub mod data;
pub mod decimate;
pub mod dop;
pub mod dr;
pub mod geometry;
pub mod legend;
pub mod line;
pub mod skyplot;
pub mod style;
pub mod ticks;
pub mod track;

pub use data::RunPlotData;
pub use line::{draw_line_plot, LinePlot, Series, LINE_PLOT_SIZE};
pub use style::register_font;

use std::path::{Path, PathBuf};

/// Why a plot could not be drawn. Names the file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The drawing backend failed (e.g. the PNG could not be written).
    #[error("cannot draw the plot `{file}`: {reason}; check the directory is writable and the disk is not full")]
    Draw {
        /// File being drawn.
        file: String,
        /// What the backend reported.
        reason: String,
    },
}

/// Draws `track.png`, `skyplot.png`, `cn0.png` and `dop.png` of `data` into `dir` (those
/// with data); returns the files written. A plot that fails is logged as a warning and
/// skipped.
pub fn write_run_plots(dir: &Path, data: &RunPlotData) -> Vec<PathBuf> {
    let fixes = data.fixes.values();
    let mut written = Vec::new();
    let mut draw = |name: &str, has_data: bool, f: &dyn Fn(&Path) -> Result<(), PlotError>| {
        if !has_data {
            return;
        }
        let path = dir.join(name);
        match f(&path) {
            Ok(()) => written.push(path),
            Err(e) => tracing::warn!("{e} (the run's other outputs are complete)"),
        }
    };
    let has_valid = fixes.iter().any(|f| f.valid);
    draw("track.png", has_valid, &|p| {
        track::draw_track(fixes, None, p)
    });
    draw("skyplot.png", !data.sky.is_empty(), &|p| {
        skyplot::draw_skyplot(&data.sky, p)
    });
    draw("cn0.png", !data.cn0.is_empty(), &|p| {
        cn0::draw_cn0(&data.cn0, p)
    });
    draw("dop.png", !fixes.is_empty(), &|p| dop::draw_dop(fixes, p));
    written
}
