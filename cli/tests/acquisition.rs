//! Acquisition checked on real captures (../shared/data/real, values measured by others) and on
//! the simulator (truth_sv.csv), plus its false-alarm rate on noise.
//!
//! Test data: when ../shared/data is missing the real-file tests print a note and pass, except
//! with CI=true, where they fail.

use clap::Parser;
use gpsrx_cli::commands::acquire::{acquire, render_table, AcquireArgs, AcquireReport};
use gpsrx_dsp::acquisition::{stats, AcqConfig, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_samples::sim::{Scenario, Simulator};
use num_complex::Complex32;
use std::path::{Path, PathBuf};

#[derive(Debug, Parser)]
struct Cmd {
    #[command(flatten)]
    args: AcquireArgs,
}

/// Parses `gpsrx acquire` arguments exactly as the command line would.
fn args(list: &[&str]) -> AcquireArgs {
    let argv = std::iter::once("acquire").chain(list.iter().copied());
    match Cmd::try_parse_from(argv) {
        Ok(c) => c.args,
        Err(e) => panic!("arguments {list:?}: {e}"),
    }
}

fn run(list: &[&str]) -> AcquireReport {
    acquire(&args(list)).unwrap_or_else(|e| panic!("acquire {list:?}: {e:#}"))
}

/// A file of ../shared/data, or None (skip) when the data folder is absent; with CI=true a
/// missing file is a failure.
fn data_file(rel: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data")
        .join(rel);
    if p.is_file() {
        return Some(p);
    }
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!("test data {} missing (CI=true)", p.display());
    }
    eprintln!("skipping: test data {} not found", p.display());
    None
}

/// Circular distance between code phases, samples.
fn code_err(a: f64, b: f64, period: f64) -> f64 {
    let d = (a - b).rem_euclid(period);
    d.min(period - d)
}

/// (PRN, code delay in samples, Doppler in Hz) from the README tables.
fn check_table(report: &AcquireReport, expected: &[(u8, f64, f64)], exclusive: bool) {
    let detected: Vec<u8> = report
        .rows
        .iter()
        .filter(|r| r.detected)
        .map(|r| r.prn.get())
        .collect();
    for &(prn, delay, doppler) in expected {
        let Some(r) = report
            .rows
            .iter()
            .find(|r| r.prn.get() == prn && r.detected)
        else {
            panic!("PRN {prn} not detected; detected {detected:?}");
        };
        assert!(
            code_err(r.code_phase_samples, delay, 4000.0) <= 1.0,
            "PRN {prn}: code delay {:.2} vs {delay}",
            r.code_phase_samples
        );
        assert!(
            (r.doppler_hz - doppler).abs() <= 50.0,
            "PRN {prn}: Doppler {:.1} vs {doppler}",
            r.doppler_hz
        );
    }
    if exclusive {
        let mut want: Vec<u8> = expected.iter().map(|e| e.0).collect();
        let mut got = detected.clone();
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, want, "exactly the reference PRNs must be detected");
    }
}

#[test]
fn real_hello_world_prn1() {
    let Some(f) = data_file("real/GPS_L1_CA_ID_1_Fs_4Msps_2ms.dat") else {
        return;
    };
    let f = f.to_string_lossy().to_string();
    // 2 ms only: the default 10 non-coherent blocks shrink to 2 (reported as a warning).
    let report = run(&[&f, "--format", "cf32_le", "--fs", "4e6"]);
    println!("{}", render_table(&report, true));
    assert_eq!(report.noncoherent, 2);
    // --json prints the detected rows as an array of objects with these fields.
    let json = serde_json::to_value(&report.rows).unwrap_or_else(|e| panic!("{e}"));
    for key in [
        "prn",
        "code_phase_samples",
        "doppler_hz",
        "cn0_dbhz",
        "metric",
        "peak_ratio",
    ] {
        assert!(
            json[0].get(key).is_some(),
            "JSON row lacks {key}: {}",
            json[0]
        );
    }
    // The README says 524; the correlation triangle here is symmetric about 523 to 0.2 %
    // (lags 522 and 524 equal), so in the README's own convention ("sample index where a C/A
    // period starts", counted from 0) the period starts at 523: its 524 counts from 1. Checked
    // as "within 1 sample" with 0.05 sample of interpolation slack.
    let r = report.rows.iter().find(|r| r.prn.get() == 1 && r.detected);
    let Some(r) = r else {
        panic!("PRN 1 not detected")
    };
    assert!(
        code_err(r.code_phase_samples, 524.0, 4000.0) <= 1.05,
        "{r:?}"
    );
    assert!(
        code_err(r.code_phase_samples, 523.0, 4000.0) <= 0.1,
        "{r:?}"
    );
    assert!((r.doppler_hz - 1680.0).abs() <= 50.0, "{r:?}");
    // The signal is practically noise-free, so every other PRN's grid holds only its
    // deterministic cross-correlation with PRN 1 (the Gamma noise model does not apply): those
    // peaks pass the threshold and are all recognised as cross-correlations of PRN 1.
    for r in report.rows.iter().filter(|r| r.prn.get() != 1) {
        assert!(!r.detected, "{r:?}");
    }
}

