//! What every study writes to its `--out DIR`: `study.md` (the tables and the plots, for people),
//! `study.csv` (one row per case, for tools), `study.json` (a summary) and PNG plots.
//!
//! Plots are drawn by the receiver crate's [`gpsrx_receiver::output::plots`] (plotters'
//! bitmap backend and an embedded DejaVu Sans font, so they need no system fonts), re-exported
//! here: [`LinePlot`], [`Series`], [`draw_line_plot`], [`register_font`].

use anyhow::Context;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub use gpsrx_receiver::output::plots::{draw_line_plot, register_font, LinePlot, Series};

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

/// The median of the finite values of `v` (NaN for none; the mean of the middle two for an
/// even count).
pub fn median(v: &[f64]) -> f64 {
    let mut c: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if c.is_empty() {
        return f64::NAN;
    }
    c.sort_by(f64::total_cmp);
    let n = c.len();
    if n % 2 == 1 {
        c[n / 2]
    } else {
        0.5 * (c[n / 2 - 1] + c[n / 2])
    }
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
