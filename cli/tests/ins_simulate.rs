//! `gpsrx simulate` with an `[ins]` table: `ins.csv` against `truth.csv`.

use gpsrx_ins_aiding::read_ins_csv;
use gpsrx_receiver::error_message;
use gpsrx_receiver::simulate::{ins_config, simulate, InsOutput};
use gpsrx_samples::sim::Scenario;
use gpsrx_samples::sim::SimReport;
use std::path::Path;

/// Start of every scenario here (geodetic, WGS-84).
const LAT_DEG: f64 = 37.5665;
const LON_DEG: f64 = 126.978;

/// A short, cheap scenario (2 s of ci8 at 1.2 MHz, two satellites) of a vehicle accelerating
/// and turning, with a biased receiver clock, and the given `[ins]` table body.
fn scenario_text(ins: &str) -> String {
    format!(
        r#"
duration_s = 2.0
seed = 3
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci8"
fs_hz = 1.2e6
[receiver]
kind = "motion"
start_llh_deg = [{LAT_DEG}, {LON_DEG}, 40.0]
heading_deg = 30.0
speed_mps = 20.0
transition_s = 0.2
segments = [
  {{ type = "accelerate", duration_s = 1.0, accel_mps2 = 3.0 }},
  {{ type = "turn", duration_s = 5.0, accel_g = 2.0, direction = "right" }},
]
[clock]
bias_s = 2.0e-4
drift_s_s = 3.0e-8
[satellites]
prns = [26, 31]
[truth]
rate_hz = 50.0
[ins]
{ins}
"#
    )
}

fn load(text: &str) -> Scenario {
    Scenario::from_toml(text).unwrap_or_else(|e| panic!("{e}"))
}

/// Local east and north unit vectors in ECEF at a geodetic latitude and longitude (the
/// derivatives of the ECEF position along longitude and latitude, normalised).
fn east_north(lat_deg: f64, lon_deg: f64) -> ([f64; 3], [f64; 3]) {
    let (sp, cp) = lat_deg.to_radians().sin_cos();
    let (sl, cl) = lon_deg.to_radians().sin_cos();
    ([-sl, cl, 0.0], [-sp * cl, -sp * sl, cp])
}

/// Rows of a CSV file as maps from column name to value.
fn read_rows(path: &Path) -> Vec<std::collections::HashMap<String, f64>> {
    let mut rdr = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{e}"));
    let headers = rdr.headers().unwrap_or_else(|e| panic!("{e}")).clone();
    rdr.records()
        .map(|r| {
            let r = r.unwrap_or_else(|e| panic!("{e}"));
            headers
                .iter()
                .zip(r.iter())
                .map(|(h, v)| (h.to_string(), v.parse::<f64>().unwrap_or(f64::NAN)))
                .collect()
        })
        .collect()
}

#[test]
fn ins_csv_is_truth_plus_bias_times_t() {
    let (be, bn, bu) = (0.01, -0.02, 0.005);
    let sc = load(&scenario_text(&format!(
        "rate_hz = 50.0\naccel_bias_enu_mps2 = [{be}, {bn}, {bu}]"
    )));
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (report, ins) = simulate_with_ins(&sc, dir.path());
    let ins = ins.unwrap_or_else(|| panic!("no ins.csv written"));
    assert_eq!(ins.path, dir.path().join("ins.csv"));
    assert_eq!(ins.rows, 101);
    // The file passes the receiver's own validation.
    let track = read_ins_csv(&ins.path, 0.5).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(track.samples().len(), 101);

    // B in ECEF from the start point's local axes (up = east x north).
    let (e, n) = east_north(LAT_DEG, LON_DEG);
    let u = [
        e[1] * n[2] - e[2] * n[1],
        e[2] * n[0] - e[0] * n[2],
        e[0] * n[1] - e[1] * n[0],
    ];
    let b: Vec<f64> = (0..3).map(|i| be * e[i] + bn * n[i] + bu * u[i]).collect();

    let ins_rows = read_rows(&ins.path);
    let truth_rows = read_rows(&report.truth_path);
    assert_eq!(ins_rows.len(), truth_rows.len());
    let mut moved = 0.0f64;
    for (a, t) in ins_rows.iter().zip(&truth_rows) {
        let ts = t["t_s"];
        assert!((a["t_s"] - ts).abs() < 1e-9, "{} vs {ts}", a["t_s"]);
        // The same true time of week as truth.csv (the receiver clock bias is 200 us).
        assert!((a["gps_tow_s"] - t["tow_s"]).abs() < 1e-8, "t {ts}");
        for (i, (p, v)) in [("x_m", "vx_mps"), ("y_m", "vy_mps"), ("z_m", "vz_mps")]
            .iter()
            .enumerate()
        {
            // truth.csv rounds velocities to 1e-6 m/s and positions to 1e-4 m.
            let dv = a[*v] - t[*v];
            assert!((dv - b[i] * ts).abs() <= 1e-6, "t {ts} {v}: {dv}");
            let dp = a[*p] - t[*p];
            assert!(
                (dp - b[i] * ts * ts / 2.0).abs() <= 1e-4,
                "t {ts} {p}: {dp}"
            );
        }
        moved = moved.max((t["vx_mps"] - truth_rows[0]["vx_mps"]).abs());
    }
    // The truth really moves (so velocities are compared on a changing trajectory).
    assert!(moved > 1.0, "{moved}");
    // The last row: 2 s of |B| = 0.0229 m/s^2.
    let last = ins_rows.len() - 1;
    let dv: f64 = ["vx_mps", "vy_mps", "vz_mps"]
        .iter()
        .map(|c| (ins_rows[last][*c] - truth_rows[last][*c]).powi(2))
        .sum::<f64>()
        .sqrt();
    let want = 2.0 * (be * be + bn * bn + bu * bu).sqrt();
    assert!((dv - want).abs() < 2e-6, "{dv} vs {want}");
}

