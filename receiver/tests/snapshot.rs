//! Snapshot positioning (`gpsrx_receiver::snapshot`): short simulated snapshots against the
//! simulator's truth, bad snapshots, and the shared real snapshots (skipped with a note when
//! `../shared/data` is absent, required with CI=true).

use gpsrx_nav::{GpsTime, Llh, NavData};
use gpsrx_receiver::snapshot::driver::Seed;
use gpsrx_receiver::snapshot::measure::{look_at_predicted, PredictedPhase};
use gpsrx_receiver::snapshot::output::{horizontal_error_m, score, Truth};
use gpsrx_receiver::snapshot::smooth::{smooth_track, SmoothOptions, DEFAULT_RANGE_SIGMA_M};
use gpsrx_receiver::snapshot::snappergps::read_snappergps;
use gpsrx_receiver::snapshot::{
    read_raw_snapshot, SampleSpec, Snapshot, SnapshotOptions, SnapshotProcessor, SnapshotQuality,
};
use gpsrx_samples::sim::{Scenario, Simulator};
use num_complex::Complex32;
use std::path::{Path, PathBuf};

const SEOUL: [f64; 3] = [37.5665, 126.9780, 40.0];
/// Receiver-clock time of the first simulated sample.
const START: &str = "2022-01-01 12:29:48";

fn samples_data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data")
}

fn nav() -> NavData {
    gpsrx_nav::read_rinex_nav(&samples_data().join("brdc0010.22n")).expect("shipped nav file")
}

/// One simulated snapshot: format, rate, IF, length, C/N0 of every satellite, and a receiver
/// moving east at `speed_mps` (0: static).
#[derive(Debug, Clone, Copy)]
struct SimCase {
    format: &'static str,
    fs_hz: f64,
    if_hz: f64,
    ms: f64,
    cn0: f64,
    speed_mps: f64,
}

const fn case(
    format: &'static str,
    fs_hz: f64,
    if_hz: f64,
    ms: f64,
    cn0: f64,
    speed_mps: f64,
) -> SimCase {
    SimCase {
        format,
        fs_hz,
        if_hz,
        ms,
        cn0,
        speed_mps,
    }
}

/// Simulates `c` into `dir` (noise seed `seed`) and reads it back.
fn simulate(dir: &Path, c: &SimCase, seed: u64) -> Snapshot {
    let SimCase {
        format,
        fs_hz,
        if_hz,
        ms,
        cn0,
        speed_mps,
    } = *c;
    let receiver = if speed_mps == 0.0 {
        format!(
            "kind = \"static\"\nllh_deg = [{}, {}, {}]",
            SEOUL[0], SEOUL[1], SEOUL[2]
        )
    } else {
        format!(
            "kind = \"motion\"\nstart_llh_deg = [{}, {}, {}]\nheading_deg = 90.0\nspeed_mps = {speed_mps}\n\
             segments = [{{ type = \"cruise\", duration_s = 1.0 }}]",
            SEOUL[0], SEOUL[1], SEOUL[2]
        )
    };
    let toml = format!(
        "duration_s = {}\nseed = {seed}\nnav = \"brdc0010.22n\"\n[start]\ngps_calendar = \"{START}\"\n\
         [output]\nformat = \"{format}\"\nfs_hz = {fs_hz}\nif_hz = {if_hz}\n[receiver]\n{receiver}\n\
         [clock]\nbias_s = -3.0e-4\ndrift_s_s = 1.0e-7\n[satellites]\ncn0_all_dbhz = {cn0}\n\
         [atmosphere]\nionosphere = true\ntroposphere = true\n",
        ms * 1e-3
    );
    let scenario = Scenario::from_toml(&toml).expect("scenario");
    let sim = Simulator::new(&scenario, &samples_data()).expect("simulator");
    let report = sim.run(dir, &|_| {}).expect("simulated");
    let spec = SampleSpec {
        format: None,
        fs_hz: None,
        if_hz: 0.0,
        invert_q: false,
    };
    read_raw_snapshot(&report.data_path, &spec, None).expect("read back")
}

fn start_time() -> GpsTime {
    GpsTime::from_calendar(2022, 1, 1, 12, 29, 48.0)
}

/// An a-priori 30 km north-east of Seoul and `dt_s` late.
fn seed(dt_s: f64) -> Seed {
    Seed {
        pos_ecef_m: Llh::from_degrees(SEOUL[0] + 0.19, SEOUL[1] + 0.24, 0.0).to_ecef(),
        time_correction_s: 0.0,
        time: Some(start_time().add_seconds(dt_s)),
    }
}

