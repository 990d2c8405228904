//! `gpsrx run --dr --accel` end to end (issue 6): a simulated drive with a 30 s outage of every
//! satellite and its DR and accelerometer logs from the simulator, against the truth.

use crate::common::{run, truth};
use gpsrx_nav::frames::{enu_rotation, Llh, Vector3};
use gpsrx_receiver::simulate::simulate;
use gpsrx_samples::sim::Scenario;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn scenario_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/scenarios/drive-dr-outage.toml")
}

fn nav_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n")
}

/// `fused.csv` rows as column -> text maps.
fn fused_rows(out: &Path) -> Vec<HashMap<String, String>> {
    let mut rdr = csv::Reader::from_path(out.join("fused.csv")).unwrap_or_else(|e| panic!("{e}"));
    rdr.deserialize()
        .map(|r| r.unwrap_or_else(|e| panic!("{e}")))
        .collect()
}

/// Horizontal error of a (lat, lon) against the truth at GPS time `tow_s` (linear
/// interpolation), and the truth's horizontal speed.
fn horizontal_error(
    tr: &[(f64, [f64; 3], [f64; 3])],
    tow_s: f64,
    lat_deg: f64,
    lon_deg: f64,
    h_m: f64,
) -> (f64, f64) {
    let i = tr.partition_point(|r| r.0 <= tow_s).clamp(1, tr.len() - 1);
    let (a, b) = (&tr[i - 1], &tr[i]);
    let u = (tow_s - a.0) / (b.0 - a.0);
    let p = Vector3::from_fn(|k, _| a.1[k] + u * (b.1[k] - a.1[k]));
    let v = Vector3::from_fn(|k, _| a.2[k] + u * (b.2[k] - a.2[k]));
    let llh = Llh::from_degrees(lat_deg, lon_deg, h_m);
    let r = enu_rotation(&llh);
    let d = r * (llh.to_ecef() - p);
    let ve = r * v;
    (d.x.hypot(d.y), ve.x.hypot(ve.y))
}

#[test]
fn fused_fixes_continue_through_a_30_s_outage_within_metres_of_the_truth() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (sc, base) = Scenario::load(&scenario_path()).unwrap_or_else(|e| panic!("{e}"));
    let (report, sensors) =
        simulate(&sc, &base, dir.path(), &|_| ()).unwrap_or_else(|e| panic!("{e}"));
    let dr = sensors
        .dr
        .unwrap_or_else(|| panic!("the scenario has a [dr] table"));
    let accel = sensors
        .accel
        .unwrap_or_else(|| panic!("the scenario has an [accel] table"));
    let out = dir.path().join("run");
    let nav = nav_file();
    let fixes = run(
        &report.data_path,
        &out,
        &[
            "--nav",
            nav.to_str().unwrap_or_default(),
            "--dr",
            dr.path.to_str().unwrap_or_default(),
            "--accel",
            accel.path.to_str().unwrap_or_default(),
        ],
    );
    // The outage is real: no GNSS fix between 72 and 100 s of the file (a fix's GPS time minus
    // the file start; the lock detectors take up to 2 s to see the signal go).
    let t0 = 538198.0;
    let in_outage = fixes
        .iter()
        .filter(|f| (72.0..100.0).contains(&(f.time.tow_s - t0)))
        .count();
    assert_eq!(in_outage, 0, "GNSS fixes inside the outage");

    let tr = truth(dir.path());
    let rows = fused_rows(&out);
    let num = |r: &HashMap<String, String>, k: &str| -> f64 {
        r[k].parse()
            .unwrap_or_else(|e| panic!("{k} = {:?}: {e}", r[k]))
    };
    // Continuous: from the first fused row to the end of the log, no gap over 0.15 s.
    let first_fused = rows
        .iter()
        .position(|r| r["source"] == "fused")
        .unwrap_or_else(|| panic!("no fused row"));
    let gaps = rows[first_fused..]
        .windows(2)
        .map(|w| num(&w[1], "t_s") - num(&w[0], "t_s"))
        .fold(0.0f64, f64::max);
    assert!(gaps < 0.15, "largest gap between fused rows {gaps} s");

    let mut by_source: HashMap<String, Vec<f64>> = HashMap::new();
    let mut speed_err2 = (0.0, 0usize);
    for r in &rows[first_fused..] {
        let (e, truth_speed) = horizontal_error(
            &tr,
            num(r, "tow_s"),
            num(r, "lat_deg"),
            num(r, "lon_deg"),
            num(r, "h_m"),
        );
        by_source.entry(r["source"].clone()).or_default().push(e);
        if r["source"] == "dr" {
            let s = num(r, "speed_filter_mps");
            speed_err2.0 += (s - truth_speed).powi(2);
            speed_err2.1 += 1;
        }
    }
    let stats = |v: &[f64]| {
        let rms = (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
        let max = v.iter().copied().fold(0.0, f64::max);
        (v.len(), rms, max)
    };
    let (n_dr, dr_rms, dr_max) = stats(by_source.get("dr").map_or(&[][..], |v| v));
    let (n_fused, fused_rms, fused_max) = stats(by_source.get("fused").map_or(&[][..], |v| v));
    let speed_rms = (speed_err2.0 / speed_err2.1.max(1) as f64).sqrt();
    println!(
        "fused: {n_fused} rows, horizontal RMS {fused_rms:.2} m (max {fused_max:.2}); DR only: {n_dr} rows, RMS {dr_rms:.2} m (max {dr_max:.2}); speed filter RMS in the outage {speed_rms:.3} m/s"
    );
    // The outage (30 s) plus the time to re-acquire and re-decode the time of week.
    assert!(n_dr >= 290, "{n_dr} DR-only rows");
    assert!(fused_rms < 1.5, "fused horizontal RMS {fused_rms} m");
    // Seed 000's DR grows tens of metres over a minute; a calibrated gyro and odometer over 30 s
    // and 360 m must stay within about 2 % of the distance.
    assert!(dr_max < 6.0, "DR-only max horizontal error {dr_max} m");
    // Seed 002's KF2 lets its accelerometer-bias state random-walk (1e-3 (m/s^2)^2/s, for
    // slope changes), so at the start of a gap its bias error is a few 0.01 m/s^2 and the speed
    // drifts by 0.3-1 m/s over this 30-40 s gap depending on the last GNSS speeds (0.33 m/s
    // and 0.70 m/s on two receiver versions). `gpsrx study dr` measures the filter's gain over
    // many gaps; here it must stay a bounded drift.
    assert!(speed_rms < 1.0, "speed filter RMS {speed_rms} m/s");

    // The plots, dr.png with them: PNG signatures (PNG spec 5.2).
    for name in ["track.png", "skyplot.png", "cn0.png", "dop.png", "dr.png"] {
        let bytes = std::fs::read(out.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name}");
    }

    // NMEA marks DR-only fixes with GGA quality 6; the calibration is saved.
    let nmea = std::fs::read_to_string(out.join("fused.nmea")).unwrap_or_else(|e| panic!("{e}"));
    assert!(nmea
        .lines()
        .any(|l| l.starts_with("$GPGGA") && l.split(',').nth(6) == Some("6")));
    let p = gpsrx_ins_aiding::DrParams::load(&out.join("dr_params.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    // The simulated odometer counts 2 % too many pulses: the calibrated Sf_N moves towards
    // 0.1 / 1.02 = 0.09804 m/pulse.
    assert!(
        (p.sf_n_m_per_pulse - 0.1 / 1.02).abs() < 0.001,
        "Sf_N {}",
        p.sf_n_m_per_pulse
    );
}