#[test]
fn scenario_without_ins_writes_no_ins_csv() {
    let text = scenario_text("");
    let text = text.replace("[ins]\n", "");
    let sc = load(&text);
    assert!(sc.ins.is_none());
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (_, ins) = simulate_with_ins(&sc, dir.path());
    assert!(ins.is_none());
    assert!(!dir.path().join("ins.csv").exists());
}

#[test]
fn bad_ins_tables_are_named_before_simulating() {
    let cases = [
        (
            "acel_bias_enu_mps2 = [0.01, 0.0, 0.0]",
            "[ins] `acel_bias_enu_mps2`: unknown field `acel_bias_enu_mps2`, expected one of",
        ),
        (
            "rate_hz = 5.0",
            "rate_hz = 5 must be between 10 and 10000 Hz",
        ),
        ("latency_s = -0.1", "latency_s = -0.1 must be"),
        (
            "band_limit_alpha_rad_s = 0.0",
            "band_limit_alpha_rad_s = 0 must be positive",
        ),
        (
            "accel_bias_enu_mps2 = [0.01, 0.0]",
            "[ins] `accel_bias_enu_mps2`: invalid length 2",
        ),
        (
            "rate_hz = \"fast\"",
            "[ins] `rate_hz`: invalid type: string \"fast\"",
        ),
    ];
    for (body, needle) in cases {
        // The scenario itself parses: the samples crate keeps [ins] as a plain table.
        let sc = load(&scenario_text(body));
        let e = ins_config(&sc)
            .err()
            .map(|e| error_message(&e))
            .unwrap_or_default();
        assert!(e.contains(needle), "{body}: {e} (wanted {needle})");
        assert!(e.contains("[ins]"), "{body}: {e}");
        let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let e = simulate(&sc, Path::new("."), dir.path(), &|_| ())
            .err()
            .map(|e| error_message(&e))
            .unwrap_or_default();
        assert!(e.contains(needle), "{body}: {e}");
        // Nothing was simulated.
        assert!(!dir.path().join("truth.csv").exists());
    }
}

#[test]
fn gpsrx_simulate_prints_the_ins_file() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let scenario = dir.path().join("s.toml");
    std::fs::write(
        &scenario,
        scenario_text("rate_hz = 20.0\nvelocity_random_walk_mps_per_sqrt_s = 0.01\nseed = 9"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_gpsrx"))
        .arg("simulate")
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .args(["--duration", "1"])
        .output()
        .unwrap_or_else(|e| panic!("{e}"));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let line = format!(
        "ins:       {} (21 rows at 20 Hz",
        out.join("ins.csv").display()
    );
    assert!(stdout.contains(&line), "{stdout}");
    let track = read_ins_csv(&out.join("ins.csv"), 0.5).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(track.span_s(), (0.0, 1.0));
}

/// Simulates `sc` into `dir` and returns the report and the `ins.csv` written, if any.
fn simulate_with_ins(sc: &Scenario, dir: &Path) -> (SimReport, Option<InsOutput>) {
    let (report, sensors) = simulate(sc, Path::new("."), dir, &|_| ())
        .unwrap_or_else(|e| panic!("{}", error_message(&e)));
    (report, sensors.ins)
}
