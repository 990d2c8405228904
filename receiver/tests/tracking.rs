//! Tracking channels on simulated recordings, against the simulator's truth.

use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_receiver::pipeline::tracker::track;
use gpsrx_samples::sim::{Scenario, SimSatellite, Simulator};
use gpsrx_samples::{open_source, SourceConfig};
use gpsrx_tracking::{Channel, ChannelConfig, ChannelEpoch, ChannelStart, ChannelState};
use std::collections::BTreeMap;
use std::path::Path;

fn simulate(extra: &str, duration_s: f64, dir: &Path) -> (Simulator, std::path::PathBuf) {
    let text = format!(
        r#"
duration_s = {duration_s}
seed = 21
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci8"
fs_hz = 2.6e6
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[clock]
bias_s = 1.0e-4
drift_s_s = 3.0e-8
[truth]
rate_hz = 10.0
{extra}
"#
    );
    let sc = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let report = sim.run(dir, &|_| {}).unwrap_or_else(|e| panic!("{e}"));
    (sim, report.data_path)
}

/// A channel start from truth: the first code period after sample 0, Doppler off by `df`.
fn start_from_truth(sim: &Simulator, sat: &SimSatellite, fs: f64, df: f64) -> ChannelStart {
    let (o, _) = sim.observe(sat, 0.0);
    let (o2, _) = sim.observe(sat, 1e-3);
    let rate = (o2.chips - o.chips) / 1e-3;
    let to_start = (1023.0 - o.chips.rem_euclid(1023.0)) / rate * fs;
    let doppler = (o2.carrier_cycles - o.carrier_cycles) / 1e-3;
    ChannelStart {
        prn: sat.prn,
        code_start_sample: to_start.round() as u64,
        doppler_hz: doppler + df,
    }
}

fn run(
    sim: &Simulator,
    data: &Path,
    cfg: &ChannelConfig,
    df: f64,
) -> BTreeMap<u8, Vec<ChannelEpoch>> {
    let fs = 2.6e6;
    let channels: Vec<Channel> = sim
        .satellites
        .iter()
        .map(|s| {
            Channel::new(&start_from_truth(sim, s, fs, df), fs, cfg)
                .unwrap_or_else(|e| panic!("{e}"))
        })
        .collect();
    let mut src =
        open_source(&SourceConfig::new(data.to_path_buf())).unwrap_or_else(|e| panic!("{e}"));
    let mut epochs: BTreeMap<u8, Vec<ChannelEpoch>> = BTreeMap::new();
    track(src.as_mut(), channels, |e| {
        epochs.entry(e.prn).or_default().push(*e)
    })
    .unwrap_or_else(|e| panic!("{e}"));
    epochs
}

