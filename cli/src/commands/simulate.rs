//! `gpsrx simulate`: scenario file -> IF recording + truth files, and the simulated sensors the
//! scenario asks for, a thin layer over [`gpsrx_receiver::simulate`] (a progress bar, the
//! printed summary).

use crate::cli::SimulateArgs;
use gpsrx_receiver::simulate::{InsOutput, SensorOutputs};
use gpsrx_samples::sim::{Scenario, SimReport};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Runs `gpsrx simulate`.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let (mut scenario, base) = match (&args.scenario, args.default) {
        (Some(p), false) => Scenario::load(p)?,
        (None, true) => (Scenario::default_scenario()?, PathBuf::new()),
        _ => {
            anyhow::bail!("give a scenario file (e.g. samples/scenarios/default.toml) or --default")
        }
    };
    if let Some(d) = args.duration {
        scenario.duration_s = d;
    }
    if let Some(s) = args.seed {
        scenario.seed = s;
    }
    if let Some(f) = &args.format {
        scenario.output.format = f.clone();
    }
    if let Some(fs) = args.fs {
        scenario.output.fs_hz = fs;
    }
    let (report, sensors) = simulate_with_sensors(&scenario, &base, &args.out, !args.json)?;
    let mut out = crate::exit::stdout();
    if args.json {
        let mut v = serde_json::to_value(&report)?;
        if let Some(map) = v.as_object_mut() {
            for (key, f) in [
                ("ins", serde_json::to_value(&sensors.ins)?),
                ("dr", serde_json::to_value(&sensors.dr)?),
                ("accel", serde_json::to_value(&sensors.accel)?),
            ] {
                if !f.is_null() {
                    map.insert(key.into(), f);
                }
            }
        }
        let text = serde_json::to_string_pretty(&v)?;
        writeln!(out, "{text}")?;
    } else {
        print_report_with_ins(&mut out, &report, sensors.ins.as_ref())?;
        let dr = sensors.dr.as_ref().map(|f| (&f.path, f.rows));
        let accel = sensors.accel.as_ref().map(|f| (&f.path, f.rows));
        for (what, f) in [("dr:", dr), ("accel:", accel)] {
            if let Some((path, rows)) = f {
                writeln!(out, "{what:<10} {} ({rows} rows)", path.display())?;
            }
        }
    }
    out.flush()?;
    Ok(())
}

/// Runs a scenario into `out` with [`gpsrx_receiver::simulate::simulate`] (the sensor logs
/// too), with a progress bar when `progress` is set, and returns the recording's report.
pub fn simulate(
    scenario: &Scenario,
    base: &Path,
    out: &Path,
    progress: bool,
) -> anyhow::Result<SimReport> {
    Ok(simulate_with_sensors(scenario, base, out, progress)?.0)
}

/// [`simulate`], also returning the sensor logs written.
pub fn simulate_with_sensors(
    scenario: &Scenario,
    base: &Path,
    out: &Path,
    progress: bool,
) -> anyhow::Result<(SimReport, SensorOutputs)> {
    let bar = if progress {
        ProgressBar::new(1000)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("simulating {bar:40} {percent:>3}% {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let done = gpsrx_receiver::simulate::simulate(scenario, base, out, &|f| {
        bar.set_position((f * 1000.0) as u64)
    })?;
    bar.finish_and_clear();
    Ok(done)
}

/// Writes a human summary of a run to `out`.
pub fn print_report(out: &mut dyn Write, r: &SimReport) -> std::io::Result<()> {
    print_report_with_ins(out, r, None)
}

/// Writes a human summary of a run and of the `ins.csv` it wrote, if any, to `out`.
pub fn print_report_with_ins(
    out: &mut dyn Write,
    r: &SimReport,
    ins: Option<&InsOutput>,
) -> std::io::Result<()> {
    writeln!(out, "satellites ({}):", r.satellites.len())?;
    writeln!(out, "  PRN  elev(deg)  C/N0(dB-Hz)")?;
    for (prn, el, cn0) in &r.satellites {
        writeln!(out, "  G{prn:02}  {el:9.1}  {cn0:11.1}")?;
    }
    writeln!(
        out,
        "recording: {} ({}, {:.3} MHz, {:.1} s, {} samples, {:.1} MB, {} clipped)",
        r.data_path.display(),
        r.format,
        r.fs_hz / 1e6,
        r.duration_s,
        r.samples,
        r.bytes as f64 / 1e6,
        r.clipped
    )?;
    writeln!(out, "metadata:  {}", r.meta_path.display())?;
    writeln!(
        out,
        "truth:     {} and {}",
        r.truth_path.display(),
        r.truth_sv_path.display()
    )?;
    if let Some(ins) = ins {
        let c = &ins.config;
        let b = c.accel_bias_enu_mps2;
        writeln!(out, "ins:       {} ({} rows at {} Hz; accel bias ENU [{}, {}, {}] m/s^2, VRW {} m/s/sqrt(s), scale factor {}, latency {} s, band limit {})",
            ins.path.display(),
            ins.rows,
            c.rate_hz,
            b[0],
            b[1],
            b[2],
            c.velocity_random_walk_mps_per_sqrt_s,
            c.scale_factor,
            c.latency_s,
            c.band_limit_alpha_rad_s
                .map_or("none".to_string(), |a| format!("{a} rad/s"))
        )?;
    }
    writeln!(
        out,
        "simulated {:.1} s in {:.2} s: {:.1}x real time ({:.1} Msamples/s)",
        r.duration_s,
        r.wall_s,
        r.realtime_factor,
        r.samples as f64 / r.wall_s.max(1e-9) / 1e6
    )?;
    Ok(())
}
