//! Wall time of a 32-PRN cold search (1 ms coherent x 10 non-coherent, Doppler +-5 kHz in
//! 500 Hz bins) at front-end sampling rates from 2.048 to 25 MHz, on the whole rayon pool:
//! `cargo run -p gpsrx-dsp --example acq_rates --release [-- RATE_MHZ ...]`.
//!
//! Per rate: the engine build time, the median of 7 searches (after one untimed search that
//! warms the scratch pools), ns per input sample read (`samples_needed`), and the satellites
//! found of the three simulated (45 dB-Hz).

use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine};
use num_complex::Complex32;
use std::time::Instant;

fn samples(n: usize, fs: f64) -> Vec<Complex32> {
    let sats = [
        (5u8, 0.3085, 1500.0),
        (12, 0.08325, -2750.0),
        (30, 0.975, 4100.0),
    ]
    .map(|(prn, delay_ms, dop)| (prn, delay_ms * 1e-3 * fs, dop));
    gpsrx_dsp::synthetic::noisy_ca_signal(n, fs, &sats, 45.0, 42)
}

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse::<f64>().ok())
        .collect();
    // ACQ_REFINE_MS=0 times the grid search alone; ACQ_COHERENT_MS, ACQ_NONCOHERENT and
    // ACQ_BIT_EDGES=0 time another search (e.g. the background levels: 10, 50, 0);
    // ACQ_RUNS the number of timed searches (7).
    let env = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<u32>().ok());
    let base = AcqConfig::default();
    let refine_ms = env("ACQ_REFINE_MS").unwrap_or(base.refine_ms);
    let coherent_ms = env("ACQ_COHERENT_MS").unwrap_or(base.coherent_ms);
    let noncoherent = env("ACQ_NONCOHERENT").unwrap_or(base.noncoherent);
    let bit_edge_offsets = env("ACQ_BIT_EDGES").map(|b| b != 0);
    let runs = env("ACQ_RUNS").unwrap_or(7).max(1) as usize;
    let rates = if args.is_empty() {
        vec![2.048, 2.6, 4.0, 5.0, 12.0, 16.368, 20.0, 24.0, 25.0]
    } else {
        args
    };
    println!(
        "threads {}\n{:>8} {:>9} {:>10} {:>10} {:>8} {:>6}",
        rayon::current_num_threads(),
        "fs MHz",
        "new ms",
        "search ms",
        "ns/sample",
        "found",
        "spc"
    );
    for mhz in rates {
        let fs = mhz * 1e6;
        let t = Instant::now();
        let engine = match AcquisitionEngine::new(
            fs,
            AcqConfig {
                refine_ms,
                coherent_ms,
                noncoherent,
                bit_edge_offsets,
                ..AcqConfig::default()
            },
        ) {
            Ok(e) => e,
            Err(e) => panic!("{e}"),
        };
        let new_ms = t.elapsed().as_secs_f64() * 1e3;
        let x = samples(engine.samples_wanted(), fs);
        let run = || match engine.search_all(&x) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        };
        run();
        let mut times = Vec::new();
        let mut found = 0;
        for _ in 0..runs {
            let t = Instant::now();
            let r = run();
            times.push(t.elapsed().as_secs_f64() * 1e3);
            found = r.iter().filter(|r| r.detected).count();
        }
        times.sort_by(f64::total_cmp);
        let med = times[times.len() / 2];
        let ns = med * 1e6 / engine.samples_needed() as f64;
        println!(
            "{mhz:>8.3} {new_ms:>9.1} {med:>10.1} {ns:>10.1} {found:>8} {:>6.2}",
            fs / 1.023e6
        );
    }
}
