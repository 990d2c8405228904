//! Integration tests of the sample layer: every format round-trips through `create_writer` and
//! `open_source`; mixing, Q inversion, skip/duration, warnings, errors, SigMF, WAV, `inspect`,
//! and the real recordings in `../shared/data`.

use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use gpsrx_samples::format::DEFAULT_PACKED2_MAP;
use gpsrx_samples::info::{inspect, Histogram};
use gpsrx_samples::sigmf::{
    format_datetime_utc, parse_datetime_utc, read_sigmf_meta, recording_start, write_sigmf_meta,
    SigmfMeta,
};
use gpsrx_samples::span::{sample_position, samples_in_bytes, Span};
use gpsrx_samples::{
    create_wav_writer, create_writer, open_source, SampleError, SampleFormat, SampleSource,
    SourceConfig,
};
use num_complex::Complex32;
use proptest::prelude::*;

const FS: f64 = 4.0e6;

fn c(re: f32, im: f32) -> Complex32 {
    Complex32::new(re, im)
}

/// Every format, with non-default parameters too.
fn all_formats() -> Vec<SampleFormat> {
    let mut v: Vec<SampleFormat> = SampleFormat::SUPPORTED
        .iter()
        .map(|n| n.parse().expect("supported"))
        .collect();
    v.push(SampleFormat::Cu8 { zero: 128.0 });
    v.push(SampleFormat::Packed2 {
        complex: true,
        map: [-1.5, -0.5, 0.5, 1.5],
        msb_first: true,
    });
    v
}

/// Reference quantiser, written independently of the library: the value a component reads
/// back as, and whether writing it clipped.
fn quantise(format: &SampleFormat, v: f32) -> (f32, bool) {
    let int = |lo: f32, hi: f32| {
        let r = v.round();
        (r.clamp(lo, hi), r < lo || r > hi)
    };
    match format {
        SampleFormat::Ci8 | SampleFormat::Ri8 => int(-128.0, 127.0),
        SampleFormat::Ci16Le | SampleFormat::Ri16Le => int(-32768.0, 32767.0),
        SampleFormat::Cu8 { zero } => {
            let r = (v + zero).round();
            (r.clamp(0.0, 255.0) - zero, !(0.0..=255.0).contains(&r))
        }
        SampleFormat::Cf32Le | SampleFormat::Cf64Le | SampleFormat::Rf32Le => (v, false),
        SampleFormat::Packed2 { map, .. } => {
            let mut sorted = *map;
            sorted.sort_by(f32::total_cmp);
            let best = sorted.iter().copied().fold(sorted[0], |b, l| {
                if (v - l).abs() <= (v - b).abs() {
                    l
                } else {
                    b
                }
            });
            let lo = sorted[0] - 0.5 * (sorted[1] - sorted[0]);
            let hi = sorted[3] + 0.5 * (sorted[3] - sorted[2]);
            (best, v < lo || v > hi)
        }
        SampleFormat::Packed1Complex | SampleFormat::Packed1Real { .. } => {
            (if v > 0.0 { 1.0 } else { -1.0 }, v.abs() > 2.0)
        }
    }
}

/// Value of padding samples of packed formats (zero bits).
fn pad_value(format: &SampleFormat) -> f32 {
    match format {
        SampleFormat::Packed2 { map, .. } => map[0],
        // A zero bit is the positive sign.
        SampleFormat::Packed1Real { .. } => 1.0,
        _ => -1.0,
    }
}

fn cfg(path: &Path, format: &SampleFormat) -> SourceConfig {
    let mut cfg = SourceConfig::new(path)
        .with_format(format.clone())
        .with_fs_hz(FS);
    if !format.is_complex() {
        cfg.if_hz = FS / 4.0;
    }
    cfg
}

fn read_all(src: &mut dyn SampleSource) -> Result<Vec<Complex32>, SampleError> {
    let mut all = Vec::new();
    let mut buf = vec![Complex32::default(); 777];
    let mut next = None;
    loop {
        let (first, n) = src.read(&mut buf)?;
        if n == 0 {
            return Ok(all);
        }
        if let Some(expected) = next {
            assert_eq!(first, expected, "indices must be contiguous");
        }
        next = Some(first + n as u64);
        all.extend_from_slice(&buf[..n]);
    }
}

fn write_file(path: &Path, format: &SampleFormat, samples: &[Complex32]) {
    let mut w = create_writer(path, format).expect("create writer");
    w.write(samples).expect("write");
    w.finish().expect("finish");
}

/// `exp(-j 2π n / 4)`: the IF = fs/4 mixer at sample n.
fn quarter_rotation(n: usize) -> Complex32 {
    [c(1.0, 0.0), c(0.0, -1.0), c(-1.0, 0.0), c(0.0, 1.0)][n % 4]
}

fn round_trip(format: &SampleFormat, raw: &[(f32, f32)]) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join(format!("x.{}", format.name()));
    let fs = format.full_scale();
    let samples: Vec<Complex32> = raw.iter().map(|&(i, q)| c(i * fs, q * fs)).collect();
    let mut w = create_writer(&path, format).expect("create writer");
    // Two writes, to exercise a packed byte split across calls.
    let (a, b) = samples.split_at(samples.len() / 3);
    w.write(a).expect("write");
    w.write(b).expect("write");
    let stats = w.finish().expect("finish");
    let file_len = std::fs::metadata(&path).expect("metadata").len();
    prop_assert_eq!(stats.bytes_written, file_len);
    prop_assert_eq!(stats.samples_written, samples.len() as u64);
    prop_assert_eq!(
        file_len,
        (samples.len() as u64 * u64::from(format.bits_per_sample())).div_ceil(8)
    );

    let mut expected_clipped = 0u64;
    let mut expected: Vec<Complex32> = Vec::new();
    for s in &samples {
        let (i, ci) = quantise(format, s.re);
        let (q, cq) = if format.is_complex() {
            quantise(format, s.im)
        } else {
            (0.0, false)
        };
        expected_clipped += u64::from(ci) + u64::from(cq);
        expected.push(c(i, q));
    }
    prop_assert_eq!(stats.clipped, expected_clipped);
    let per_byte = (8 / format.bits_per_sample().min(8)) as usize;
    while !expected.len().is_multiple_of(per_byte) {
        let p = pad_value(format);
        expected.push(c(p, if format.is_complex() { p } else { 0.0 }));
    }

    let mut src = open_source(&cfg(&path, format)).expect("open");
    prop_assert_eq!(src.total_samples(), Some(expected.len() as u64));
    let got = read_all(src.as_mut()).expect("read");
    prop_assert_eq!(got.len(), expected.len());
    for (n, (g, e)) in got.iter().zip(&expected).enumerate() {
        if format.is_complex() {
            prop_assert_eq!(g, e, "sample {}", n);
        } else {
            let e = e * quarter_rotation(n);
            prop_assert!(
                (g - e).norm() <= 1e-4 * e.norm() + 1e-4,
                "sample {n}: {g} vs {e}"
            );
        }
    }
    prop_assert!(src.warnings().is_empty(), "{:?}", src.warnings());
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Every format: what is written reads back as the reference quantisation, for odd
    /// lengths, values beyond full scale, and packed partial bytes.
    #[test]
    fn every_format_round_trips(
        raw in proptest::collection::vec((-1.4f32..1.4, -1.4f32..1.4), 1..300),
    ) {
        for format in all_formats() {
            round_trip(&format, &raw)?;
        }
    }

    /// Skip and duration pick exactly the samples asked for, by absolute index.
    #[test]
    fn skip_and_duration_select_samples(skip in 0u64..900, dur in 0u64..400) {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("ramp.ci16");
        let ramp: Vec<Complex32> = (0..1000).map(|k| c(k as f32, -(k as f32))).collect();
        write_file(&path, &SampleFormat::Ci16Le, &ramp);
        let mut cfg = cfg(&path, &SampleFormat::Ci16Le);
        cfg.skip_s = skip as f64 / FS;
        cfg.duration_s = Some(dur as f64 / FS);
        let mut src = open_source(&cfg).expect("open");
        let n = dur.min(1000 - skip);
        prop_assert_eq!(src.total_samples(), Some(n));
        let mut buf = vec![Complex32::default(); 2000];
        let (first, got) = src.read(&mut buf).expect("read");
        prop_assert_eq!(got as u64, n);
        if n > 0 {
            prop_assert_eq!(first, skip);
        }
        for (k, s) in buf[..got].iter().enumerate() {
            prop_assert_eq!(s.re, (skip + k as u64) as f32);
        }
        prop_assert_eq!(src.read(&mut buf).expect("read").1, 0);
        prop_assert_eq!(src.warnings().iter().any(|w| w.contains("past the end")), dur > 1000 - skip);
    }
}

