//! What every study writes to its `--out DIR`: `study.md` (the tables and the plots, for people),
//! `study.csv` (one row per case, for tools), `study.json` (a summary) and PNG plots.
//!
//! Plots are drawn with plotters' bitmap backend and an embedded DejaVu Sans font
//! (`studies/assets/fonts`, Bitstream Vera licence), so they need no system fonts.

use anyhow::Context;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Once;

/// A table: a header row and string cells, written as Markdown and as CSV.
#[derive(Debug, Clone, Default)]
pub struct Table {
    /// Column names (CSV header; Markdown header).
    pub columns: Vec<String>,
    /// Rows, each with one cell per column.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new<S: AsRef<str>>(columns: &[S]) -> Self {
        Self {
            columns: columns.iter().map(|c| c.as_ref().to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (must have one cell per column).
    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.columns.len());
        self.rows.push(row);
    }

    /// The table as GitHub Markdown.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "| {} |", self.columns.join(" | "));
        let _ = writeln!(
            s,
            "|{}",
            self.columns.iter().map(|_| "---|").collect::<String>()
        );
        for r in &self.rows {
            let _ = writeln!(s, "| {} |", r.join(" | "));
        }
        s
    }

    /// Writes the table as CSV.
    pub fn write_csv(&self, path: &Path) -> anyhow::Result<()> {
        let mut w = csv::Writer::from_path(path)
            .with_context(|| format!("cannot create {}", path.display()))?;
        w.write_record(&self.columns)?;
        for r in &self.rows {
            w.write_record(r)?;
        }
        w.flush()
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(())
    }
}

/// One named curve of a line plot.
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// (x, y) points, drawn in order; non-finite points are skipped.
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

/// A complete study result.
#[derive(Debug, Clone, Default)]
pub struct StudyReport {
    /// Title (first heading of `study.md`).
    pub title: String,
    /// Markdown before the table: what was simulated and how to read the table.
    pub intro_md: String,
    /// The per-case table (`study.csv`, and in `study.md`).
    pub table: Table,
    /// Markdown after the table: conclusions, departures from theory.
    pub conclusions_md: String,
    /// The summary written to `study.json`.
    pub summary: serde_json::Value,
    /// Plots (PNG), linked from `study.md`.
    pub plots: Vec<LinePlot>,
}

/// Paths of the files a report was written to.
#[derive(Debug, Clone)]
pub struct Written {
    /// `study.md`.
    pub markdown: PathBuf,
    /// `study.csv`.
    pub csv: PathBuf,
    /// `study.json`.
    pub json: PathBuf,
    /// The PNG plots.
    pub plots: Vec<PathBuf>,
}

impl StudyReport {
    /// Writes `study.md`, `study.csv`, `study.json` and the plots into `dir` (created if
    /// needed).
    pub fn write(&self, dir: &Path) -> anyhow::Result<Written> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let csv = dir.join("study.csv");
        self.table.write_csv(&csv)?;
        let json = dir.join("study.json");
        std::fs::write(&json, serde_json::to_string_pretty(&self.summary)? + "\n")
            .with_context(|| format!("cannot write {}", json.display()))?;
        let mut plots = Vec::new();
        for p in &self.plots {
            let path = dir.join(&p.file_name);
            draw_line_plot(p, &path)?;
            plots.push(path);
        }
        let mut md = format!("# {}\n\n{}\n\n", self.title, self.intro_md.trim_end());
        md += &self.table.to_markdown();
        md += "\n";
        if !self.conclusions_md.trim().is_empty() {
            md += self.conclusions_md.trim_end();
            md += "\n\n";
        }
        for p in &self.plots {
            let _ = writeln!(md, "![{}]({})\n", p.title, p.file_name);
        }
        let markdown = dir.join("study.md");
        std::fs::write(&markdown, md)
            .with_context(|| format!("cannot write {}", markdown.display()))?;
        Ok(Written {
            markdown,
            csv,
            json,
            plots,
        })
    }
}

static FONT: Once = Once::new();

/// Registers the embedded font as `sans-serif` (once per process).
pub(crate) fn register_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
        if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_err() {
            tracing::warn!("the embedded plot font could not be loaded; plots have no text");
        }
    });
}

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// Axis range of the finite values (positive ones on a log axis), padded a little.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        (lo / 1.3, hi * 1.3)
    } else if hi - lo < 1e-12 {
        (lo - 1.0, hi + 1.0)
    } else {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    }
}

