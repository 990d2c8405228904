//! The small bad-input defects of issue 13, through the `gpsrx` binary: exit codes, messages
//! on standard error, and no panic.

use gpsrx_cli::commands::run::run_file;
use gpsrx_cli::exit::error_message;
use gpsrx_receiver::ReceiverConfig;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn gpsrx() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gpsrx"));
    // Plain log lines (no colours) so the messages can be searched.
    c.env("NO_COLOR", "1").env_remove("GPSRX_LOG");
    c
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Runs `gpsrx ARGS` with standard output captured.
fn output(args: &[&str]) -> Output {
    gpsrx()
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot start gpsrx: {e}"))
}

/// Checks that the run ended with `code` and no panic, and returns its standard error.
fn expect(o: &Output, code: i32, what: &str) -> String {
    let err = text(&o.stderr);
    assert!(!err.contains("panicked"), "{what}: a panic:\n{err}");
    assert_eq!(
        o.status.code(),
        Some(code),
        "{what}: status; stderr:\n{err}"
    );
    err
}

/// Runs `gpsrx ARGS` with standard output a pipe whose reader is already closed.
fn output_to_closed_pipe(args: &[&str]) -> Output {
    let (reader, writer) = std::io::pipe().unwrap_or_else(|e| panic!("{e}"));
    drop(reader);
    let child = gpsrx()
        .args(args)
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start gpsrx: {e}"));
    child.wait_with_output().unwrap_or_else(|e| panic!("{e}"))
}

/// 0.06 s of complex float noise at 2.048 MHz with one NaN and one stray trailing byte: no
/// satellite in it.
fn noise_cf32(dir: &Path) -> PathBuf {
    let n = 2048 * 60;
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut bytes = Vec::with_capacity(n * 8 + 1);
    for _ in 0..2 * n {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let v = (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5;
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes[40..44].copy_from_slice(&f32::NAN.to_le_bytes());
    bytes.push(1);
    let p = dir.join("noise.cf32");
    std::fs::write(&p, bytes).unwrap_or_else(|e| panic!("{e}"));
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap_or_default()
}

fn nav_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n")
}

#[test]
fn a_closed_standard_output_ends_quietly_with_status_0() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let study = dir.path().join("study");
    let data = noise_cf32(dir.path());
    for args in [
        vec!["config", "--default"],
        vec!["study", "dr", "--quick", "--out", s(&study)],
        vec!["info", s(&data), "--format", "cf32_le", "--fs", "2.048e6"],
    ] {
        let o = output_to_closed_pipe(&args);
        let err = expect(&o, 0, &args.join(" "));
        assert!(
            !err.contains("error"),
            "{args:?}: a closed pipe is not an error to report:\n{err}"
        );
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_standard_output_is_a_one_line_error_with_status_1() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap_or_else(|e| panic!("{e}"));
    let o = gpsrx()
        .args(["config", "--default"])
        .stdout(Stdio::from(full))
        .output()
        .unwrap_or_else(|e| panic!("{e}"));
    let err = expect(&o, 1, "config --default > /dev/full");
    assert_eq!(
        err.trim(),
        "error: cannot write to standard output: No space left on device (os error 28)"
    );
}

#[test]
fn simulate_refuses_a_rate_above_100_mhz_and_a_huge_recording() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("sim");
    let o = output(&["simulate", "--default", "--fs", "1e12", "--out", s(&out)]);
    let err = expect(&o, 1, "simulate --fs 1e12");
    assert!(
        err.contains("fs_hz = 1000000000000 Hz is above the simulator's limit of 100 MHz"),
        "{err}"
    );
    let o = output(&[
        "simulate",
        "--default",
        "--duration",
        "1e9",
        "--out",
        s(&out),
    ]);
    let err = expect(&o, 1, "simulate --duration 1e9");
    assert!(
        err.contains("above the simulator's limit of 1e11 samples")
            && err.contains("shorten duration_s or lower fs_hz"),
        "{err}"
    );
    assert!(!out.join("signal.ci8").exists(), "nothing is simulated");
}