#[test]
fn channels_lock_and_follow_truth() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (sim, data) = simulate(
        "[satellites]\nprns = [16, 26, 31, 32]\ncn0 = [{ prn = 16, dbhz = 45.0 }, { prn = 26, dbhz = 40.0 }, { prn = 31, dbhz = 35.0 }, { prn = 32, dbhz = 48.0 }]",
        4.0,
        dir.path(),
    );
    let cfg = ChannelConfig::default();
    // Start 80 Hz off the true Doppler: the FLL-assisted pull-in must absorb it.
    let epochs = run(&sim, &data, &cfg, 80.0);
    for sat in &sim.satellites {
        let prn = sat.prn.get();
        let eps = epochs
            .get(&prn)
            .unwrap_or_else(|| panic!("no epochs for {prn}"));
        let last = eps.last().unwrap_or_else(|| panic!("no epochs"));
        assert_eq!(
            last.state,
            ChannelState::Track,
            "G{prn} did not reach tracking"
        );
        assert!(last.pll_lock, "G{prn} not phase locked at the end");
        // C/N0: NWPR over 1 s, within 1 dB of the configured value (the issue's requirement
        // from 30 to 50 dB-Hz); 8-bit quantisation costs < 0.05 dB.
        let cn0_set = match prn {
            16 => 45.0,
            26 => 40.0,
            31 => 35.0,
            _ => 48.0,
        };
        assert!(
            (last.cn0_dbhz - cn0_set).abs() < 1.0,
            "G{prn}: C/N0 {:.2} vs {cn0_set}",
            last.cn0_dbhz
        );
        // After the first 2 s: code phase and Doppler against truth at each epoch's first sample.
        let mut dphi = Vec::new();
        for e in eps.iter().filter(|e| e.t_rx_s > 2.0) {
            let (o, _) = sim.observe(sat, e.t_rx_s);
            let (o2, _) = sim.observe(sat, e.t_rx_s + 1e-3);
            let truth_cp = o.chips.rem_euclid(1023.0);
            let mut dcp = e.code_phase_chips - truth_cp;
            if dcp > 511.5 {
                dcp -= 1023.0;
            } else if dcp < -511.5 {
                dcp += 1023.0;
            }
            // DLL jitter at 35 dB-Hz, Bn 1 Hz, d = 1, T = 1 ms: sigma = 0.016 chip; 0.1 chip is
            // over 6 sigma at the weakest.
            assert!(
                dcp.abs() < 0.1,
                "G{prn} t {:.3}: code error {dcp:.4} chip",
                e.t_rx_s
            );
            let truth_doppler = (o2.carrier_cycles - o.carrier_cycles) / 1e-3;
            assert!(
                (e.doppler_hz - truth_doppler).abs() < 15.0,
                "G{prn} t {:.3}: Doppler {:.2} vs {truth_doppler:.2}",
                e.t_rx_s,
                e.doppler_hz
            );
            dphi.push(e.carrier_phase_cycles - o.carrier_cycles);
        }
        // Carrier phase: the replica's accumulated phase follows the truth up to a constant
        // (and the Costas half-cycle ambiguity): the difference must not drift or slip.
        let mean = dphi.iter().sum::<f64>() / dphi.len() as f64;
        let max_dev = dphi.iter().map(|d| (d - mean).abs()).fold(0.0, f64::max);
        assert!(
            max_dev < 0.2,
            "G{prn}: carrier phase wanders {max_dev:.3} cycles from truth"
        );
        let _ = CA_CHIP_RATE_HZ;
    }
}

#[test]
fn bit_edges_and_bits_match_truth() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (sim, data) = simulate(
        "[satellites]\nprns = [26, 29]\ncn0_all_dbhz = 40.0",
        3.0,
        dir.path(),
    );
    let epochs = run(&sim, &data, &ChannelConfig::default(), 0.0);
    for sat in &sim.satellites {
        let prn = sat.prn.get();
        let eps = &epochs[&prn];
        let bits: Vec<_> = eps.iter().filter_map(|e| e.bit).collect();
        assert!(bits.len() >= 100, "G{prn}: only {} bits", bits.len());
        let mut agree = 0usize;
        let mut disagree = 0usize;
        for b in &bits {
            // The bit's leading edge must be a truth bit edge: truth chips at that time are a
            // multiple of 20460 (within a sample).
            let (o, _) = sim.observe(sat, b.t_s);
            let frac = o.chips.rem_euclid(20460.0);
            let dist = frac.min(20460.0 - frac);
            assert!(
                dist < 1.0,
                "G{prn}: bit at {:.4} s is {dist:.2} chips from a truth edge",
                b.t_s
            );
            let (mid, _) = sim.observe(sat, b.t_s + 0.01);
            let idx = (mid.chips / 20460.0).floor() as usize;
            let truth_bit = sat.bits[idx];
            if truth_bit == b.value {
                agree += 1
            } else {
                disagree += 1
            }
        }
        // Costas ambiguity: all bits agree, or all are inverted.
        assert!(
            agree == 0 || disagree == 0,
            "G{prn}: {agree} agree, {disagree} disagree"
        );
    }
}

#[test]
#[ignore]
fn debug_print() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (sim, data) = simulate("[satellites]\nprns = [16, 26, 31, 32]\ncn0 = [{ prn = 16, dbhz = 45.0 }, { prn = 26, dbhz = 40.0 }, { prn = 31, dbhz = 35.0 }, { prn = 32, dbhz = 48.0 }]", 4.0, dir.path());
    let epochs = run(&sim, &data, &ChannelConfig::default(), 80.0);
    let sat = &sim.satellites[0];
    for e in epochs[&16].iter().step_by(200) {
        let (o, _) = sim.observe(sat, e.t_rx_s);
        eprintln!("t {:.4} st {:?} cp {:.3} truth {:.3} dop {:.1} P {:.0},{:.0} E {:.0} L {:.0} cn0 {:.1} lock {}", e.t_rx_s, e.state, e.code_phase_chips, o.chips.rem_euclid(1023.0), e.doppler_hz, e.prompt.re, e.prompt.im, e.early.norm(), e.late.norm(), e.cn0_dbhz, e.pll_lock);
    }
}
