//! Acquisition: a cold search of all 32 PRNs, 1 ms coherent x 10 non-coherent, Doppler +-5 kHz
//! in 500 Hz bins (21 bins), 4 MHz complex baseband (10 ms of samples), on the whole rayon pool.
//!
//! Throughput is counted in correlator cells: 32 PRNs x 21 Doppler bins x 4000 code lags x 10
//! blocks = 26.88 M cells per search. Target: one search in 100 ms or less on 2 cores.
//!
//! The same search at front-end rates that are not 4 MHz (`acquisition_rates`), throughput in
//! input samples read (10 ms): the grid runs at a fast FFT length of at most 4096 lags per ms
//! whatever the rate, so 12 to 25 MHz must cost about what 4 MHz does (target: under 300 ms).
//! `cargo run -p gpsrx-dsp --example acq_rates --release` prints the same as a table.
//! 16.3676 MHz (the GN3S sampler) has no whole number of samples per code period.
//!
//! The weak background level (`acquisition_weak`): 10 ms x 50 in one pass over +-5 kHz (201
//! bins), 4 MHz, the 20 PRNs a 12-satellite sky leaves absent.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use num_complex::Complex32;

/// 10 ms at 4 MHz: unit-variance noise (SplitMix64 + Box-Muller) and three satellites at
/// 45 dB-Hz, so the refinement after detection is part of the timing as in real use.
fn samples(n: usize, fs: f64) -> Vec<Complex32> {
    let sats = [
        (5u8, 1234.0, 1500.0),
        (12, 333.0, -2750.0),
        (30, 3900.0, 4100.0),
    ];
    gpsrx_dsp::synthetic::noisy_ca_signal(n, fs, &sats, 45.0, 42)
}

fn bench_cold_search(c: &mut Criterion) {
    let fs = 4.0e6;
    let config = AcqConfig::default();
    let engine = match AcquisitionEngine::new(fs, config) {
        Ok(e) => e,
        Err(e) => panic!("{e}"),
    };
    let x = samples(engine.samples_wanted(), fs);
    let (lo, hi) = engine.doppler_range_hz();
    let bins = ((hi - lo) / engine.doppler_step_hz()).round() as u64 + 1;
    let mut group = c.benchmark_group("acquisition");
    group.sample_size(20);
    group.throughput(Throughput::Elements(32 * bins * 4000 * 10));
    group.bench_function("cold_32prn_1msx10_pm5kHz_4MHz", |b| {
        b.iter(|| match engine.search_all(&x) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        })
    });
    group.finish();
}

fn bench_rates(c: &mut Criterion) {
    let mut group = c.benchmark_group("acquisition_rates");
    group.sample_size(10);
    for mhz in [2.6, 4.0, 12.0, 16.368, 16.3676, 20.0, 24.0] {
        let fs = mhz * 1e6;
        let engine = match AcquisitionEngine::new(fs, AcqConfig::default()) {
            Ok(e) => e,
            Err(e) => panic!("{e}"),
        };
        let x = samples(engine.samples_wanted(), fs);
        group.throughput(Throughput::Elements(engine.samples_needed() as u64));
        group.bench_function(format!("cold_32prn_1msx10_pm5kHz_{mhz}MHz"), |b| {
            b.iter(|| match engine.search_all(&x) {
                Ok(r) => r,
                Err(e) => panic!("{e}"),
            })
        });
    }
    group.finish();
}

fn bench_weak_level(c: &mut Criterion) {
    let fs = 4.0e6;
    let config = AcqConfig {
        coherent_ms: 10,
        noncoherent: 50,
        bit_edge_offsets: Some(false),
        refine_ms: 0,
        ..AcqConfig::default()
    };
    let engine = match AcquisitionEngine::new(fs, config) {
        Ok(e) => e,
        Err(e) => panic!("{e}"),
    };
    let x = samples(engine.samples_wanted(), fs);
    let targets: Vec<SearchTarget> = (13u8..=32)
        .filter_map(|p| Prn::new(p).ok())
        .map(SearchTarget::full)
        .collect();
    let mut group = c.benchmark_group("acquisition_weak");
    group.sample_size(10);
    group.throughput(Throughput::Elements(targets.len() as u64));
    group.bench_function("20prn_10msx50_one_pass_pm5kHz_4MHz", |b| {
        b.iter(|| match engine.search(&x, &targets) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        })
    });
    group.finish();
}

criterion_group!(benches, bench_cold_search, bench_rates, bench_weak_level);
criterion_main!(benches);
