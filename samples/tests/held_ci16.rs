//! cu8, ri8 and ri16 recordings held as ci16 for the int16 correlators
//! ([`gpsrx_samples::held_gain`]): the integers are `read`'s values times the gain, rounded,
//! and the int16 kernel on them, divided by the gain, gives the f32 correlations of `read`'s
//! values within the roundings of the conversion and of the kernel.

use std::io::Write;

use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_dsp::correlator::{Arithmetic, Correlator, Isa, ReplicaState};
use gpsrx_dsp::{CaCode, PackedCode, Prn, SampleSlice};
use gpsrx_samples::format::SampleFormat;
use gpsrx_samples::{held_gain, open_source, IntegerFormat, IntegerSamplesMut, SourceConfig};
use num_complex::Complex32;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const FS: f64 = 4.0e6;
/// One code period at [`FS`]: the block the channels correlate.
const N: usize = 4000;

/// `n` samples of `format` (stored bytes): a C/A code of PRN 5 with Doppler `doppler_hz` at
/// `amplitude` (a fraction of full scale) plus uniform noise of the same size, on the IF
/// `if_hz` for the real formats; seeded.
fn recording(
    format: &SampleFormat,
    n: usize,
    amplitude: f64,
    doppler_hz: f64,
    seed: u64,
) -> Vec<u8> {
    let code = CaCode::new(Prn::new(5).expect("prn")).chips().to_vec();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let full = f64::from(format.full_scale());
    let mut bytes = Vec::new();
    for k in 0..n {
        let t = k as f64 / FS;
        let chip = f64::from(code[((t * CA_CHIP_RATE_HZ) as usize) % code.len()]);
        let phase = std::f64::consts::TAU * (IF_HZ + doppler_hz) * t;
        let mut noise = || rng.random_range(-1.0..1.0) * amplitude * full;
        let (i, q) = (
            amplitude * full * chip * phase.cos() + noise(),
            amplitude * full * chip * phase.sin() + noise(),
        );
        match format {
            SampleFormat::Cu8 { .. } => {
                let u = |v: f64| (v + 127.5).round().clamp(0.0, 255.0) as u8;
                bytes.extend([u(i), u(q)]);
            }
            SampleFormat::Ri8 => bytes.push(i.round().clamp(-128.0, 127.0) as i8 as u8),
            SampleFormat::Ri16Le => {
                bytes.extend((i.round().clamp(-32768.0, 32767.0) as i16).to_le_bytes());
            }
            other => panic!("not a format of this test: {other}"),
        }
    }
    bytes
}

/// The IF every test recording is written on ([`config`] mixes it down).
const IF_HZ: f64 = 1.02e6;

/// The source of a recording written on [`IF_HZ`]: mixed down to baseband by the source
/// (cu8 is complex on the IF, ri8 and ri16 real), the same mixer on both paths.
fn config(path: &std::path::Path, format: &SampleFormat) -> SourceConfig {
    SourceConfig {
        if_hz: IF_HZ,
        ..SourceConfig::new(path)
            .with_format(format.clone())
            .with_fs_hz(FS)
    }
}

/// `read`'s values and the ci16 `read_integer` gives, of the first `n` samples.
fn both_paths(
    bytes: &[u8],
    format: &SampleFormat,
    n: usize,
) -> (Vec<Complex32>, Vec<[i16; 2]>, f32) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.bin");
    std::fs::File::create(&path)
        .and_then(|mut f| f.write_all(bytes))
        .expect("write");
    let cfg = config(&path, format);
    let mut by_read = open_source(&cfg).expect("open");
    let mut by_int = open_source(&cfg).expect("open");
    assert_eq!(
        by_int.integer_format(),
        Some(IntegerFormat::Ci16),
        "{format}"
    );
    let gain = by_int.integer_gain();
    assert_eq!(Some(gain), held_gain(format));
    let mut f = vec![Complex32::new(0.0, 0.0); n];
    assert_eq!(by_read.read(&mut f).expect("read"), (0, n));
    let mut h = vec![[0i16; 2]; n];
    assert_eq!(
        by_int
            .read_integer(IntegerSamplesMut::Ci16(&mut h))
            .expect("integer read"),
        (0, n)
    );
    (f, h, gain)
}

