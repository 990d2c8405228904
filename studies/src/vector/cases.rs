//! The study's scenarios and tracking modes: what is simulated and how it is tracked.

use gpsrx_samples::sim::{Scenario, Simulator};
use std::path::Path;

/// Sampling rate of the simulated IF, Hz (complex float samples).
pub const FS_HZ: f64 = 2.048e6;
/// GPS time of week of the first sample, s.
pub const START_TOW_S: f64 = 538_198.0;
/// An accelerometer bias of 1 mg, m/s^2: the INS of the aided modes has it on every
/// east-north-up axis.
pub const INS_BIAS_MPS2: f64 = 1e-3 * 9.80665;
/// Rate of the simulated INS log, Hz.
pub const INS_RATE_HZ: f64 = 50.0;
/// The blockage of every satellite: start and end, s.
pub const BLOCKAGE_S: (f64, f64) = (11.0, 14.0);
/// How long after the blockage the first fixes are scored, s.
pub const AFTER_BLOCKAGE_S: f64 = 3.0;
/// The turn starts this long into the run (straight flight before it), s.
pub const TURN_START_S: f64 = 12.0;
/// The turn lasts this long (acceleration ramped over 1 s at each end), s.
pub const TURN_S: f64 = 6.0;
/// Straight flight after the turn, s.
pub const AFTER_TURN_S: f64 = 2.0;

/// How the channels are tracked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
pub enum Mode {
    /// Scalar loops (`gpsrx run`).
    Scalar,
    /// Scalar loops with the INS Doppler feed-forward (seed 004, `--ins`).
    ScalarAided,
    /// The navigation filter drives the channels (`--tracking vector`).
    Vector,
    /// ... with the INS's motion in its prediction (`--tracking vector --ins`).
    VectorIns,
}

impl Mode {
    /// Every mode, scalar first.
    pub const ALL: [Mode; 4] = [
        Mode::Scalar,
        Mode::ScalarAided,
        Mode::Vector,
        Mode::VectorIns,
    ];

    /// The label in tables and plots.
    pub fn label(self) -> &'static str {
        match self {
            Mode::Scalar => "scalar",
            Mode::ScalarAided => "scalar + INS",
            Mode::Vector => "vector",
            Mode::VectorIns => "vector + INS",
        }
    }

    /// The mode has an INS.
    pub fn has_ins(self) -> bool {
        matches!(self, Mode::ScalarAided | Mode::VectorIns)
    }

    /// The navigation filter drives the channels.
    pub fn is_vector(self) -> bool {
        matches!(self, Mode::Vector | Mode::VectorIns)
    }
}

/// What a scenario tests.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum Test {
    /// Every satellite fades at `db_per_s` from 10 s to `end_s`: the tracking threshold.
    Fade {
        /// Fading rate, dB/s (negative).
        db_per_s: f64,
        /// End of the fade, s (the run ends 2 s later).
        end_s: f64,
    },
    /// Every satellite blocked over [`BLOCKAGE_S`]: the time back to a valid fix.
    Blockage,
    /// A level turn at `g` g of an aircraft at 250 m/s: the satellites held through it.
    Turn {
        /// Turning acceleration, g.
        g: f64,
    },
}

impl Test {
    /// The label in tables and plots.
    pub fn label(&self) -> String {
        match self {
            Test::Fade { db_per_s, .. } => format!("fade {:.1} dB/s", db_per_s.abs()),
            Test::Blockage => format!("blockage {:.0} s", BLOCKAGE_S.1 - BLOCKAGE_S.0),
            Test::Turn { g } => format!("turn {g:.0} g"),
        }
    }

