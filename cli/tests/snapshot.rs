//! `gpsrx snapshot` through the binary: bad snapshots give rows with reasons (no crash, exit
//! 0), a bad file gives one error line (exit 1).

use std::path::Path;
use std::process::Command;

fn gpsrx() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_gpsrx"));
    c.env("NO_COLOR", "1").env_remove("GPSRX_LOG");
    c
}

fn nav() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../samples/data/brdc0010.22n")
        .display()
        .to_string()
}

#[test]
fn bad_snappergps_snapshots_give_rows_with_reasons() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Empty, all +1 (bytes of zero bits: a constant, no signal), not base64, too short.
    // 2000 base64 digits of zero bits: 1500 bytes, 12,000 samples, 2.9 ms.
    let zeros = "A".repeat(2000);
    let json = format!(
        r#"{{"deviceID": "test", "snapshots": [
        {{"timestamp": "2022-01-01T12:29:30.000Z", "data": ""}},
        {{"timestamp": "2022-01-01T12:29:31.000Z", "data": "{zeros}"}},
        {{"timestamp": "2022-01-01T12:29:32.000Z", "data": "***"}},
        {{"timestamp": "not a time", "data": "AAAA"}}
    ]}}"#
    );
    let input = dir.path().join("snaps.json");
    std::fs::write(&input, json).expect("write");
    let out = dir.path().join("out");
    let o = gpsrx()
        .args(["snapshot", &input.display().to_string(), "--nav", &nav()])
        .args([
            "--approx-llh",
            "37.5,127.0,40",
            "--out",
            &out.display().to_string(),
        ])
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(o.status.code(), Some(0), "{err}");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("4 snapshots: 0 fixes"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("snapshots.csv")).expect("csv");
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 5, "{csv}");
    assert!(rows[0].starts_with("index,label,time_utc"));
    for r in &rows[1..] {
        assert!(r.contains(",none,"), "{r}");
    }
    assert!(rows[1].contains("too short"), "{}", rows[1]);
    assert!(rows[3].contains("too short"), "{}", rows[3]);
    assert!(rows[4].contains("no a-priori time"), "{}", rows[4]);
    // The constant snapshot has signal power but no satellite.
    assert!(rows[2].contains("satellites"), "{}", rows[2]);
    for f in ["track.geojson", "track.kml", "track.gpx"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn a_file_that_is_not_snappergps_json_is_one_error_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("bad.json");
    std::fs::write(&input, "{\"not\": 1}").expect("write");
    let o = gpsrx()
        .args(["snapshot", &input.display().to_string(), "--nav", &nav()])
        .args([
            "--approx-llh",
            "37.5,127.0,40",
            "--out",
            &dir.path().join("o").display().to_string(),
        ])
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("not a SnapperGPS JSON file") && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn a_missing_navigation_file_is_named_by_its_option_on_the_command_line_only() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("snaps.json");
    std::fs::write(
        &input,
        r#"{"deviceID": "test", "snapshots": [{"timestamp": "2022-01-01T12:29:30.000Z", "data": "AAAA"}]}"#,
    )
    .expect("write");
    let o = gpsrx()
        .args(["snapshot", &input.display().to_string()])
        .args([
            "--approx-llh",
            "37.5,127.0,40",
            "--out",
            &dir.path().join("o").display().to_string(),
        ])
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    // The command line: what is missing, then the option that gives it.
    assert!(
        err.contains("no navigation data were given")
            && err.trim_end().ends_with("(option --nav FILE)"),
        "{err}"
    );
    // The library's message (as Python raises it) describes the data and names no option.
    let library = gpsrx_receiver::snapshot::SnapshotProcessor::new(
        &gpsrx_nav::NavData::default(),
        gpsrx_receiver::snapshot::SnapshotOptions::default(),
    )
    .err()
    .map(|e| gpsrx_receiver::error_message(&e))
    .unwrap_or_default();
    assert!(
        library.contains("no navigation data were given"),
        "{library}"
    );
    assert!(!library.contains("--"), "{library}");
}
