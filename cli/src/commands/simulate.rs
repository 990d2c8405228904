//! `gpsrx simulate`: scenario file -> IF recording + truth files, and the simulated sensors the
//! scenario asks for: `ins.csv` for an `[ins]` table (the truth through the INS error models of
//! [`gpsrx_ins_aiding::error_model`]), `dr.csv` for a `[dr]` table (gyro and odometer of a
//! vehicle, [`gpsrx_ins_aiding::dr_sensors`]) and `accel.csv` for an `[accel]` table
//! (longitudinal accelerometer).

use crate::cli::SimulateArgs;
use anyhow::Context;
use gpsrx_ins_aiding::{
    simulate_accel, simulate_dr, simulate_ins, write_accel_csv, write_dr_csv, write_ins_csv,
    AccelSensorConfig, DrSensorConfig, InsErrorConfig, TruthState, VehicleTruth,
};
use gpsrx_nav::frames::Llh;
use gpsrx_receiver::fusion::vehicle::{vehicle_truth, EcefState};
use gpsrx_samples::sim::{Scenario, SimReport, Simulator};
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

/// The file name of the simulated INS, written beside `truth.csv`.
pub const INS_FILE_NAME: &str = "ins.csv";

/// The simulated INS file a run wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct InsOutput {
    /// `ins.csv`.
    pub path: PathBuf,
    /// Rows written.
    pub rows: usize,
    /// Its error models (the scenario's `[ins]` table with defaults filled in).
    pub config: InsErrorConfig,
}

/// Parses and checks a scenario's `[ins]` table (None without one). Errors name the bad key:
/// an unknown key, a value of the wrong type, or a value out of range.
pub fn ins_config(scenario: &Scenario) -> anyhow::Result<Option<InsErrorConfig>> {
    let Some(cfg) = parse_sensor_table::<InsErrorConfig>("ins", scenario.ins.as_ref())? else {
        return Ok(None);
    };
    cfg.validate().context("scenario [ins]")?;
    Ok(Some(cfg))
}

/// Parses and checks a scenario's `[dr]` table (None without one).
pub fn dr_config(scenario: &Scenario) -> anyhow::Result<Option<DrSensorConfig>> {
    let Some(cfg) = parse_sensor_table::<DrSensorConfig>("dr", scenario.dr.as_ref())? else {
        return Ok(None);
    };
    cfg.validate().context("scenario [dr]")?;
    Ok(Some(cfg))
}

/// Parses and checks a scenario's `[accel]` table (None without one).
pub fn accel_config(scenario: &Scenario) -> anyhow::Result<Option<AccelSensorConfig>> {
    let Some(cfg) = parse_sensor_table::<AccelSensorConfig>("accel", scenario.accel.as_ref())?
    else {
        return Ok(None);
    };
    cfg.validate().context("scenario [accel]")?;
    Ok(Some(cfg))
}

/// Deserialises a sensor table whose every key has a default. Each key alone is then a valid
/// table, so parsing them one by one finds the key a type error belongs to.
fn parse_sensor_table<T: serde::de::DeserializeOwned>(
    name: &str,
    table: Option<&toml::Table>,
) -> anyhow::Result<Option<T>> {
    let Some(table) = table else {
        return Ok(None);
    };
    let parse = |t: toml::Table| -> Result<T, toml::de::Error> { toml::Value::Table(t).try_into() };
    for (key, value) in table {
        let mut one = toml::Table::new();
        one.insert(key.clone(), value.clone());
        if let Err(e) = parse(one) {
            anyhow::bail!(
                "scenario [{name}] `{key}`: {} (the keys are documented in samples/scenarios/README.md)",
                e.message().trim()
            );
        }
    }
    let cfg = parse(table.clone()).map_err(|e| {
        anyhow::anyhow!(
            "scenario [{name}]: {} (see samples/scenarios/README.md)",
            e.message().trim()
        )
    })?;
    Ok(Some(cfg))
}

/// Writes the INS of `cfg` for the simulation `sim` to `path` (see
/// [`gpsrx_ins_aiding::error_model`]) and returns the number of rows. Truth at sample time `t`
/// (seconds since the first IF sample) is [`Simulator::receiver_truth`], as in `truth.csv`:
/// position and velocity at the true time `t_true` solving `t_true + b(t_true) = t`, and
/// `gps_tow_s` the GPS time of week of `t_true`.
pub fn write_ins_for(sim: &Simulator, cfg: &InsErrorConfig, path: &Path) -> anyhow::Result<usize> {
    let truth = |t_s: f64| {
        let (tow_s, s) = sim.receiver_truth(t_s);
        TruthState {
            t_s,
            gps_tow_s: Some(tow_s),
            pos_m: s.pos_m,
            vel_mps: s.vel_mps,
        }
    };
    let samples = simulate_ins(&truth, sim.duration_s(), cfg)?;
    write_ins_csv(path, &samples)?;
    Ok(samples.len())
}

