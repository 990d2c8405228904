//! `gpsrx study dr`: GPS/DR integration with carrier velocity (seed 000) and the GPS/accelerometer
//! speed filter (seed 002) on a simulated 28-minute urban drive.
//!
//! - **Drive** ([`drive`]): `samples/scenarios/urban-drive.toml` tabulated by the simulator's
//!   motion model (turns, stops, hills), sampled at 50 Hz as
//!   [`gpsrx_ins_aiding::VehicleTruth`].
//! - **Sensors**: [`gpsrx_ins_aiding::simulate_dr`] (10 Hz gyro voltage and odometer pulses: a
//!   zero-rate voltage 4 mV off nominal, 2 mV noise, odometer 2 % off, and in Case 3 a gyro
//!   tilted 20 deg) and [`gpsrx_ins_aiding::simulate_accel`] (50 Hz, bias, vibration, slope).
//! - **GNSS** ([`gnss`]): the fast path: solutions simulated from the truth, positions with white
//!   noise and a Gauss-Markov bias that jumps at satellite-set changes, unbiased carrier
//!   velocities; the noise levels and set-change rates vary over eight course sections like
//!   seed 000's O-A ... G-H.
//! - **Filters** ([`fusion`], [`speed`]): [`gpsrx_ins_aiding::DrFusion`] proposed 8-state
//!   (position + velocity updates) and conventional 4-state (position only), closed loop from
//!   the nominal sensor parameters; [`gpsrx_ins_aiding::SpeedFilter`] after
//!   [`gpsrx_ins_aiding::AccelSmoother`] against [`gpsrx_ins_aiding::HoldLastSpeed`].
//! - **Cases** ([`cases`]): Case 1 per-section error statistics; Case 2 outages of 60-120 s
//!   five seconds after a satellite-set change, several placements and seeds; Case 3 the tilted
//!   gyro's scale-factor estimate (45.045 / cos 20 deg = 47.936 deg/s/V); the speed filter through
//!   20-60 s gaps.
//!
//! `study.json` carries `case2_outage_error_ratio` (proposed / conventional mean error over the
//! outages, pooled), `case3_gyro_scale_final_dps_per_v` and `speed_gap_rms_ratio` (filter /
//! hold, RMS pooled over all gaps and seeds).

pub mod cases;
mod conclusions;
#[cfg(test)]
mod conclusions_tests;
pub mod drive;
pub mod fusion;
pub mod gnss;
pub mod hilly;
pub mod params;
mod plots;
pub mod speed;
pub mod stats;
mod summary;
mod tables;

use super::report::StudyReport;
use super::{run_cases, CommonStudyArgs};
use cases::{outage_placements, run_job, Job};
use drive::Drive;
use gnss::set_change_times;
use params::{OUTAGE_PLACEMENTS, OUTAGE_PLACEMENTS_QUICK, OUTAGE_SEEDS};
use std::time::Instant;

/// `gpsrx study dr` options.
#[derive(Debug, Clone, clap::Args)]
pub struct DrArgs {
    /// Options every study has.
    #[command(flatten)]
    pub common: CommonStudyArgs,
}

/// The jobs of a run: Cases 1 and 3 and the speed filter on the first seed (the speed filter on
/// every seed of a full run), Case 2 over the placements and seeds.
pub fn jobs(drive: &Drive, seed: u64, quick: bool) -> Vec<Job> {
    let seeds: Vec<u64> = if quick {
        vec![seed]
    } else {
        (0..OUTAGE_SEEDS).map(|k| seed + k).collect()
    };
    let n = if quick {
        OUTAGE_PLACEMENTS_QUICK
    } else {
        OUTAGE_PLACEMENTS
    };
    let placements = outage_placements(&set_change_times(drive.duration_s), drive.duration_s, n);
    let mut jobs = vec![Job::Case1 { seed }, Job::Case3 { seed }];
    for &s in &seeds {
        jobs.push(Job::Speed {
            seed: s,
            hilly: true,
        });
        jobs.push(Job::Speed {
            seed: s,
            hilly: false,
        });
        for (placement, &(change_s, len_s)) in placements.iter().enumerate() {
            jobs.push(Job::Case2 {
                seed: s,
                placement,
                change_s,
                len_s,
            });
        }
    }
    jobs
}

/// Runs the study.
pub fn run(args: &DrArgs, progress: bool) -> anyhow::Result<StudyReport> {
    let started = Instant::now();
    let drive = Drive::urban(None)?;
    let hilly = Drive::hilly()?;
    let jobs = jobs(&drive, args.common.seed, args.common.quick);
    let results = run_cases(&jobs, "dr", progress, |j| run_job(&drive, &hilly, j))
        .into_iter()
        .collect::<anyhow::Result<Vec<_>>>()?;
    summary::build_report(
        args,
        &drive,
        &hilly,
        &results,
        started.elapsed().as_secs_f64(),
    )
}