#[test]
fn run_without_a_valid_fix_exits_with_status_2_and_errors_keep_1() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = noise_cf32(dir.path());
    let out = dir.path().join("out");
    let args = [
        "run",
        s(&data),
        "--format",
        "cf32_le",
        "--fs",
        "2.048e6",
        "--out",
        s(&out),
    ];
    let o = output(&args);
    expect(&o, 2, "run on noise");
    assert!(
        text(&o.stdout).contains("no fix: no satellite was tracked"),
        "{}",
        text(&o.stdout)
    );
    let missing = dir.path().join("missing.ci8");
    let o = output(&[
        "run",
        s(&missing),
        "--format",
        "ci8",
        "--fs",
        "2e6",
        "--out",
        s(&out),
    ]);
    let err = expect(&o, 1, "run on a missing file");
    assert!(err.contains("does not exist"), "{err}");
    let help = text(&output(&["run", "--help"]).stdout);
    assert!(
        help.contains("2  the recording was processed to the end but gave no valid fix"),
        "{help}"
    );
}

#[test]
fn run_and_track_report_nan_values_and_trailing_bytes() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = noise_cf32(dir.path());
    let out = dir.path().join("out");
    let source = [s(&data), "--format", "cf32_le", "--fs", "2.048e6"];
    let run = output(&[&["run"][..], &source, &["--out", s(&out)]].concat());
    let track = output(&[&["track"][..], &source].concat());
    for (what, o, code) in [("run", run, 2), ("track", track, 1)] {
        let err = expect(&o, code, what);
        for warning in [
            "WARN",
            "1 non-finite value(s) (NaN or infinity) read as 0",
            "the last 1 byte(s) do not make a whole cf32_le sample and were dropped",
        ] {
            assert!(err.contains(warning), "{what}: no `{warning}` in\n{err}");
        }
    }
}

#[test]
fn nav_and_wav_errors_print_each_cause_once() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = noise_cf32(dir.path());
    let out = dir.path().join("out");
    // A navigation file cut in the middle of a record.
    let nav = std::fs::read_to_string(nav_file()).unwrap_or_else(|e| panic!("{e}"));
    let cut: String = nav.lines().take(20).map(|l| format!("{l}\n")).collect();
    let bad_nav = dir.path().join("cut.22n");
    std::fs::write(&bad_nav, cut).unwrap_or_else(|e| panic!("{e}"));
    let o = output(&[
        "run",
        s(&data),
        "--format",
        "cf32_le",
        "--fs",
        "2.048e6",
        "--nav",
        s(&bad_nav),
        "--out",
        s(&out),
    ]);
    let err = expect(&o, 1, "run --nav with a truncated file");
    assert_eq!(err.matches("the file is truncated").count(), 1, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    // A WAV file whose header stops short.
    let wav = dir.path().join("short.wav");
    std::fs::write(&wav, b"RIFF\x24\x00\x00\x00WAVEfmt ").unwrap_or_else(|e| panic!("{e}"));
    let o = output(&["run", s(&wav), "--out", s(&out)]);
    let err = expect(&o, 1, "run on a WAV file with a bad header");
    assert_eq!(
        err.matches("Failed to read enough bytes").count(),
        1,
        "{err}"
    );
    assert!(err.contains("WAV file"), "{err}");
}

#[test]
fn an_error_message_keeps_each_cause_once() {
    #[derive(Debug)]
    struct Root;
    impl std::fmt::Display for Root {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("line 3: bad number")
        }
    }
    impl std::error::Error for Root {}
    let e = anyhow::Error::new(Root)
        .context("nav.rnx: line 3: bad number")
        .context("cannot read the navigation file");
    assert_eq!(
        error_message(&e),
        "cannot read the navigation file: nav.rnx: line 3: bad number"
    );
}