/// PocketSDR capture at the default settings: the five satellites of the README table, plus
/// PRN 18, which the table omits but which is a real satellite (not a false alarm):
/// - it is found at the same Doppler (+2725 Hz) and a code phase drifting by -0.7 sample per
///   100 ms, the code Doppler of +2725 Hz (1.77 chip/s), in four disjoint 100-ms windows;
///   with 10 ms x 15 its metric is 45 to 51 against a threshold of 3.8, peak ratio 9 to 11;
/// - the broadcast ephemerides of brdc0010.22n taken one month later at the sidereal repeat
///   time (2022-01-01 06:49 UTC for 2021-12-02 08:47 UTC, Tokyo) predict PRN 18 at 16 deg
///   elevation and +2407 Hz, the same +300 Hz from its measured Doppler as the other five (the
///   front-end clock plus the ground-track drift);
/// - its C/N0 of 38 dB-Hz fits a satellite that low.
///
/// A detector that missed it at the default settings would be 4 dB less sensitive than this
/// one for nothing; the test therefore allows exactly these six.
#[test]
fn real_pocketsdr_default_settings() {
    let Some(f) = data_file("real/pocketsdr_L1_20211202_084700_4MHz_IQ.bin") else {
        return;
    };
    let f = f.to_string_lossy().to_string();
    let report = run(&[&f, "--format", "ci8", "--fs", "4e6", "--invert-q"]);
    println!("{}", render_table(&report, false));
    let table = [
        (31, 1159.0, -205.0, 49.0),
        (26, 3599.0, 650.0, 48.0),
        (29, 1653.0, -2215.0, 43.0),
        (16, 3958.0, 2575.0, 43.0),
        (32, 2766.0, -3280.0, 42.0),
    ];
    let mut expected: Vec<(u8, f64, f64)> = table.iter().map(|t| (t.0, t.1, t.2)).collect();
    check_table(&report, &expected, false);
    expected.push((18, 2440.4, 2725.0));
    check_table(&report, &expected, true);
    // C/N0: the README's values are +-2 dB and ours has its own estimator and noise (100
    // prompts: +-0.3 dB at 43 dB-Hz), so allow 3 dB.
    for &(prn, _, _, cn0) in &table {
        let r = report.rows.iter().find(|r| r.prn.get() == prn);
        let est = r.and_then(|r| r.cn0_dbhz).unwrap_or(0.0);
        assert!(
            (est - cn0).abs() <= 3.0,
            "PRN {prn}: C/N0 {est:.1} vs {cn0}"
        );
    }
    // PRN 18 again 300 ms later with the weak-signal setting: same Doppler, code phase moved by
    // the code Doppler (-0.69 sample per 100 ms).
    let later = run(&[
        &f,
        "--format",
        "ci8",
        "--fs",
        "4e6",
        "--invert-q",
        "--skip",
        "0.3",
        "--coherent-ms",
        "10",
        "--noncoherent",
        "15",
        "--prn",
        "18",
    ]);
    let r = &later.rows[0];
    assert!(r.detected && r.metric > 5.0 * r.threshold, "{r:?}");
    assert!((r.doppler_hz - 2725.0).abs() < 20.0, "{r:?}");
    assert!(
        code_err(r.code_phase_samples, 2440.4 - 3.0 * 0.69, 4000.0) < 1.5,
        "{r:?}"
    );
}

