//! The study's PNG plots: position error against time with the outage shaded (Case 2), Cases 1
//! and 3 over the whole drive, the gyro scale-factor estimate (Case 3, seed 000 Fig. 6b) and the
//! speed errors with the gaps shaded. Drawn here rather than by
//! [`crate::report::draw_line_plot`] because of the shaded windows.

use super::drive::Drive;
use super::fusion::FusionRun;
use super::gnss::in_windows;
use super::speed::GapResult;
use super::summary::Gathered;
use crate::report::{register_font, LinePlot, Series};
use anyhow::Context;
use gpsrx_receiver::output::plots::legend::{
    draw_legend, draw_legend_in_corner, free_corner, legend_size_px, LegendEntry, Swatch,
};
use gpsrx_receiver::output::plots::ticks::tick_label;
use plotters::prelude::*;
use std::path::Path;

const COLORS: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
];

fn series(name: &str, t: &[f64], v: &[f64], reference: bool) -> Series {
    Series {
        name: name.into(),
        points: t.iter().copied().zip(v.iter().copied()).collect(),
        reference,
    }
}

fn error_plot(file: &str, title: &str, run: &FusionRun, window: Option<(f64, f64)>) -> LinePlot {
    let keep = |t: f64| window.is_none_or(|(a, b)| t >= a - 300.0 && t <= b + 30.0);
    let idx: Vec<usize> = (0..run.t_s.len()).filter(|&i| keep(run.t_s[i])).collect();
    let pick = |v: &[f64]| idx.iter().map(|&i| v[i]).collect::<Vec<_>>();
    let t = pick(&run.t_s);
    LinePlot {
        file_name: file.into(),
        title: title.into(),
        x_label: "time (s)".into(),
        y_label: "horizontal position error (m)".into(),
        series: vec![
            series("proposed (8 states)", &t, &pick(&run.err_proposed_m), false),
            series(
                "conventional (4 states)",
                &t,
                &pick(&run.err_conventional_m),
                false,
            ),
            series("GNSS alone", &t, &pick(&run.err_gnss_m), false),
        ],
        ..LinePlot::default()
    }
}

/// Draws every plot into `dir`; returns (file name, title) pairs.
pub(super) fn draw_plots(dir: &Path, g: &Gathered) -> anyhow::Result<Vec<(String, String)>> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut out = Vec::new();
    let mut draw = |p: LinePlot, shaded: &[(f64, f64)]| -> anyhow::Result<()> {
        let from_zero = p.file_name.starts_with("position_error");
        draw_shaded(&p, shaded, from_zero, &dir.join(&p.file_name))?;
        out.push((p.file_name, p.title));
        Ok(())
    };
    if let Some((run, w)) = g.outage_run {
        draw(
            error_plot(
                "position_error_outage.png",
                &format!(
                    "Case 2: outage {:.0}-{:.0} s (shaded) after a satellite-set change",
                    w.0, w.1
                ),
                run,
                Some(w),
            ),
            &[w],
        )?;
    }
    draw(
        error_plot(
            "position_error_case1.png",
            "Case 1: position error over the drive",
            g.case1.0,
            None,
        ),
        &[],
    )?;
    draw(
        error_plot(
            "position_error_case3.png",
            "Case 3 (gyro tilted 20 deg): position error over the drive",
            g.case3.0,
            None,
        ),
        &[],
    )?;
    let run3 = g.case3.0;
    let target = g.headline.case3_sf_g_true;
    let flat = |v: f64| vec![v; run3.t_s.len()];
    draw(
        LinePlot {
            file_name: "gyro_scale_case3.png".into(),
            title: "Case 3: estimated gyro scale factor (proposed filter)".into(),
            x_label: "time (s)".into(),
            y_label: "Sf_G (deg/s/V)".into(),
            series: vec![
                series("estimate", &run3.t_s, &run3.sf_g_dps_per_v, false),
                series(
                    "45.045 / cos 20 deg = 47.936",
                    &run3.t_s,
                    &flat(target),
                    true,
                ),
                series("+-1 %", &run3.t_s, &flat(target * 1.01), true),
                series("", &run3.t_s, &flat(target * 0.99), true),
            ],
            ..LinePlot::default()
        },
        &[],
    )?;
    for (run, gaps, file, road) in [
        (g.speed_run, &g.speed, "speed_error_gaps.png", "hilly road"),
        (
            g.speed_run_urban,
            &g.speed_urban,
            "speed_error_gaps_urban.png",
            "urban drive",
        ),
    ] {
        let Some(run) = run else {
            continue;
        };
        let gaps = first_phase_gaps(gaps);
        draw(
            LinePlot {
                file_name: file.into(),
                title: format!("Speed error through GNSS gaps (shaded), {road}"),
                x_label: "time (s)".into(),
                y_label: "speed error (m/s)".into(),
                series: vec![
                    series("KF1 + KF2 (seed 002)", &run.t_s, &run.err_filter_mps, false),
                    series("hold last speed", &run.t_s, &run.err_hold_mps, false),
                ],
                ..LinePlot::default()
            },
            &gaps,
        )?;
    }
    Ok(out)
}