/// The code-th value of a 2-bit pattern for sample k (deterministic, irregular).
fn pattern(k: u64) -> (f32, f32) {
    let m = DEFAULT_PACKED2_MAP;
    (
        m[((k * 7 + k / 3) % 4) as usize],
        m[((k * 5 + k / 7 + 1) % 4) as usize],
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    /// Packed samples read the same whatever the skip (sub-byte starts) and block sizes.
    #[test]
    fn packed_reads_agree_for_any_skip_and_block(skip in 0u64..50, block in 1usize..40) {
        let dir = tempfile::tempdir().expect("tempdir");
        for format in [SampleFormat::ci2(), SampleFormat::Packed1Complex, SampleFormat::Packed2 {
            complex: true, map: DEFAULT_PACKED2_MAP, msb_first: false }]
        {
            let path = dir.path().join(format.name());
            let x: Vec<Complex32> = (0..203u64).map(|k| {
                let (i, q) = pattern(k);
                if matches!(format, SampleFormat::Packed1Complex) { c(i.signum(), q.signum()) } else { c(i, q) }
            }).collect();
            write_file(&path, &format, &x);
            let mut cfg = cfg(&path, &format);
            cfg.skip_s = skip as f64 / FS;
            let mut src = open_source(&cfg).expect("open");
            let mut buf = vec![Complex32::default(); block];
            let mut k = skip;
            loop {
                let (first, n) = src.read(&mut buf).expect("read");
                if n == 0 { break; }
                prop_assert_eq!(first, k);
                for s in &buf[..n] {
                    if k < 203 { prop_assert_eq!(*s, x[k as usize], "{} sample {}", format, k); }
                    k += 1;
                }
            }
            prop_assert!(k >= 203);
        }
    }
}

#[test]
fn reads_cross_the_1_mib_buffer_boundaries() {
    // 5 M ci2 samples = 2.5 MiB: several refills, with packed samples straddling them.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("long.ci2");
    let n = 5_000_000u64;
    let mut w = create_writer(&path, &SampleFormat::ci2()).expect("create");
    let mut block = Vec::with_capacity(1 << 16);
    for start in (0..n).step_by(1 << 16) {
        block.clear();
        block.extend((start..(start + (1 << 16)).min(n)).map(|k| {
            let (i, q) = pattern(k);
            c(i, q)
        }));
        w.write(&block).expect("write");
    }
    assert_eq!(w.finish().expect("finish").bytes_written, n / 2);
    let mut cfg = cfg(&path, &SampleFormat::ci2());
    cfg.skip_s = 3.0 / FS;
    let mut src = open_source(&cfg).expect("open");
    let mut buf = vec![Complex32::default(); 100_003];
    let mut k = 3;
    loop {
        let (first, got) = src.read(&mut buf).expect("read");
        if got == 0 {
            break;
        }
        assert_eq!(first, k);
        for s in &buf[..got] {
            let (i, q) = pattern(k);
            assert_eq!(*s, c(i, q), "sample {k}");
            k += 1;
        }
    }
    assert_eq!(k, n);
}

#[test]
fn packed_partial_byte_is_padded_as_documented() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (format, n, extra) in [
        (SampleFormat::ci2(), 3, 1),
        (SampleFormat::ri2(), 5, 3),
        (SampleFormat::Packed1Complex, 6, 2),
        (SampleFormat::Packed1Real { lsb_first: true }, 5, 3),
        (SampleFormat::Packed1Real { lsb_first: false }, 9, 7),
    ] {
        let path = dir.path().join(format.name());
        let samples = vec![c(-3.0, -3.0); n];
        write_file(&path, &format, &samples);
        let mut src = open_source(&cfg(&path, &format)).expect("open");
        assert_eq!(src.total_samples(), Some((n + extra) as u64), "{format}");
        let got = read_all(src.as_mut()).expect("read");
        let last = got[got.len() - 1] * quarter_rotation(got.len() - 1).conj();
        assert!(
            (last.re - pad_value(&format)).abs() < 1e-4,
            "{format}: {last}"
        );
    }
}

/// Tone estimate: mean phase step between consecutive samples, in Hz.
fn tone_hz(x: &[Complex32], fs: f64) -> f64 {
    let acc: Complex32 = x.windows(2).map(|w| w[1] * w[0].conj()).sum();
    f64::from(acc.arg()) * fs / std::f64::consts::TAU
}

#[test]
fn real_tone_at_if_mixes_down_to_dc() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("tone.ri16");
    let (fs, f_if) = (5.0e6, 1.25e6 + 300.0);
    let x: Vec<Complex32> = (0..20_000)
        .map(|n| {
            c(
                1000.0 * (std::f64::consts::TAU * f_if * n as f64 / fs).cos() as f32,
                0.0,
            )
        })
        .collect();
    write_file(&path, &SampleFormat::Ri16Le, &x);
    let mut cfg = SourceConfig::new(&path)
        .with_format(SampleFormat::Ri16Le)
        .with_fs_hz(fs);
    cfg.if_hz = 1.25e6;
    let y = read_all(open_source(&cfg).expect("open").as_mut()).expect("read");
    // cos = (e^{jwt} + e^{-jwt})/2: the wanted half lands at +300 Hz with amplitude 500,
    // the image at -2.5 MHz averages out.
    let dc = y
        .iter()
        .enumerate()
        .map(|(n, s)| {
            s * Complex32::from_polar(1.0, -(std::f64::consts::TAU * 300.0 * n as f64 / fs) as f32)
        })
        .sum::<Complex32>()
        / y.len() as f32;
    assert!((dc - c(500.0, 0.0)).norm() < 5.0, "{dc}");
}

#[test]
fn complex_if_is_removed_and_q_inversion_flips_the_tone() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("tone.ci8");
    let f = 200e3;
    let x: Vec<Complex32> = (0..8_000)
        .map(|n| Complex32::from_polar(100.0, (std::f64::consts::TAU * f * n as f64 / FS) as f32))
        .collect();
    write_file(&path, &SampleFormat::Ci8, &x);
    let base = cfg(&path, &SampleFormat::Ci8);
    let y = read_all(open_source(&base).expect("open").as_mut()).expect("read");
    assert!((tone_hz(&y, FS) - f).abs() < 10.0);
    let inverted = SourceConfig {
        invert_q: true,
        ..base.clone()
    };
    let y = read_all(open_source(&inverted).expect("open").as_mut()).expect("read");
    assert!((tone_hz(&y, FS) + f).abs() < 10.0, "{}", tone_hz(&y, FS));
    let mixed = SourceConfig { if_hz: f, ..base };
    let y = read_all(open_source(&mixed).expect("open").as_mut()).expect("read");
    assert!(tone_hz(&y, FS).abs() < 10.0);
}