#[test]
fn simulated_snapshots_are_positioned_from_30_km_and_seconds_away() {
    let nav = nav();
    let truth = Llh::from_degrees(SEOUL[0], SEOUL[1], SEOUL[2]);
    // Cases and the largest horizontal error accepted, m (measured: 8.7, 16.5, 9.5 m; 6.5,
    // 17.9, 6.6 m with the parabola fit alone).
    let cases = [
        (case("ci2", 4.0e6, 0.0, 10.0, 42.0, 0.0), 30.0),
        (case("ri1_lsb", 4.092e6, 1.3e6, 20.0, 45.0, 0.0), 40.0),
        (case("ri2", 8.0e6, 2.1e6, 4.0, 45.0, 30.0), 30.0),
    ];
    for (k, (c, max_err)) in cases.iter().enumerate() {
        let SimCase {
            format,
            ms,
            cn0,
            speed_mps: speed,
            ..
        } = *c;
        let dir = tempfile::tempdir().expect("tempdir");
        let snap = simulate(dir.path(), c, 11 + k as u64);
        let mut p = SnapshotProcessor::new(&nav, SnapshotOptions::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let out = p.run(std::slice::from_ref(&snap), seed(2.5), |_| {});
        let o = &out[0];
        assert_eq!(o.quality, SnapshotQuality::Fix, "{format}: {}", o.reason);
        let e = horizontal_error_m(&o.llh.expect("position"), &truth);
        // The a-priori was 2.5 s late: the correction finds it (receiver clock -0.3 ms).
        let dt = o.time_correction_s.expect("time");
        eprintln!("{format} {ms} ms {cn0} dB-Hz {speed} m/s: {} satellites, error {e:.1} m, dt {dt:+.4} s", o.used_prns.len());
        assert!(e < *max_err, "{format}: {e:.1} m");
        assert!((dt + 2.5).abs() < 0.05, "{format}: {dt}");
        assert!(o.used_prns.len() >= 6, "{format}: {:?}", o.used_prns);
    }
}

/// The table of the closing note: horizontal error by snapshot length, 1-bit real and 2-bit
/// complex, static and moving, 30 and 40 dB-Hz, the a-priori 30 km and 2.5 s off (`cargo test
/// --profile ci -p gpsrx-receiver --test receiver snapshot_table -- --ignored --nocapture`).
/// The 1-bit rows run at 4.092 MHz, 4 samples per chip exactly as SnapperGPS: the simulator's
/// chips are ideal (no front-end filter), so with a whole number of samples per chip and a
/// code Doppler that moves the code by 0.04 sample in 12 ms, the correlation does not change
/// between sample instants and the code phase is known to a sample (+-37 m) only; `ri8` at
/// 4.092 MHz gives 20 m where 8.184 MHz gives 5 m (measured once, 10 ms at 45 dB-Hz).
#[test]
#[ignore = "a table for the documentation, about a minute"]
fn snapshot_table() {
    let nav = nav();
    let truth = Llh::from_degrees(SEOUL[0], SEOUL[1], SEOUL[2]);
    println!("| format | ms | C/N0 | speed m/s | satellites | quality | horizontal error m (parabola fit alone) | time error ms | reason |");
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut seed_no = 100;
    for (format, fs, if_hz) in [("ri1_lsb", 4.092e6, 1.3e6), ("ci2", 4.0e6, 0.0)] {
        for ms in [2.0, 5.0, 10.0, 20.0] {
            for cn0 in [35.0, 45.0] {
                for speed in [0.0, 100.0] {
                    seed_no += 1;
                    let dir = tempfile::tempdir().expect("tempdir");
                    let snap = simulate(
                        dir.path(),
                        &case(format, fs, if_hz, ms, cn0, speed),
                        seed_no,
                    );
                    let mut opts = SnapshotOptions::default();
                    opts.measure.max_speed_mps = 120.0;
                    // The parabola fit alone, for comparison.
                    let mut parabola = opts.clone();
                    parabola.measure.code_band_hz = None;
                    let mut p =
                        SnapshotProcessor::new(&nav, parabola).unwrap_or_else(|e| panic!("{e}"));
                    let before = &p.run(std::slice::from_ref(&snap), seed(2.5), |_| {})[0];
                    let mut p =
                        SnapshotProcessor::new(&nav, opts).unwrap_or_else(|e| panic!("{e}"));
                    let o = &p.run(std::slice::from_ref(&snap), seed(2.5), |_| {})[0];
                    let error = |o: &gpsrx_receiver::snapshot::SnapshotOutcome| {
                        o.llh.map_or("-".to_string(), |l| {
                            format!("{:.1}", horizontal_error_m(&l, &truth))
                        })
                    };
                    let e = format!("{} ({})", error(o), error(before));
                    let dt = o
                        .time_correction_s
                        .map_or("-".to_string(), |d| format!("{:.1}", (d + 2.5) * 1e3));
                    println!(
                        "| {format} | {ms} | {cn0} | {speed} | {} | {} | {e} | {dt} | {} |",
                        o.used_prns.len(),
                        o.quality.name(),
                        o.reason.chars().take(70).collect::<String>()
                    );
                }
            }
        }
    }
}

#[test]
fn bad_snapshots_give_rows_with_reasons_and_do_not_move_the_seed() {
    let nav = nav();
    let dir = tempfile::tempdir().expect("tempdir");
    let good = simulate(dir.path(), &case("ci2", 4.0e6, 0.0, 10.0, 44.0, 0.0), 5);
    let with = |samples: Vec<Complex32>, index: usize| Snapshot {
        index,
        samples,
        ..good.clone()
    };
    let fs = good.fs_hz;
    // Noise only: a fixed-seed pseudo-random sign sequence.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let noise: Vec<Complex32> = (0..good.samples.len())
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            Complex32::new(
                if x & 1 == 0 { 1.0 } else { -1.0 },
                if x & 2 == 0 { 1.0 } else { -1.0 },
            )
        })
        .collect();
    let snaps = vec![
        with(good.samples.clone(), 0),
        with(vec![Complex32::new(0.0, 0.0); good.samples.len()], 1),
        with(good.samples[..(fs * 0.5e-3) as usize].to_vec(), 2),
        with(noise, 3),
        with(Vec::new(), 4),
        with(good.samples.clone(), 5),
    ];
    let mut p =
        SnapshotProcessor::new(&nav, SnapshotOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let out = p.run(&snaps, seed(1.0), |_| {});
    assert_eq!(out.len(), 6);
    let q: Vec<SnapshotQuality> = out.iter().map(|o| o.quality).collect();
    use SnapshotQuality::{Fix, None};
    assert_eq!(q, vec![Fix, None, None, None, None, Fix]);
    assert!(out[1].reason.contains("zero"), "{}", out[1].reason);
    assert!(out[2].reason.contains("too short"), "{}", out[2].reason);
    assert!(out[3].reason.contains("satellites"), "{}", out[3].reason);
    assert!(out[4].reason.contains("too short"), "{}", out[4].reason);
    // The last snapshot started from the first one's fix: the bad ones in between moved
    // nothing (the same result as from that seed directly).
    let after_first = Seed {
        pos_ecef_m: out[0].ecef_m.expect("fix"),
        ..seed(1.0)
    };
    let (direct, _) = p.process(&snaps[5], &after_first);
    assert_eq!(direct.llh, out[5].llh);
    assert_eq!(direct.used_prns, out[5].used_prns);
    // No time at all: said, not guessed.
    let no_time = Seed {
        time: Option::None,
        ..seed(0.0)
    };
    let o = p.run(&snaps[..1], no_time, |_| {});
    assert_eq!(o[0].quality, None);
    assert!(o[0].reason.contains("no a-priori time"), "{}", o[0].reason);
    assert!(!o[0].reason.contains("--"), "{}", o[0].reason);
}