#[test]
fn real_cttc_large_lo_offset() {
    let Some(f) = data_file("real/GSoC_CTTC_capture_2012_07_26_4Msps_4ms.dat") else {
        return;
    };
    let f = f.to_string_lossy().to_string();
    let report = run(&[
        &f,
        "--format",
        "cf32_le",
        "--fs",
        "4e6",
        "--doppler-max",
        "15000",
    ]);
    println!("{}", render_table(&report, false));
    let expected = [
        (29, 3705.0, 9725.0),
        (25, 686.0, 8995.0),
        (31, 1949.0, 11785.0),
        (12, 510.0, 7180.0),
        (2, 873.0, 8080.0),
    ];
    check_table(&report, &expected, false);
}

// ---------------------------------------------------------------------------------------------
// Simulated signals: detection rates and accuracy against truth_sv.csv.

const FS: f64 = 4.0e6;

/// The recording's sample format and rates.
#[derive(Debug, Clone, Copy)]
struct Output {
    format: &'static str,
    fs_hz: f64,
    if_hz: f64,
}

/// ci8 complex baseband at 4 MHz (the default of these tests).
const CI8_4MHZ: Output = Output {
    format: "ci8",
    fs_hz: FS,
    if_hz: 0.0,
};

/// A static receiver in Seoul on 2022-01-01, ci8 at 4 MHz, perfect clock, every satellite above
/// 5 deg at `cn0` dB-Hz. Different `k` start 15 min apart (other satellites, Dopplers and code
/// phases) with another noise seed.
fn scenario(k: u64, cn0: f64, duration_s: f64) -> Scenario {
    scenario_as(k, cn0, duration_s, CI8_4MHZ)
}

/// [`scenario`] written as `out`.
fn scenario_as(k: u64, cn0: f64, duration_s: f64, out: Output) -> Scenario {
    let text = format!(
        r#"
duration_s = {duration_s}
seed = {seed}
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = {tow}
[output]
format = "{format}"
fs_hz = {fs_hz}
if_hz = {if_hz}
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[satellites]
elevation_mask_deg = 5.0
cn0_all_dbhz = {cn0}
"#,
        seed = 1000 + k,
        tow = 538_194.0 + 900.0 * k as f64,
        format = out.format,
        fs_hz = out.fs_hz,
        if_hz = out.if_hz,
    );
    Scenario::from_toml(&text).unwrap_or_else(|e| panic!("scenario: {e}"))
}

/// Truth of one satellite at t = 0.
#[derive(Debug, Clone, Copy)]
struct Truth {
    prn: u8,
    code_phase_samples: f64,
    doppler_hz: f64,
}

/// Reads the t = 0 rows of truth_sv.csv of a recording at `fs` Hz; the code phase in samples is
/// where the next C/A period starts: (1023 - code_phase_chips) / code_rate * fs.
fn truth_at_start(path: &Path, fs: f64) -> Vec<Truth> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (t, prn, on, chips, rate, dop) = (
        col("t_s"),
        col("prn"),
        col("signal_on"),
        col("code_phase_chips"),
        col("code_rate_chips_s"),
        col("doppler_hz"),
    );
    let num = |v: &str| -> f64 { v.parse().unwrap_or_else(|e| panic!("{v}: {e}")) };
    lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| num(f[t]) == 0.0 && f[on] == "1")
        .map(|f| Truth {
            prn: num(f[prn]) as u8,
            code_phase_samples: (1023.0 - num(f[chips])).rem_euclid(1023.0) / num(f[rate]) * fs,
            doppler_hz: num(f[dop]),
        })
        .collect()
}

/// Simulates scenario `k` into a temporary folder; returns the folder, the recording and the
/// truth at t = 0.
fn simulate(k: u64, cn0: f64, duration_s: f64) -> (tempfile::TempDir, String, Vec<Truth>) {
    simulate_as(k, cn0, duration_s, CI8_4MHZ)
}

/// [`simulate`] written as `out`.
fn simulate_as(
    k: u64,
    cn0: f64,
    duration_s: f64,
    out: Output,
) -> (tempfile::TempDir, String, Vec<Truth>) {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&scenario_as(k, cn0, duration_s, out), Path::new("."))
        .unwrap_or_else(|e| panic!("{e}"));
    let rep = sim
        .run(dir.path(), &|_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    let truth = truth_at_start(&rep.truth_sv_path, out.fs_hz);
    (dir, rep.data_path.to_string_lossy().to_string(), truth)
}

