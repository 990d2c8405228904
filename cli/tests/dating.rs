//! Dating the outputs (issue 13): a recording's SigMF `core:datetime` dates them before the
//! broadcast week is decoded, `--week`/`--nav` do when given, and nothing is ever dated from
//! the system clock. Also `gpsrx demo`'s exit status and Ctrl-C on an idle stream.

use gpsrx_nav::GpsTime;
use gpsrx_samples::sigmf::{meta_path_for, read_sigmf_meta};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// 16 s from TOW 538208 of week 2190 (2022-01-01 05:30:08 GPS time), 8 s into subframe 2:
/// frame sync on subframe 3 at about 10 s, and subframe 1 (the week) not before 28 s, so the
/// last 6 s give observables with no broadcast week.
const SCENARIO: &str = r#"
description = "dating test"
duration_s = 16.0
seed = 7
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538208.0
[output]
format = "ci8"
fs_hz = 1.2e6
[receiver]
kind = "static"
llh_deg = [36.3721, 127.3604, 80.0]
[satellites]
elevation_mask_deg = 10.0
"#;
const START: (u32, f64) = (2190, 538_208.0);
const DURATION_S: f64 = 16.0;

fn gpsrx() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gpsrx"));
    c.env("NO_COLOR", "1").env_remove("GPSRX_LOG");
    c
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap_or_default()
}

/// Runs `gpsrx ARGS`; checks the status and that nothing panicked; returns (stdout, stderr).
fn gpsrx_ok(args: &[&str], code: i32) -> (String, String) {
    let o: Output = gpsrx()
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot start gpsrx: {e}"));
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    );
    assert!(!err.contains("panicked"), "{args:?}: a panic:\n{err}");
    assert_eq!(
        o.status.code(),
        Some(code),
        "{args:?}: status; stderr:\n{err}"
    );
    (out, err)
}

/// `gpsrx simulate` of [`SCENARIO`] into `dir`; returns the recording.
fn simulate(dir: &Path) -> PathBuf {
    let scenario = dir.join("dating.toml");
    std::fs::write(&scenario, SCENARIO).unwrap_or_else(|e| panic!("{e}"));
    let sim = dir.join("sim");
    gpsrx_ok(&["simulate", s(&scenario), "--out", s(&sim)], 0);
    sim.join("signal.ci8")
}

/// The GPS times of the epoch lines of `observables.rnx`.
fn rinex_epochs(out: &Path) -> Vec<GpsTime> {
    let text =
        std::fs::read_to_string(out.join("observables.rnx")).unwrap_or_else(|e| panic!("{e}"));
    text.lines()
        .filter(|l| l.starts_with("> "))
        .map(|l| {
            let f: Vec<&str> = l[2..].split_whitespace().collect();
            let n = |i: usize| f[i].parse::<u32>().unwrap_or_else(|e| panic!("`{l}`: {e}"));
            let sec: f64 = f[5].parse().unwrap_or_else(|e| panic!("`{l}`: {e}"));
            GpsTime::from_calendar(n(0) as i32, n(1), n(2), n(3), n(4), sec)
        })
        .collect()
}

