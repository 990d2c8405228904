//! The background search (`search_schedule`): weak satellites found within seconds whatever
//! the number of strong ones, and no false satellite on noise; weak satellites (28-29 dB-Hz)
//! held from their first acquisition by the weak-signal pull-in and used in the fixes.

use gpsrx_receiver::pipeline::{MemorySink, ReceiverEvent};
use gpsrx_samples::sim::{Scenario, Simulator};
use num_complex::Complex32;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use std::path::Path;

const FS_HZ: f64 = 2.048e6;

/// Runs the receiver over `n` samples made by `fill(first index, buffer)`; returns the sink.
fn run(n: u64, mut fill: impl FnMut(u64, &mut Vec<Complex32>)) -> MemorySink {
    let mut rx = crate::pipeline::receiver(FS_HZ);
    let mut sink = MemorySink::new();
    let chunk = (0.1 * FS_HZ) as u64;
    let mut buf = Vec::new();
    let mut first = 0;
    while first < n {
        buf.clear();
        fill(first, &mut buf);
        rx.push(&buf, &mut sink).unwrap_or_else(|e| panic!("{e}"));
        first += chunk;
    }
    // A run that ends without a fix is an error of `finish` for some configurations: the
    // events are what is tested here.
    let _ = rx.finish(&mut sink);
    sink
}

/// Runs the receiver over the whole simulation, handed over in 0.1 s pieces.
fn run_simulation(sim: &Simulator) -> MemorySink {
    let chunk = sim.chunk_samples() as u64;
    let mut pending: Vec<Complex32> = Vec::new();
    let mut next_chunk = 0;
    run(sim.chunk_count() * chunk, |_, buf| {
        let want = (0.1 * FS_HZ) as usize;
        while pending.len() < want && next_chunk < sim.chunk_count() {
            let mut c = Vec::new();
            sim.generate_chunk(next_chunk, &mut c);
            pending.extend(c);
            next_chunk += 1;
        }
        let take = want.min(pending.len());
        buf.extend(pending.drain(..take));
    })
}

/// The PRNs acquired, with the stream time of their first acquisition.
fn acquired(sink: &MemorySink) -> Vec<(u8, f64)> {
    let mut out: Vec<(u8, f64)> = Vec::new();
    for e in &sink.events {
        if let ReceiverEvent::Acquired { prn, t_s, .. } = e {
            if !out.iter().any(|a| a.0 == *prn) {
                out.push((*prn, *t_s));
            }
        }
    }
    out
}

#[test]
fn noise_alone_gives_no_satellite_however_long_it_is_searched() {
    // 8 s of white noise, three seeds: every PRN is searched at 1 ms x 10 and 10 ms x 10 and
    // most at 10 ms x 40 within the budget, each search at its share of the run's false-alarm
    // probability (1e-5 per PRN): the chance of any false satellite in these three runs is
    // below 1e-3, so one is a defect.
    for seed in [1u64, 2, 3] {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let sink =
            run((8.0 * FS_HZ) as u64, |_, buf| {
                buf.extend((0..(0.1 * FS_HZ) as usize).map(|_| {
                    Complex32::new(rng.sample(StandardNormal), rng.sample(StandardNormal))
                }));
            });
        let found = acquired(&sink);
        assert!(found.is_empty(), "seed {seed}: false satellites {found:?}");
    }
}