/// Trial statistics over several simulated recordings.
#[derive(Debug, Default)]
struct Tally {
    trials: usize,
    hits: usize,
    false_alarms: usize,
    absent_searched: usize,
    doppler_err: Vec<f64>,
    cn0: Vec<f64>,
}

impl Tally {
    /// Scores one report against the truth: a hit is a detection within 1 sample of code phase
    /// and half a Doppler bin of Doppler; any detection of a PRN not simulated is a false alarm.
    fn score(&mut self, report: &AcquireReport, truth: &[Truth]) {
        for t in truth {
            self.trials += 1;
            let Some(r) = report.rows.iter().find(|r| r.prn.get() == t.prn) else {
                continue;
            };
            let code_ok = code_err(r.code_phase_samples, t.code_phase_samples, FS * 1e-3) <= 1.0;
            let dop_ok = (r.doppler_hz - t.doppler_hz).abs() <= report.doppler_step_hz / 2.0;
            if r.detected && code_ok && dop_ok {
                self.hits += 1;
                self.doppler_err.push(r.doppler_hz - t.doppler_hz);
                self.cn0.extend(r.cn0_dbhz);
            } else {
                println!("  miss: {t:?} -> {r:?}");
            }
        }
        for r in report
            .rows
            .iter()
            .filter(|r| !truth.iter().any(|t| t.prn == r.prn.get()))
        {
            self.absent_searched += 1;
            if r.detected {
                self.false_alarms += 1;
                println!("  false alarm: {r:?}");
            }
        }
    }

