//! Simulator throughput: one 100 ms work unit of a 4 MHz, all-satellites-in-view scenario.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gpsrx_samples::sim::{Scenario, Simulator};
use std::path::Path;

fn scenario() -> Scenario {
    let text = r#"
duration_s = 1.0
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci16_le"
fs_hz = 4.0e6
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[satellites]
elevation_mask_deg = 0.0
"#;
    match Scenario::from_toml(text) {
        Ok(s) => s,
        Err(e) => panic!("bench scenario: {e}"),
    }
}

fn bench_chunk(c: &mut Criterion) {
    let sim = match Simulator::new(&scenario(), Path::new(".")) {
        Ok(s) => s,
        Err(e) => panic!("{e}"),
    };
    let mut group = c.benchmark_group("simulator");
    group.throughput(Throughput::Elements(sim.chunk_samples() as u64));
    let mut buf = Vec::new();
    group.bench_function(format!("chunk_4MHz_{}sv", sim.satellites.len()), |b| {
        b.iter(|| sim.generate_chunk(3, &mut buf))
    });
    group.finish();
}

criterion_group!(benches, bench_chunk);
criterion_main!(benches);