#[test]
fn weak_satellites_are_found_within_seconds_beside_strong_ones() {
    // Eight satellites from 45 down to 30 dB-Hz: the 1 ms x 10 cold start finds the strong
    // ones; the background search escalates for the rest at once.
    let text = r#"
duration_s = 6.0
seed = 5
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538198.0
[output]
format = "cf32_le"
fs_hz = 2.048e6
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[satellites]
cn0 = [
  { prn = 31, dbhz = 45.0 },
  { prn = 26, dbhz = 43.0 },
  { prn = 32, dbhz = 41.0 },
  { prn = 25, dbhz = 39.0 },
  { prn = 29, dbhz = 34.0 },
  { prn = 22, dbhz = 32.0 },
  { prn = 3, dbhz = 31.0 },
  { prn = 16, dbhz = 30.0 },
]
"#;
    let sc = Scenario::from_toml(text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let sink = run_simulation(&sim);
    let found = acquired(&sink);
    let truth: Vec<u8> = sim.satellites.iter().map(|s| s.prn.get()).collect();
    for (prn, t) in &found {
        assert!(
            truth.contains(prn),
            "G{prn:02} acquired at {t:.1} s: not in the sky"
        );
    }
    for prn in [31u8, 26, 32, 25, 29, 22, 3, 16] {
        let t = found.iter().find(|f| f.0 == prn).map(|f| f.1);
        assert!(
            t.is_some_and(|t| t <= 3.0),
            "G{prn:02}: first acquired at {t:?} s (want within 3 s)"
        );
    }
}

#[test]
fn a_28_dbhz_satellite_is_acquired_held_and_used_in_the_fixes() {
    // Static antenna in Seoul, G16 at 28.5 and G03 at 29 dB-Hz beside five strong satellites:
    // the background search finds the weak ones, the weak-signal pull-in (FLL on 10 ms sums,
    // differential bit sync, bit-aligned 20 ms PLL) holds them from their first acquisition,
    // their subframes give their time, and they are used in the fixes.
    let text = r#"
duration_s = 24.0
seed = 2828
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "cf32_le"
fs_hz = 2.048e6
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[satellites]
cn0 = [
  { prn = 31, dbhz = 45.0 },
  { prn = 26, dbhz = 42.0 },
  { prn = 32, dbhz = 40.0 },
  { prn = 25, dbhz = 38.0 },
  { prn = 29, dbhz = 36.0 },
  { prn = 22, dbhz = 35.0 },
  { prn = 3, dbhz = 29.0 },
  { prn = 16, dbhz = 28.5 },
]
"#;
    let sc = Scenario::from_toml(text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let sink = run_simulation(&sim);
    let (_, truth) = sim.receiver_truth(0.0);
    for weak in [3u8, 16] {
        let acquisitions: Vec<f64> = sink
            .events
            .iter()
            .filter_map(|e| match e {
                ReceiverEvent::Acquired { prn, t_s, .. } if *prn == weak => Some(*t_s),
                _ => None,
            })
            .collect();
        let losses: Vec<f64> = sink
            .events
            .iter()
            .filter_map(|e| match e {
                ReceiverEvent::Lost { prn, t_s } if *prn == weak => Some(*t_s),
                _ => None,
            })
            .collect();
        assert_eq!(
            acquisitions.len(),
            1,
            "G{weak:02}: acquired at {acquisitions:?} s, lost at {losses:?} s"
        );
        assert!(losses.is_empty(), "G{weak:02}: lost at {losses:?} s");
        // Held: tracked with the C/N0 it has (within 2 dB) over the last 5 s (10 Hz rows).
        let cn0: Vec<f64> = sink
            .channels
            .iter()
            .filter(|r| r.prn == weak && r.t_stream_s > 19.0 && r.state == "track")
            .filter_map(|r| r.cn0_dbhz)
            .collect();
        let set = if weak == 3 { 29.0 } else { 28.5 };
        let mean = cn0.iter().sum::<f64>() / cn0.len().max(1) as f64;
        assert!(
            cn0.len() > 40 && (mean - set).abs() < 2.0,
            "G{weak:02}: {} rows, C/N0 {mean:.1} dB-Hz (set {set})",
            cn0.len()
        );
        // Used in the fixes, and those fixes land on the truth.
        let with: Vec<&gpsrx_receiver::pipeline::FixReport> = sink
            .fixes
            .iter()
            .filter(|f| f.solution.used_prns.contains(&weak))
            .collect();
        assert!(with.len() >= 20, "G{weak:02} in {} fixes", with.len());
        for f in with {
            let [x, y, z] = f.fix.ecef_m;
            let error_m = ((x - truth.pos_m[0]).powi(2)
                + (y - truth.pos_m[1]).powi(2)
                + (z - truth.pos_m[2]).powi(2))
            .sqrt();
            assert!(
                error_m < 15.0,
                "fix at {:.1} s with G{weak:02}: {error_m:.1} m off",
                f.t_stream_s
            );
        }
        eprintln!(
            "G{weak:02}: acquired at {:.2} s, C/N0 {mean:.2} dB-Hz, in fixes from {:.1} s",
            acquisitions[0],
            sink.fixes
                .iter()
                .find(|f| f.solution.used_prns.contains(&weak))
                .map_or(f64::NAN, |f| f.t_stream_s)
        );
    }
}