    fn summary(&self, what: &str) -> (f64, f64, f64) {
        let n = self.doppler_err.len().max(1) as f64;
        let rms = (self.doppler_err.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
        let max = self.doppler_err.iter().fold(0.0f64, |m, e| m.max(e.abs()));
        let cn0 = self.cn0.iter().sum::<f64>() / self.cn0.len().max(1) as f64;
        println!(
            "{what}: {}/{} detected ({:.1} %), Doppler error rms {rms:.1} Hz max {max:.1} Hz, \
             mean C/N0 {cn0:.2} dB-Hz, false alarms {} in {} absent-PRN searches",
            self.hits,
            self.trials,
            100.0 * self.hits as f64 / self.trials.max(1) as f64,
            self.false_alarms,
            self.absent_searched
        );
        (rms, max, cn0)
    }
}

/// 40 dB-Hz, default settings (1 ms x 10, +-5 kHz, all 32 PRNs), 10 recordings of 7 to 10
/// satellites each (about 85 trials). Requirement: >= 95 % detected with code phase within 1
/// sample and Doppler within half a bin of the truth. With 85 trials a detector with a true
/// rate of 99 % fails this with probability below 0.3 %, and one with 90 % passes with
/// probability below 2 %, so the count separates the two. The same runs give 2,000-odd searches
/// of absent PRNs (all in the presence of 8 signals: cross-correlations included), which must
/// give no false alarm, and the refined Doppler, which must be within 25 Hz (the pull-in of a
/// tracking loop), and the C/N0, whose mean must be within 1 dB of 40.
#[test]
fn simulated_40dbhz_default_settings() {
    let mut tally = Tally::default();
    for k in 0..10 {
        let (_dir, file, truth) = simulate(k, 40.0, 0.12);
        let report = run(&[&file, "--format", "ci8", "--fs", "4e6"]);
        tally.score(&report, &truth);
    }
    let (_, max_err, cn0) = tally.summary("40 dB-Hz, 1 ms x 10");
    assert!(tally.hits * 100 >= tally.trials * 95, "{tally:?}");
    assert_eq!(tally.false_alarms, 0);
    assert!(max_err < 25.0, "refined Doppler error up to {max_err} Hz");
    assert!((cn0 - 40.0).abs() < 1.0, "mean C/N0 {cn0}");
}

/// 32 dB-Hz with the documented weak-signal setting: 10 ms coherent x 10 non-coherent (100 ms,
/// 50 Hz bins, with the half-offset bit-edge pass). Only the simulated PRNs are searched, to
/// keep the run short (the cost is 2 passes x 201 bins x 10 blocks of 4000-point inverse FFTs
/// per PRN). 10 recordings, about 85 trials; requirement >= 90 %.
#[test]
fn simulated_32dbhz_weak_signal_setting() {
    let mut tally = Tally::default();
    for k in 0..10 {
        let (_dir, file, truth) = simulate(k, 32.0, 0.21);
        let prns: Vec<String> = truth.iter().map(|t| t.prn.to_string()).collect();
        let prns = prns.join(",");
        let report = run(&[
            &file,
            "--format",
            "ci8",
            "--fs",
            "4e6",
            "--coherent-ms",
            "10",
            "--noncoherent",
            "10",
            "--prn",
            &prns,
        ]);
        tally.score(&report, &truth);
    }
    let (_, max_err, cn0) = tally.summary("32 dB-Hz, 10 ms x 10");
    assert!(tally.hits * 100 >= tally.trials * 90, "{tally:?}");
    assert!(max_err < 25.0, "refined Doppler error up to {max_err} Hz");
    assert!((cn0 - 32.0).abs() < 1.5, "mean C/N0 {cn0}");
}

/// Front-end rates other than 4 MHz, against the simulator's truth: 16.368 MHz real IF (ri8,
/// IF 4.092 MHz, the MAX2769/SiGe configuration: mixed down, 16368 samples per period searched
/// in its 4096 lowest bins) and 24 MHz complex (ci8). Every satellite simulated (40 dB-Hz) is
/// found by the default 1 ms x 10 search, its code phase within half a sample at 4.092 MHz
/// (1/8 chip, half a 4 MHz search lag), its Doppler within 25 Hz after refinement (a tenth of
/// the 250 Hz half bin), and no PRN is reported that was not simulated.
#[test]
fn simulated_front_end_rates_real_if_and_complex() {
    let cases = [
        Output {
            format: "ri8",
            fs_hz: 16.368e6,
            if_hz: 4.092e6,
        },
        Output {
            format: "ci8",
            fs_hz: 24.0e6,
            if_hz: 0.0,
        },
    ];
    for (k, out) in [(4u64, cases[0]), (5, cases[1])] {
        let (_dir, file, truth) = simulate_as(k, 40.0, 0.12, out);
        let (fs, if_hz) = (out.fs_hz.to_string(), out.if_hz.to_string());
        let report = run(&[&file, "--format", out.format, "--fs", &fs, "--if", &if_hz]);
        let period = out.fs_hz * 1e-3;
        for t in &truth {
            let r = report
                .rows
                .iter()
                .find(|r| r.prn.get() == t.prn)
                .unwrap_or_else(|| panic!("{out:?}: G{:02} simulated, not found", t.prn));
            let chips =
                code_err(r.code_phase_samples, t.code_phase_samples, period) * 1.023e6 / out.fs_hz;
            println!(
                "{} {:.3} MHz G{:02}: code error {chips:.4} chip, Doppler error {:.2} Hz, \
                 C/N0 {:?}",
                out.format,
                out.fs_hz * 1e-6,
                t.prn,
                r.doppler_hz - t.doppler_hz,
                r.cn0_dbhz
            );
            assert!(r.detected, "{out:?}: {r:?}");
            assert!(chips <= 0.125, "{out:?}: {chips} chip {r:?}");
            assert!((r.doppler_hz - t.doppler_hz).abs() < 25.0, "{out:?}: {r:?}");
        }
        for r in report.rows.iter().filter(|r| r.detected) {
            assert!(
                truth.iter().any(|t| t.prn == r.prn.get()),
                "{out:?}: {} reported, not simulated",
                r.prn
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Noise only: false alarms and the calibration of the statistic.

/// Complex Gaussian noise of 20 LSB per component quantised like ci8 (SplitMix64 + Box-Muller,
/// seeded, so every run sees the same numbers).
fn ci8_noise(seed: u64, n: usize) -> Vec<Complex32> {
    let mut state = seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x1234_5678;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (((z ^ (z >> 31)) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let q = |v: f64| (20.0 * v).round().clamp(-128.0, 127.0) as f32;
    (0..n)
        .map(|_| {
            let r = (-2.0 * next().ln()).sqrt();
            let t = 2.0 * std::f64::consts::PI * next();
            Complex32::new(q(r * t.cos()), q(r * t.sin()))
        })
        .collect()
}

/// 100 independent 32-PRN searches at the default settings on noise alone: no detection.
/// The threshold is set for a false-alarm probability of 1e-5 per PRN search (union bound, so
/// at most that), i.e. at most 0.032 expected false alarms in these 3,200 PRN searches: seeing
/// none is expected (one or more has probability 3 % under the bound). The same
/// searches are scored against the thresholds for 1e-2 and 1e-3 per PRN search, where the
/// union bound allows at most 32 and 3.2 exceedances; the counts must stay below 48 and 8
/// (Poisson tails of 0.5 %; far in the tail the exceedances of neighbouring cells are nearly independent, so the
/// bound is close to the real rate). Two more 32-PRN searches with
/// the weak-signal setting (10 ms x 10, two bit-edge passes) check the long-block statistic.
#[test]
fn noise_only_no_false_alarm_in_100_searches() {
    let cfg = AcqConfig::default();
    let engine = AcquisitionEngine::new(FS, cfg.clone()).unwrap_or_else(|e| panic!("{e}"));
    let cells = 21 * 4000;
    let t2 = stats::detection_threshold(10, 1e-2, cells) / 10.0;
    let t3 = stats::detection_threshold(10, 1e-3, cells) / 10.0;
    let (mut worst, mut alarms, mut over2, mut over3) = (0.0f64, 0, 0, 0);
    for seed in 0..100 {
        let x = ci8_noise(seed, engine.samples_needed());
        let res = engine.search_all(&x).unwrap_or_else(|e| panic!("{e}"));
        for r in &res {
            worst = worst.max(r.metric / r.threshold);
            over2 += usize::from(r.metric > t2);
            over3 += usize::from(r.metric > t3);
            if r.detected || r.cross_correlation_of.is_some() {
                alarms += 1;
                println!("false alarm: seed {seed} {r:?}");
            }
        }
    }
    println!(
        "100 x 32 PRN searches on noise: {alarms} false alarms, largest metric/threshold \
         {worst:.3}; above the pfa=1e-2 threshold {over2} (bound 32), above 1e-3 {over3} (bound 3.2)"
    );
    assert_eq!(alarms, 0);
    assert!(over2 <= 48 && over3 <= 8, "{over2} {over3}");
    let weak = AcqConfig {
        coherent_ms: 10,
        ..cfg
    };
    let engine = AcquisitionEngine::new(FS, weak).unwrap_or_else(|e| panic!("{e}"));
    for seed in 0..2 {
        let x = ci8_noise(900 + seed, engine.samples_needed());
        let res = engine.search_all(&x).unwrap_or_else(|e| panic!("{e}"));
        let worst = res
            .iter()
            .fold(0.0f64, |m, r| m.max(r.metric / r.threshold));
        println!("10 ms x 10 on noise, seed {seed}: largest metric/threshold {worst:.3}");
        assert!(res.iter().all(|r| !r.detected), "{res:?}");
    }
}

/// The normalised cells follow Gamma(N, 1) under noise: over 8 grids (672,000 cells, 1 ms x 10)
/// the number of cells above the Gamma(10, 1) quantile for p = 1e-3 and 1e-4 must match
/// cells * p. Neighbouring cells are correlated (about 0.74 in amplitude one lag apart at 4
/// samples per chip), which inflates the spread of the count about threefold, hence +-20 % at
/// 1e-3 (expected 672, sd about 45) and +-50 % at 1e-4 (expected 67, sd about 14).
#[test]
fn noise_cells_follow_the_gamma_model() {
    let engine = AcquisitionEngine::new(FS, AcqConfig::default()).unwrap_or_else(|e| panic!("{e}"));
    let (mut cells, mut over3, mut over4) = (0usize, 0usize, 0usize);
    let x3 = stats::gamma_upper_quantile(10, 1e-3);
    let x4 = stats::gamma_upper_quantile(10, 1e-4);
    for seed in 0..8 {
        let x = ci8_noise(500 + seed, engine.samples_needed());
        let prn = Prn::new(3 + 4 * seed as u8).unwrap_or_else(|e| panic!("{e}"));
        let g = engine
            .grid(&x, &SearchTarget::full(prn))
            .unwrap_or_else(|e| panic!("{e}"));
        for row in g.power.chunks(g.n_lags) {
            // Row floor = N sigma^2; the normalised cell S / sigma^2 = N cell / floor.
            let floor = row.iter().map(|&v| f64::from(v)).sum::<f64>() / row.len() as f64;
            for &v in row {
                let z = 10.0 * f64::from(v) / floor;
                cells += 1;
                over3 += usize::from(z > x3);
                over4 += usize::from(z > x4);
            }
        }
    }
    let (e3, e4) = (cells as f64 * 1e-3, cells as f64 * 1e-4);
    println!("{cells} cells: {over3} over the 1e-3 point (expected {e3:.0}), {over4} over 1e-4 (expected {e4:.0})");
    assert!((over3 as f64 - e3).abs() < 0.2 * e3);
    assert!((over4 as f64 - e4).abs() < 0.5 * e4);
}

// ---------------------------------------------------------------------------------------------
// Assisted search.

/// Assisted search on a simulated recording (perfect receiver clock): the predicted Dopplers
/// match the simulator's truth within 2 Hz (same ephemeris, static receiver: only the light-time
/// and Earth-rotation modelling differ), every simulated satellite is predicted visible and found
/// inside its +-500 Hz window, and the per-PRN threshold is lower than a cold search's (fewer
/// cells).
#[test]
fn assisted_search_on_simulated_recording() {
    let k = 3;
    let (dir, file, truth) = simulate(k, 38.0, 0.12);
    let sc = scenario(k, 38.0, 0.12);
    let (nav_text, _) = sc
        .nav_text(Path::new("."))
        .unwrap_or_else(|e| panic!("{e}"));
    let nav = dir.path().join("brdc.nav");
    std::fs::write(&nav, nav_text).unwrap_or_else(|e| panic!("{e}"));
    let nav = nav.to_string_lossy().to_string();
    let time = format!("2190:{}", 538_194.0 + 900.0 * k as f64);
    let report = run(&[
        &file,
        "--format",
        "ci8",
        "--fs",
        "4e6",
        "--nav",
        &nav,
        "--approx-llh",
        "37.5665,126.9780,40",
        "--time",
        &time,
        "--doppler-uncertainty",
        "500",
        "--all",
    ]);
    println!("{}", render_table(&report, true));
    let cold = run(&[&file, "--format", "ci8", "--fs", "4e6"]);
    for t in &truth {
        let Some(r) = report.rows.iter().find(|r| r.prn.get() == t.prn) else {
            panic!("PRN {} simulated but not predicted visible", t.prn);
        };
        let pred = r.predicted_doppler_hz.unwrap_or(f64::NAN);
        assert!(
            (pred - t.doppler_hz).abs() < 2.0,
            "PRN {}: predicted {pred} truth {}",
            t.prn,
            t.doppler_hz
        );
        assert!(r.detected, "{r:?}");
        assert!(
            code_err(r.code_phase_samples, t.code_phase_samples, 4000.0) <= 1.0,
            "{r:?}"
        );
        assert!((r.doppler_hz - t.doppler_hz).abs() < 25.0, "{r:?}");
        let c = cold
            .rows
            .iter()
            .find(|c| c.prn == r.prn)
            .map_or(0.0, |c| c.threshold);
        assert!(
            r.threshold < c,
            "assisted threshold {} vs cold {c}",
            r.threshold
        );
    }
}

#[test]
fn bad_assistance_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let file = dir.path().join("x.ci8");
    std::fs::write(&file, vec![0u8; 200_000]).unwrap_or_else(|e| panic!("{e}"));
    let file = file.to_string_lossy().to_string();
    let nav = dir.path().join("empty.nav");
    std::fs::write(&nav, "not a rinex file\n").unwrap_or_else(|e| panic!("{e}"));
    let nav = nav.to_string_lossy().to_string();
    for extra in [
        vec!["--nav", &nav, "--approx-llh", "91,0,0", "--time", "2190:0"],
        vec!["--nav", &nav, "--approx-llh", "37,127", "--time", "2190:0"],
        vec!["--nav", &nav, "--approx-llh", "37,127,0", "--time", "166:0"],
        vec![
            "--nav",
            &nav,
            "--approx-llh",
            "37,127,0",
            "--time",
            "2190:700000",
        ],
        vec![
            "--nav",
            &nav,
            "--approx-llh",
            "37,127,0",
            "--time",
            "2190:0",
        ],
        vec!["--coherent-ms", "11"],
        vec!["--doppler-step", "900"],
        vec!["--prn", "33"],
        vec!["--pfa", "2"],
    ] {
        let mut list = vec![file.as_str(), "--format", "ci8", "--fs", "4e6"];
        list.extend(extra.iter().copied());
        let r = acquire(&args(&list));
        assert!(r.is_err(), "{list:?} should fail");
        println!(
            "{list:?}: {:#}",
            r.err().map(|e| format!("{e:#}")).unwrap_or_default()
        );
    }
}