#[test]
fn non_finite_values_read_as_zero_and_are_counted() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("nan.cf32");
    let x = [
        c(f32::NAN, 1.0),
        c(f32::INFINITY, f32::NEG_INFINITY),
        c(2.0, 3.0),
    ];
    let mut w = create_writer(&path, &SampleFormat::Cf32Le).expect("create");
    w.write(&x).expect("write");
    assert_eq!(w.finish().expect("finish").non_finite, 3);
    let mut src = open_source(&cfg(&path, &SampleFormat::Cf32Le)).expect("open");
    let y = read_all(src.as_mut()).expect("read");
    assert_eq!(y, vec![c(0.0, 1.0), c(0.0, 0.0), c(2.0, 3.0)]);
    let w = src.warnings();
    assert!(w.iter().any(|w| w.contains("3 non-finite")), "{w:?}");
}

#[test]
fn trailing_partial_sample_is_dropped_with_a_warning() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("odd.ci16");
    std::fs::write(&path, [1, 0, 2, 0, 3, 0, 4, 0, 9, 9, 9]).expect("write");
    let mut src = open_source(&cfg(&path, &SampleFormat::Ci16Le)).expect("open");
    assert_eq!(src.total_samples(), Some(2));
    assert_eq!(
        read_all(src.as_mut()).expect("read"),
        vec![c(1.0, 2.0), c(3.0, 4.0)]
    );
    let w = src.warnings();
    assert!(w.iter().any(|w| w.contains("last 3 byte(s)")), "{w:?}");
}

#[test]
fn offsets_beyond_4_gib_use_u64_arithmetic() {
    // 1 h of ci8 at 26 MHz: 187.2 GB.
    let fmt = SampleFormat::Ci8;
    let bytes = 187_200_000_001u64;
    let span =
        Span::plan(Path::new("big.ci8"), &fmt, bytes, 26e6, 3000.0, Some(10.0)).expect("plan");
    assert_eq!(span.file_samples, 93_600_000_000);
    assert_eq!(span.trailing_bytes, 1);
    assert_eq!(span.first_sample, 78_000_000_000);
    assert_eq!(span.n_samples, 260_000_000);
    assert_eq!(
        sample_position(&fmt, span.first_sample),
        (156_000_000_000, 0)
    );
    let ci2 = SampleFormat::ci2();
    assert_eq!(sample_position(&ci2, 10_000_000_001), (5_000_000_000, 1));
    assert_eq!(samples_in_bytes(&ci2, 5_000_000_000), (10_000_000_000, 0));

    // A sparse 5 GiB file: the samples just past 4.5 GiB read back at the right index.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("sparse.ci8");
    let offset = 4_831_838_208u64; // 4.5 GiB
    let made = std::fs::File::create(&path).and_then(|mut f| {
        f.set_len(5 << 30)?;
        f.seek(SeekFrom::Start(offset))?;
        f.write_all(&[1, 2, 3, 4, 0xff, 0x80])
    });
    if let Err(e) = made {
        eprintln!("skip sparse-file part: cannot make a sparse 5 GiB file here ({e})");
        return;
    }
    let mut cfg = cfg(&path, &SampleFormat::Ci8);
    cfg.skip_s = (offset / 2) as f64 / FS;
    cfg.duration_s = Some(3.0 / FS);
    let mut src = open_source(&cfg).expect("open");
    let mut buf = [Complex32::default(); 8];
    let (first, n) = src.read(&mut buf).expect("read");
    assert_eq!((first, n), (offset / 2, 3));
    assert_eq!(&buf[..3], &[c(1.0, 2.0), c(3.0, 4.0), c(-1.0, -128.0)]);
}

