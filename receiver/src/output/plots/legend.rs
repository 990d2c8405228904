//! Legends that never hide data: drawn in the emptiest corner of the plotting area, or beside
//! it when every corner has data.

use super::style::LEGEND_PX;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// How a legend entry shows its series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Swatch {
    /// A solid line.
    Line,
    /// A dashed line (a reference curve).
    Dashed,
    /// A filled dot (scattered points).
    Dot,
    /// A cross (a marked position).
    Cross,
}

/// One legend row.
#[derive(Debug, Clone)]
pub struct LegendEntry {
    /// Text.
    pub name: String,
    /// Colour of the series.
    pub color: RGBColor,
    /// How the series is drawn.
    pub swatch: Swatch,
}

/// A corner of the plotting area.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    /// Top left.
    UpperLeft,
    /// Top right.
    UpperRight,
    /// Bottom left.
    LowerLeft,
    /// Bottom right.
    LowerRight,
}

const ROW_PX: u32 = LEGEND_PX + 6;
const SWATCH_PX: u32 = 24;
const PAD_PX: u32 = 8;

/// Legend box size in pixels (estimated from the text length, DejaVu Sans at
/// [`LEGEND_PX`]: about 0.6 em per character).
pub fn legend_size_px(entries: &[LegendEntry]) -> (u32, u32) {
    let chars = entries
        .iter()
        .map(|e| e.name.chars().count())
        .max()
        .unwrap_or(0) as u32;
    let text_px = chars * LEGEND_PX * 6 / 10;
    (
        2 * PAD_PX + SWATCH_PX + 6 + text_px,
        2 * PAD_PX + ROW_PX * entries.len() as u32,
    )
}

/// The first corner (upper left, upper right, lower left, lower right) where a box of
/// `box_frac` (width, height as fractions of the plotting area) covers none of the `series`
/// (polylines in plotting-area fractions, x right, y up; segments are sampled every 0.5 %
/// so a line through a corner counts); `None` when every corner has data.
pub fn free_corner(series: &[Vec<(f64, f64)>], box_frac: (f64, f64)) -> Option<Corner> {
    let (w, h) = (box_frac.0 + 0.02, box_frac.1 + 0.02);
    let corners = [
        (Corner::UpperLeft, 0.0, 1.0 - h),
        (Corner::UpperRight, 1.0 - w, 1.0 - h),
        (Corner::LowerLeft, 0.0, 0.0),
        (Corner::LowerRight, 1.0 - w, 0.0),
    ];
    let inside =
        |(x, y): (f64, f64), x0: f64, y0: f64| x >= x0 && x <= x0 + w && y >= y0 && y <= y0 + h;
    corners.into_iter().find_map(|(corner, x0, y0)| {
        let hit = series.iter().any(|line| {
            line.iter().any(|&p| inside(p, x0, y0))
                || line.windows(2).any(|s| {
                    let (a, b) = (s[0], s[1]);
                    let n = (((b.0 - a.0).hypot(b.1 - a.1)) / 0.005).ceil().min(400.0) as usize;
                    (1..n).any(|k| {
                        let t = k as f64 / n as f64;
                        inside((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)), x0, y0)
                    })
                })
        });
        (!hit).then_some(corner)
    })
}

/// Top-left pixel of a legend of `size` in `corner` of the plotting area whose pixel
/// ranges are `x_px` and `y_px`.
pub fn corner_origin(
    corner: Corner,
    x_px: std::ops::Range<i32>,
    y_px: std::ops::Range<i32>,
    size: (u32, u32),
) -> (i32, i32) {
    let (w, h) = (size.0 as i32, size.1 as i32);
    let m = 6;
    match corner {
        Corner::UpperLeft => (x_px.start + m, y_px.start + m),
        Corner::UpperRight => (x_px.end - w - m, y_px.start + m),
        Corner::LowerLeft => (x_px.start + m, y_px.end - h - m),
        Corner::LowerRight => (x_px.end - w - m, y_px.end - h - m),
    }
}

/// Draws the legend of `entries` inside `area` (a chart's plotting area) at `corner`.
pub fn draw_legend_in_corner<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    corner: Corner,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (pw, ph) = area.dim_in_pixel();
    let size = legend_size_px(entries);
    let at = corner_origin(corner, 0..pw as i32, 0..ph as i32, size);
    draw_legend(area, entries, at)
}

/// Draws the legend with its top-left corner at `origin` (pixels of `area`).
pub fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    origin: (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    if entries.is_empty() {
        return Ok(());
    }
    let (w, h) = legend_size_px(entries);
    let (x, y) = origin;
    area.draw(&Rectangle::new(
        [(x, y), (x + w as i32, y + h as i32)],
        WHITE.mix(0.9).filled(),
    ))?;
    area.draw(&Rectangle::new(
        [(x, y), (x + w as i32, y + h as i32)],
        BLACK.stroke_width(1),
    ))?;
    let font = TextStyle::from(("sans-serif", LEGEND_PX).into_font())
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (i, e) in entries.iter().enumerate() {
        let cy = y + (PAD_PX + ROW_PX * i as u32 + ROW_PX / 2) as i32;
        let sx = x + PAD_PX as i32;
        let style = e.color.stroke_width(2);
        match e.swatch {
            Swatch::Line => area.draw(&PathElement::new(
                vec![(sx, cy), (sx + SWATCH_PX as i32, cy)],
                style,
            ))?,
            Swatch::Dashed => {
                for k in 0..3 {
                    let a = sx + 9 * k;
                    area.draw(&PathElement::new(vec![(a, cy), (a + 5, cy)], style))?;
                }
            }
            Swatch::Dot => area.draw(&Circle::new(
                (sx + SWATCH_PX as i32 / 2, cy),
                4,
                e.color.filled(),
            ))?,
            Swatch::Cross => area.draw(&Cross::new(
                (sx + SWATCH_PX as i32 / 2, cy),
                6,
                e.color.stroke_width(2),
            ))?,
        }
        area.draw(&Text::new(
            e.name.clone(),
            (sx + SWATCH_PX as i32 + 6, cy + 1),
            font.clone(),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_the_first_corner_without_data() {
        // A rising line from the lower left to the upper right: upper left is free.
        let rising = vec![vec![(0.0, 0.0), (1.0, 1.0)]];
        assert_eq!(free_corner(&rising, (0.3, 0.2)), Some(Corner::UpperLeft));
        // A horizontal line along the top: the lower left is the first free corner.
        let top = vec![vec![(0.0, 0.95), (1.0, 0.95)]];
        assert_eq!(free_corner(&top, (0.3, 0.2)), Some(Corner::LowerLeft));
        // A line crossing a corner between its two points still counts (sampled segment).
        let cross = vec![vec![(-0.5, 0.5), (0.5, 1.0)], vec![(0.0, 0.0), (1.0, 1.0)]];
        assert_eq!(free_corner(&cross, (0.3, 0.2)), Some(Corner::LowerRight));
        // Data in all four corners: the legend goes outside.
        let full = vec![vec![(0.0, 0.0), (1.0, 1.0)], vec![(0.0, 1.0), (1.0, 0.0)]];
        assert_eq!(free_corner(&full, (0.3, 0.2)), None);
    }
}