/// Writes the first seed's speed-filter errors per GNSS epoch as `speed_trace.csv` (time, truth
/// speed, road height and grade, filter and hold errors, in a gap or not).
pub(super) fn write_speed_trace(dir: &Path, g: &Gathered, drive: &Drive) -> anyhow::Result<()> {
    let Some(run) = g.speed_run else {
        return Ok(());
    };
    let gaps = first_phase_gaps(&g.speed);
    let path = dir.join("speed_trace.csv");
    let mut w = csv::Writer::from_path(&path)
        .with_context(|| format!("cannot create {}", path.display()))?;
    w.write_record([
        "t_s",
        "speed_mps",
        "up_m",
        "grade_percent",
        "filter_error_mps",
        "hold_error_mps",
        "gap",
    ])?;
    for (i, &t) in run.t_s.iter().enumerate() {
        let s = drive.at(t);
        w.write_record([
            format!("{t:.1}"),
            format!("{:.3}", s.speed_mps),
            format!("{:.2}", s.up_m),
            format!("{:.2}", 100.0 * s.pitch_rad.tan()),
            format!("{:.4}", run.err_filter_mps[i]),
            format!("{:.4}", run.err_hold_mps[i]),
            u8::from(in_windows(t, &gaps)).to_string(),
        ])?;
    }
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

/// The gap windows of the first seed's first phase (those of its plotted run).
fn first_phase_gaps(speed: &[(u64, &[GapResult])]) -> Vec<(f64, f64)> {
    let Some((_, gaps)) = speed.first() else {
        return Vec::new();
    };
    let mut out: Vec<(f64, f64)> = Vec::new();
    for r in gaps.iter() {
        if out.last().is_some_and(|l| r.window.0 < l.1) {
            break;
        }
        out.push(r.window);
    }
    out
}

/// Markdown links to the plots.
pub(super) fn plot_links(plots: &[(String, String)]) -> String {
    plots
        .iter()
        .map(|(f, t)| format!("\n![{t}]({f})\n"))
        .collect()
}

fn plot_err<E: std::error::Error + Send + Sync + 'static>(
    path: &Path,
) -> impl FnOnce(E) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("cannot draw {}: {e}", path.display())
}

/// The curves and the shaded windows (outline and inside) of a plot in fractions of its axes
/// `x` and `y`: what the legend must not cover.
fn legend_obstacles(
    plot: &LinePlot,
    shaded: &[(f64, f64)],
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let frac = |(x, y): (f64, f64)| ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0));
    let mut shapes: Vec<Vec<(f64, f64)>> = plot
        .series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(frac)
                .collect()
        })
        .collect();
    for &(a, b) in shaded {
        shapes.push(
            [(a, y0), (a, y1), (b, y1), (b, y0), (a, y0)]
                .map(frac)
                .to_vec(),
        );
        // A vertical line every 1 % of the width inside the window.
        let n = (((b - a) / (x1 - x0)) * 100.0).ceil().max(1.0) as usize;
        for k in 0..=n {
            let x = a + (b - a) * k as f64 / n as f64;
            shapes.push(vec![frac((x, y0)), frac((x, y1))]);
        }
    }
    shapes
}