fn formats() -> [SampleFormat; 3] {
    [
        SampleFormat::Cu8 { zero: 127.5 },
        SampleFormat::Ri8,
        SampleFormat::Ri16Le,
    ]
}

/// The held integers are `read`'s values times the gain within half a unit (cu8 at its zero of
/// 127.5: exactly `2 code - 255` before the mixing), across the reader's conversion pieces.
#[test]
fn converted_integers_are_the_read_values_times_the_gain() {
    for format in formats() {
        let n = 100_003; // several 32 Ki-sample conversion pieces
        let bytes = recording(&format, n, 0.3, 1234.0, 3);
        let (f, h, gain) = both_paths(&bytes, &format, n);
        for (x, y) in f.iter().zip(&h) {
            for (v, q) in [(x.re, y[0]), (x.im, y[1])] {
                assert!(
                    (f32::from(q) - v * gain).abs() <= 0.5 + 1e-3,
                    "{format}: {q} for {}",
                    v * gain
                );
            }
        }
        // Not all zero or saturated: the conversion kept the signal's range.
        let peak = h
            .iter()
            .map(|s| s[0].unsigned_abs().max(s[1].unsigned_abs()))
            .max();
        assert!(
            peak.is_some_and(|p| p > 20 && p < 32767),
            "{format}: peak {peak:?}"
        );
    }
    // cu8 at IF 0: no mixing, so every held value is exactly 2 code - 255.
    let format = SampleFormat::Cu8 { zero: 127.5 };
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.cu8");
    let bytes: Vec<u8> = (0..=255u8).chain((0..=255u8).rev()).collect();
    std::fs::write(&path, &bytes).expect("write");
    let cfg = SourceConfig::new(&path).with_format(format).with_fs_hz(FS);
    let mut s = open_source(&cfg).expect("open");
    let mut h = vec![[0i16; 2]; bytes.len() / 2];
    s.read_integer(IntegerSamplesMut::Ci16(&mut h))
        .expect("read");
    for (pair, q) in bytes.chunks_exact(2).zip(&h) {
        assert_eq!(
            *q,
            [2 * i16::from(pair[0]) - 255, 2 * i16::from(pair[1]) - 255]
        );
    }
}

