//! `gpsrx snapshot`: one position per snapshot of a few milliseconds (coarse-time navigation),
//! a thin layer over [`gpsrx_receiver::snapshot::set`]: the options become a
//! [`SnapshotSetSpec`], the set is run and written, and the summary printed.

use crate::commands::acquire::assist::{parse_llh, parse_time};
use anyhow::{bail, Context};
use gpsrx_receiver::snapshot::{run_set, write_set, SetResult, SnapshotSetSpec};
use std::io::Write;

pub use crate::cli::SnapshotArgs;

/// Runs `gpsrx snapshot`.
pub fn run(args: &SnapshotArgs) -> anyhow::Result<()> {
    let spec = spec(args)?;
    let r = run_set(&spec, |o| {
        if (o.index + 1) % 10 == 0 {
            tracing::info!("snapshot {}", o.index + 1);
        }
    })?;
    write_set(&args.out, &r)?;
    let mut out = crate::exit::stdout();
    print_summary(&mut out, &r, args.smooth_accel)?;
    writeln!(out, "wrote {}", args.out.join("snapshots.csv").display())?;
    out.flush()?;
    Ok(())
}

/// The set the options describe (checked here where the messages name the options).
fn spec(args: &SnapshotArgs) -> anyhow::Result<SnapshotSetSpec> {
    let llh = parse_llh(&args.approx_llh)?;
    if let Some(t) = &args.time {
        parse_time(t)?;
    }
    if !(args.max_speed.is_finite() && (0.0..=2000.0).contains(&args.max_speed)) {
        bail!("--max-speed {}: give 0 to 2000 m/s", args.max_speed);
    }
    if !(args.height_sigma.is_finite() && args.height_sigma >= 0.0) {
        bail!(
            "--height-sigma {}: give a non-negative number of metres",
            args.height_sigma
        );
    }
    if let Some(a) = args.smooth_accel {
        if !(a.is_finite() && a > 0.0) {
            bail!("--smooth-accel {a}: give a positive acceleration in m/s^2");
        }
    }
    let nav = args.nav.as_ref().map(|p| p.display().to_string());
    let mut spec = SnapshotSetSpec::new(
        &args.input,
        nav,
        [llh.lat_rad.to_degrees(), llh.lon_rad.to_degrees(), llh.h_m],
    );
    spec.time.clone_from(&args.time);
    spec.format.clone_from(&args.format);
    spec.map = args.map.as_deref().map(parse_map).transpose()?;
    spec.fs_hz = args.fs;
    spec.if_hz = args.if_hz;
    spec.height_sigma_m = args.height_sigma;
    spec.max_speed_mps = args.max_speed;
    spec.coherent_ms = args.coherent_ms;
    spec.coherent_look = args.coherent_look;
    spec.smooth_accel_mps2 = args.smooth_accel;
    spec.truth.clone_from(&args.truth);
    spec.truth_h_m = args.truth_h;
    spec.truth_ecef_m = args.truth_ecef.as_deref().map(parse_ecef).transpose()?;
    Ok(spec)
}

/// The summary lines: counts and throughput, the smoothing, a single snapshot's position,
/// the errors against the truth.
fn print_summary(
    out: &mut dyn Write,
    r: &SetResult,
    smooth_accel: Option<f64>,
) -> anyhow::Result<()> {
    let s = &r.score;
    writeln!(
        out,
        "{} snapshots: {} fixes ({:.1} %), {} unverified (5 satellites), {} without a position; \
         {:.2} s, {:.1} snapshots/s",
        s.snapshots,
        s.fixes,
        100.0 * s.fixes as f64 / s.snapshots.max(1) as f64,
        s.unverified,
        s.snapshots - s.fixes - s.unverified,
        r.elapsed_s,
        s.snapshots as f64 / r.elapsed_s.max(1e-9)
    )?;
    if let Some(moved) = r.smoothed {
        writeln!(
            out,
            "smoothed {moved} fixes across snapshots (acceleration sigma {} m/s^2)",
            smooth_accel.unwrap_or_default()
        )?;
    }
    if let [o] = r.outcomes.as_slice() {
        if let Some(l) = o.llh {
            writeln!(
                out,
                "position {:.7} {:.7} {:.1} m, {} satellites, HDOP {:.1}, residual RMS {:.1} m, \
                 time correction {:+.4} s",
                l.lat_rad.to_degrees(),
                l.lon_rad.to_degrees(),
                l.h_m,
                o.used_prns.len(),
                o.hdop.unwrap_or(f64::NAN),
                o.residual_rms_m.unwrap_or(f64::NAN),
                o.time_correction_s.unwrap_or(f64::NAN)
            )?;
        }
        if !o.reason.is_empty() {
            writeln!(out, "{}: {}", o.quality.name(), o.reason)?;
        }
    }
    if r.scored {
        writeln!(
            out,
            "horizontal error of the fixes: median {:.1} m, 95th percentile {:.1} m, max {:.1} m",
            s.median_m, s.p95_m, s.max_m
        )?;
    }
    Ok(())
}

/// `--map V0,V1,V2,V3`.
fn parse_map(text: &str) -> anyhow::Result<[f32; 4]> {
    let v: Vec<f32> = text
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--map {text:?}: give four numbers V0,V1,V2,V3"))?;
    let [a, b, c, d] = v.as_slice() else {
        bail!("--map {text:?}: give four numbers V0,V1,V2,V3");
    };
    Ok([*a, *b, *c, *d])
}

/// `--truth-ecef X,Y,Z`.
fn parse_ecef(text: &str) -> anyhow::Result<[f64; 3]> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--truth-ecef {text:?}: give X,Y,Z in metres"))?;
    let [x, y, z] = v.as_slice() else {
        bail!("--truth-ecef {text:?}: give X,Y,Z in metres");
    };
    Ok([*x, *y, *z])
}
