//! A scenario into an IF recording, its truth files and the simulated sensors the scenario
//! asks for (`gpsrx simulate`, the Python package's `simulate`, the benchmarks): the signal
//! from [`gpsrx_samples::sim::Simulator`]; `ins.csv` for an `[ins]` table (the truth through
//! the INS error models of [`gpsrx_ins_aiding::error_model`]), `dr.csv` for a `[dr]` table
//! (gyro and odometer of a vehicle, [`gpsrx_ins_aiding::dr_sensors`]) and `accel.csv` for an
//! `[accel]` table (longitudinal accelerometer).
//!
//! It lives here rather than in `samples::sim` because the sensor logs need the land-vehicle
//! view of the truth ([`crate::fusion::vehicle`]) and the sensor models of
//! `gpsrx-ins-aiding`, neither of which the samples crate depends on.

mod tables;

pub use tables::{accel_config, dr_config, ins_config};

use crate::fusion::vehicle::{vehicle_truth, EcefState};
use gpsrx_ins_aiding::{
    simulate_accel, simulate_dr, simulate_ins, write_accel_csv, write_dr_csv, write_ins_csv,
    AccelSensorConfig, DrSensorConfig, InsError, InsErrorConfig, InsSample, TruthState,
    VehicleTruth,
};
use gpsrx_nav::frames::Llh;
use gpsrx_samples::sim::{Scenario, SimError, SimReport, Simulator};
use std::path::{Path, PathBuf};

/// The file name of the simulated INS, written beside `truth.csv`.
pub const INS_FILE_NAME: &str = "ins.csv";
/// The file names of the simulated DR and accelerometer logs, written beside `truth.csv`.
pub const DR_FILE_NAME: &str = "dr.csv";
/// See [`DR_FILE_NAME`].
pub const ACCEL_FILE_NAME: &str = "accel.csv";

/// Truth rate of the vehicle view the DR sensor models integrate, Hz.
const VEHICLE_TRUTH_RATE_HZ: f64 = 100.0;

/// A simulation that cannot be done; the message names the table, key or file.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    /// A sensor table that does not parse: an unknown key or a value of the wrong type.
    #[error(
        "scenario [{table}]{}: {message} (the keys are documented in samples/scenarios/README.md)",
        key.as_ref().map_or(String::new(), |k| format!(" `{k}`"))
    )]
    SensorTable {
        /// `ins`, `dr` or `accel`.
        table: &'static str,
        /// The key the error belongs to, when one alone is wrong.
        key: Option<String>,
        /// What the parser said.
        message: String,
    },
    /// A sensor table whose values are out of range.
    #[error("scenario [{table}]")]
    SensorModel {
        /// `ins`, `dr` or `accel`.
        table: &'static str,
        /// What is wrong.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The scenario cannot be prepared (trajectory, navigation data, output settings).
    #[error("cannot prepare the scenario")]
    Prepare(#[source] SimError),
    /// The signal simulation failed.
    #[error("simulation into {} failed", out.display())]
    Run {
        /// The output directory.
        out: PathBuf,
        /// Why.
        #[source]
        source: SimError,
    },
    /// A sensor log cannot be simulated or written.
    #[error("cannot write {}", path.display())]
    SensorLog {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
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

/// The simulated INS file a run wrote (`ins.csv`).
pub type InsOutput = SensorLogOutput<InsErrorConfig>;

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

/// Runs a scenario into `out` (`progress` is told the fraction done) and writes the sensor logs
/// its `[ins]`, `[dr]` and `[accel]` tables ask for (all checked before anything is simulated).
/// `base` is the directory the scenario's relative paths start from.
pub fn simulate(
    scenario: &Scenario,
    base: &Path,
    out: &Path,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(SimReport, SensorOutputs), SimulateError> {
    let ins_cfg = ins_config(scenario)?;
    let dr_cfg = dr_config(scenario)?;
    let accel_cfg = accel_config(scenario)?;
    let sim = Simulator::new(scenario, base).map_err(SimulateError::Prepare)?;
    let report = sim
        .run(out, progress)
        .map_err(|source| SimulateError::Run {
            out: out.to_path_buf(),
            source,
        })?;
    let mut sensors = SensorOutputs::default();
    let log_error = |path: &Path| {
        let path = path.to_path_buf();
        move |e: Box<dyn std::error::Error + Send + Sync>| SimulateError::SensorLog {
            path,
            source: e,
        }
    };
    if let Some(config) = ins_cfg {
        let path = report.truth_path.with_file_name(INS_FILE_NAME);
        let rows =
            write_ins_for(&sim, &config, &path).map_err(|e| log_error(&path)(Box::new(e)))?;
        sensors.ins = Some(SensorLogOutput { path, rows, config });
    }
    if dr_cfg.is_some() || accel_cfg.is_some() {
        let truth = vehicle_truth_for(&sim);
        if let Some(config) = dr_cfg {
            let path = report.truth_path.with_file_name(DR_FILE_NAME);
            let rows = simulate_dr(&truth, &config)
                .and_then(|log| write_dr_csv(&path, &log).map(|_| log.len()))
                .map_err(|e| log_error(&path)(Box::new(e)))?;
            sensors.dr = Some(SensorLogOutput { path, rows, config });
        }
        if let Some(config) = accel_cfg {
            let path = report.truth_path.with_file_name(ACCEL_FILE_NAME);
            let rows = simulate_accel(&truth, &config)
                .and_then(|log| write_accel_csv(&path, &log).map(|_| log.len()))
                .map_err(|e| log_error(&path)(Box::new(e)))?;
            sensors.accel = Some(SensorLogOutput { path, rows, config });
        }
    }
    Ok((report, sensors))
}

/// Writes the INS of `cfg` for the simulation `sim` to `path` ([`simulate_ins_for`]) and
/// returns the number of rows.
pub fn write_ins_for(
    sim: &Simulator,
    cfg: &InsErrorConfig,
    path: &Path,
) -> Result<usize, InsError> {
    let samples = simulate_ins_for(sim, cfg)?;
    write_ins_csv(path, &samples)?;
    Ok(samples.len())
}

/// The INS of `cfg` for the simulation `sim` over the whole recording (see
/// [`gpsrx_ins_aiding::error_model`]). Truth at sample time `t` (seconds since the first IF
/// sample) is [`Simulator::receiver_truth`], as in `truth.csv`: position and velocity at the
/// true time `t_true` solving `t_true + b(t_true) = t`, and `gps_tow_s` the GPS time of week
/// of `t_true`.
pub fn simulate_ins_for(sim: &Simulator, cfg: &InsErrorConfig) -> Result<Vec<InsSample>, InsError> {
    let truth = |t_s: f64| {
        let (tow_s, s) = sim.receiver_truth(t_s);
        TruthState {
            t_s,
            gps_tow_s: Some(tow_s),
            pos_m: s.pos_m,
            vel_mps: s.vel_mps,
        }
    };
    simulate_ins(&truth, sim.duration_s(), cfg)
}

/// The simulation's truth as a land vehicle, at 100 Hz over the whole recording, in the local
/// level frame of the receiver's position at the first sample (receiver-clock time `t_s`, as in
/// `truth.csv`; see [`crate::fusion::vehicle`]).
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
