//! Truth files written beside every simulated recording.
//!
//! `truth.csv`, one row per truth epoch (receiver time `t_s` since the first sample):
//! `t_s,gps_week,tow_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,ax_mps2,ay_mps2,az_mps2,lat_deg,lon_deg,h_m,clock_bias_s,clock_drift_s_s,clock_bias_m,clock_drift_mps`
//! where `gps_week`/`tow_s` is the true GPS time of that instant (receiver clock bias removed)
//! and the position is the antenna's at that true time (ECEF, WGS-84).
//!
//! `truth_sv.csv`, one row per satellite per epoch:
//! `t_s,prn,signal_on,code_phase_chips,code_rate_chips_s,carrier_phase_cycles,doppler_hz,cn0_dbhz,pseudorange_m,range_m,iono_m,tropo_m,sv_clock_s,tx_tow_s,data_bit,elevation_deg,azimuth_deg,sv_x_m,sv_y_m,sv_z_m`
//! - `code_phase_chips`: phase in [0, 1023) of the C/A code arriving at that sample;
//! - `carrier_phase_cycles`: baseband carrier phase without the IF term, `-Phi/lambda` (so its
//!   rate is the Doppler); `doppler_hz` is that rate (positive when approaching, receiver clock
//!   drift included);
//! - `pseudorange_m`: `c (t_rcv - t_sv)`, the code pseudorange a perfect receiver measures;
//! - `tx_tow_s`: SV time of transmission of that sample's code (TOW, seconds);
//! - `data_bit`: the navigation data bit (+1/-1) being received;
//! - `sv_*`: satellite position at transmission in the ECEF frame of reception.

use crate::sim::{SimError, Simulator};
use gpsrx_dsp::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::frames::Llh;
use std::io::Write;
use std::path::Path;

fn io_err(path: &Path, e: impl std::fmt::Display) -> SimError {
    SimError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Truth epochs: receiver times (s since the first sample) at the truth rate.
pub fn truth_epochs(sim: &Simulator) -> Vec<f64> {
    let rate = sim.scenario.truth.rate_hz;
    let duration = sim.total_samples() as f64 / sim.scenario.output.fs_hz;
    let n = (duration * rate + 1e-9).floor() as usize;
    (0..=n)
        .map(|i| i as f64 / rate)
        .filter(|&t| t <= duration)
        .collect()
}

/// Writes `truth.csv`.
pub fn write_receiver_truth(sim: &Simulator, path: &Path) -> Result<(), SimError> {
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(
        w,
        "t_s,gps_week,tow_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,ax_mps2,ay_mps2,az_mps2,lat_deg,lon_deg,h_m,clock_bias_s,clock_drift_s_s,clock_bias_m,clock_drift_mps"
    )
    .map_err(|e| io_err(path, e))?;
    let env = &sim.env;
    for t_rcv in truth_epochs(sim) {
        let t = env.clock.true_time(t_rcv);
        let s = env.trajectory.state(t);
        let gt = env.start.add_seconds(t);
        let llh = Llh::from_ecef(&s.pos_m);
        let b = env.clock.bias_s(t);
        let d = env.clock.drift_s_s(t);
        writeln!(
            w,
            "{t_rcv:.6},{},{:.9},{:.4},{:.4},{:.4},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.9},{:.9},{:.4},{:.12e},{:.6e},{:.4},{:.6}",
            gt.week,
            gt.tow_s,
            s.pos_m.x,
            s.pos_m.y,
            s.pos_m.z,
            s.vel_mps.x,
            s.vel_mps.y,
            s.vel_mps.z,
            s.acc_mps2.x,
            s.acc_mps2.y,
            s.acc_mps2.z,
            llh.lat_rad.to_degrees(),
            llh.lon_rad.to_degrees(),
            llh.h_m,
            b,
            d,
            b * SPEED_OF_LIGHT_MPS,
            d * SPEED_OF_LIGHT_MPS
        )
        .map_err(|e| io_err(path, e))?;
    }
    w.flush().map_err(|e| io_err(path, e))
}

/// Writes `truth_sv.csv`.
pub fn write_satellite_truth(sim: &Simulator, path: &Path) -> Result<(), SimError> {
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(
        w,
        "t_s,prn,signal_on,code_phase_chips,code_rate_chips_s,carrier_phase_cycles,doppler_hz,cn0_dbhz,pseudorange_m,range_m,iono_m,tropo_m,sv_clock_s,tx_tow_s,data_bit,elevation_deg,azimuth_deg,sv_x_m,sv_y_m,sv_z_m"
    )
    .map_err(|e| io_err(path, e))?;
    let h = 0.5e-3;
    for t in truth_epochs(sim) {
        for sat in &sim.satellites {
            let (o, slow) = sim.observe(sat, t);
            // Rates by central differences of the same model the samples come from.
            let (a, _) = sim.observe(sat, t - h);
            let (b, _) = sim.observe(sat, t + h);
            let doppler = (b.carrier_cycles - a.carrier_cycles) / (2.0 * h);
            let code_rate = (b.chips - a.chips) / (2.0 * h);
            let tx_tow = sim
                .env
                .start
                .add_seconds(t - o.pseudorange_m / SPEED_OF_LIGHT_MPS)
                .tow_s;
            let bit_index = (o.chips / super::signal::CHIPS_PER_BIT).floor().max(0.0) as usize;
            let bit = sat.bits.get(bit_index).copied().unwrap_or(1);
            let on = sim.signal_on(sat, t, slow.el_rad);
            writeln!(
                w,
                "{t:.6},{},{},{:.6},{:.6},{:.6},{:.6},{:.3},{:.4},{:.4},{:.4},{:.4},{:.12e},{:.9},{},{:.4},{:.4},{:.3},{:.3},{:.3}",
                sat.prn.get(),
                u8::from(on),
                o.chips.rem_euclid(1023.0),
                code_rate,
                o.carrier_cycles,
                doppler,
                if on { sim.cn0_dbhz(sat, slow.el_rad, t) } else { f64::NEG_INFINITY },
                o.pseudorange_m,
                o.range_m,
                slow.iono_m,
                slow.tropo_m,
                o.sv_clock_s,
                tx_tow,
                bit,
                slow.el_rad.to_degrees(),
                slow.az_rad.to_degrees().rem_euclid(360.0),
                o.sv_pos_m.x,
                o.sv_pos_m.y,
                o.sv_pos_m.z
            )
            .map_err(|e| io_err(path, e))?;
        }
    }
    w.flush().map_err(|e| io_err(path, e))
}