/// The file names of the simulated DR and accelerometer logs, written beside `truth.csv`.
pub const DR_FILE_NAME: &str = "dr.csv";
/// See [`DR_FILE_NAME`].
pub const ACCEL_FILE_NAME: &str = "accel.csv";

/// Truth rate of the vehicle view the DR sensor models integrate, Hz.
const VEHICLE_TRUTH_RATE_HZ: f64 = 100.0;

/// The simulation's truth as a land vehicle, at 100 Hz over the whole recording, in the local
/// level frame of the receiver's position at the first sample (receiver-clock time `t_s`, as in
/// `truth.csv`; see [`gpsrx_receiver::fusion::vehicle`]).
pub fn vehicle_truth_for(sim: &Simulator) -> Vec<VehicleTruth> {
    let n = (sim.duration_s() * VEHICLE_TRUTH_RATE_HZ).floor() as usize;
    let states: Vec<EcefState> = (0..=n)
        .map(|k| {
            let t_s = k as f64 / VEHICLE_TRUTH_RATE_HZ;
            let (_, s) = sim.receiver_truth(t_s);
            EcefState {
                t_s,
                pos_m: s.pos_m,
                vel_mps: s.vel_mps,
                acc_mps2: s.acc_mps2,
            }
        })
        .collect();
    let origin = Llh::from_ecef(&states[0].pos_m);
    vehicle_truth(&origin, &states)
}

/// A simulated sensor log a run wrote.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SensorLogOutput<C> {
    /// The file.
    pub path: PathBuf,
    /// Rows written.
    pub rows: usize,
    /// Its error model (the scenario's table with defaults filled in).
    pub config: C,
}

/// Every simulated sensor file of a run.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SensorOutputs {
    /// `ins.csv`, with an `[ins]` table.
    pub ins: Option<InsOutput>,
    /// `dr.csv`, with a `[dr]` table.
    pub dr: Option<SensorLogOutput<DrSensorConfig>>,
    /// `accel.csv`, with an `[accel]` table.
    pub accel: Option<SensorLogOutput<AccelSensorConfig>>,
}

/// Prepares and runs a scenario into `out`, with a progress bar when `progress` is set; with an
/// `[ins]` table it also writes `ins.csv` (see [`simulate_with_ins`]).
pub fn simulate(
    scenario: &Scenario,
    base: &Path,
    out: &Path,
    progress: bool,
) -> anyhow::Result<SimReport> {
    Ok(simulate_with_ins(scenario, base, out, progress)?.0)
}

/// [`simulate`], also returning the `ins.csv` written when the scenario has an `[ins]` table
/// (checked before anything is simulated).
pub fn simulate_with_ins(
    scenario: &Scenario,
    base: &Path,
    out: &Path,
    progress: bool,
) -> anyhow::Result<(SimReport, Option<InsOutput>)> {
    let (report, sensors) = simulate_with_sensors(scenario, base, out, progress)?;
    Ok((report, sensors.ins))
}

/// [`simulate`], also writing the sensor logs the scenario's `[ins]`, `[dr]` and `[accel]` tables
/// ask for (all checked before anything is simulated).
pub fn simulate_with_sensors(
    scenario: &Scenario,
    base: &Path,
    out: &Path,
    progress: bool,
) -> anyhow::Result<(SimReport, SensorOutputs)> {
    let ins_cfg = ins_config(scenario)?;
    let dr_cfg = dr_config(scenario)?;
    let accel_cfg = accel_config(scenario)?;
    let sim = Simulator::new(scenario, base).context("cannot prepare the scenario")?;
    let bar = if progress {
        ProgressBar::new(1000)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("simulating {bar:40} {percent:>3}% {elapsed} (eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let report = sim
        .run(out, &|f| bar.set_position((f * 1000.0) as u64))
        .with_context(|| format!("simulation into {} failed", out.display()))?;
    bar.finish_and_clear();
    let mut sensors = SensorOutputs::default();
    if let Some(config) = ins_cfg {
        let path = report.truth_path.with_file_name(INS_FILE_NAME);
        let rows = write_ins_for(&sim, &config, &path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        sensors.ins = Some(InsOutput { path, rows, config });
    }
    if dr_cfg.is_some() || accel_cfg.is_some() {
        let truth = vehicle_truth_for(&sim);
        if let Some(config) = dr_cfg {
            let path = report.truth_path.with_file_name(DR_FILE_NAME);
            let rows = simulate_dr(&truth, &config)
                .and_then(|log| write_dr_csv(&path, &log).map(|_| log.len()))
                .with_context(|| format!("cannot write {}", path.display()))?;
            sensors.dr = Some(SensorLogOutput { path, rows, config });
        }
        if let Some(config) = accel_cfg {
            let path = report.truth_path.with_file_name(ACCEL_FILE_NAME);
            let rows = simulate_accel(&truth, &config)
                .and_then(|log| write_accel_csv(&path, &log).map(|_| log.len()))
                .with_context(|| format!("cannot write {}", path.display()))?;
            sensors.accel = Some(SensorLogOutput { path, rows, config });
        }
    }
    Ok((report, sensors))
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
