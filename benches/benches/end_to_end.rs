//! End to end: the receiver library as `gpsrx run` drives it (file -> acquisition -> 12 tracking channels with re-acquisition
//! -> navigation data -> observables -> outputs) on 3 s of the built-in 4 MHz ci8
//! 12-satellite scenario (`samples/scenarios/static-seoul-4msps.toml`), simulated once into a
//! temporary directory before timing. Throughput is counted in input samples (12 M per
//! iteration); real time is 4 Msamples/s, so the real-time factor is throughput / 4e6.
//! `gpsrx bench` measures the full 60 s recording the same way.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gpsrx_receiver::output::FileSink;
use gpsrx_receiver::simulate::simulate;
use gpsrx_receiver::{Assistance, Receiver, ReceiverConfig};
use gpsrx_samples::sim::Scenario;
use gpsrx_samples::{open_source, SourceConfig};
use std::path::Path;

const SEOUL_SCENARIO_TOML: &str = include_str!("../../samples/scenarios/static-seoul-4msps.toml");

/// Recording length, s.
const DURATION_S: f64 = 3.0;

fn bench_run(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let mut scenario = Scenario::from_toml(SEOUL_SCENARIO_TOML).unwrap_or_else(|e| panic!("{e}"));
    scenario.nav = "builtin:brdc0010.22n".into();
    scenario.duration_s = DURATION_S;
    let (sim, _) = simulate(&scenario, Path::new(""), dir.path(), &|_| ())
        .unwrap_or_else(|e| panic!("{}", gpsrx_receiver::error_message(&e)));
    let mut config = ReceiverConfig::default();
    config.run.week = Some(scenario.start_time().unwrap_or_else(|e| panic!("{e}")).week);
    let out = dir.path().join("run");
    let run = || {
        let mut source = open_source(&SourceConfig::new(sim.data_path.clone()))
            .unwrap_or_else(|e| panic!("{e}"));
        let mut receiver = Receiver::new(&config, source.fs_hz(), Assistance::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let mut sink = FileSink::create(&out, config.run.rate_hz).unwrap_or_else(|e| panic!("{e}"));
        receiver
            .run(source.as_mut(), &mut sink)
            .unwrap_or_else(|e| panic!("{e}"))
    };

    let mut g = c.benchmark_group("end_to_end");
    g.sample_size(10);
    g.throughput(Throughput::Elements(sim.samples));
    g.bench_function("run 3 s 4 MHz ci8 12 satellites", |b| b.iter(run));
    g.finish();
}

criterion_group!(benches, bench_run);
criterion_main!(benches);
