//! Correlator kernels: every kernel this CPU runs x sample format (ci8, ci16, cf32) x taps
//! (1, 3, 5), one 4000-sample block (1 ms at 4 MHz) per iteration, carrier (1.25 MHz IF plus
//! Doppler, with a rate) and code generated inside the kernel, the code prepared once
//! ([`PackedCode`]) as tracking does.
//!
//! Throughput is in samples. Targets, one core: 3-tap ci8 >= 500 Msamples/s (AMD EPYC, issue
//! 7); `avx2+fma/i16` 3-tap ci8 >= 2x GNSS-SDR's `16ic_16i_rotator` on the same machine (issue
//! 17; `scripts/bench-vs-gnss-sdr.sh` times the two back to back). The carrier here has a
//! rate, which takes the AVX2 int16 ci8 kernel's per-step f32 carrier; tracking (and `gpsrx
//! bench`) correlate at a constant frequency per block.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gpsrx_dsp::correlator::{Arithmetic, Correlator, PackedCode, ReplicaState, SampleSlice};
use gpsrx_dsp::{CaCode, Prn};
use num_complex::Complex32;
use std::time::Duration;

const N: usize = 4000;
const FS_HZ: f64 = 4.0e6;

/// Deterministic pseudo-random samples (SplitMix64) in all three formats.
fn samples() -> (Vec<[i8; 2]>, Vec<[i16; 2]>, Vec<Complex32>) {
    let mut state = 7u64;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    let mut ci8 = Vec::with_capacity(N);
    let mut ci16 = Vec::with_capacity(N);
    let mut cf32 = Vec::with_capacity(N);
    for _ in 0..N {
        let v = next();
        let (a, b) = ((v as i16) >> 4, ((v >> 16) as i16) >> 4);
        ci8.push([(a >> 6) as i8, (b >> 6) as i8]);
        ci16.push([a, b]);
        cf32.push(Complex32::new(f32::from(a) / 2048.0, f32::from(b) / 2048.0));
    }
    (ci8, ci16, cf32)
}

fn bench_correlators(c: &mut Criterion) {
    let (ci8, ci16, cf32) = samples();
    let code = match Prn::new(7) {
        Ok(prn) => PackedCode::new(CaCode::new(prn).chips()),
        Err(e) => panic!("{e}"),
    };
    let state = ReplicaState {
        code_phase_chips: 321.7,
        code_rate_chips_s: 1.023e6 + 2.3,
        carrier_phase_cycles: 0.25,
        carrier_freq_hz: 1.25e6 + 3456.0,
        carrier_rate_hz_s: 120.0,
    };
    let mut group = c.benchmark_group("correlator");
    group
        .throughput(Throughput::Elements(N as u64))
        .sample_size(30)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_millis(800));
    for kernel in Correlator::available() {
        for (fmt, x) in [
            ("ci8", SampleSlice::Ci8(&ci8)),
            ("ci16", SampleSlice::Ci16(&ci16)),
            ("cf32", SampleSlice::Cf32(&cf32)),
        ] {
            // The int16 kernels run the f32 path on cf32 input: nothing new to measure.
            if kernel.arithmetic() == Arithmetic::I16 && fmt == "cf32" {
                continue;
            }
            for taps in [1usize, 3, 5] {
                let offsets: Vec<f64> = (0..taps)
                    .map(|i| (i as f64 - (taps / 2) as f64) * 0.5)
                    .collect();
                let mut out = vec![Complex32::new(0.0, 0.0); taps];
                let id = BenchmarkId::new(format!("{}/{fmt}", kernel.name()), taps);
                group.bench_function(id, |b| {
                    b.iter(|| {
                        kernel.correlate_packed(
                            std::hint::black_box(x),
                            FS_HZ,
                            &code,
                            &state,
                            &offsets,
                            &mut out,
                        );
                        std::hint::black_box(&out);
                    })
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, bench_correlators);
criterion_main!(benches);
