//! Wall time of a 32-PRN cold search (1 ms coherent x 10 non-coherent, Doppler +-5 kHz in
//! 500 Hz bins) at front-end sampling rates from 2.048 to 25 MHz, on the whole rayon pool:
//! `cargo run -p gpsrx-dsp --example acq_rates --release [-- RATE_MHZ ...]`.
//!
//! Per rate: the engine build time, the median of 7 searches (after one untimed search that
//! warms the scratch pools), ns per input sample read (`samples_needed`), and the satellites
//! found of the three simulated (45 dB-Hz).

use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine};
use gpsrx_dsp::{CaCode, Prn};
use num_complex::Complex32;
use std::time::Instant;

fn samples(n: usize, fs: f64) -> Vec<Complex32> {
    let mut state = 42u64;
    let mut uniform = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (((z ^ (z >> 31)) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut x: Vec<Complex32> = (0..n)
        .map(|_| {
            let r = (-uniform().ln()).sqrt();
            let t = 2.0 * std::f64::consts::PI * uniform();
            Complex32::new((r * t.cos()) as f32, (r * t.sin()) as f32)
        })
        .collect();
    let amp = (10f64.powf(4.5) / fs).sqrt();
    for (prn, delay_ms, dop) in [
        (5u8, 0.3085, 1500.0),
        (12, 0.08325, -2750.0),
        (30, 0.975, 4100.0),
    ] {
        let Ok(prn) = Prn::new(prn) else { continue };
        let code = CaCode::new(prn);
        let delay = delay_ms * 1e-3 * fs;
        for (k, v) in x.iter_mut().enumerate() {
            let chip = ((k as f64 - delay) * 1.023e6 / fs).rem_euclid(1023.0) as usize;
            let ph = 2.0 * std::f64::consts::PI * dop * k as f64 / fs;
            let a = amp * f64::from(code.chip(chip));
            *v += Complex32::new((a * ph.cos()) as f32, (a * ph.sin()) as f32);
        }
    }
    x
}

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse::<f64>().ok())
        .collect();
    // ACQ_REFINE_MS=0 times the grid search alone.
    let refine_ms = std::env::var("ACQ_REFINE_MS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(AcqConfig::default().refine_ms);
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
        for _ in 0..7 {
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