fn err_of(cfg: &SourceConfig) -> String {
    match open_source(cfg) {
        Ok(_) => panic!("expected an error for {cfg:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_inputs_give_useful_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let good = dir.path().join("good.ci8");
    write_file(&good, &SampleFormat::Ci8, &[c(1.0, 1.0); 100]);
    let ci8 = cfg(&good, &SampleFormat::Ci8);

    let missing = SourceConfig {
        path: dir.path().join("nope.ci8"),
        ..ci8.clone()
    };
    assert!(matches!(
        open_source(&missing),
        Err(SampleError::NotFound { .. })
    ));
    assert!(err_of(&missing).contains("nope.ci8") && err_of(&missing).contains("does not exist"));

    let e = err_of(&SourceConfig {
        path: dir.path().to_path_buf(),
        ..ci8.clone()
    });
    assert!(e.contains("not a regular file"), "{e}");

    let empty = dir.path().join("empty.ci8");
    std::fs::write(&empty, []).expect("write");
    let e = err_of(&SourceConfig {
        path: empty,
        ..ci8.clone()
    });
    assert!(e.contains("empty.ci8") && e.contains("empty"), "{e}");

    for fs in [0.0, -4e6, f64::NAN, f64::INFINITY] {
        let e = err_of(&SourceConfig {
            fs_hz: Some(fs),
            ..ci8.clone()
        });
        assert!(
            e.contains("not a positive finite number")
                && e.contains("give the sampling rate")
                && !e.contains("--fs"),
            "{e}"
        );
    }
    let e = err_of(&SourceConfig {
        fs_hz: Some(1.0e6),
        ..ci8.clone()
    });
    assert!(
        e.contains("too low for GPS L1 C/A") && e.contains("1023000"),
        "{e}"
    );
    let ri8 = SourceConfig {
        format: Some(SampleFormat::Ri8),
        fs_hz: Some(2.0e6),
        if_hz: 0.5e6,
        ..ci8.clone()
    };
    let e = err_of(&ri8);
    assert!(
        e.contains("too low for GPS L1 C/A") && e.contains("2046000") && e.contains("real"),
        "{e}"
    );

    let e = err_of(&SourceConfig {
        if_hz: 2.5e6,
        ..ci8.clone()
    });
    assert!(matches!(
        open_source(&SourceConfig {
            if_hz: 2.5e6,
            ..ci8.clone()
        }),
        Err(SampleError::IfOutOfRange { .. })
    ));
    assert!(e.contains("2500000") && e.contains("|IF| <= fs/2"), "{e}");
    let e = err_of(&SourceConfig {
        if_hz: 0.0,
        fs_hz: Some(FS),
        ..ri8.clone()
    });
    assert!(e.contains("0 < IF < fs/2"), "{e}");

    let e = err_of(&SourceConfig {
        skip_s: 1.0,
        ..ci8.clone()
    });
    assert!(matches!(
        open_source(&SourceConfig {
            skip_s: 1.0,
            ..ci8.clone()
        }),
        Err(SampleError::SkipBeyondEnd { .. })
    ));
    assert!(
        e.contains("beyond the end") && e.contains("100 samples") && e.contains("skip less"),
        "{e}"
    );
    let e = err_of(&SourceConfig {
        skip_s: -1.0,
        ..ci8.clone()
    });
    assert!(e.contains("skip = -1"), "{e}");
    let e = err_of(&SourceConfig {
        duration_s: Some(f64::NAN),
        ..ci8.clone()
    });
    assert!(e.contains("duration"), "{e}");

    let e = err_of(&SourceConfig {
        format: None,
        ..ci8.clone()
    });
    assert!(
        e.contains("give the sample format") && e.contains("cf32_le") && e.contains("good.ci8"),
        "{e}"
    );
    let e = err_of(&SourceConfig {
        fs_hz: None,
        ..ci8.clone()
    });
    assert!(
        e.contains("give the sampling rate") && e.contains("good.ci8"),
        "{e}"
    );

    let meta = dir.path().join("orphan.sigmf-meta");
    write_sigmf_meta(
        &dir.path().join("orphan.sigmf-data"),
        &SigmfMeta::new("ci8", FS),
    )
    .expect("meta");
    let e = err_of(&SourceConfig {
        path: meta,
        ..ci8.clone()
    });
    assert!(
        e.contains("orphan.sigmf-data") && e.contains("no data file"),
        "{e}"
    );

    let broken = dir.path().join("broken.ci8");
    std::fs::write(&broken, [0u8; 8]).expect("write");
    std::fs::write(dir.path().join("broken.sigmf-meta"), "{ not json").expect("write");
    let e = err_of(&SourceConfig {
        path: broken,
        ..ci8.clone()
    });
    assert!(
        e.contains("broken.sigmf-meta") && e.contains("not valid JSON"),
        "{e}"
    );

    let e = "int12"
        .parse::<SampleFormat>()
        .expect_err("unknown")
        .to_string();
    assert!(e.contains("int12") && e.contains("ci16_le"), "{e}");
}

#[test]
fn sigmf_round_trip_and_open_from_metadata() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = dir.path().join("rec.sigmf-data");
    let map = [0.5, 1.5, -1.5, -0.5];
    let format = SampleFormat::Packed2 {
        complex: false,
        map,
        msb_first: true,
    };
    write_file(
        &data,
        &format,
        &[c(1.4, 0.0), c(-0.4, 0.0), c(-2.0, 0.0), c(0.6, 0.0)],
    );
    let mut meta = SigmfMeta::for_format(&format, 8.0e6);
    assert_eq!(meta.packed_map, Some(map));
    meta.if_hz = 2.0e6;
    meta.invert_q = true;
    meta.description = "test".into();
    meta.extra
        .insert("gpsrx:start_gps_week".into(), 2190.into());
    meta.extra
        .insert("gpsrx:start_tow_s".into(), 538200.5.into());
    let meta_path = write_sigmf_meta(&data, &meta).expect("write meta");
    assert_eq!(meta_path, dir.path().join("rec.sigmf-meta"));
    let back = read_sigmf_meta(&meta_path).expect("read meta");
    assert_eq!(back, meta);
    let text = std::fs::read_to_string(&meta_path).expect("read");
    for key in [
        "core:version",
        "core:extensions",
        "core:sample_start",
        "1575420000",
    ] {
        assert!(text.contains(key), "{key} missing in {text}");
    }

    for path in [&data, &meta_path] {
        let mut src = open_source(&SourceConfig::new(path)).expect("open from meta");
        assert_eq!(src.format(), &format);
        assert_eq!(src.fs_hz(), 8.0e6);
        let y = read_all(src.as_mut()).expect("read");
        // IF = fs/4 from the metadata; real samples ignore the Q sign.
        let raw: Vec<f32> = y
            .iter()
            .enumerate()
            .map(|(n, s)| (s * quarter_rotation(n).conj()).re)
            .collect();
        assert_eq!(raw, vec![1.5, -0.5, -1.5, 0.5]);
    }

    // Metadata beside a raw file named by its format.
    let raw = dir.path().join("cap.ci8");
    write_file(&raw, &SampleFormat::Ci8, &[c(1.0, 2.0); 10]);
    write_sigmf_meta(
        &raw,
        &SigmfMeta {
            invert_q: true,
            ..SigmfMeta::new("ci8", FS)
        },
    )
    .expect("meta");
    let mut src = open_source(&SourceConfig::new(&raw)).expect("open");
    assert_eq!(read_all(src.as_mut()).expect("read")[0], c(1.0, -2.0));
    // The metadata names its non-conforming data file (SigMF core:dataset), so the recording
    // opens from the .sigmf-meta too (as sigmf-python opens it).
    let meta_path = raw.with_extension("sigmf-meta");
    let text = std::fs::read_to_string(&meta_path).expect("meta text");
    assert!(text.contains(r#""core:dataset": "cap.ci8""#), "{text}");
    let mut src = open_source(&SourceConfig::new(&meta_path)).expect("open by its meta");
    assert_eq!(read_all(src.as_mut()).expect("read")[0], c(1.0, -2.0));
    // --fs overriding the metadata is allowed, with a warning.
    let src = open_source(&SourceConfig::new(&raw).with_fs_hz(2.0e6)).expect("open");
    assert!(
        src.warnings().iter().any(|w| w.contains("overrides")),
        "{:?}",
        src.warnings()
    );
}

#[test]
fn wav_one_and_two_channels() {
    let dir = tempfile::tempdir().expect("tempdir");
    for complex in [false, true] {
        let path = dir.path().join(format!("x{complex}.wav"));
        let x: Vec<Complex32> = (0..1001)
            .map(|k| c(k as f32 * 40.0 - 20000.0, 7.4 - k as f32))
            .collect();
        let mut w = create_wav_writer(&path, 4_000_000, complex).expect("create wav");
        w.write(&x).expect("write");
        w.write(&[c(40000.0, -40000.0)]).expect("write");
        let stats = w.finish().expect("finish");
        assert_eq!(stats.samples_written, 1002);
        assert_eq!(stats.clipped, if complex { 2 } else { 1 });

        let spec = hound::WavReader::open(&path)
            .expect("hound reads it")
            .spec();
        assert_eq!(
            (spec.channels, spec.bits_per_sample, spec.sample_rate),
            (1 + u16::from(complex), 16, 4_000_000)
        );

        let mut cfg = SourceConfig::new(&path);
        if !complex {
            cfg.if_hz = 1.0e6;
        }
        let mut src = open_source(&cfg).expect("open wav");
        assert_eq!(src.fs_hz(), 4.0e6);
        assert_eq!(src.format().is_complex(), complex);
        let y = read_all(src.as_mut()).expect("read");
        assert_eq!(y.len(), 1002);
        for (n, (g, s)) in y.iter().zip(x.iter()).enumerate() {
            let want = if complex {
                c(s.re.round(), s.im.round())
            } else {
                c(s.re.round(), 0.0) * quarter_rotation(n)
            };
            assert!((g - want).norm() < 0.05, "{n}: {g} vs {want}");
        }
        let last = y[1001]
            * if complex {
                c(1.0, 0.0)
            } else {
                quarter_rotation(1001).conj()
            };
        let want = if complex {
            c(32767.0, -32768.0)
        } else {
            c(32767.0, 0.0)
        };
        assert!((last - want).norm() < 0.05, "{last}");
    }
}

#[test]
fn inspect_notes_point_at_mistakes() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Real data stored as ci8 with Q = 0.
    let path = dir.path().join("realq0.ci8");
    let x: Vec<Complex32> = (0..4096)
        .map(|k| c(((k * 37 % 19) as f32) - 9.0, 0.0))
        .collect();
    write_file(&path, &SampleFormat::Ci8, &x);
    let r = inspect(&cfg(&path, &SampleFormat::Ci8), 1 << 20).expect("inspect");
    assert!(
        r.notes
            .iter()
            .any(|n| n.contains("real data read as complex")),
        "{:?}",
        r.notes
    );

    // cu8 noise read as ci8: values pile up at the extremes.
    let path = dir.path().join("u8.cu8");
    let x: Vec<Complex32> = (0..4096)
        .map(|k| {
            c(
                ((k * 7919) % 21) as f32 - 10.0,
                ((k * 104_729) % 17) as f32 - 8.0,
            )
        })
        .collect();
    write_file(&path, &SampleFormat::cu8(), &x);
    let r = inspect(&cfg(&path, &SampleFormat::Ci8), 1 << 20).expect("inspect");
    assert!(
        r.notes.iter().any(|n| n.contains("cu8 read as ci8")),
        "{:?}",
        r.notes
    );
    let r = inspect(&cfg(&path, &SampleFormat::cu8()), 1 << 20).expect("inspect");
    assert!(
        !r.notes.iter().any(|n| n.contains("mix-up")),
        "{:?}",
        r.notes
    );

    // Clipping.
    let path = dir.path().join("clip.ci8");
    let x: Vec<Complex32> = (0..4096)
        .map(|k| c(if k % 4 == 0 { 500.0 } else { 3.0 }, -2.0))
        .collect();
    write_file(&path, &SampleFormat::Ci8, &x);
    let r = inspect(&cfg(&path, &SampleFormat::Ci8), 1 << 20).expect("inspect");
    assert!(
        r.notes.iter().any(|n| n.contains("clipping")),
        "{:?}",
        r.notes
    );
    assert!((r.clip_fraction.expect("ci8 has extremes") - 0.125).abs() < 1e-9);
}

/// A file in `../shared/data`, or `None` (with a note) when it is absent outside CI.
fn shared_data(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data")
        .join(name);
    if path.is_file() {
        return Some(path);
    }
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!(
            "shared test data {} is missing, and CI=true requires it",
            path.display()
        );
    }
    eprintln!("skip: shared test data {} is absent", path.display());
    None
}

#[test]
fn pocketsdr_capture_is_a_2_bit_ci8_recording() {
    let Some(path) = shared_data("real/pocketsdr_L1_20211202_084700_4MHz_IQ.bin") else {
        return;
    };
    let cfg = SourceConfig {
        invert_q: true,
        ..SourceConfig::new(&path)
            .with_format(SampleFormat::Ci8)
            .with_fs_hz(4e6)
    };
    let r = inspect(&cfg, u64::MAX).expect("inspect");
    println!("{r}");
    assert_eq!(r.n_samples, 2_000_000);
    assert_eq!(r.analysed_samples, 2_000_000);
    assert!((r.duration_s - 0.5).abs() < 1e-12);
    for c in [&r.i, r.q.as_ref().expect("complex")] {
        match &c.histogram {
            Histogram::Values { values, .. } => assert_eq!(values, &vec![-3.0, -1.0, 1.0, 3.0]),
            h => panic!("expected exact values, got {h:?}"),
        }
    }
    assert!(
        r.notes.iter().any(|n| n.contains("only 4 distinct values")),
        "{:?}",
        r.notes
    );
    assert!(
        !r.notes.iter().any(|n| n.contains("real data")),
        "{:?}",
        r.notes
    );
    let json = serde_json::to_string(&r).expect("json");
    assert!(json.contains("\"n_samples\":2000000"));
}

#[test]
fn cttc_capture_is_16000_cf32_samples() {
    let Some(path) = shared_data("real/GSoC_CTTC_capture_2012_07_26_4Msps_4ms.dat") else {
        return;
    };
    let cfg = SourceConfig::new(&path)
        .with_format(SampleFormat::Cf32Le)
        .with_fs_hz(4e6);
    let mut src = open_source(&cfg).expect("open");
    assert_eq!(src.total_samples(), Some(16_000));
    let y = read_all(src.as_mut()).expect("read");
    assert_eq!(y.len(), 16_000);
    let rms = (y.iter().map(|s| s.norm_sqr()).sum::<f32>() / y.len() as f32).sqrt();
    assert!(
        rms > 100.0 && rms < 5000.0,
        "values are about +-700, rms {rms}"
    );
    let r = inspect(&cfg, u64::MAX).expect("inspect");
    println!("{r}");
    assert_eq!(r.n_samples, 16_000);
    assert!(matches!(r.i.histogram, Histogram::Binned { .. }));
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn default_packed_map_is_sign_magnitude() {
    assert_eq!(DEFAULT_PACKED2_MAP, [1.0, 3.0, -3.0, -1.0]);
}

/// Throughput of writing and reading 24 M samples per format (the simulator writes 240 M).
/// Run with `cargo test --release -p gpsrx-samples --test io -- --ignored --nocapture`.
#[test]
#[ignore = "timing, not a check"]
fn writer_and_reader_throughput() {
    let dir = tempfile::tempdir().expect("tempdir");
    let block: Vec<Complex32> = (0..1 << 16)
        .map(|k| c(((k * 37) % 11) as f32 - 5.0, ((k * 53) % 13) as f32 - 6.0))
        .collect();
    for format in [
        SampleFormat::Ci8,
        SampleFormat::ci2(),
        SampleFormat::Packed1Complex,
        SampleFormat::Cf32Le,
    ] {
        let path = dir.path().join(format.name());
        let t = std::time::Instant::now();
        let mut w = create_writer(&path, &format).expect("create");
        for _ in 0..366 {
            w.write(&block).expect("write");
        }
        let stats = w.finish().expect("finish");
        let tw = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let mut src = open_source(&cfg(&path, &format)).expect("open");
        let mut buf = vec![Complex32::default(); 1 << 16];
        let mut n = 0u64;
        loop {
            let (_, k) = src.read(&mut buf).expect("read");
            if k == 0 {
                break;
            }
            n += k as u64;
        }
        let tr = t.elapsed().as_secs_f64();
        assert_eq!(n, stats.samples_written);
        println!(
            "{format}: write {:.0} Msamples/s, read {:.0} Msamples/s",
            n as f64 / tw / 1e6,
            n as f64 / tr / 1e6
        );
    }
}

/// `ReaderSource`: the same samples as `FileSource` from any reader, skip/duration on a stream,
/// the errors a stream gives, and a named pipe through `open_source`.
mod stream {
    use std::io::{ErrorKind, Read};
    use std::path::Path;

    use gpsrx_samples::file_source::FileSource;
    use gpsrx_samples::{
        open_source, ReaderSource, SampleError, SampleFormat, SampleSource, SourceConfig,
    };
    use num_complex::Complex32;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    use super::{c, read_all, FS};

    /// A reader over bytes that returns 1..=`max` bytes per call (seeded) and now and then
    /// fails with `Interrupted`, as a pipe may.
    struct Trickle {
        data: Vec<u8>,
        at: usize,
        max: usize,
        rng: Xoshiro256PlusPlus,
    }

    impl Trickle {
        fn new(data: Vec<u8>, max: usize, seed: u64) -> Self {
            Trickle {
                data,
                at: 0,
                max,
                rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            }
        }
    }

    impl Read for Trickle {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            if self.rng.random_range(0..10) == 0 {
                return Err(std::io::Error::from(ErrorKind::Interrupted));
            }
            let n = self
                .rng
                .random_range(1..=self.max)
                .min(buf.len())
                .min(self.data.len() - self.at);
            buf[..n].copy_from_slice(&self.data[self.at..self.at + n]);
            self.at += n;
            Ok(n)
        }
    }

    /// Every `read` call's (first, n), and all samples, with buffer sizes drawn from `seed`.
    type Calls = (Vec<(u64, usize)>, Vec<Complex32>);

    fn read_in_random_blocks(
        src: &mut dyn SampleSource,
        max_block: usize,
        seed: u64,
    ) -> Result<Calls, SampleError> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut calls = Vec::new();
        let mut all = Vec::new();
        let mut buf = vec![Complex32::default(); max_block];
        loop {
            let len = rng.random_range(1..=max_block);
            let (first, n) = src.read(&mut buf[..len])?;
            calls.push((first, n));
            if n == 0 {
                return Ok((calls, all));
            }
            all.extend_from_slice(&buf[..n]);
        }
    }

    fn bits(x: &[Complex32]) -> Vec<(u32, u32)> {
        x.iter().map(|s| (s.re.to_bits(), s.im.to_bits())).collect()
    }

    fn random_bytes(n: usize, seed: u64) -> Vec<u8> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        (0..n).map(|_| rng.random::<u8>()).collect()
    }

    /// Reads `bytes` as a file and as a stream (trickled, or in large pieces) under `cfg`, with
    /// the same sequence of read sizes, and checks both deliver the same bits at the same
    /// indices, and the same warnings when read to the end.
    fn compare(bytes: &[u8], cfg: &SourceConfig, trickle_max: usize, block_max: usize, seed: u64) {
        std::fs::write(&cfg.path, bytes).expect("write");
        let what = format!(
            "{} skip {} dur {:?} if {} inv {}",
            cfg.format.as_ref().map_or("?".into(), SampleFormat::name),
            cfg.skip_s,
            cfg.duration_s,
            cfg.if_hz,
            cfg.invert_q
        );
        let mut file = FileSource::open(cfg).expect("open file");
        let reader = Trickle::new(bytes.to_vec(), trickle_max, seed ^ 0x5eed);
        let mut stream = ReaderSource::new(reader, cfg).expect("open stream");
        assert_eq!(stream.fs_hz(), file.fs_hz());
        assert_eq!(stream.format(), file.format());
        let (calls_f, x_f) = read_in_random_blocks(&mut file, block_max, seed).expect("file");
        let (calls_s, x_s) = read_in_random_blocks(&mut stream, block_max, seed).expect("stream");
        assert!(!x_f.is_empty(), "{what}");
        assert_eq!(calls_s, calls_f, "{what}: indices");
        assert!(bits(&x_s) == bits(&x_f), "{what}: samples differ");
        if cfg.duration_s.is_some() {
            assert_eq!(stream.total_samples(), file.total_samples(), "{what}");
        } else {
            assert_eq!(stream.total_samples(), None, "{what}");
            assert_eq!(stream.warnings(), file.warnings(), "{what}: warnings");
        }
    }

    #[test]
    fn stream_matches_file_source_bit_for_bit() {
        let dir = tempfile::tempdir().expect("tempdir");
        let cases: [(SampleFormat, f64, bool); 10] = [
            (SampleFormat::Ci8, 0.0, false),
            (SampleFormat::cu8(), 0.0, false),
            (SampleFormat::Ci16Le, -0.7e6, true),
            (SampleFormat::Cf32Le, 0.0, true),
            (SampleFormat::Ri8, 1.1e6, false),
            (SampleFormat::ci2(), 0.0, false),
            (SampleFormat::ci2(), 0.3e6, true),
            (SampleFormat::ri2(), 1.25e6, false),
            (SampleFormat::Packed1Complex, 0.0, false),
            (SampleFormat::Packed1Real { lsb_first: true }, 1.0e6, false),
        ];
        let spans = [
            (0u64, None),
            (37, Some(5000u64)),
            (1001, None),
            (3, Some(1)),
        ];
        for (k, (format, if_hz, invert_q)) in cases.into_iter().enumerate() {
            // Random bytes: every code, NaN and infinity for floats, a trailing partial
            // sample for the multi-byte formats.
            let bytes = random_bytes(40_003, k as u64);
            for (j, &(skip, dur)) in spans.iter().enumerate() {
                let cfg = SourceConfig {
                    if_hz,
                    invert_q,
                    skip_s: skip as f64 / FS,
                    duration_s: dur.map(|d| d as f64 / FS),
                    ..SourceConfig::new(dir.path().join(format!("rec{k}")))
                        .with_format(format.clone())
                        .with_fs_hz(FS)
                };
                compare(&bytes, &cfg, 7, 2000, (k * 10 + j) as u64);
            }
        }
    }

    #[test]
    fn stream_crosses_the_1_mib_buffer_like_a_file() {
        // 3 MiB of ci2 (6.3 M samples): reads larger than the buffer, pieces of up to 300 kB.
        let dir = tempfile::tempdir().expect("tempdir");
        let bytes = random_bytes(3 << 20, 99);
        for format in [SampleFormat::ci2(), SampleFormat::Ci16Le] {
            let cfg = SourceConfig {
                skip_s: 12_345.0 / FS,
                ..SourceConfig::new(dir.path().join(format.name()))
                    .with_format(format.clone())
                    .with_fs_hz(FS)
            };
            compare(&bytes, &cfg, 300_000, 3_000_000, 7);
        }
    }

    fn ci8_ramp(n: usize) -> Vec<u8> {
        (0..n)
            .flat_map(|k| [(k % 100) as u8, (k / 100) as u8])
            .collect()
    }

    fn ci8_cfg() -> SourceConfig {
        SourceConfig::new("-")
            .with_format(SampleFormat::Ci8)
            .with_fs_hz(FS)
    }

    #[test]
    fn stream_skip_and_duration() {
        let bytes = ci8_ramp(1000);
        let cfg = SourceConfig {
            skip_s: 100.0 / FS,
            duration_s: Some(50.0 / FS),
            ..ci8_cfg()
        };
        let mut src = ReaderSource::new(Trickle::new(bytes.clone(), 7, 1), &cfg).expect("new");
        assert_eq!(src.total_samples(), Some(50));
        let mut buf = vec![Complex32::default(); 64];
        let (first, n) = src.read(&mut buf).expect("read");
        assert_eq!((first, n), (100, 50));
        for (k, s) in buf[..n].iter().enumerate() {
            let idx = 100 + k;
            assert_eq!(*s, c((idx % 100) as f32, (idx / 100) as f32));
        }
        assert_eq!(src.read(&mut buf).expect("read"), (150, 0));
        assert!(src.warnings().is_empty(), "{:?}", src.warnings());

        // No duration: to the end, length unknown.
        let cfg = SourceConfig {
            skip_s: 990.0 / FS,
            ..ci8_cfg()
        };
        let mut src = ReaderSource::new(Trickle::new(bytes.clone(), 7, 2), &cfg).expect("new");
        assert_eq!(src.total_samples(), None);
        let y = read_all(&mut src).expect("read");
        assert_eq!(y.len(), 10);
        assert_eq!(y[0], c(90.0, 9.0));

        // A duration past the end: what is there, with a warning.
        let cfg = SourceConfig {
            skip_s: 900.0 / FS,
            duration_s: Some(500.0 / FS),
            ..ci8_cfg()
        };
        let mut src = ReaderSource::new(Trickle::new(bytes.clone(), 7, 3), &cfg).expect("new");
        assert_eq!(src.total_samples(), Some(500));
        assert_eq!(read_all(&mut src).expect("read").len(), 100);
        assert_eq!(src.total_samples(), Some(100));
        let w = src.warnings();
        assert!(
            w.iter()
                .any(|w| w.contains("standard input") && w.contains("read 100 samples")),
            "{w:?}"
        );

        // A skip beyond the end, and an empty stream, fail at the first read.
        let cfg = SourceConfig {
            skip_s: 1000.0 / FS,
            ..ci8_cfg()
        };
        let mut src = ReaderSource::new(Trickle::new(bytes, 7, 4), &cfg).expect("new");
        let e = src.read(&mut buf).expect_err("skip beyond the end");
        assert!(matches!(e, SampleError::SkipBeyondEnd { .. }), "{e}");
        assert!(e.to_string().contains("1000 samples"), "{e}");
        let mut src = ReaderSource::new(Trickle::new(vec![7], 7, 5), &ci8_cfg()).expect("new");
        let e = src.read(&mut buf).expect_err("empty");
        assert!(matches!(e, SampleError::EmptyFile { .. }), "{e}");
        assert!(e.to_string().contains("standard input is empty"), "{e}");

        // Bad times are refused up front, like for a file.
        let e = ReaderSource::new(
            std::io::empty(),
            &SourceConfig {
                skip_s: -1.0,
                ..ci8_cfg()
            },
        )
        .expect_err("negative skip");
        assert!(e.to_string().contains("skip = -1"), "{e}");
    }

    #[test]
    fn stream_needs_format_and_rate() {
        let err = |cfg: &SourceConfig| match open_source(cfg) {
            Ok(_) => panic!("expected an error for {cfg:?}"),
            Err(e) => e,
        };
        let e = err(&SourceConfig::new("-"));
        assert!(matches!(e, SampleError::StreamNeedsFormatAndRate { .. }));
        let msg = e.to_string();
        assert!(
            msg.contains(
                "reading from standard input needs the sample format and the sampling rate"
            ) && msg.ends_with("give both"),
            "{msg}"
        );
        let msg = err(&SourceConfig::new("-").with_format(SampleFormat::Ci8)).to_string();
        assert!(msg.ends_with("give the sampling rate"), "{msg}");
        let msg = err(&SourceConfig::new("-").with_fs_hz(FS)).to_string();
        assert!(msg.ends_with("give the sample format"), "{msg}");

        // Rate and IF are checked as for a file.
        let msg = err(&SourceConfig {
            fs_hz: Some(1.0e6),
            ..ci8_cfg()
        })
        .to_string();
        assert!(
            msg.contains("too low for GPS L1 C/A") && msg.contains("standard input"),
            "{msg}"
        );
        let ri8 = ci8_cfg().with_format(SampleFormat::Ri8);
        let e = err(&ri8);
        assert!(matches!(e, SampleError::IfOutOfRange { .. }), "{e}");
        assert!(e.to_string().contains("0 < IF < fs/2"), "{e}");

        // Opening standard input reads nothing yet.
        let src = open_source(&ci8_cfg()).expect("stdin");
        assert_eq!((src.fs_hz(), src.total_samples()), (FS, None));
    }

    #[test]
    fn stream_trailing_partial_sample_is_dropped_with_a_warning() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("odd.ci16");
        let bytes = vec![1, 0, 2, 0, 3, 0, 4, 0, 9, 9, 9];
        std::fs::write(&path, &bytes).expect("write");
        let cfg = SourceConfig::new(&path)
            .with_format(SampleFormat::Ci16Le)
            .with_fs_hz(FS);
        let mut src = ReaderSource::new(Trickle::new(bytes, 7, 11), &cfg).expect("new");
        assert!(src.warnings().is_empty());
        assert_eq!(
            read_all(&mut src).expect("read"),
            vec![c(1.0, 2.0), c(3.0, 4.0)]
        );
        let w = src.warnings();
        assert!(w.iter().any(|w| w.contains("last 3 byte(s)")), "{w:?}");
        let file = FileSource::open(&cfg).expect("file");
        assert_eq!(w, file.warnings());
    }

    fn mkfifo(path: &Path) -> bool {
        match std::process::Command::new("mkfifo").arg(path).status() {
            Ok(s) if s.success() => true,
            other => {
                eprintln!("skip: cannot run mkfifo ({other:?})");
                false
            }
        }
    }

    #[cfg(unix)]
    #[test]
    fn fifo_streams_through_open_source() {
        use std::io::Write;

        let dir = tempfile::tempdir().expect("tempdir");
        let fifo = dir.path().join("live.ci2");
        if !mkfifo(&fifo) {
            return;
        }
        let bytes = random_bytes(300_001, 21);
        let cfg = SourceConfig {
            skip_s: 5.0 / FS,
            if_hz: 0.25e6,
            ..SourceConfig::new(&fifo)
                .with_format(SampleFormat::ci2())
                .with_fs_hz(FS)
        };

        // Configuration errors come before the pipe is opened (which would wait for a writer).
        let e = match open_source(&SourceConfig::new(&fifo)) {
            Ok(_) => panic!("a pipe without --format must fail"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("live.ci2") && e.contains("needs the sample format and the sampling rate"),
            "{e}"
        );
        let meta = dir.path().join("live.sigmf-meta");
        if !mkfifo(&meta) {
            return;
        }
        let e = match open_source(&SourceConfig {
            path: meta,
            ..cfg.clone()
        }) {
            Ok(_) => panic!("SigMF metadata is file-only"),
            Err(e) => e,
        };
        assert!(matches!(e, SampleError::NotStreamable { .. }), "{e}");

        let writer = {
            let (fifo, bytes) = (fifo.clone(), bytes.clone());
            std::thread::spawn(move || -> std::io::Result<()> {
                let mut f = std::fs::OpenOptions::new().write(true).open(&fifo)?;
                for piece in bytes.chunks(70_001) {
                    f.write_all(piece)?;
                    f.flush()?;
                    std::thread::sleep(std::time::Duration::from_millis(5));
                }
                Ok(())
            })
        };
        let mut src = open_source(&cfg).expect("open the pipe");
        assert_eq!(src.total_samples(), None);
        let streamed = read_all(src.as_mut());
        writer
            .join()
            .expect("writer thread")
            .expect("write the pipe");
        let streamed = streamed.expect("read the pipe");

        let plain = dir.path().join("plain.ci2");
        std::fs::write(&plain, &bytes).expect("write");
        let mut file = open_source(&SourceConfig {
            path: plain,
            ..cfg.clone()
        })
        .expect("open the file");
        let expected = read_all(file.as_mut()).expect("read the file");
        assert_eq!(streamed.len(), 600_002 - 5);
        assert!(bits(&streamed) == bits(&expected), "pipe and file differ");
    }
}

