//! Snapshot positioning throughput, snapshots per second on the whole rayon pool (issue 27:
//! "throughput in snapshots per second on 2 cores, a benchmark, not a timed test"): the
//! acquisition, sub-sample code phases, coarse-time fixes and the sequence clock's second pass
//! of [`gpsrx_receiver::snapshot::SnapshotProcessor::run`], the inputs already in memory.
//!
//! - `snapshot/snappergps_walk_60`: the 60 shared SnapperGPS snapshots (12 ms, 1-bit real at
//!   4.092 MHz, the a-priori 30 km off; `../shared/data/real/snapshots`, skipped with a note
//!   when absent);
//! - `snapshot/simulated_8x12ms_1bit`: 8 simulated snapshots of the same kind (45 dB-Hz,
//!   static, 20 s apart; always runs).
//!
//! `cargo bench --profile ci -p gpsrx-benches --bench snapshot`

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gpsrx_nav::{Llh, NavData};
use gpsrx_receiver::snapshot::driver::Seed;
use gpsrx_receiver::snapshot::snappergps::read_snappergps;
use gpsrx_receiver::snapshot::{
    read_raw_snapshot, SampleSpec, Snapshot, SnapshotOptions, SnapshotProcessor,
};
use gpsrx_samples::sim::{Scenario, Simulator};
use std::path::Path;

fn shared(name: &str) -> Option<std::path::PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data/real/snapshots")
        .join(name);
    p.is_file().then_some(p)
}

fn bench_set(
    c: &mut Criterion,
    name: &str,
    nav: &NavData,
    snaps: &[Snapshot],
    seed: Seed,
    opts: &SnapshotOptions,
) {
    let mut group = c.benchmark_group("snapshot");
    group.sample_size(10);
    group.throughput(Throughput::Elements(snaps.len() as u64));
    group.bench_function(name, |b| {
        b.iter(|| {
            let mut p = match SnapshotProcessor::new(nav, opts.clone()) {
                Ok(p) => p,
                Err(e) => panic!("{e}"),
            };
            p.run(snaps, seed, |_| {})
        })
    });
    group.finish();
}

fn bench_walk(c: &mut Criterion) {
    let (Some(json), Some(navp)) = (
        shared("snappergps_w00_first60.json"),
        shared("snappergps_w00.nav"),
    ) else {
        eprintln!("skip snapshot/snappergps_walk_60: ../shared/data/real/snapshots is absent");
        return;
    };
    let nav = gpsrx_nav::read_rinex_nav(&navp).unwrap_or_else(|e| panic!("{e}"));
    let snaps = read_snappergps(&json).unwrap_or_else(|e| panic!("{e}"));
    let apriori = Llh::from_degrees(52.03, -1.2574, 112.0);
    let mut opts = SnapshotOptions::default();
    opts.solve.height = Some(gpsrx_nav::pvt::HeightConstraint {
        h_m: 112.0,
        sigma_m: 30.0,
    });
    let seed = Seed {
        pos_ecef_m: apriori.to_ecef(),
        time_correction_s: 0.0,
        time: None,
    };
    bench_set(c, "snappergps_walk_60", &nav, &snaps, seed, &opts);
}

fn bench_simulated(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data");
    let mut snaps = Vec::new();
    for k in 0..8u32 {
        let toml = format!(
            "duration_s = 0.012\nseed = {}\nnav = \"brdc0010.22n\"\n[start]\nweek = 2190\n\
             tow_s = {}\n[output]\nformat = \"ri1_lsb\"\nfs_hz = 4.092e6\nif_hz = 1.3e6\n\
             [receiver]\nkind = \"static\"\nllh_deg = [36.3721, 127.3604, 80.0]\n\
             [satellites]\ncn0_all_dbhz = 45.0\n",
            60 + k,
            538_194.0 + 20.0 * f64::from(k)
        );
        let out = dir.path().join(k.to_string());
        let report = Scenario::from_toml(&toml)
            .and_then(|s| Simulator::new(&s, &data))
            .and_then(|s| s.run(&out, &|_| {}))
            .unwrap_or_else(|e| panic!("{e}"));
        let spec = SampleSpec {
            format: None,
            fs_hz: None,
            if_hz: 0.0,
            invert_q: false,
        };
        let start = gpsrx_samples::sigmf::recording_start(&report.data_path)
            .ok()
            .flatten()
            .map(|s| s.time);
        let mut s =
            read_raw_snapshot(&report.data_path, &spec, start).unwrap_or_else(|e| panic!("{e}"));
        s.index = k as usize;
        snaps.push(s);
    }
    let nav =
        gpsrx_nav::read_rinex_nav(&data.join("brdc0010.22n")).unwrap_or_else(|e| panic!("{e}"));
    let seed = Seed {
        pos_ecef_m: Llh::from_degrees(36.5621, 127.6004, 80.0).to_ecef(),
        time_correction_s: 0.0,
        time: None,
    };
    bench_set(
        c,
        "simulated_8x12ms_1bit",
        &nav,
        &snaps,
        seed,
        &SnapshotOptions::default(),
    );
}

criterion_group!(benches, bench_walk, bench_simulated);
criterion_main!(benches);
