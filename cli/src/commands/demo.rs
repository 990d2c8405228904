//! `gpsrx demo`: simulate the built-in scenario and show what was made. Needs no file.

use crate::cli::{DemoArgs, LoopArgs, SourceArgs};
use crate::commands::run::{run_file, IonoModel, RunArgs, TropoModel};
use crate::commands::simulate::{print_report, simulate};
use crate::exit::Completion;
use anyhow::Context;
use gpsrx_nav::frames::{enu_rotation, Vector3};
use gpsrx_samples::sim::Scenario;
use std::io::Write;
use std::path::PathBuf;

/// Runs `gpsrx demo`: [`Completion::NoValidFix`] (exit status 2, as `gpsrx run`) when the
/// receiver made no valid fix on the simulated recording.
pub fn run(args: &DemoArgs) -> anyhow::Result<Completion> {
    let mut scenario = Scenario::default_scenario()?;
    if let Some(d) = args.duration {
        scenario.duration_s = d;
    }
    let (dir, _tmp) = super::work_dir(args.keep.as_deref())?;
    let mut out = crate::exit::stdout();
    writeln!(out, "gpsrx demo: {}", scenario.description)?;
    writeln!(
        out,
        "simulating {:.0} s of {} at {:.3} MHz into {}",
        scenario.duration_s,
        scenario.output.format,
        scenario.output.fs_hz / 1e6,
        dir.display()
    )?;
    let report = simulate(&scenario, &PathBuf::new(), &dir, true)?;
    print_report(&mut out, &report)?;
    print_truth_summary(&mut out, &report.truth_sv_path)?;
    writeln!(
        out,
        "\nrunning the receiver on it (gpsrx run {} --out {})",
        report.data_path.display(),
        dir.join("run").display()
    )?;
    let run_args = RunArgs {
        source: SourceArgs {
            file: report.data_path.clone(),
            format: None,
            fs: None,
            if_hz: 0.0,
            invert_q: false,
            skip: 0.0,
            duration: None,
        },
        loops: LoopArgs::default(),
        out: dir.join("run"),
        json: false,
        // The plots only when the files are kept.
        no_plots: args.keep.is_none(),
        profile: false,
        tracking: None,
        nav: None,
        iono: Some(IonoModel::Klobuchar),
        tropo: Some(TropoModel::Saastamoinen),
        elevation_mask: None,
        rate: None,
        // Dated by the recording's SigMF core:datetime, as a user's recording would be.
        week: None,
        approx_time: None,
        approx_llh: None,
        doppler_max: None,
        doppler_center: None,
        acq_coherent_ms: None,
        acq_noncoherent: None,
        raim_pfa: None,
        max_pdop: None,
        acq_pfa: None,
        search_budget: None,
        defer_deep_search: None,
        allow_unhealthy: false,
        landmarks: None,
        ins: None,
        dr: None,
        accel: None,
        dr_filter: None,
        dr_params: None,
        no_aiding: false,
        ins_band_limit: None,
        ins_max_gap: 0.5,
    };
    let (run_report, fixes) = run_file(&run_args, true)?;
    let summary = &run_report.receiver;
    writeln!(
        out,
        "processed {:.1} s in {:.1} s ({:.1}x real time); satellites tracked: {:?}",
        summary.duration_s,
        summary.wall_s,
        summary.duration_s / summary.wall_s.max(1e-9),
        summary.tracked_prns
    )?;
    match (summary.first_fix_s, truth_position(&report.truth_path)?) {
        (Some(t), Some(truth)) => {
            let (mut h2, mut v2) = (0.0, 0.0);
            for f in &fixes {
                let d = Vector3::new(
                    f.ecef_m[0] - truth.x,
                    f.ecef_m[1] - truth.y,
                    f.ecef_m[2] - truth.z,
                );
                let enu = enu_rotation(&f.llh) * d;
                h2 += enu.x * enu.x + enu.y * enu.y;
                v2 += enu.z * enu.z;
            }
            let n = fixes.len() as f64;
            let last = &fixes[fixes.len() - 1];
            writeln!(
                out,
                "first fix {t:.1} s after the start (subframes 1-3 complete at 24.1 s); {} fixes",
                fixes.len()
            )?;
            writeln!(
                out,
                "last fix: {:.7} deg, {:.7} deg, {:.2} m, {} satellites, PDOP {:.2}",
                last.llh.lat_rad.to_degrees(),
                last.llh.lon_rad.to_degrees(),
                last.llh.h_m,
                last.n_sv,
                last.pdop
            )?;
            writeln!(
                out,
                "error against the truth: horizontal RMS {:.2} m, vertical RMS {:.2} m",
                (h2 / n).sqrt(),
                (v2 / n).sqrt()
            )?;
        }
        (Some(_), None) => writeln!(out, "{} fixes (no truth position to compare)", fixes.len())?,
        (None, _) if summary.invalid_fixes > 0 => writeln!(
            out,
            "no valid fix: all {} solutions failed the RAIM test (exit status 2)",
            summary.invalid_fixes
        )?,
        (None, _) => writeln!(
            out,
            "no valid fix (exit status 2): the recording ended before 4 satellites had their ephemeris (subframes 1-3 need about 24 s here; --duration {:.0} s)",
            scenario.duration_s
        )?,
    }
    if args.keep.is_none() {
        writeln!(
            out,
            "(temporary files removed; use --keep DIR to keep them)"
        )?;
    }
    out.flush()?;
    Ok(if summary.fixes == 0 {
        Completion::NoValidFix
    } else {
        Completion::Done
    })
}