#[test]
fn sigmf_datetime_is_read_as_utc_and_round_trips() {
    use gpsrx_nav::GpsTime;
    // 2022-01-01 05:29:42 UTC = 05:30:00 GPS time = week 2190, TOW 538200.
    let t = parse_datetime_utc("2022-01-01T05:29:42Z").expect("SigMF form");
    assert_eq!((t.week, t.tow_s), (2190, 538_200.0));
    for (text, tow) in [
        ("2022-01-01T05:29:42.250Z", 538_200.25),
        ("2022-01-01T14:29:42+09:00", 538_200.0),
        ("2022-01-01T00:29:42-0500", 538_200.0),
        ("2022-01-01 05:29:42", 538_200.0),
    ] {
        let t = parse_datetime_utc(text).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(t.week, 2190, "{text}");
        assert!((t.tow_s - tow).abs() < 1e-9, "{text}: {}", t.tow_s);
    }
    for bad in [
        "",
        "2022-01-01",
        "2022-13-01T00:00:00Z",
        "2022-01-01T25:00:00Z",
        "2022-01-01T00:00:00+9",
        "01/01/2022 00:00:00",
        "2022-01-01T00:00:0xZ",
        "2022-01-01T00:00:00.1e3Z",
        "2022-01-01T\u{e9}0:00:00Z",
    ] {
        let e = parse_datetime_utc(bad).expect_err(bad);
        assert!(e.contains("ISO 8601"), "{e}");
    }
    let t = GpsTime::new(2190, 538_200.123_456_7);
    assert_eq!(format_datetime_utc(t), "2022-01-01T05:29:42.123457Z");
    let back = parse_datetime_utc(&format_datetime_utc(t)).expect("round trip");
    assert!(back.diff_s(t).abs() < 1e-6);

    // Written in the first capture, read back; the date of a later sample_start is moved back
    // to the first sample; an unreadable date is an error naming the file.
    let dir = tempfile::tempdir().expect("tempdir");
    let raw = dir.path().join("cap.ci8");
    write_file(&raw, &SampleFormat::Ci8, &[c(1.0, 2.0); 10]);
    write_sigmf_meta(
        &raw,
        &SigmfMeta {
            datetime: Some("2022-01-01T05:29:42Z".into()),
            ..SigmfMeta::new("ci8", FS)
        },
    )
    .expect("meta");
    let meta = read_sigmf_meta(&raw.with_extension("sigmf-meta")).expect("read");
    assert_eq!(meta.datetime.as_deref(), Some("2022-01-01T05:29:42Z"));
    let start = recording_start(&raw).expect("readable").expect("dated");
    assert_eq!((start.time.week, start.time.tow_s), (2190, 538_200.0));
    assert!(start.origin.contains("core:datetime"), "{}", start.origin);
    let later = SigmfMeta {
        capture_sample_start: (2.0 * FS) as u64,
        ..meta.clone()
    };
    let (t, _) = later.start_time().expect("readable").expect("dated");
    assert!((t.tow_s - 538_198.0).abs() < 1e-9, "{}", t.tow_s);
    write_sigmf_meta(
        &raw,
        &SigmfMeta {
            datetime: Some("yesterday".into()),
            ..SigmfMeta::new("ci8", FS)
        },
    )
    .expect("meta");
    let e = recording_start(&raw).expect_err("not a date").to_string();
    assert!(
        e.contains("cap.sigmf-meta") && e.contains("yesterday"),
        "{e}"
    );
    assert!(recording_start(Path::new("-")).expect("stdin").is_none());
}

