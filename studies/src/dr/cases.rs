//! The study's jobs (Case 1, Case 2 per placement and seed, Case 3, the speed filter per seed),
//! each self-contained: it simulates its GNSS solutions and sensor logs from the shared drive
//! and runs the filters. Jobs run in parallel ([`crate::run_cases`]).

use super::drive::Drive;
use super::fusion::{run_fusion, FusionRun};
use super::gnss::{blockages, section_span, simulate_gnss};
use super::params::{
    ACCEL_BIAS_MPS2, ACCEL_RATE_HZ, ACCEL_VIBRATION_MPS2, CASE3_TILT_DEG, DR_RATE_HZ, GAP_PHASES_S,
    GYRO_BIAS_OFFSET_V, GYRO_NOISE_V, ODO_SCALE_ERROR, OUTAGE_DELAY_S, OUTAGE_EARLIEST_S,
    OUTAGE_LENGTHS_S, SECTIONS, SF_N_M_PER_PULSE,
};
use super::speed::{gap_results, gap_windows, run_speed, GapResult, SpeedRun};
use super::stats::mean_var;
use anyhow::Context;
use gpsrx_ins_aiding::{
    simulate_accel, simulate_dr, AccelSensorConfig, DrSensorConfig, SEED000_SF_G_DPS_PER_V,
};

/// The DR sensors of every case: seed 000's gyro (45.045 deg/s/V nominal) with a zero-rate
/// voltage offset and noise, a 2 % odometer scale error; `tilt_deg` for Case 3.
pub fn dr_config(tilt_deg: f64, seed: u64) -> DrSensorConfig {
    DrSensorConfig {
        rate_hz: DR_RATE_HZ,
        raw: true,
        sf_g_dps_per_v: SEED000_SF_G_DPS_PER_V,
        v_nom_v: 2.5,
        gyro_bias_offset_v: GYRO_BIAS_OFFSET_V,
        gyro_tilt_deg: tilt_deg,
        gyro_noise_v: GYRO_NOISE_V,
        sf_n_m_per_pulse: SF_N_M_PER_PULSE,
        odo_scale_error: ODO_SCALE_ERROR,
        seed: seed.wrapping_mul(7919).wrapping_add(1),
    }
}

/// The accelerometer: bias and vibration (the slope term comes from the truth).
pub fn accel_config(seed: u64) -> AccelSensorConfig {
    AccelSensorConfig {
        rate_hz: ACCEL_RATE_HZ,
        bias_mps2: ACCEL_BIAS_MPS2,
        vibration_noise_mps2: ACCEL_VIBRATION_MPS2,
        seed: seed.wrapping_mul(104_729).wrapping_add(3),
    }
}

/// One job.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Job {
    /// Case 1: normal sensors, no outage.
    Case1 { seed: u64 },
    /// Case 2: one outage of `len_s` starting [`OUTAGE_DELAY_S`] after the satellite-set change
    /// at `change_s`.
    Case2 {
        seed: u64,
        placement: usize,
        change_s: f64,
        len_s: f64,
    },
    /// Case 3: the gyro tilted by [`CASE3_TILT_DEG`].
    Case3 { seed: u64 },
    /// The speed filter through the gaps, on the urban drive or on seed 002's hilly road.
    Speed { seed: u64, hilly: bool },
}

/// Statistics of one course section.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionStats {
    /// Section index in [`SECTIONS`] (or `SECTIONS.len()` for the whole drive).
    pub index: usize,
    /// Span, s.
    pub span: (f64, f64),
    /// Mean and variance of the proposed filter's error, m, m^2.
    pub proposed: (f64, f64),
    /// The conventional filter's.
    pub conventional: (f64, f64),
    /// GNSS alone.
    pub gnss: (f64, f64),
}

/// Mean errors over one outage.
#[derive(Debug, Clone, PartialEq)]
pub struct OutageStats {
    /// Seed.
    pub seed: u64,
    /// Placement index.
    pub placement: usize,
    /// The satellite-set change before it, s.
    pub change_s: f64,
    /// Outage window, s.
    pub window: (f64, f64),
    /// Mean and variance of the proposed filter's error over the outage, m, m^2.
    pub proposed: (f64, f64),
    /// The conventional filter's.
    pub conventional: (f64, f64),
    /// Errors at the end of the outage, m (proposed, conventional).
    pub final_m: (f64, f64),
}

impl OutageStats {
    /// Proposed / conventional mean error.
    pub fn ratio(&self) -> f64 {
        self.proposed.0 / self.conventional.0
    }
}

/// What a job produced.
#[derive(Debug, Clone)]
pub enum JobResult {
    /// Case 1 or 3: the run and its per-section statistics (last entry: whole drive).
    Drive {
        /// Which case (1 or 3).
        case: u8,
        /// The run.
        run: FusionRun,
        /// Sections, then the whole drive.
        sections: Vec<SectionStats>,
    },
    /// Case 2: one outage.
    Outage {
        /// The statistics.
        stats: OutageStats,
        /// The run (kept for the plot of the first placement).
        run: FusionRun,
    },
    /// The speed filter.
    Speed {
        /// Seed.
        seed: u64,
        /// On the hilly road (else the urban drive).
        hilly: bool,
        /// Per-gap results.
        gaps: Vec<GapResult>,
        /// The run.
        run: SpeedRun,
    },
}

