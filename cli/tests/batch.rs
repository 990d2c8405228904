//! `gpsrx batch`: a simulated recording, a missing one and a corrupt one in one manifest; the
//! exit status rule; a bad manifest.

use gpsrx_samples::sim::{Scenario, Simulator};
use std::path::Path;
use std::process::{Command, Output};

fn batch(manifest: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gpsrx"))
        .env("NO_COLOR", "1")
        .env_remove("GPSRX_LOG")
        .args(["batch", &manifest.display().to_string(), "--out"])
        .arg(out)
        .output()
        .unwrap_or_else(|e| panic!("cannot start gpsrx: {e}"))
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// 4 s of the default scenario's static antenna (fixes from about 1 s with the navigation
/// data and an approximate position).
fn simulate(dir: &Path) {
    let mut scenario = Scenario::default_scenario().expect("default scenario");
    scenario.duration_s = 4.0;
    Simulator::new(&scenario, Path::new("."))
        .and_then(|s| s.run(dir, &|_| {}))
        .expect("simulation");
}

#[test]
fn a_bad_recording_is_a_row_of_the_summary_and_the_batch_goes_on() {
    let dir = tempfile::tempdir().expect("tempdir");
    simulate(&dir.path().join("good"));
    std::fs::write(dir.path().join("corrupt.ci8"), [1u8, 2, 3]).expect("write");
    let manifest = dir.path().join("m.csv");
    std::fs::write(
        &manifest,
        "name,path,format,fs_hz,nav,approx_llh\n\
         good,good/signal.ci8,,,builtin:brdc0010.22n,\"[36.4, 127.4, 0.0]\"\n\
         missing,nowhere.ci8,ci8,2048000,,\n\
         corrupt,corrupt.ci8,ci8,2048000,,\n",
    )
    .expect("write");
    let out = dir.path().join("out");
    let o = batch(&manifest, &out);
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    assert_eq!(o.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(stdout.contains("3 recordings: 1 with fixes"), "{stdout}");
    let summary = std::fs::read_to_string(out.join("summary.csv")).expect("summary.csv");
    let rows: Vec<&str> = summary.lines().collect();
    assert_eq!(rows.len(), 4, "{summary}");
    assert!(
        rows[1].starts_with("good,") && rows[1].contains(",ok,"),
        "{summary}"
    );
    assert!(
        rows[2].contains(",error,") && rows[2].contains("does not exist"),
        "{summary}"
    );
    // One byte and a half sample: read, with a warning, but far too short for a fix.
    assert!(rows[3].starts_with("corrupt,"), "{summary}");
    assert!(!rows[3].contains(",ok,"), "{summary}");
    assert!(out.join("good").join("pvt.csv").exists());
}

#[test]
fn every_entry_failing_or_a_bad_manifest_is_exit_status_1() {
    let dir = tempfile::tempdir().expect("tempdir");
    let manifest = dir.path().join("m.toml");
    std::fs::write(&manifest, "[[recording]]\npath = \"nowhere.ci8\"\n").expect("write");
    let o = batch(&manifest, &dir.path().join("out"));
    assert_eq!(o.status.code(), Some(1));
    assert!(text(&o.stderr).contains("every entry of the batch failed"));
    assert!(dir.path().join("out").join("summary.csv").exists());

    std::fs::write(&manifest, "[[recording]]\nfile = \"a.bin\"\n").expect("write");
    let o = batch(&manifest, &dir.path().join("out2"));
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(err.contains("m.toml") && err.contains("file"), "{err}");
}

/// `gpsrx run --json`: the summary as one JSON object on standard output, equal to the fixes
/// written to `pvt.csv`; the log on standard error has no colour codes (not a terminal).
#[test]
fn run_json_prints_the_summary_for_scripts() {
    let dir = tempfile::tempdir().expect("tempdir");
    simulate(&dir.path().join("rec"));
    let out_dir = dir.path().join("out");
    let nav = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n");
    let out = Command::new(env!("CARGO_BIN_EXE_gpsrx"))
        .env_remove("NO_COLOR")
        .env_remove("GPSRX_LOG")
        .arg("run")
        .arg(dir.path().join("rec/signal.ci8"))
        .arg("--nav")
        .arg(&nav)
        .args(["--approx-llh", "36.4,127.4,0", "--json", "--out"])
        .arg(&out_dir)
        .output()
        .unwrap_or_else(|e| panic!("cannot start gpsrx: {e}"));
    assert!(out.status.success(), "{}", text(&out.stderr));
    // The log goes to a pipe here: no colour codes in it.
    assert!(text(&out.stderr).contains("INFO"), "{}", text(&out.stderr));
    assert!(!out.stderr.contains(&0x1b), "escape codes in a piped log");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("not JSON ({e}): {}", text(&out.stdout)));
    let fixes = v["fixes"].as_u64().unwrap_or(0);
    let rows = std::fs::read_to_string(out_dir.join("pvt.csv"))
        .expect("pvt.csv")
        .lines()
        .skip(1)
        .filter(|l| !l.contains(",none,"))
        .count() as u64;
    assert!(fixes > 10 && fixes == rows, "{v}");
    assert!(v["first_fix_s"].as_f64().is_some_and(|t| t < 2.0), "{v}");
    assert_eq!(
        v["outputs"].as_str(),
        Some(out_dir.display().to_string().as_str())
    );
    assert!(
        v["tracked_prns"].as_array().is_some_and(|a| a.len() >= 6),
        "{v}"
    );
}

/// A `[[snapshots]]` set in a TOML manifest: one simulated 12 ms snapshot (1-bit real at
/// 4.092 MHz, dated by its SigMF `core:datetime`) positioned against the simulator's antenna,
/// and a missing set reported without stopping the batch.
#[test]
fn a_snapshot_set_in_a_manifest_is_positioned_and_a_missing_one_is_a_row() {
    let dir = tempfile::tempdir().expect("tempdir");
    let toml = "duration_s = 0.012\nseed = 21\nnav = \"builtin:brdc0010.22n\"\n\
                [start]\nweek = 2190\ntow_s = 538194.0\n\
                [output]\nformat = \"ri1_lsb\"\nfs_hz = 4.092e6\nif_hz = 1.3e6\n\
                [receiver]\nkind = \"static\"\nllh_deg = [36.3721, 127.3604, 80.0]\n\
                [satellites]\ncn0_all_dbhz = 45.0\n";
    let scenario = Scenario::from_toml(toml).expect("scenario");
    Simulator::new(&scenario, Path::new("."))
        .and_then(|s| s.run(&dir.path().join("snap"), &|_| {}))
        .expect("simulation");
    let manifest = dir.path().join("m.toml");
    // The a-priori 30 km north-east of the antenna.
    std::fs::write(
        &manifest,
        "[[snapshots]]\nname = \"sim\"\npath = \"snap/signal.ri1_lsb\"\n\
         nav = \"builtin:brdc0010.22n\"\napprox_llh = [36.5621, 127.6004, 80.0]\n\
         [[snapshots]]\npath = \"nowhere.json\"\nnav = \"builtin:brdc0010.22n\"\n\
         approx_llh = [36.5621, 127.6004, 80.0]\n",
    )
    .expect("write");
    let out = dir.path().join("out");
    let o = batch(&manifest, &out);
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    assert_eq!(o.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("2 snapshot sets: 1 with fixes, 0 without a fix, 1 failed"),
        "{stdout}"
    );
    let mut reader = csv::Reader::from_path(out.join("summary.csv")).expect("summary.csv");
    let header = reader.headers().expect("header").clone();
    let col = |name: &str| header.iter().position(|h| h == name).expect(name);
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.expect("row")).collect();
    assert_eq!(rows.len(), 2);
    let (sim, missing) = (&rows[0], &rows[1]);
    assert_eq!(&sim[col("kind")], "snapshots");
    assert_eq!(&sim[col("status")], "ok", "{sim:?}");
    assert_eq!(&sim[col("fixes")], "1");
    // Within 0.0005 deg (about 55 m north, 45 m east) of the simulated antenna.
    let lat: f64 = sim[col("mean_lat_deg")].parse().expect("lat");
    let lon: f64 = sim[col("mean_lon_deg")].parse().expect("lon");
    assert!(
        (lat - 36.3721).abs() < 5e-4 && (lon - 127.3604).abs() < 5e-4,
        "{lat} {lon}"
    );
    assert_eq!(&missing[col("name")], "nowhere");
    assert_eq!(&missing[col("status")], "error");
    assert!(
        missing[col("message")].contains("nowhere.json"),
        "{missing:?}"
    );
    assert!(out.join("sim").join("snapshots.csv").is_file());
}