#[test]
fn out_of_range_settings_are_refused_with_the_key_and_range() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = noise_cf32(dir.path());
    let out = dir.path().join("out");
    let source = [
        "run",
        s(&data),
        "--format",
        "cf32_le",
        "--fs",
        "2.048e6",
        "--out",
        s(&out),
    ];
    let cases = [
        (
            "[tracking]\ncn0_lost_dbhz = -1000\n",
            "[tracking] cn0_lost_dbhz = -1000: use 10 to 45 dB-Hz",
        ),
        (
            "[dr]\nsf_n_m_per_pulse = -0.1\n",
            "[dr] sf_n_m_per_pulse = -0.1: use a value in (0, 10] m/pulse",
        ),
        (
            "[dr]\nsf_g_dps_per_v = 0\n",
            "[dr] sf_g_dps_per_v = 0: use a value in (0, 1000] deg/s/V",
        ),
        (
            "[dr]\nv_nom_v = 1e9\n",
            "[dr] v_nom_v = 1000000000: use a value in [-10, 10] V",
        ),
        (
            "[dr]\nupdate_interval_s = -1\n",
            "[dr] update_interval_s = -1: use a value in (0, 60] s",
        ),
        (
            "[dr]\nfilter = \"kalman\"\n",
            "[dr] filter = \"kalman\": use \"proposed\" or \"conventional\"",
        ),
        (
            "[run]\nweek = 99999\n",
            "[run] week: GPS week 99999: give the full week number, 1024 to 4096",
        ),
        (
            "[run]\napprox_llh = [37.5, 200.0, 40.0]\n",
            "[run] approx_llh: approximate longitude 200 deg: use -180 to 180 deg",
        ),
        (
            "[run]\napprox_time = { week = 2190, tow_s = 700000.0 }\n",
            "[run] approx_time: approximate time of week 700000 s: use 0 to 604800 s",
        ),
    ];
    for (toml, message) in cases {
        let config = dir.path().join("gpsrx.toml");
        std::fs::write(&config, toml).unwrap_or_else(|e| panic!("{e}"));
        let o = output(&[&source[..], &["--config", s(&config)]].concat());
        let err = expect(&o, 1, toml);
        assert!(err.contains(message), "{toml}: want `{message}` in\n{err}");
        // The library refuses the same configuration.
        let c = ReceiverConfig::from_toml(toml, "t").unwrap_or_else(|e| panic!("{e}"));
        let e = c
            .validate()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains(message), "{toml}: library says `{e}`");
    }
    let o = output(&[&source[..], &["--week", "99999"]].concat());
    let err = expect(&o, 1, "--week 99999");
    // The library describes the setting; the command line adds its option.
    assert!(
        err.contains("GPS week 99999") && err.trim_end().ends_with("(option --week WEEK)"),
        "{err}"
    );
    // The defaults and the edges of the ranges are fine.
    let mut c = ReceiverConfig::default();
    c.tracking.cn0_lost_dbhz = 10.0;
    c.run.week = Some(1024);
    c.dr.sf_n_m_per_pulse = Some(0.1);
    assert!(c.validate().is_ok());
}

#[test]
fn a_navigation_file_without_ephemeris_is_refused() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = noise_cf32(dir.path());
    let out = dir.path().join("out");
    let nav = std::fs::read_to_string(nav_file()).unwrap_or_else(|e| panic!("{e}"));
    let end = nav
        .find("END OF HEADER")
        .unwrap_or_else(|| panic!("no header end"));
    let header_end = nav[end..].find('\n').map_or(nav.len(), |i| end + i + 1);
    let header_only = dir.path().join("header.22n");
    std::fs::write(&header_only, &nav[..header_end]).unwrap_or_else(|e| panic!("{e}"));
    let o = output(&[
        "run",
        s(&data),
        "--format",
        "cf32_le",
        "--fs",
        "2.048e6",
        "--nav",
        s(&header_only),
        "--out",
        s(&out),
    ]);
    let err = expect(&o, 1, "run --nav header-only");
    let want = format!(
        "the navigation file {} holds no GPS ephemeris",
        header_only.display()
    );
    assert!(err.contains(&want), "{err}");
}