/// `channels.csv` as (gps_week, tow_s, t_stream_s) text cells.
fn channel_times(out: &Path) -> Vec<(String, String, f64)> {
    let mut r = csv::Reader::from_path(out.join("channels.csv")).unwrap_or_else(|e| panic!("{e}"));
    let h = r.headers().unwrap_or_else(|e| panic!("{e}")).clone();
    let col = |name: &str| {
        h.iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (w, t, ts) = (col("gps_week"), col("tow_s"), col("t_stream_s"));
    r.records()
        .map(|x| {
            let x = x.unwrap_or_else(|e| panic!("{e}"));
            let stream: f64 = x[ts].parse().unwrap_or_else(|e| panic!("{e}"));
            (x[w].to_string(), x[t].to_string(), stream)
        })
        .collect()
}

/// Checks the epochs lie in the simulated span of week `week` (the truth: the scenario's
/// start, moved by `shift_weeks` when the metadata was edited).
fn assert_epochs_in_truth_span(epochs: &[GpsTime], week: u32) {
    assert!(epochs.len() > 20, "{} epochs", epochs.len());
    for t in epochs {
        assert_eq!(t.week, week, "epoch {t:?}");
        assert!(
            (START.1..START.1 + DURATION_S + 0.1).contains(&t.tow_s),
            "epoch {t:?} outside the recording"
        );
    }
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn a_short_recording_is_dated_by_its_sigmf_datetime() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(dir.path());
    // The simulator writes the start in UTC (18 leap seconds before GPS time).
    let meta_path = meta_path_for(&data);
    let meta = read_sigmf_meta(&meta_path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        meta.datetime.as_deref(),
        Some("2022-01-01T05:29:50.000000Z")
    );
    let (start, _) = meta
        .start_time()
        .unwrap_or_else(|e| panic!("{e}"))
        .unwrap_or_else(|| panic!("no start"));
    assert_eq!(start.week, START.0);
    assert!((start.tow_s - START.1).abs() < 1e-6, "{start:?}");

    let out = dir.path().join("out");
    let (stdout, err) = gpsrx_ok(&["run", s(&data), "--out", s(&out)], 2);
    assert!(stdout.contains("no fix"), "{stdout}");
    assert!(
        err.contains("GPS week 2190 from core:datetime 2022-01-01T05:29:50.000000Z"),
        "{err}"
    );
    assert!(!err.contains("week is unknown"), "{err}");
    // No subframe 1 in these 16 s (it starts at TOW 538230): the metadata dates the epochs.
    assert_epochs_in_truth_span(&rinex_epochs(&out), START.0);
    // channels.csv: no time before frame sync (the stream time instead), then week 2190 and
    // a time of week that runs with the stream time.
    let rows = channel_times(&out);
    let (before, after): (Vec<_>, Vec<_>) = rows.iter().partition(|r| r.1.is_empty());
    assert!(!before.is_empty() && after.len() > 20);
    assert!(
        before.iter().all(|r| r.0.is_empty()),
        "a week without a time"
    );
    for (week, tow, stream) in &after {
        assert_eq!(week, "2190");
        let tow: f64 = tow.parse().unwrap_or_else(|e| panic!("{e}"));
        assert!(
            (tow - stream - START.1).abs() < 0.05,
            "tow {tow} at {stream} s"
        );
    }

    // The date is the metadata's: moved by a week there, the outputs follow.
    let text = std::fs::read_to_string(&meta_path).unwrap_or_else(|e| panic!("{e}"));
    let moved = text.replace("2022-01-01T05:29:50", "2022-01-08T05:29:50");
    std::fs::write(&meta_path, moved).unwrap_or_else(|e| panic!("{e}"));
    let (_, err) = gpsrx_ok(&["run", s(&data), "--out", s(&out)], 2);
    assert!(err.contains("GPS week 2191 from core:datetime"), "{err}");
    assert_epochs_in_truth_span(&rinex_epochs(&out), START.0 + 1);
}

#[test]
fn a_recording_without_a_date_is_never_dated_from_the_system_clock() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(dir.path());
    // The same samples without their metadata: nothing dates them.
    let raw = dir.path().join("cap.bin");
    std::fs::copy(&data, &raw).unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    let raw_args = |extra: &[&'static str]| -> Vec<String> {
        let mut a: Vec<String> = ["run", s(&raw), "--format", "ci8", "--fs", "1.2e6", "--out"]
            .iter()
            .map(|x| x.to_string())
            .collect();
        a.push(s(&out).to_string());
        a.extend(extra.iter().map(|x| x.to_string()));
        a
    };

    // --week dates them.
    let with_week = raw_args(&["--week", "2190"]);
    let (_, err) = gpsrx_ok(&strs(&with_week), 2);
    assert!(err.contains("GPS week 2190 (as given)"), "{err}");
    assert_epochs_in_truth_span(&rinex_epochs(&out), START.0);

    // Nothing: a warning, no observation file (the previous run's is gone too), no week.
    let (_, err) = gpsrx_ok(&strs(&raw_args(&[])), 2);
    assert!(err.contains("the GPS week is unknown"), "{err}");
    assert!(err.contains("observables.rnx not written"), "{err}");
    assert!(!out.join("observables.rnx").exists());
    let rows = channel_times(&out);
    assert!(rows.iter().any(|r| !r.1.is_empty()), "frame sync");
    assert!(rows.iter().all(|r| r.0.is_empty()), "a week was invented");

    // A navigation file dates them too, and gives fixes before subframe 1: pvt.csv and the
    // NMEA date are those of the recording.
    let nav = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n");
    let mut with_nav = raw_args(&["--nav"]);
    with_nav.push(s(&nav).to_string());
    let (_, err) = gpsrx_ok(&strs(&with_nav), 0);
    assert!(
        err.contains("GPS week 2190 from the navigation file"),
        "{err}"
    );
    let pvt = std::fs::read_to_string(out.join("pvt.csv")).unwrap_or_else(|e| panic!("{e}"));
    let fixes: Vec<&str> = pvt.lines().skip(1).collect();
    assert!(!fixes.is_empty());
    for f in &fixes {
        let tow: f64 = f
            .split(',')
            .nth(1)
            .and_then(|t| t.parse().ok())
            .unwrap_or(-1.0);
        assert!(f.starts_with("2190,"), "{f}");
        assert!((START.1..START.1 + DURATION_S).contains(&tow), "{f}");
    }
    let nmea = std::fs::read_to_string(out.join("pvt.nmea")).unwrap_or_else(|e| panic!("{e}"));
    let rmc: Vec<&str> = nmea.lines().filter(|l| l.starts_with("$GPRMC")).collect();
    assert!(!rmc.is_empty());
    for l in rmc {
        assert_eq!(l.split(',').nth(9), Some("010122"), "{l}");
    }
}