/// Prints what a receiver should find at the first sample: the truth of every satellite.
fn print_truth_summary(out: &mut dyn Write, truth_sv: &std::path::Path) -> anyhow::Result<()> {
    let mut rdr = csv::Reader::from_path(truth_sv)
        .with_context(|| format!("cannot read {}", truth_sv.display()))?;
    let headers = rdr.headers()?.clone();
    let col = |name: &str| {
        headers
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("{name} missing in truth_sv.csv"))
    };
    let (t, prn, cp, dop, cn0, pr) = (
        col("t_s")?,
        col("prn")?,
        col("code_phase_chips")?,
        col("doppler_hz")?,
        col("cn0_dbhz")?,
        col("pseudorange_m")?,
    );
    writeln!(
        out,
        "\ntruth at the first sample (what acquisition should find):"
    )?;
    writeln!(
        out,
        "  PRN  code phase(chips)  Doppler(Hz)  C/N0(dB-Hz)  pseudorange(m)"
    )?;
    for rec in rdr.records() {
        let rec = rec?;
        if rec.get(t).and_then(|v| v.parse::<f64>().ok()) != Some(0.0) {
            break;
        }
        let f = |i: usize| {
            rec.get(i)
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or(f64::NAN)
        };
        writeln!(
            out,
            "  G{:02}  {:17.3}  {:11.1}  {:11.1}  {:14.1}",
            rec.get(prn).unwrap_or("?").parse::<u8>().unwrap_or(0),
            f(cp),
            f(dop),
            f(cn0),
            f(pr)
        )?;
    }
    Ok(())
}

/// The (static) truth position: the first row of `truth.csv`.
fn truth_position(truth: &std::path::Path) -> anyhow::Result<Option<Vector3<f64>>> {
    let mut rdr = csv::Reader::from_path(truth)
        .with_context(|| format!("cannot read {}", truth.display()))?;
    let headers = rdr.headers()?.clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (Some(x), Some(y), Some(z)) = (col("x_m"), col("y_m"), col("z_m")) else {
        return Ok(None);
    };
    let Some(rec) = rdr.records().next() else {
        return Ok(None);
    };
    let rec = rec?;
    let f = |i: usize| rec.get(i).and_then(|v| v.parse::<f64>().ok());
    Ok(match (f(x), f(y), f(z)) {
        (Some(a), Some(b), Some(c)) => Some(Vector3::new(a, b, c)),
        _ => None,
    })
}