#[test]
fn only_locked_satellites_count_as_tracked() {
    // Two satellites: the other 30 PRNs are searched on noise for 6 s, harder and harder.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let scenario = r#"
duration_s = 6.0
seed = 7
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538198.0
[output]
format = "ci8"
fs_hz = 2.048e6
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[satellites]
prns = [26, 31]
cn0 = [{ prn = 26, dbhz = 45.0 }, { prn = 31, dbhz = 45.0 }]
[truth]
rate_hz = 1.0
"#;
    let sc = gpsrx_samples::sim::Scenario::from_toml(scenario).unwrap_or_else(|e| panic!("{e}"));
    let sim =
        gpsrx_samples::sim::Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let data = sim
        .run(dir.path(), &|_| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .data_path;
    let out = dir.path().join("out");
    let argv = ["gpsrx", "run", s(&data), "--out", s(&out)];
    let cli = <gpsrx_cli::cli::Cli as clap::Parser>::try_parse_from(argv)
        .unwrap_or_else(|e| panic!("{e}"));
    let gpsrx_cli::cli::Command::Run(args) = cli.command else {
        panic!("not run")
    };
    let (report, _) = run_file(&args, false).unwrap_or_else(|e| panic!("{e:#}"));
    // Two satellites in the sky, 30 PRNs searched again and again up to 10 ms x 40 (the
    // background search spends its false-alarm probability over the searches): no false
    // satellite is counted as tracked. A channel pulled in on noise (rare now) must show in
    // `dropped_prns`, never in `tracked_prns`.
    assert_eq!(report.receiver.tracked_prns, vec![26, 31]);
    assert!(
        !report.receiver.dropped_prns.contains(&26) && !report.receiver.dropped_prns.contains(&31)
    );
    // Every dropped PRN has rows in channels.csv, none with bit sync or lock in tracking.
    let mut rdr =
        csv::Reader::from_path(out.join("channels.csv")).unwrap_or_else(|e| panic!("{e}"));
    let headers = rdr.headers().unwrap_or_else(|e| panic!("{e}")).clone();
    let col = |n: &str| {
        headers
            .iter()
            .position(|h| h == n)
            .unwrap_or_else(|| panic!("{n}"))
    };
    let (prn, state, lock, bit) = (
        col("prn"),
        col("state"),
        col("carrier_lock"),
        col("bit_sync"),
    );
    let mut seen = std::collections::BTreeSet::new();
    for r in rdr.records() {
        let r = r.unwrap_or_else(|e| panic!("{e}"));
        let p: u8 = r[prn].parse().unwrap_or_else(|e| panic!("{e}"));
        seen.insert(p);
        if report.receiver.dropped_prns.contains(&p) {
            assert!(
                &r[bit] == "0" && !(&r[lock] == "1" && &r[state] == "track"),
                "{r:?}"
            );
        }
    }
    for p in &report.receiver.dropped_prns {
        assert!(seen.contains(p), "G{p:02} has no channel row");
    }
}

#[test]
fn bad_approximate_time_and_position_are_usage_errors_with_status_2() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = noise_cf32(dir.path());
    let out = dir.path().join("out");
    let source = [
        "run",
        s(&data),
        "--format",
        "cf32_le",
        "--fs",
        "2.048e6",
        "--out",
        s(&out),
    ];
    let cases: [(&[&str], &str); 7] = [
        (
            &["--time", "2190"],
            "give the full GPS week and the time of week in seconds as WEEK:TOW",
        ),
        (&["--time", "2190:abc"], "as WEEK:TOW, e.g. 2190:538200"),
        (
            &["--time", "190:538200"],
            "give the full GPS week, 1024 to 4096",
        ),
        (&["--time", "2190:604800"], "use 0 to 604800 s"),
        (
            &["--approx-llh", "37.5,127"],
            "as LAT,LON,H, e.g. 37.57,126.98,40",
        ),
        (
            &["--approx-llh", "-91,127,40"],
            "approximate latitude -91 deg",
        ),
        (
            &["--approx-llh", "37.5,127,1e6"],
            "approximate height 1000000 m",
        ),
    ];
    for (args, message) in cases {
        let o = output(&[&source[..], args].concat());
        let err = expect(&o, 2, &args.join(" "));
        assert!(
            err.contains(message),
            "{args:?}: want `{message}` in\n{err}"
        );
    }
    // Good values pass the parser (the run then ends without a fix: status 2 too, but with
    // the summary on standard output).
    let o = output(
        &[
            &source[..],
            &["--time", "2190:538200.5", "--approx-llh", "-33.9,18.4,10"],
        ]
        .concat(),
    );
    let err = expect(&o, 2, "good values");
    assert!(!err.contains("error: invalid value"), "{err}");
}