#[test]
fn demo_without_a_valid_fix_exits_with_status_2_and_says_why() {
    let (stdout, _) = gpsrx_ok(&["demo", "--duration", "4"], 2);
    assert!(stdout.contains("no valid fix (exit status 2)"), "{stdout}");
}

#[test]
fn ctrl_c_ends_a_run_on_an_idle_stream() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    let mut child = gpsrx()
        .args([
            "run",
            "-",
            "--format",
            "ci8",
            "--fs",
            "2.6e6",
            "--out",
            s(&out),
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start gpsrx: {e}"));
    // Standard input stays open and sends nothing. The receiver is made (its first log line)
    // after the Ctrl-C handler is installed.
    let _idle = child.stdin.take();
    let stderr = child.stderr.take().unwrap_or_else(|| panic!("no stderr"));
    let mut lines = BufReader::new(stderr).lines();
    let mut err = String::new();
    for line in lines.by_ref() {
        let line = line.unwrap_or_else(|e| panic!("{e}"));
        err.push_str(&line);
        err.push('\n');
        if line.contains("GPS week") {
            break;
        }
    }
    // Let it block in its wait for samples (a Ctrl-C before the first read ends it anyway).
    std::thread::sleep(Duration::from_millis(800));
    let pid = child.id().to_string();
    let sent = Command::new("kill").args(["-INT", &pid]).status();
    assert!(sent.is_ok_and(|s| s.success()), "kill -INT");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap_or_else(|e| panic!("{e}")) {
            break status;
        }
        if start.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            panic!("Ctrl-C did not end the run on an idle stream");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    for line in lines {
        err.push_str(&line.unwrap_or_default());
        err.push('\n');
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    // No samples came: the cold start says so, as an error after the interrupt.
    assert_eq!(status.code(), Some(1), "{err}");
    assert!(out.join("channels.csv").exists());
}