#[test]
fn navigation_data_without_an_ephemeris_is_an_error_that_names_no_flag() {
    let e = SnapshotProcessor::new(&NavData::default(), SnapshotOptions::default())
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("no navigation data were given"), "{e}");
    assert!(!e.contains("--"), "{e}");
}

#[test]
fn an_apriori_beyond_the_limits_gives_no_fix() {
    let nav = nav();
    let dir = tempfile::tempdir().expect("tempdir");
    let snap = simulate(dir.path(), &case("ci2", 4.0e6, 0.0, 10.0, 44.0, 0.0), 9);
    let mut p =
        SnapshotProcessor::new(&nav, SnapshotOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    // 1000 km away (Beijing is ~950 km from Seoul), the right time.
    let far = Seed {
        pos_ecef_m: Llh::from_degrees(39.9, 116.4, 50.0).to_ecef(),
        ..seed(0.0)
    };
    let o = &p.run(std::slice::from_ref(&snap), far, |_| {})[0];
    if let Some(l) = o.llh {
        let truth = Llh::from_degrees(SEOUL[0], SEOUL[1], SEOUL[2]);
        assert!(
            horizontal_error_m(&l, &truth) < 100.0,
            "a confident wrong fix: {o:?}"
        );
    } else {
        assert_eq!(o.quality, SnapshotQuality::None);
        assert!(!o.reason.is_empty());
    }
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
fn snappergps_walk_first_60_snapshots_against_rtk_truth() {
    let (Some(json), Some(navp), Some(truthp)) = (
        shared_data("real/snapshots/snappergps_w00_first60.json"),
        shared_data("real/snapshots/snappergps_w00.nav"),
        shared_data("real/snapshots/snappergps_w00_first60_truth.json"),
    ) else {
        return;
    };
    let nav = gpsrx_nav::read_rinex_nav(&navp).expect("nav");
    let snaps = read_snappergps(&json).expect("snapshots");
    assert_eq!(snaps.len(), 60);
    // 30 km north of the walk, at its height.
    let apriori = Llh::from_degrees(52.03, -1.2574, 112.0);
    let mut opts = SnapshotOptions::default();
    opts.solve.height = Some(gpsrx_nav::pvt::HeightConstraint {
        h_m: 112.0,
        sigma_m: 30.0,
    });
    let mut p = SnapshotProcessor::new(&nav, opts).unwrap_or_else(|e| panic!("{e}"));
    let seed = Seed {
        pos_ecef_m: apriori.to_ecef(),
        time_correction_s: 0.0,
        time: None,
    };
    let out = p.run(&snaps, seed, |_| {});
    let truth = gpsrx_receiver::snapshot::output::read_truth_track(&truthp, 112.4).expect("truth");
    let errors = truth.errors(&out);
    let s = score(&out, &errors);
    eprintln!("{s:?}");
    // Each snapshot alone, measured: 56 of 60, median 14.7 m, 95th percentile 25.0 m (17.3
    // and 45.5 m with the parabola fit alone; the 10 m median of issue 27 is not reached by
    // single GPS-only snapshots): these bounds guard against regressions.
    assert!(s.fixes >= 54, "{s:?}");
    assert!(s.median_m <= 17.0 && s.p95_m <= 30.0, "{s:?}");
    assert!(matches!(truth, Truth::Track { .. }));
    // Smoothed across snapshots as a walker (0.5 m/s^2), measured: median 6.0 m, 95th
    // percentile 9.3 m; the acceptance is 10 m and 25 m.
    let mut smoothed = out.clone();
    let opts = SmoothOptions {
        accel_sigma_mps2: 0.5,
        range_sigma_m: DEFAULT_RANGE_SIGMA_M,
    };
    assert!(smooth_track(&mut smoothed, &opts) >= 50);
    let s = score(&smoothed, &truth.errors(&smoothed));
    eprintln!("smoothed: {s:?}");
    assert!(s.fixes >= 54, "{s:?}");
    assert!(s.median_m <= 10.0 && s.p95_m <= 25.0, "{s:?}");
}

#[test]
fn airborne_capture_within_50_m_of_the_reference() {
    let (Some(stream), Some(navp)) = (
        shared_data("real/snapshots/sxnsr_test_data_flight.stream"),
        shared_data("real/snapshots/sxnsr_test_data_flight.12n"),
    ) else {
        return;
    };
    let nav = gpsrx_nav::read_rinex_nav(&navp).expect("nav");
    let spec = SampleSpec {
        format: Some(gpsrx_samples::SampleFormat::Packed2 {
            complex: false,
            map: [0.5, 1.5, -1.5, -0.5],
            msb_first: false,
        }),
        fs_hz: Some(20.48e6),
        if_hz: 5_499_998.474,
        invert_q: false,
    };
    // The time 3 s late and the position 35 km off.
    let t = GpsTime::new(1672, 391_561.0);
    let snap = read_raw_snapshot(&stream, &spec, Some(t)).expect("capture");
    let mut p =
        SnapshotProcessor::new(&nav, SnapshotOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let seed = Seed {
        pos_ecef_m: Llh::from_degrees(52.6, 10.9, 0.0).to_ecef(),
        time_correction_s: 0.0,
        time: Some(t),
    };
    let o = &p.run(std::slice::from_ref(&snap), seed, |_| {})[0];
    assert_eq!(o.quality, SnapshotQuality::Fix, "{}", o.reason);
    let reference = Llh::from_ecef(&gpsrx_nav::Vector3::new(
        3_839_479.7,
        721_777.3,
        5_025_349.9,
    ));
    let e = horizontal_error_m(&o.llh.expect("position"), &reference);
    let dz = (o.llh.expect("position").h_m - reference.h_m).abs();
    // Measured 5.0 m horizontally, 2 m vertically, 9 satellites.
    assert!(e < 50.0 && dz < 50.0, "{e:.1} m, {dz:.1} m");
    // First sample at TOW 391558.1 +- 0.1 s.
    let dt = o.time_correction_s.expect("time");
    assert!((dt + 2.9).abs() < 0.15, "{dt}");
}

/// The coherent test at a known code phase against the simulator's truth: 12 ms of 1-bit real
/// samples at 4.092 MHz, every satellite at 31 dB-Hz, each looked for at its true code phase
/// and Doppler (`truth_sv.csv` at the first sample) by the non-coherent test alone and with
/// the coherent one; and at a code phase 300 chips off (noise).
#[test]
fn the_coherent_test_finds_weak_satellites_where_the_truth_puts_them() {
    let dir = tempfile::tempdir().expect("tempdir");
    let c = case("ri1_lsb", 4.092e6, 1.3e6, 12.0, 31.0, 0.0);
    let snap = simulate(dir.path(), &c, 77);
    let truth_sv = std::fs::read_to_string(dir.path().join("truth_sv.csv")).expect("truth_sv");
    let header: Vec<&str> = truth_sv
        .lines()
        .next()
        .expect("header")
        .split(',')
        .collect();
    let col = |name: &str| header.iter().position(|x| *x == name).expect(name);
    let (i_t, i_prn, i_phase) = (col("t_s"), col("prn"), col("code_phase_chips"));
    let (i_rate, i_dop, i_el) = (
        col("code_rate_chips_s"),
        col("doppler_hz"),
        col("elevation_deg"),
    );
    let fs = snap.fs_hz;
    let period = fs * 1e-3;
    let per_chip = fs / 1.023e6;
    let mut truth = Vec::new();
    let mut wrong = Vec::new();
    for line in truth_sv.lines().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().unwrap_or(f64::NAN))
            .collect();
        if v[i_t] != 0.0 {
            continue;
        }
        let prn = gpsrx_dsp::Prn::new(v[i_prn] as u8).expect("prn");
        // The code arrives at chip `phase` at sample 0: a period starts 1023 - phase chips on.
        let tau = ((1023.0 - v[i_phase]) / v[i_rate] * fs).rem_euclid(period);
        let p = PredictedPhase {
            prn,
            code_phase_samples: tau,
            doppler_hz: v[i_dop],
            elevation_deg: v[i_el],
        };
        wrong.push(PredictedPhase {
            code_phase_samples: (tau + 300.0 * per_chip).rem_euclid(period),
            ..p
        });
        truth.push(p);
    }
    assert!(truth.len() >= 8, "{} satellites", truth.len());
    let band = Some(gpsrx_receiver::snapshot::measure::DEFAULT_CODE_BAND_HZ);
    let alone = look_at_predicted(&snap.samples, fs, 0.0, &truth, band, false);
    let both = look_at_predicted(&snap.samples, fs, 0.0, &truth, band, true);
    eprintln!(
        "31 dB-Hz, {} satellites: {} found non-coherently, {} with the coherent test",
        truth.len(),
        alone.len(),
        both.len()
    );
    // Measured: 4 and 8 of 12 (a simulation of the two tests predicts 57 % and 86 % at
    // 31 dB-Hz).
    assert!(
        both.len() >= alone.len() + 3,
        "{} vs {}",
        both.len(),
        alone.len()
    );
    for s in &both {
        let t = truth
            .iter()
            .find(|t| t.prn == s.prn)
            .expect("a true satellite");
        let d = (s.code_phase_samples - t.code_phase_samples + 0.5 * period).rem_euclid(period)
            - 0.5 * period;
        // The band-limited fit of a 31 dB-Hz signal over 12 ms: metres to tens of metres.
        assert!(d.abs() < 0.3 * per_chip, "{:?}: {d} samples", s.prn);
    }
    let noise = look_at_predicted(&snap.samples, fs, 0.0, &wrong, band, true);
    assert!(noise.is_empty(), "false alarms: {noise:?}");
}