/// A linear line plot (lines only, reference series dashed) with the `shaded` x windows filled
/// in grey behind the curves, 1200x640; the y axis starts at 0 if `from_zero`. The legend goes
/// in a corner free of curves and windows, else beside the plot.
fn draw_shaded(
    plot: &LinePlot,
    shaded: &[(f64, f64)],
    from_zero: bool,
    path: &Path,
) -> anyhow::Result<()> {
    register_font();
    let (w, h) = (1200u32, 640u32);
    let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err(path))?;
    let root = root
        .titled(&plot.title, ("sans-serif", 24))
        .map_err(plot_err(path))?;
    let finite = |s: &Series| {
        s.points
            .iter()
            .copied()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect::<Vec<_>>()
    };
    let all: Vec<(f64, f64)> = plot.series.iter().flat_map(finite).collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if all.is_empty() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let pad = 0.05 * (y1 - y0).max(1e-6);
    let (y0, y1) = (if from_zero { 0.0 } else { y0 - pad }, y1 + pad);
    let x1 = x1.max(x0 + 1.0);
    // Colours: an unnamed series continues the previous one's (e.g. the two +-1 % lines).
    let mut colors = Vec::new();
    let mut color_index = 0;
    for (i, s) in plot.series.iter().enumerate() {
        if i > 0 && !s.name.is_empty() {
            color_index += 1;
        }
        colors.push(COLORS[color_index.min(COLORS.len() - 1)]);
    }
    let entries: Vec<LegendEntry> = plot
        .series
        .iter()
        .zip(&colors)
        .filter(|(s, _)| !s.name.is_empty())
        .map(|(s, &color)| LegendEntry {
            name: s.name.clone(),
            color,
            swatch: if s.reference {
                Swatch::Dashed
            } else {
                Swatch::Line
            },
        })
        .collect();
    let shapes = legend_obstacles(plot, shaded, (x0, x1), (y0, y1));
    let (lw, lh) = legend_size_px(&entries);
    let (area_w, area_h) = (f64::from(w - 100), f64::from(h - 100));
    let corner = free_corner(&shapes, (f64::from(lw) / area_w, f64::from(lh) / area_h));
    let (chart_area, side) = match corner {
        None if !entries.is_empty() => {
            let (a, b) = root.split_horizontally(w - lw - 30);
            (a, Some(b))
        }
        _ => (root.clone(), None),
    };
    let mut chart = ChartBuilder::on(&chart_area)
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_err(path))?;
    chart
        .configure_mesh()
        .light_line_style(TRANSPARENT)
        .x_desc(plot.x_label.as_str())
        .y_desc(plot.y_label.as_str())
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()
        .map_err(plot_err(path))?;
    chart
        .draw_series(shaded.iter().map(|&(a, b)| {
            Rectangle::new(
                [(a, y0), (b, y1)],
                RGBColor(200, 200, 200).mix(0.5).filled(),
            )
        }))
        .map_err(plot_err(path))?;
    for (s, &color) in plot.series.iter().zip(&colors) {
        let style = ShapeStyle::from(&color).stroke_width(if s.reference { 1 } else { 2 });
        // Break lines at NaN (no GNSS in an outage).
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &(x, y) in &s.points {
            if x.is_finite() && y.is_finite() {
                if let Some(r) = runs.last_mut() {
                    r.push((x, y));
                }
            } else if runs.last().is_some_and(|r| !r.is_empty()) {
                runs.push(Vec::new());
            }
        }
        for r in runs {
            if s.reference {
                chart.draw_series(DashedLineSeries::new(r, 8, 5, style))
            } else {
                chart.draw_series(LineSeries::new(r, style))
            }
            .map_err(plot_err(path))?;
        }
    }
    if let Some(corner) = corner {
        let area = chart.plotting_area().strip_coord_spec();
        draw_legend_in_corner(&area, &entries, corner).map_err(plot_err(path))?;
    }
    if let Some(side) = side {
        draw_legend(&side, &entries, (0, 20)).map_err(plot_err(path))?;
    }
    root.present().map_err(plot_err(path))?;
    Ok(())
}