fn section_stats(drive: &Drive, run: &FusionRun) -> Vec<SectionStats> {
    let start = run.t_s.first().copied().unwrap_or(0.0);
    (0..=SECTIONS.len())
        .map(|k| {
            let span = if k == SECTIONS.len() {
                (start, drive.duration_s + 1.0)
            } else {
                section_span(k, drive.duration_s)
            };
            let s = |v: &[f64]| mean_var(&run.t_s, v, span.0, span.1);
            SectionStats {
                index: k,
                span,
                proposed: s(&run.err_proposed_m),
                conventional: s(&run.err_conventional_m),
                gnss: s(&run.err_gnss_m),
            }
        })
        .collect()
}

/// Case 2 placements: `n` satellite-set changes spread evenly over those after
/// [`OUTAGE_EARLIEST_S`] that leave room for the longest outage and 30 s after it.
pub fn outage_placements(set_changes_s: &[f64], duration_s: f64, n: usize) -> Vec<(f64, f64)> {
    let longest = OUTAGE_LENGTHS_S.iter().fold(0.0f64, |a, &b| a.max(b));
    let cands: Vec<f64> = set_changes_s
        .iter()
        .copied()
        .filter(|&t| t >= OUTAGE_EARLIEST_S && t + OUTAGE_DELAY_S + longest + 30.0 <= duration_s)
        .collect();
    if cands.is_empty() || n == 0 {
        return Vec::new();
    }
    let n = n.min(cands.len());
    (0..n)
        .map(|i| {
            let idx = if n == 1 {
                0
            } else {
                i * (cands.len() - 1) / (n - 1)
            };
            (cands[idx], OUTAGE_LENGTHS_S[i % OUTAGE_LENGTHS_S.len()])
        })
        .collect()
}

/// Runs one job on the urban drive (or, for a hilly speed job, on `hilly`).
pub fn run_job(drive: &Drive, hilly: &Drive, job: &Job) -> anyhow::Result<JobResult> {
    let (seed, drive) = match *job {
        Job::Case1 { seed } | Job::Case3 { seed } | Job::Case2 { seed, .. } => (seed, drive),
        Job::Speed { seed, hilly: h } => (seed, if h { hilly } else { drive }),
    };
    let gnss = simulate_gnss(drive, seed);
    match *job {
        Job::Case1 { .. } | Job::Case3 { .. } => {
            let (case, tilt) = if matches!(job, Job::Case1 { .. }) {
                (1, 0.0)
            } else {
                (3, CASE3_TILT_DEG)
            };
            let cfg = dr_config(tilt, seed);
            let dr = simulate_dr(&drive.truth, &cfg).context("DR sensor simulation")?;
            let run = run_fusion(
                drive,
                &gnss,
                &dr,
                cfg.nominal_params(),
                &blockages(drive.duration_s),
                drive.duration_s,
            )?;
            let sections = section_stats(drive, &run);
            Ok(JobResult::Drive {
                case,
                run,
                sections,
            })
        }
        Job::Case2 {
            placement,
            change_s,
            len_s,
            ..
        } => {
            let cfg = dr_config(0.0, seed);
            let dr = simulate_dr(&drive.truth, &cfg).context("DR sensor simulation")?;
            let window = (change_s + OUTAGE_DELAY_S, change_s + OUTAGE_DELAY_S + len_s);
            let end = (window.1 + 30.0).min(drive.duration_s);
            let mut outages = blockages(drive.duration_s);
            outages.push(window);
            let run = run_fusion(drive, &gnss, &dr, cfg.nominal_params(), &outages, end)?;
            let mv = |v: &[f64]| mean_var(&run.t_s, v, window.0, window.1);
            let last = run
                .t_s
                .iter()
                .rposition(|&t| t < window.1)
                .context("no epoch in the outage")?;
            let stats = OutageStats {
                seed,
                placement,
                change_s,
                window,
                proposed: mv(&run.err_proposed_m),
                conventional: mv(&run.err_conventional_m),
                final_m: (run.err_proposed_m[last], run.err_conventional_m[last]),
            };
            Ok(JobResult::Outage { stats, run })
        }
        Job::Speed { hilly, .. } => {
            let accel =
                simulate_accel(&drive.truth, &accel_config(seed)).context("accelerometer")?;
            let mut gaps = Vec::new();
            let mut first_run = None;
            for &phase in &GAP_PHASES_S {
                let windows = gap_windows(drive.duration_s, phase);
                let run = run_speed(drive, &gnss, &accel, &windows)?;
                gaps.extend(gap_results(drive, &run, &windows));
                first_run.get_or_insert(run);
            }
            let run = first_run.unwrap_or_default();
            Ok(JobResult::Speed {
                seed,
                hilly,
                gaps,
                run,
            })
        }
    }
}
