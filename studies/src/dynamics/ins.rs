//! The INS aiding: an INS made from the simulator's truth trajectory, fed to the receiver's
//! feed-forward.

use super::aiding::bias_direction_enu;
use super::params::{CLOCK_DRIFT_S_S, INS_RATE_HZ};
use gpsrx_dsp::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_ins_aiding::{simulate_ins, InsErrorConfig, InsTrack, TruthState};
use gpsrx_nav::rinex_nav::NavData;
use gpsrx_receiver::pipeline::aiding::InsFeedForward;
use gpsrx_samples::sim::Simulator;

/// An INS with accelerometer bias magnitude `b` (m/s^2, along
/// [`bias_direction_enu`]) made from the simulator's truth over `duration_s` (bias only: the
/// effect studied), as the receiver's feed-forward would use it after a fix at `t = 0`.
pub(super) fn feedforward(
    sim: &Simulator,
    nav: &NavData,
    b: f64,
    duration_s: f64,
    seed: u64,
) -> anyhow::Result<InsFeedForward> {
    let d = bias_direction_enu();
    let cfg = InsErrorConfig {
        rate_hz: INS_RATE_HZ,
        accel_bias_enu_mps2: [b * d[0], b * d[1], b * d[2]],
        seed,
        ..InsErrorConfig::default()
    };
    let env = &sim.env;
    let truth = |t: f64| {
        let s = env.trajectory.state(env.clock.true_time(t));
        TruthState {
            t_s: t,
            gps_tow_s: None,
            pos_m: s.pos_m,
            vel_mps: s.vel_mps,
        }
    };
    let samples = simulate_ins(&truth, duration_s + 0.5, &cfg)?;
    let track = InsTrack::from_samples(samples)?;
    let ff = InsFeedForward::new(track, Some(nav.clone()), Some(env.start.week), None);
    ff.set_time_origin(env.start);
    ff.set_fix(
        0.0,
        truth(0.0).pos_m,
        Some(CLOCK_DRIFT_S_S * SPEED_OF_LIGHT_MPS),
        None,
    );
    Ok(ff)
}