fn plot_err<E: std::error::Error + Send + Sync + 'static>(
    path: &Path,
) -> impl FnOnce(E) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("cannot draw {}: {e}", path.display())
}

/// Draws `plot` into a 1000x640 PNG at `path`.
pub fn draw_line_plot(plot: &LinePlot, path: &Path) -> anyhow::Result<()> {
    register_font();
    let root = BitMapBackend::new(path, (1000, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err(path))?;
    let xs = plot
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = plot
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1));
    let (x0, x1) = range(xs, plot.log_x);
    let (y0, y1) = range(ys, plot.log_y);
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(&plot.title, ("sans-serif", 24))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70);
    // The four axis combinations have different coordinate types.
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart.map_err(plot_err(path))?;
            chart
                .configure_mesh()
                .x_desc(plot.x_label.as_str())
                .y_desc(plot.y_label.as_str())
                .label_style(("sans-serif", 15))
                .axis_desc_style(("sans-serif", 17))
                .draw()
                .map_err(plot_err(path))?;
            for (i, s) in plot.series.iter().enumerate() {
                let color = COLORS[i % COLORS.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|(x, y)| {
                        x.is_finite()
                            && y.is_finite()
                            && (!plot.log_x || *x > 0.0)
                            && (!plot.log_y || *y > 0.0)
                    })
                    .collect();
                let style = ShapeStyle::from(&color).stroke_width(2);
                let series = if s.reference {
                    chart.draw_series(DashedLineSeries::new(pts.clone(), 8, 5, style))
                } else {
                    chart.draw_series(LineSeries::new(pts.clone(), style))
                }
                .map_err(plot_err(path))?;
                series.label(s.name.as_str()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
                if !s.reference {
                    chart
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                        .map_err(plot_err(path))?;
                }
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .position(SeriesLabelPosition::UpperLeft)
                .draw()
                .map_err(plot_err(path))?;
        }};
    }
    match (plot.log_x, plot.log_y) {
        (false, false) => draw!(builder.build_cartesian_2d(x0..x1, y0..y1)),
        (true, false) => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
        (false, true) => draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())),
        (true, true) => {
            draw!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale()))
        }
    }
    root.present().map_err(plot_err(path))?;
    Ok(())
}

/// Formats a number with `digits` decimals, `-` for NaN (a cell with no value).
pub fn fmt(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else if v.is_nan() {
        "-".to_string()
    } else if v > 0.0 {
        "inf".to_string()
    } else {
        "-inf".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_every_file() -> anyhow::Result<()> {
        let dir = tempfile::tempdir()?;
        let mut table = Table::new(&["a", "b"]);
        table.push(vec!["1".into(), fmt(f64::NAN, 2)]);
        let report = StudyReport {
            title: "t".into(),
            intro_md: "intro".into(),
            table,
            conclusions_md: "done".into(),
            summary: serde_json::json!({"cells_total": 1}),
            plots: vec![LinePlot {
                file_name: "p.png".into(),
                title: "jitter".into(),
                x_label: "Bn (Hz)".into(),
                y_label: "deg".into(),
                log_x: true,
                log_y: true,
                series: vec![
                    Series {
                        name: "measured".into(),
                        points: vec![(1.0, 2.0), (10.0, 6.0)],
                        reference: false,
                    },
                    Series {
                        name: "formula".into(),
                        points: vec![(1.0, 2.1), (10.0, 6.5)],
                        reference: true,
                    },
                ],
            }],
        };
        let w = report.write(dir.path())?;
        let md = std::fs::read_to_string(&w.markdown)?;
        assert!(md.contains("| a | b |") && md.contains("| 1 | - |") && md.contains("p.png"));
        assert_eq!(std::fs::read_to_string(&w.csv)?, "a,b\n1,-\n");
        let png = std::fs::read(&w.plots[0])?;
        assert_eq!(&png[1..4], b"PNG");
        assert!(
            png.len() > 5000,
            "a plot with text and lines, not a blank image"
        );
        Ok(())
    }
}
