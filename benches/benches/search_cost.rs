//! The background search's cost model against its measured CPU time
//! (`gpsrx_receiver::pipeline::channels`, the search schedule: `fixed_cost_s + sum of cost_s` per batch).
//!
//! Every level of the background search (1 ms x 10, 10 ms x 13, 10 ms x 50 over +-5 kHz)
//! at 2.6 and 4 MHz, batches of 1 and 8 absent PRNs on 8-bit noise held as the receiver
//! holds it (ci8, converted block by block): the process CPU time of one search on the whole
//! rayon pool (`CLOCK_PROCESS_CPUTIME_ID`: every thread, the pool's spinning included, the
//! allocation and release of the search's memory included), the least of a few repetitions in each of 3 rounds over all rows,
//! next to the modelled cost. Issue 28 asks the two to agree within 20 %; the table says
//! for each row whether they do, and the run fails when one does not.
//!
//! `cargo bench -p gpsrx-benches --bench search_cost` (a release build; on an idle machine:
//! CPU time grows with other load, as caches are shared).

use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::{Prn, SampleSlice};
use gpsrx_receiver::pipeline::channels::{cost_s, fixed_cost_s, level_config, LEVELS};
use std::hint::black_box;

/// Agreement asked for: measured within this fraction of the model.
const TOLERANCE: f64 = 0.20;

/// Rounds over all rows; each row keeps its least time.
const ROUNDS: usize = 3;

/// One row of the table: a level's engine at one rate with a batch of PRNs.
struct Row {
    fs: f64,
    name: String,
    engine: std::sync::Arc<AcquisitionEngine>,
    samples: std::sync::Arc<Vec<[i8; 2]>>,
    targets: Vec<SearchTarget>,
    model_s: f64,
    /// Least process CPU time of one search so far, s.
    measured_s: f64,
}

impl Row {
    /// One warm-up search, then the least CPU time of the repetitions (about 0.3 s of
    /// modelled work, 3 to 50 searches), kept when less than before.
    fn measure(&mut self) {
        let run = || match self
            .engine
            .search_slice(SampleSlice::Ci8(&self.samples), &self.targets)
        {
            Ok(r) => black_box(r),
            Err(e) => panic!("{e}"),
        };
        run();
        let reps = ((0.3 / self.model_s).ceil() as usize).clamp(3, 50);
        let least = (0..reps)
            .map(|_| {
                let t0 = process_cpu_s();
                run();
                process_cpu_s() - t0
            })
            .fold(f64::INFINITY, f64::min);
        self.measured_s = self.measured_s.min(least);
    }
}

/// CPU time of the whole process so far, s.
fn process_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec to write to.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_PROCESS_CPUTIME_ID) failed");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// `n` samples of 8-bit complex noise (sigma about 20 LSB), from a fixed seed.
fn ci8_noise(n: usize, seed: u64) -> Vec<[i8; 2]> {
    let mut state = seed;
    let mut next = move || {
        // SplitMix64.
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    (0..n)
        .map(|_| {
            // Sum of four uniform bytes: nearly Gaussian, variance 4 x 85^2 / 16.
            let v = next();
            let g = |s: u32| {
                let b = |k: u32| i32::from((v >> (s + 8 * k)) as u8) - 128;
                ((b(0) + b(1) + b(2) + b(3)) / 4).clamp(-128, 127) as i8
            };
            [g(0), g(32)]
        })
        .collect()
}

fn main() {
    // `cargo bench` passes `--bench`; nothing else is taken.
    let base = AcqConfig::default();
    println!(
        "background search cost: modelled (search_schedule) against measured process CPU time"
    );
    println!(
        "{:>7} {:>12} {:>5} {:>11} {:>11} {:>9}  within {:.0} %",
        "fs MHz",
        "level",
        "PRNs",
        "model ms",
        "measured ms",
        "ratio",
        TOLERANCE * 100.0
    );
    // Every row is measured in each of ROUNDS rounds and keeps its least time: a slow
    // stretch of a shared or virtual machine (minutes long) then spoils at most one round.
    let mut rows = Vec::new();
    for fs in [2.6e6, 4.0e6] {
        for level in 0..=LEVELS.len() {
            let cfg = level_config(&base, level, fs);
            let name = format!("{} ms x {}", cfg.coherent_ms, cfg.noncoherent);
            let engine = match AcquisitionEngine::new(fs, cfg) {
                Ok(e) => e,
                Err(e) => panic!("{e}"),
            };
            let x = std::sync::Arc::new(ci8_noise(engine.samples_wanted(), 7));
            let engine = std::sync::Arc::new(engine);
            for n_prn in [1usize, 8] {
                let targets: Vec<SearchTarget> = (25u8..25 + n_prn as u8)
                    .filter_map(|p| Prn::new(p).ok())
                    .map(SearchTarget::full)
                    .collect();
                let model_s =
                    fixed_cost_s(&engine) + targets.iter().map(|t| cost_s(&engine, t)).sum::<f64>();
                rows.push(Row {
                    fs,
                    name: name.clone(),
                    engine: std::sync::Arc::clone(&engine),
                    samples: std::sync::Arc::clone(&x),
                    targets,
                    model_s,
                    measured_s: f64::INFINITY,
                });
            }
        }
    }
    for _ in 0..ROUNDS {
        for row in &mut rows {
            row.measure();
        }
    }
    let mut worst: f64 = 0.0;
    for row in &rows {
        let ratio = row.measured_s / row.model_s;
        worst = worst.max((ratio - 1.0).abs());
        println!(
            "{:>7.1} {:>12} {:>5} {:>11.2} {:>11.2} {:>9.2}  {}",
            row.fs / 1e6,
            row.name,
            row.targets.len(),
            row.model_s * 1e3,
            row.measured_s * 1e3,
            ratio,
            if (ratio - 1.0).abs() <= TOLERANCE {
                "yes"
            } else {
                "NO"
            }
        );
    }
    println!("largest deviation from the model: {:.0} %", worst * 100.0);
    if worst > TOLERANCE {
        eprintln!(
            "search_cost: the model is off by more than {:.0} %",
            TOLERANCE * 100.0
        );
        std::process::exit(1);
    }
}