/// Samples handed over as stored (`read_integer`) are the values `read` gives, across the
/// 1 MiB read chunks and in uneven requests, for ci8 and ci16; with a non-zero IF or an
/// inverted Q they are offered converted, as ci16 within half a unit of `read`'s values times
/// the gain.
#[test]
fn integer_reads_give_the_values_read_gives() {
    use gpsrx_samples::{IntegerFormat, IntegerSamplesMut};
    let dir = tempfile::tempdir().expect("tempdir");
    let n = 700_001; // ci8: 1.4 MB, ci16: 2.8 MB -- both span several chunks.
    for (format, expect) in [
        (SampleFormat::Ci8, IntegerFormat::Ci8),
        (SampleFormat::Ci16Le, IntegerFormat::Ci16),
    ] {
        let path = dir.path().join(format!("x.{}", format.name()));
        let full = format.full_scale();
        let samples: Vec<Complex32> = (0..n)
            .map(|k| {
                let a = (k as f32 * 0.37).sin() * full;
                let b = (k as f32 * 0.11).cos() * full;
                c(a.round(), b.round())
            })
            .collect();
        let mut w = create_writer(&path, &format).expect("create writer");
        w.write(&samples).expect("write");
        w.finish().expect("finish");
        let cfg = SourceConfig::new(&path)
            .with_format(format.clone())
            .with_fs_hz(FS);
        let mut by_read = open_source(&cfg).expect("open");
        let mut by_int = open_source(&cfg).expect("open");
        assert_eq!(by_int.integer_format(), Some(expect));
        let mut got = Vec::new();
        let mut sizes = [1usize, 333_333, 4096, 999_999].into_iter().cycle();
        loop {
            let size = sizes.next().unwrap_or(4096);
            let (first, m) = match expect {
                IntegerFormat::Ci8 => {
                    let mut room = vec![[0i8; 2]; size];
                    let r = by_int.read_integer(IntegerSamplesMut::Ci8(&mut room));
                    let (first, m) = r.expect("integer read");
                    got.extend(
                        room[..m]
                            .iter()
                            .map(|&[i, q]| c(f32::from(i), f32::from(q))),
                    );
                    (first, m)
                }
                IntegerFormat::Ci16 => {
                    let mut room = vec![[0i16; 2]; size];
                    let r = by_int.read_integer(IntegerSamplesMut::Ci16(&mut room));
                    let (first, m) = r.expect("integer read");
                    got.extend(
                        room[..m]
                            .iter()
                            .map(|&[i, q]| c(f32::from(i), f32::from(q))),
                    );
                    (first, m)
                }
            };
            assert_eq!(first as usize + m, got.len(), "{format}: indices run on");
            if m == 0 {
                break;
            }
        }
        let mut want = vec![c(0.0, 0.0); n + 10];
        let (_, m) = by_read.read(&mut want).expect("read");
        want.truncate(m);
        assert_eq!(got.len(), n, "{format}");
        assert!(got == want, "{format}: integer read differs from read()");
        assert_eq!(got, samples, "{format}: not the samples written");
        assert_eq!(by_int.integer_gain(), 1.0, "{format}: held as stored");
        // What needs converting (mixed from an IF, Q inverted) is offered as ci16, `read`'s
        // values times the format's gain, rounded; never as ci8.
        for cfg in [
            SourceConfig {
                if_hz: 1.0e6,
                ..cfg.clone()
            },
            SourceConfig {
                invert_q: true,
                ..cfg.clone()
            },
        ] {
            let mut s = open_source(&cfg).expect("open");
            assert_eq!(s.integer_format(), Some(IntegerFormat::Ci16));
            let gain = gpsrx_samples::held_gain(&format).expect("integer format");
            assert_eq!(s.integer_gain(), gain);
            let mut room = [[0i8; 2]; 4];
            assert!(matches!(
                s.read_integer(IntegerSamplesMut::Ci8(&mut room)),
                Err(SampleError::NoIntegerRead { .. })
            ));
            let mut held = vec![[0i16; 2]; 5000];
            let (first, m) = s
                .read_integer(IntegerSamplesMut::Ci16(&mut held))
                .expect("converted read");
            let mut f = open_source(&cfg).expect("open");
            let mut want = vec![c(0.0, 0.0); 5000];
            assert_eq!(f.read(&mut want).expect("read"), (first, m));
            for (h, w) in held.iter().zip(&want) {
                for (hv, wv) in [(h[0], w.re), (h[1], w.im)] {
                    let exact = (wv * gain).clamp(-32768.0, 32767.0);
                    assert!(
                        (f32::from(hv) - exact).abs() <= 0.5,
                        "{format}: {hv} for {exact}"
                    );
                }
            }
        }
    }
    let cf = dir.path().join("x.cf32");
    let mut w = create_writer(&cf, &SampleFormat::Cf32Le).expect("create writer");
    w.write(&[c(1.0, 2.0); 8]).expect("write");
    w.finish().expect("finish");
    let cfg = SourceConfig::new(&cf)
        .with_format(SampleFormat::Cf32Le)
        .with_fs_hz(FS);
    assert_eq!(open_source(&cfg).expect("open").integer_format(), None);
}
