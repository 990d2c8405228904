//! `gpsrx snapshot`: one position per snapshot of a few milliseconds (coarse-time navigation),
//! a thin layer over [`gpsrx_receiver::snapshot`].

use crate::commands::acquire::assist::{parse_llh, parse_time};
use anyhow::{bail, Context};
use gpsrx_nav::pvt::HeightConstraint;
use gpsrx_nav::{Llh, Vector3};
use gpsrx_receiver::snapshot::driver::Seed;
use gpsrx_receiver::snapshot::output::{self, Truth};
use gpsrx_receiver::snapshot::smooth::{smooth_track, SmoothOptions, DEFAULT_RANGE_SIGMA_M};
use gpsrx_receiver::snapshot::snappergps::read_snappergps;
use gpsrx_receiver::snapshot::{
    read_raw_snapshot, SampleSpec, Snapshot, SnapshotOptions, SnapshotProcessor,
};
use gpsrx_samples::SampleFormat;
use std::io::Write;
use std::path::Path;

pub use crate::cli::SnapshotArgs;

/// Runs `gpsrx snapshot`.
pub fn run(args: &SnapshotArgs) -> anyhow::Result<()> {
    let nav = match &args.nav {
        Some(path) => gpsrx_nav::read_rinex_nav(path)
            .with_context(|| format!("cannot read the navigation file {}", path.display()))?,
        // The library says what is missing; the error's hint names --nav.
        None => gpsrx_nav::NavData::default(),
    };
    let llh = parse_llh(&args.approx_llh)?;
    let time = args.time.as_deref().map(parse_time).transpose()?;
    let snapshots = read_input(args, time)?;
    if snapshots.is_empty() {
        bail!("{} holds no snapshot", args.input.display());
    }
    // --time with a SnapperGPS file: shift every timestamp by the same amount.
    let tag_correction_s = match (time, snapshots[0].approx_time) {
        (Some(t), Some(tag)) => t.diff_s(tag),
        _ => 0.0,
    };
    let seed = Seed {
        pos_ecef_m: llh.to_ecef(),
        time_correction_s: tag_correction_s,
        time,
    };
    let mut opts = SnapshotOptions::default();
    opts.measure.coherent_ms = args.coherent_ms;
    if !(args.max_speed.is_finite() && (0.0..=2000.0).contains(&args.max_speed)) {
        bail!("--max-speed {}: give 0 to 2000 m/s", args.max_speed);
    }
    opts.measure.max_speed_mps = args.max_speed;
    if !(args.height_sigma.is_finite() && args.height_sigma >= 0.0) {
        bail!(
            "--height-sigma {}: give a non-negative number of metres",
            args.height_sigma
        );
    }
    opts.solve.height = (args.height_sigma > 0.0).then_some(HeightConstraint {
        h_m: llh.h_m,
        sigma_m: args.height_sigma,
    });
    let mut processor = SnapshotProcessor::new(&nav, opts)?;
    let started = std::time::Instant::now();
    let n = snapshots.len();
    let outcomes = processor.run(&snapshots, seed, |o| {
        if n >= 10 && (o.index + 1) % 10 == 0 {
            tracing::info!("snapshot {} of {n}", o.index + 1);
        }
    });
    let mut outcomes = outcomes;
    let smoothed = match args.smooth_accel {
        Some(a) if a.is_finite() && a > 0.0 => Some(smooth_track(
            &mut outcomes,
            &SmoothOptions {
                accel_sigma_mps2: a,
                range_sigma_m: DEFAULT_RANGE_SIGMA_M,
            },
        )),
        Some(a) => bail!("--smooth-accel {a}: give a positive acceleration in m/s^2"),
        None => None,
    };
    let elapsed_s = started.elapsed().as_secs_f64();
    let truth = truth(args)?;
    let errors = truth
        .as_ref()
        .map_or_else(Vec::new, |t| t.errors(&outcomes));
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    output::write_csv(&args.out.join("snapshots.csv"), &outcomes, &errors)?;
    output::write_tracks(&args.out, &outcomes)?;
    if truth.is_some() {
        output::draw_errors(&args.out.join("errors.png"), &outcomes, &errors)?;
    }
    let mut out = crate::exit::stdout();
    let s = output::score(&outcomes, &errors);
    writeln!(
        out,
        "{} snapshots: {} fixes ({:.1} %), {} unverified (5 satellites), {} without a position; \
         {:.2} s, {:.1} snapshots/s",
        s.snapshots,
        s.fixes,
        100.0 * s.fixes as f64 / s.snapshots.max(1) as f64,
        s.unverified,
        s.snapshots - s.fixes - s.unverified,
        elapsed_s,
        s.snapshots as f64 / elapsed_s.max(1e-9)
    )?;
    if let Some(moved) = smoothed {
        writeln!(
            out,
            "smoothed {moved} fixes across snapshots (acceleration sigma {} m/s^2)",
            args.smooth_accel.unwrap_or_default()
        )?;
    }
    if n == 1 {
        let o = &outcomes[0];
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
    if truth.is_some() {
        writeln!(
            out,
            "horizontal error of the fixes: median {:.1} m, 95th percentile {:.1} m, max {:.1} m",
            s.median_m, s.p95_m, s.max_m
        )?;
    }
    writeln!(out, "wrote {}", args.out.join("snapshots.csv").display())?;
    out.flush()?;
    Ok(())
}

fn read_input(
    args: &SnapshotArgs,
    time: Option<gpsrx_nav::GpsTime>,
) -> anyhow::Result<Vec<Snapshot>> {
    if is_snappergps(&args.input) {
        return Ok(read_snappergps(&args.input)?);
    }
    let spec = SampleSpec {
        format: format(args)?,
        fs_hz: args.fs,
        if_hz: args.if_hz,
        invert_q: false,
    };
    Ok(vec![read_raw_snapshot(&args.input, &spec, time)?])
}

/// `--format` with `--map` applied to a 2-bit format.
fn format(args: &SnapshotArgs) -> anyhow::Result<Option<SampleFormat>> {
    let Some(name) = &args.format else {
        return Ok(None);
    };
    let mut f: SampleFormat = name.parse()?;
    if let Some(text) = &args.map {
        let v: Vec<f32> = text
            .split(',')
            .map(|x| x.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .with_context(|| format!("--map {text:?}: give four numbers V0,V1,V2,V3"))?;
        let SampleFormat::Packed2 { map, .. } = &mut f else {
            bail!("--map applies to the 2-bit formats (ci2, ri2, ..), not {name}");
        };
        let [a, b, c, d] = v.as_slice() else {
            bail!("--map {text:?}: give four numbers V0,V1,V2,V3");
        };
        *map = [*a, *b, *c, *d];
        f.validate()?;
    }
    Ok(Some(f))
}

fn truth(args: &SnapshotArgs) -> anyhow::Result<Option<Truth>> {
    if let Some(p) = &args.truth {
        return Ok(Some(output::read_truth_track(p, args.truth_h)?));
    }
    let Some(text) = &args.truth_ecef else {
        return Ok(None);
    };
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--truth-ecef {text:?}: give X,Y,Z in metres"))?;
    let [x, y, z] = v.as_slice() else {
        bail!("--truth-ecef {text:?}: give X,Y,Z in metres");
    };
    let llh = Llh::from_ecef(&Vector3::new(*x, *y, *z));
    Ok(Some(Truth::Static(llh)))
}

/// Whether a path names a SnapperGPS JSON file.
pub fn is_snappergps(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}
