//! The look shared by every plot: the embedded font, the colour cycle, the error mapping.
//!
//! The font is DejaVu Sans (`receiver/assets/fonts`, Bitstream Vera licence), embedded in the
//! binary and registered as `sans-serif`, so plots need no system fonts.

use super::PlotError;
use plotters::style::{FontStyle, RGBColor};
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

/// Registers the embedded font as `sans-serif` (once per process).
pub fn register_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
        if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_err() {
            tracing::warn!("the embedded plot font could not be loaded; plots have no text");
        }
    });
}

/// The colour cycle (the "tab10" palette), for series told apart by colour.
pub const COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(127, 127, 127),
];

/// Colour number `i` of the cycle.
pub fn color(i: usize) -> RGBColor {
    COLORS[i % COLORS.len()]
}

/// Title font size, px.
pub const TITLE_PX: u32 = 24;
/// Tick label font size, px.
pub const LABEL_PX: u32 = 15;
/// Axis description font size, px.
pub const AXIS_DESC_PX: u32 = 17;
/// Legend font size, px.
pub const LEGEND_PX: u32 = 14;

/// Maps a drawing error of the file at `path` to a [`PlotError`].
pub fn plot_err<E: std::error::Error + Send + Sync + 'static>(
    path: &Path,
) -> impl FnOnce(E) -> PlotError + '_ {
    move |e| PlotError::Draw {
        file: path.display().to_string(),
        reason: e.to_string(),
    }
}