/// The kernel `auto` takes on the held ci16 (the int16 one where the CPU has AVX2), divided by
/// the gain, against the scalar f32 reference on `read`'s values: equal within the
/// conversion's rounding (half a unit of the held integers per component and sample) and the
/// kernel's (products to 2^-15 of the block's largest sample, carrier within 4.1e-4).
fn assert_same_correlations(
    f: &[Complex32],
    h: &[[i16; 2]],
    gain: f32,
    state: &ReplicaState,
    what: &str,
) {
    let code = PackedCode::new(CaCode::new(Prn::new(5).expect("prn")).chips());
    let taps = [-0.5, 0.0, 0.5];
    let mut want = [Complex32::new(0.0, 0.0); 3];
    let reference = Correlator::new(Isa::Scalar, Arithmetic::F32).expect("scalar");
    reference.correlate_packed(SampleSlice::Cf32(f), FS, &code, state, &taps, &mut want);
    let auto = Correlator::best_up_to(Isa::Avx512, Arithmetic::Auto);
    let mut got = [Complex32::new(0.0, 0.0); 3];
    auto.correlate_packed(SampleSlice::Ci16(h), FS, &code, state, &taps, &mut got);
    let n = f.len() as f64;
    let sum_abs: f64 = f.iter().map(|x| f64::from(x.norm())).sum();
    let largest = h
        .iter()
        .map(|s| f64::from(s[0].unsigned_abs().max(s[1].unsigned_abs())))
        .fold(0.0, f64::max);
    let tol = 1.5
        * (4.1e-4 * sum_abs
            + n * std::f64::consts::SQRT_2 * (0.5 + largest * 2f64.powi(-14)) / f64::from(gain))
        + 1e-3 * sum_abs / n;
    for (g, w) in got.iter().zip(&want) {
        let d = f64::from((g / gain - w).norm());
        assert!(
            d <= tol,
            "{what}: {} from {}: {w} off by {d:.3} (tolerance {tol:.3}, prompt {:.1})",
            auto.kernel_for("ci16", FS),
            reference.name(),
            want[1].norm()
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn the_int16_kernel_on_held_cu8_ri8_ri16_gives_the_f32_correlations(
        which in 0usize..3,
        amplitude in 0.02f64..0.45,
        doppler_hz in -4000.0f64..4000.0,
        code_phase in 0.0f64..1023.0,
        carrier_phase in 0.0f64..1.0,
        seed in 0u64..1000,
    ) {
        let format = formats()[which].clone();
        let bytes = recording(&format, N, amplitude, doppler_hz, seed);
        let (f, h, gain) = both_paths(&bytes, &format, N);
        // Mixed down by the source, the carrier is at the Doppler (a real recording has its
        // image at -2 IF - Doppler too).
        let state = ReplicaState {
            code_phase_chips: code_phase,
            code_rate_chips_s: CA_CHIP_RATE_HZ,
            carrier_phase_cycles: carrier_phase,
            carrier_freq_hz: doppler_hz,
            carrier_rate_hz_s: 0.0,
        };
        assert_same_correlations(&f, &h, gain, &state, &format.name());
        // At the signal itself (code phase 0, its carrier): a large prompt, the same bound.
        let on_signal = ReplicaState { code_phase_chips: 0.0, carrier_phase_cycles: 0.0, ..state };
        assert_same_correlations(&f, &h, gain, &on_signal, &format!("{} on the signal", format.name()));
    }
}

/// A real recording on an IF of exactly fs/4 (the usual 16.368 MHz / 4.092 MHz front end) is
/// mixed in integers, straight from the bytes: the same ci16 as rounding `read`'s f32 mixing
/// times the gain, sample for sample, across the reader's chunks and in uneven reads, the
/// extreme codes included (-32768 negated saturates to 32767 on both paths).
#[test]
fn real_recordings_on_a_quarter_rate_if_are_mixed_exactly_in_integers() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    for format in [SampleFormat::Ri8, SampleFormat::Ri16Le] {
        let n = 1_234_567; // several 1 MiB chunks for ri16
        let mut bytes: Vec<u8> = match format {
            SampleFormat::Ri8 => (0..n).map(|_| rng.random::<u8>()).collect(),
            _ => (0..n)
                .flat_map(|_| rng.random_range(-32768i32..=32767).to_le_bytes()[..2].to_vec())
                .collect(),
        };
        // The extremes at every phase of the oscillator.
        let width = if format == SampleFormat::Ri8 { 1 } else { 2 };
        for k in 0..8 {
            let v: i16 = if k % 2 == 0 { i16::MIN } else { i16::MAX };
            let b = if width == 1 {
                vec![(v >> 8) as u8]
            } else {
                v.to_le_bytes().to_vec()
            };
            bytes[k * width..(k + 1) * width].copy_from_slice(&b);
        }
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("x.bin");
        std::fs::write(&path, &bytes).expect("write");
        for skip_s in [0.0, 0.25e-6] {
            let cfg = SourceConfig {
                if_hz: FS / 4.0,
                skip_s,
                ..SourceConfig::new(&path)
                    .with_format(format.clone())
                    .with_fs_hz(FS)
            };
            let mut by_read = open_source(&cfg).expect("open");
            let mut by_int = open_source(&cfg).expect("open");
            let gain = by_int.integer_gain();
            let mut want = Vec::new();
            let mut got = Vec::new();
            for size in [1usize, 3, 100_000, 7, 999_999, 400_000] {
                let mut f = vec![Complex32::new(0.0, 0.0); size];
                let (first, m) = by_read.read(&mut f).expect("read");
                let mut q = vec![[0i16; 2]; m];
                gpsrx_samples::quantize_to_ci16(&f[..m], gain, &mut q);
                want.extend(q);
                let mut h = vec![[0i16; 2]; size];
                let (first_h, mh) = by_int
                    .read_integer(IntegerSamplesMut::Ci16(&mut h))
                    .expect("integer read");
                assert_eq!((first_h, mh), (first, m), "{format}");
                got.extend_from_slice(&h[..mh]);
            }
            assert!(got.len() > 1_000_000, "{format}: {}", got.len());
            let bad = got.iter().zip(&want).position(|(a, b)| a != b);
            assert_eq!(bad, None, "{format} skip {skip_s}: first difference");
        }
    }
}
