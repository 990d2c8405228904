//! End to end: `gpsrx run` (file -> acquisition -> 12 tracking channels with re-acquisition
//! -> navigation data -> observables -> outputs) on 3 s of the built-in 4 MHz ci8
//! 12-satellite scenario (`samples/scenarios/static-seoul-4msps.toml`), simulated once into a
//! temporary directory before timing. Throughput is counted in input samples (12 M per
//! iteration); real time is 4 Msamples/s, so the real-time factor is throughput / 4e6.
//! `gpsrx bench` measures the full 60 s recording the same way.

use clap::Parser;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gpsrx_cli::cli::{Cli, Command};
use gpsrx_cli::commands::run::run_file;
use gpsrx_cli::commands::simulate::simulate;
use gpsrx_samples::sim::Scenario;
use std::path::Path;

const SEOUL_SCENARIO_TOML: &str = include_str!("../../samples/scenarios/static-seoul-4msps.toml");

/// Recording length, s.
const DURATION_S: f64 = 3.0;

fn bench_run(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let mut scenario = Scenario::from_toml(SEOUL_SCENARIO_TOML).unwrap_or_else(|e| panic!("{e}"));
    scenario.nav = "builtin:brdc0010.22n".into();
    scenario.duration_s = DURATION_S;
    let sim =
        simulate(&scenario, Path::new(""), dir.path(), false).unwrap_or_else(|e| panic!("{e:#}"));
    let week = scenario
        .start_time()
        .unwrap_or_else(|e| panic!("{e}"))
        .week
        .to_string();
    let data = sim.data_path.to_string_lossy().into_owned();
    let out = dir.path().join("run").to_string_lossy().into_owned();
    let cli = Cli::try_parse_from([
        "gpsrx",
        "run",
        data.as_str(),
        "--out",
        out.as_str(),
        "--week",
        week.as_str(),
    ])
    .unwrap_or_else(|e| panic!("{e}"));
    let Command::Run(args) = cli.command else {
        panic!("not a run command")
    };

    let mut g = c.benchmark_group("end_to_end");
    g.sample_size(10);
    g.throughput(Throughput::Elements(sim.samples));
    g.bench_function("run 3 s 4 MHz ci8 12 satellites", |b| {
        b.iter(|| run_file(&args, false).unwrap_or_else(|e| panic!("{e:#}")))
    });
    g.finish();
}

criterion_group!(benches, bench_run);
criterion_main!(benches);
