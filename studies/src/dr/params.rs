//! The experiment's fixed parameters: rates, the GNSS error model by course section, the DR and
//! accelerometer sensor errors, and where the outages and speed gaps go.

/// Vehicle truth rate fed to the sensor models, Hz (the motion table is integrated at 10 ms).
pub const TRUTH_RATE_HZ: f64 = 50.0;
/// Motion table step, s.
pub const TABLE_STEP_S: f64 = 0.01;
/// DR (gyro + odometer) rate, Hz (seed 000's sensors were read at 10 Hz).
pub const DR_RATE_HZ: f64 = 10.0;
/// Accelerometer rate, Hz (seed 002: 58.77 Hz).
pub const ACCEL_RATE_HZ: f64 = 50.0;
/// GNSS solution rate, Hz.
pub const GNSS_RATE_HZ: f64 = 1.0;
/// Speed above which the filters start (heading from the GNSS course), m/s.
pub const START_SPEED_MPS: f64 = 3.0;

/// GNSS velocity noise per horizontal axis (carrier-based, unbiased), m/s.
pub const GNSS_VEL_SIGMA_MPS: f64 = 0.05;
/// GNSS vertical velocity noise, m/s (only the speed filter's 3-D speed uses it).
pub const GNSS_VEL_UP_SIGMA_MPS: f64 = 0.1;
/// Correlation time of the GNSS position bias between satellite-set changes, s.
pub const BIAS_TAU_S: f64 = 300.0;

/// One course section (seed 000 drove O-A-...-H through tree-lined roads, open roads and
/// apartment blocks): its GNSS error model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Name, e.g. `"A-B"`.
    pub name: &'static str,
    /// What the road is like.
    pub environment: &'static str,
    /// White position noise per horizontal axis, m.
    pub white_sigma_m: f64,
    /// Standard deviation of the slowly varying position bias per axis, m (Gauss-Markov,
    /// [`BIAS_TAU_S`]); it jumps to a new draw at every satellite-set change.
    pub bias_sigma_m: f64,
    /// Time between satellite-set changes, s.
    pub set_change_every_s: f64,
    /// Signal blockages (buildings, foliage): one of `blockage_s` every `blockage_every_s`
    /// (0: none), in every case.
    pub blockage_every_s: f64,
    /// Length of each blockage, s.
    pub blockage_s: f64,
}

/// The eight sections, each an eighth of the drive.
pub const SECTIONS: [Section; 8] = [
    Section {
        name: "O-A",
        environment: "open road",
        white_sigma_m: 2.0,
        bias_sigma_m: 3.0,
        set_change_every_s: 150.0,
        blockage_every_s: 0.0,
        blockage_s: 0.0,
    },
    Section {
        name: "A-B",
        environment: "tree-lined road",
        white_sigma_m: 3.0,
        bias_sigma_m: 5.0,
        set_change_every_s: 60.0,
        blockage_every_s: 90.0,
        blockage_s: 8.0,
    },
    Section {
        name: "B-C",
        environment: "open road",
        white_sigma_m: 2.0,
        bias_sigma_m: 3.0,
        set_change_every_s: 150.0,
        blockage_every_s: 0.0,
        blockage_s: 0.0,
    },
    Section {
        name: "C-D",
        environment: "open road",
        white_sigma_m: 2.0,
        bias_sigma_m: 3.0,
        set_change_every_s: 150.0,
        blockage_every_s: 0.0,
        blockage_s: 0.0,
    },
    Section {
        name: "D-E",
        environment: "apartment blocks",
        white_sigma_m: 3.0,
        bias_sigma_m: 6.0,
        set_change_every_s: 45.0,
        blockage_every_s: 60.0,
        blockage_s: 15.0,
    },
    Section {
        name: "E-F",
        environment: "tree-lined road",
        white_sigma_m: 3.0,
        bias_sigma_m: 5.0,
        set_change_every_s: 60.0,
        blockage_every_s: 90.0,
        blockage_s: 8.0,
    },
    Section {
        name: "F-G",
        environment: "apartment blocks",
        white_sigma_m: 3.0,
        bias_sigma_m: 6.0,
        set_change_every_s: 45.0,
        blockage_every_s: 60.0,
        blockage_s: 15.0,
    },
    Section {
        name: "G-H",
        environment: "open road",
        white_sigma_m: 2.0,
        bias_sigma_m: 3.0,
        set_change_every_s: 150.0,
        blockage_every_s: 0.0,
        blockage_s: 0.0,
    },
];

/// Nominal gyro zero-rate voltage error the filters start with: the true `V_nom` is this much
/// above the nominal 2.5 V, V (a gyro bias of 0.18 deg/s at 45.045 deg/s/V).
pub const GYRO_BIAS_OFFSET_V: f64 = 0.004;
/// White noise on each 10 Hz row's mean gyro voltage, V (0.09 deg/s).
pub const GYRO_NOISE_V: f64 = 0.002;
/// Nominal odometer scale factor, m/pulse (an ABS wheel-speed sensor).
pub const SF_N_M_PER_PULSE: f64 = 0.02;
/// Odometer scale error (tyre 2 % smaller than nominal).
pub const ODO_SCALE_ERROR: f64 = 0.02;
/// Case 3's gyro mounting tilt, deg.
pub const CASE3_TILT_DEG: f64 = 20.0;

/// Accelerometer bias, m/s^2 (on top of the slope term `g sin(pitch)`).
pub const ACCEL_BIAS_MPS2: f64 = 0.1;
/// Accelerometer vibration noise (white at 50 Hz), m/s^2.
pub const ACCEL_VIBRATION_MPS2: f64 = 0.3;
/// GNSS speed noise fed to the speed filter (3-D speed from the carrier velocity), m/s.
pub const GNSS_SPEED_SIGMA_MPS: f64 = 0.1;

/// Case 2: an outage starts this long after a satellite-set change, s.
pub const OUTAGE_DELAY_S: f64 = 5.0;
/// Case 2 outage lengths, cycled over the placements, s.
pub const OUTAGE_LENGTHS_S: [f64; 3] = [60.0, 90.0, 120.0];
/// Case 2: the earliest satellite-set change an outage may follow (the proposed filter needs
/// a few minutes of turns to calibrate), s.
pub const OUTAGE_EARLIEST_S: f64 = 400.0;
/// Case 2 placements (full run): every `k`-th satellite-set change after
/// [`OUTAGE_EARLIEST_S`], so the outages spread over the drive.
pub const OUTAGE_PLACEMENTS: usize = 8;
/// Case 2 placements with `--quick`.
pub const OUTAGE_PLACEMENTS_QUICK: usize = 3;
/// Case 2 noise seeds per placement (full run).
pub const OUTAGE_SEEDS: u64 = 8;

/// Speed-filter gaps: lengths cycled over the drive, s (seed 002 removed windows of ~34 s).
pub const GAP_LENGTHS_S: [f64; 5] = [20.0, 30.0, 40.0, 50.0, 60.0];
/// Speed-filter gaps: GNSS speed between gaps (the filter re-learns the slope), s.
pub const GAP_SPACING_S: f64 = 60.0;
/// The first gap starts here, s.
pub const GAP_FIRST_S: f64 = 60.0;
/// The whole set of gaps is repeated shifted by each of these, s: where a gap falls relative to
/// the hills and the speed changes decides who wins it, so the placements are swept rather than
/// chosen.
pub const GAP_PHASES_S: [f64; 4] = [0.0, 15.0, 30.0, 45.0];