    /// The simulator scenario (TOML) with noise seed `seed`.
    pub fn scenario_toml(&self, seed: u64) -> String {
        let (duration_s, receiver, rest) = match *self {
            Test::Fade { db_per_s, end_s } => (
                end_s + 2.0,
                STATIC_RECEIVER.to_string(),
                format!(
                    "[satellites]\ncn0_zenith_dbhz = 38.0\ncn0_horizon_loss_db = 6.0\n[[fades]]\nstart_s = 10.0\nend_s = {end_s}\ndb_per_s = {db_per_s}\n"
                ),
            ),
            Test::Blockage => (
                BLOCKAGE_S.1 + AFTER_BLOCKAGE_S,
                STATIC_RECEIVER.to_string(),
                format!(
                    "[[outages]]\nstart_s = {}\nend_s = {}\n",
                    BLOCKAGE_S.0, BLOCKAGE_S.1
                ),
            ),
            Test::Turn { g } => (
                TURN_START_S + TURN_S + AFTER_TURN_S,
                format!(
                    "kind = \"motion\"\nstart_llh_deg = [36.3721, 127.3604, 1000.0]\nheading_deg = 30.0\nspeed_mps = 250.0\ntransition_s = 1.0\nsegments = [\n  {{ type = \"cruise\", duration_s = {TURN_START_S:.1} }},\n  {{ type = \"turn\", duration_s = {TURN_S:.1}, accel_g = {g}, direction = \"left\" }},\n  {{ type = \"cruise\", duration_s = {AFTER_TURN_S:.1} }},\n]"
                ),
                "[satellites]\ncn0_zenith_dbhz = 45.0\ncn0_horizon_loss_db = 20.0\n".to_string(),
            ),
        };
        format!(
            "duration_s = {duration_s}\nseed = {seed}\nnav = \"builtin:brdc0010.22n\"\n[start]\nweek = 2190\ntow_s = {START_TOW_S}\n[output]\nformat = \"cf32_le\"\nfs_hz = {FS_HZ}\n[receiver]\n{receiver}\n{rest}"
        )
    }

    /// The simulator of this scenario.
    pub fn simulator(&self, seed: u64) -> anyhow::Result<Simulator> {
        let sc = Scenario::from_toml(&self.scenario_toml(seed))?;
        Ok(Simulator::new(&sc, Path::new("."))?)
    }
}

/// A static receiver in Daejeon with a receiver clock bias and drift.
const STATIC_RECEIVER: &str =
    "kind = \"static\"\nllh_deg = [36.3721, 127.3604, 80.0]\n[clock]\nbias_s = 3.0e-4\ndrift_s_s = 4.0e-8";

/// The tests of the study: the quick grid has one fade (1 dB/s) and the 10 g turn; the full one
/// a slower fade (0.5 dB/s, which the threshold measures more finely) and turns of 4 and 10 g.
pub fn tests(quick: bool) -> Vec<Test> {
    if quick {
        vec![
            Test::Fade {
                db_per_s: -1.0,
                end_s: 26.0,
            },
            Test::Blockage,
            Test::Turn { g: 10.0 },
        ]
    } else {
        vec![
            Test::Fade {
                db_per_s: -0.5,
                end_s: 42.0,
            },
            Test::Blockage,
            Test::Turn { g: 4.0 },
            Test::Turn { g: 10.0 },
        ]
    }
}

/// The simulator's truth as an INS log at [`INS_RATE_HZ`] ([`gpsrx_ins_aiding::simulate_ins`])
/// whose accelerometers are biased by [`INS_BIAS_MPS2`] on every east-north-up axis, with its
/// GPS time column.
pub fn biased_ins(sim: &Simulator) -> anyhow::Result<gpsrx_ins_aiding::InsTrack> {
    let cfg = gpsrx_ins_aiding::InsErrorConfig {
        rate_hz: INS_RATE_HZ,
        accel_bias_enu_mps2: [INS_BIAS_MPS2; 3],
        ..Default::default()
    };
    let samples = gpsrx_receiver::simulate::simulate_ins_for(sim, &cfg)?;
    Ok(gpsrx_ins_aiding::InsTrack::from_samples(samples)?)
}
