//! `gpsrx run` end to end on simulated recordings, against the simulator's truth files.

use crate::common::{run, truth};
use gpsrx_receiver::output::Fix;
use gpsrx_samples::sim::{Scenario, Simulator};
use std::path::{Path, PathBuf};

/// A static antenna in Busan (the `[receiver]` table of the scenarios below).
const STATIC_BUSAN: &str = "[receiver]\nkind = \"static\"\nllh_deg = [35.1796, 129.0756, 20.0]";

fn nav_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n")
}

/// Simulates `receiver` (a TOML `[receiver]` table and anything after it) for `duration_s`.
fn simulate(receiver: &str, duration_s: f64, dir: &Path) -> PathBuf {
    let text = format!(
        r#"
duration_s = {duration_s}
seed = 99
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538198.0
[output]
format = "ci8"
fs_hz = 2.048e6
[clock]
bias_s = 3.0e-4
drift_s_s = 4.0e-8
[truth]
rate_hz = 50.0
{receiver}
"#
    );
    let sc = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    sim.run(dir, &|_| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .data_path
}

/// Horizontal and vertical RMS position error and 3D velocity RMS of the fixes against truth
/// interpolated linearly at each fix's GPS time.
fn errors(fixes: &[Fix], truth: &[(f64, [f64; 3], [f64; 3])]) -> (f64, f64, f64) {
    let (mut h2, mut v2, mut vel2, mut n, mut nv) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for f in fixes {
        let t = f.time.tow_s;
        let i = truth
            .partition_point(|r| r.0 <= t)
            .clamp(1, truth.len() - 1);
        let (a, b) = (&truth[i - 1], &truth[i]);
        let u = (t - a.0) / (b.0 - a.0);
        let p: Vec<f64> = (0..3).map(|k| a.1[k] + u * (b.1[k] - a.1[k])).collect();
        let v: Vec<f64> = (0..3).map(|k| a.2[k] + u * (b.2[k] - a.2[k])).collect();
        let r = gpsrx_nav::frames::enu_rotation(&f.llh);
        let d = gpsrx_nav::frames::Vector3::new(
            f.ecef_m[0] - p[0],
            f.ecef_m[1] - p[1],
            f.ecef_m[2] - p[2],
        );
        let enu = r * d;
        h2 += enu.x * enu.x + enu.y * enu.y;
        v2 += enu.z * enu.z;
        n += 1.0;
        if let Some(fv) = f.vel_ecef_mps {
            vel2 += (0..3).map(|k| (fv[k] - v[k]).powi(2)).sum::<f64>();
            nv += 1.0;
        }
    }
    (
        (h2 / n).sqrt(),
        (v2 / n).sqrt(),
        (vel2 / nv.max(1.0)).sqrt(),
    )
}

/// What [`simulate_and_run`] measured.
struct Scored {
    fixes: Vec<Fix>,
    h: f64,
    v: f64,
    vel: f64,
}

/// Simulates `receiver` for `duration_s`, runs `gpsrx run` on it with `extra` options, prints
/// and returns the fixes with their errors against the truth (see [`errors`]).
fn simulate_and_run(label: &str, receiver: &str, duration_s: f64, extra: &[&str]) -> Scored {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(receiver, duration_s, dir.path());
    let fixes = run(&data, &dir.path().join("out"), extra);
    let (h, v, vel) = errors(&fixes, &truth(dir.path()));
    eprintln!(
        "{label}: {} fixes, H RMS {h:.2} m, V RMS {v:.2} m, velocity RMS {vel:.3} m/s",
        fixes.len()
    );
    Scored { fixes, h, v, vel }
}

#[test]
fn static_receiver_fixes_within_a_metre() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(STATIC_BUSAN, 16.0, dir.path());
    let out = dir.path().join("out");
    let fixes = run(
        &data,
        &out,
        &["--nav", nav_file().to_str().unwrap_or_default()],
    );
    // With the ephemerides given, the first fix comes within 1 s of the first decoded TOW: the
    // TLM and HOW of the subframe starting at 2.07 s (the recording starts 2 s before a
    // subframe boundary) end at 3.27 s, confirmed by a second satellite's.
    let first = fixes.first().unwrap_or_else(|| panic!("no fix"));
    let t_first = first.time.tow_s - 538198.0;
    assert!(t_first < 3.27 + 1.0, "first fix at {t_first:.2} s");
    let (h, v, vel) = errors(&fixes, &truth(dir.path()));
    eprintln!(
        "static: {} fixes, H RMS {h:.2} m, V RMS {v:.2} m, velocity RMS {vel:.3} m/s",
        fixes.len()
    );
    // 10 s of carrier smoothing at 41-47 dB-Hz with PDOP about 2: sub-metre horizontally.
    assert!(
        h < 1.5 && v < 3.0 && vel < 0.1,
        "H {h:.2} V {v:.2} vel {vel:.3}"
    );
    // Every output file is there.
    for f in [
        "pvt.csv",
        "pvt.nmea",
        "observables.rnx",
        "ephemeris.rnx",
        "track.geojson",
        "track.kml",
        "channels.csv",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
}

#[test]
fn moving_receiver_at_constant_speed() {
    let nav = nav_file();
    let r = simulate_and_run(
        "moving 25 m/s",
        "[receiver]\nkind = \"motion\"\nstart_llh_deg = [35.1796, 129.0756, 20.0]\nheading_deg = 60.0\nspeed_mps = 25.0\nsegments = []",
        16.0,
        &["--nav", nav.to_str().unwrap_or_default()],
    );
    assert!(r.fixes.len() > 60, "{} fixes", r.fixes.len());
    assert!(
        r.h < 2.0 && r.v < 4.0 && r.vel < 0.15,
        "H {:.2} V {:.2} vel {:.3}",
        r.h,
        r.v,
        r.vel
    );
}

#[test]
fn weak_signals_are_found_by_the_second_search_and_give_fixes() {
    // Every satellite at 31 dB-Hz: the 1 ms x 10 cold search finds none of them, the automatic
    // 10 ms x 10 search finds them, and the channels run the 20 ms weak-signal loops.
    let nav = nav_file();
    let r = simulate_and_run(
        "31 dB-Hz",
        "[receiver]\nkind = \"static\"\nllh_deg = [48.8566, 2.3522, 60.0]\n[satellites]\ncn0_all_dbhz = 31.0",
        20.0,
        &["--nav", nav.to_str().unwrap_or_default()],
    );
    // Code jitter at 31 dB-Hz is several metres per satellite before the 10 s carrier
    // smoothing has converged (measured: H 4.5 m, V 8.3 m over these first 11 s of fixes).
    assert!(r.fixes.len() > 30, "{} fixes", r.fixes.len());
    assert!(r.h < 8.0 && r.v < 15.0, "H {:.2} V {:.2}", r.h, r.v);
}

#[test]
fn the_default_loops_keep_fixing_through_a_10_g_turn_without_assistance() {
    // 100 m/s, a 10 g turn from 30 to 38 s (0.5 s jerk ramps). No --nav: the ephemerides and the
    // ionosphere are decoded from the signal, and the fixes before subframe 4 page 18 use the
    // typical Klobuchar coefficients (without them the first fixes were 7 m high).
    let r = simulate_and_run(
        "10 g",
        "[receiver]\nkind = \"motion\"\nstart_llh_deg = [37.5665, 126.9780, 40.0]\nheading_deg = 30.0\nspeed_mps = 100.0\ntransition_s = 0.5\nsegments = [{ type = \"cruise\", duration_s = 30.0 }, { type = \"turn\", duration_s = 8.0, accel_g = 10.0, direction = \"left\" }, { type = \"cruise\", duration_s = 10.0 }]",
        46.0,
        &["--week", "2190"],
    );
    let longest_gap = r
        .fixes
        .windows(2)
        .map(|w| w[1].time.tow_s - w[0].time.tow_s)
        .fold(0.0, f64::max);
    // Fixes from about 20 s (subframes 1-3) to the end at 10 Hz, without a break in the turn.
    assert!(r.fixes.len() > 200, "{} fixes", r.fixes.len());
    assert!(longest_gap < 0.5, "a {longest_gap:.1} s gap in the fixes");
    assert!(
        r.h < 1.5 && r.v < 3.0 && r.vel < 0.5,
        "H {:.2} V {:.2} vel {:.2}",
        r.h,
        r.v,
        r.vel
    );
}

#[test]
fn outage_of_all_satellites_then_fixes_again() {
    // All signals blocked from 12 to 32 s: channels are released, satellites re-acquired after
    // 32 s, frame sync found again, fixes resume.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(
        "[receiver]\nkind = \"static\"\nllh_deg = [35.1796, 129.0756, 20.0]\n[[outages]]\nstart_s = 12.0\nend_s = 32.0",
        46.0,
        dir.path(),
    );
    let fixes = run(
        &data,
        &dir.path().join("out"),
        &["--nav", nav_file().to_str().unwrap_or_default()],
    );
    let t = |f: &Fix| f.time.tow_s - 538198.0;
    let before = fixes.iter().filter(|f| t(f) < 12.0).count();
    // The lock detectors need up to ~1 s to see the signal gone (phase-lock filter and
    // hysteresis, then the C/N0 test); fixes in that time coast on the NCOs and must still be
    // sane (checked below); after it there must be none.
    let coasting: Vec<Fix> = fixes
        .iter()
        .filter(|f| (12.0..13.5).contains(&t(f)))
        .cloned()
        .collect();
    let during = fixes
        .iter()
        .filter(|f| (13.5..32.0).contains(&t(f)))
        .count();
    let after: Vec<Fix> = fixes.iter().filter(|f| t(f) > 32.0).cloned().collect();
    eprintln!(
        "outage: {before} fixes before, {during} during, {} after (first at {:.1} s)",
        after.len(),
        after.first().map(t).unwrap_or(f64::NAN)
    );
    assert!(before > 10, "{before} fixes before the outage");
    assert_eq!(during, 0, "fixes during a total outage");
    assert!(!after.is_empty(), "no fix after the outage");
    if !coasting.is_empty() {
        let (h, v, _) = errors(&coasting, &truth(dir.path()));
        assert!(h < 10.0 && v < 20.0, "coasting fixes: H {h:.2} V {v:.2}");
    }
    let (h, v, _) = errors(&after, &truth(dir.path()));
    assert!(h < 3.0 && v < 6.0, "after the outage: H {h:.2} V {v:.2}");
}

#[test]
fn a_recording_too_short_for_a_fix_ends_with_a_message_not_an_error() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(STATIC_BUSAN, 3.0, dir.path());
    let fixes = run(&data, &dir.path().join("out"), &[]);
    assert!(fixes.is_empty());
}

#[test]
fn no_plots_leaves_the_png_plots_out() {
    // 3 s: no fix, but the channels' C/N0 is plotted by default.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(STATIC_BUSAN, 3.0, dir.path());
    let pngs = |out: &std::path::Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(out)
            .unwrap_or_else(|e| panic!("{e}"))
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".png"))
            .collect();
        v.sort();
        v
    };
    let on = dir.path().join("on");
    run(&data, &on, &[]);
    assert_eq!(pngs(&on), ["cn0.png"]);
    let off = dir.path().join("off");
    run(&data, &off, &["--no-plots"]);
    assert!(pngs(&off).is_empty(), "{:?}", pngs(&off));
}

#[test]
fn observables_before_the_first_fix_carry_the_decoded_week() {
    // 16 s: subframe 1 (TOW 538200-538206) is decoded, subframe 3 is not, so no fix. Without
    // its metadata the recording has no date and there is no --week: the epochs before
    // subframe 1 are held back (labelled with today's week, which is never written) and must
    // be written with the decoded week 2190, in increasing time.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(STATIC_BUSAN, 16.0, dir.path());
    std::fs::remove_file(gpsrx_samples::sigmf::meta_path_for(&data))
        .unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    let fixes = run(&data, &out, &["--format", "ci8", "--fs", "2.048e6"]);
    assert!(fixes.is_empty(), "{} fixes from 16 s", fixes.len());
    let text =
        std::fs::read_to_string(out.join("observables.rnx")).unwrap_or_else(|e| panic!("{e}"));
    // RINEX 3 epoch lines: "> yyyy mm dd hh mm ss.sssssss  flag nsat"; 2190/538200 s is
    // 2022-01-01 05:30:00 GPS time.
    let epochs: Vec<&str> = text.lines().filter(|l| l.starts_with("> ")).collect();
    assert!(epochs.len() > 5, "{} epochs", epochs.len());
    for w in epochs.windows(2) {
        assert!(
            w[0][2..29] < w[1][2..29],
            "not increasing: `{}` then `{}`",
            w[0],
            w[1]
        );
    }
    for e in &epochs {
        assert!(e.starts_with("> 2022 01 01 05 "), "wrong week: `{e}`");
    }
}

#[test]
fn three_satellites_and_one_landmark_give_fixes() {
    // Seed 001: a landmark range without a clock term completes a 3-satellite geometry.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(
        "[receiver]\nkind = \"static\"\nllh_deg = [35.1796, 129.0756, 20.0]\n[satellites]\nprns = [26, 29, 31]",
        13.0,
        dir.path(),
    );
    let truth_rows = truth(dir.path());
    let rx =
        gpsrx_nav::frames::Vector3::new(truth_rows[0].1[0], truth_rows[0].1[1], truth_rows[0].1[2]);
    // A surveyed point 30 m east, 20 m north and 25 m above the antenna (a rooftop mark); ranges
    // every 0.1 s with sigma 0.5 m (exact values: the test checks the geometry, not the noise).
    // With exactly four observations the geometry is weak and a nearly horizontal landmark can
    // leave the cold-start iteration without a solution (see nav/src/pvt/landmark.rs).
    let origin = gpsrx_nav::frames::Llh::from_ecef(&rx);
    let lm = rx
        + gpsrx_nav::frames::enu_rotation(&origin).transpose()
            * gpsrx_nav::frames::Vector3::new(30.0, 20.0, 25.0);
    let range = (lm - rx).norm();
    let mut csv = String::from("tow_s,x_m,y_m,z_m,range_m,sigma_m\n");
    for i in 0..130 {
        csv.push_str(&format!(
            "{:.1},{},{},{},{range},0.5\n",
            538198.0 + 0.1 * f64::from(i),
            lm.x,
            lm.y,
            lm.z
        ));
    }
    let lm_path = dir.path().join("landmarks.csv");
    std::fs::write(&lm_path, csv).unwrap_or_else(|e| panic!("{e}"));
    let nav = nav_file();
    let fixes = run(
        &data,
        &dir.path().join("out"),
        &[
            "--nav",
            nav.to_str().unwrap_or_default(),
            "--landmarks",
            lm_path.to_str().unwrap_or_default(),
        ],
    );
    assert!(!fixes.is_empty(), "no fix from 3 satellites + 1 landmark");
    assert!(
        fixes.iter().all(|f| f.n_sv == 3),
        "satellites used: {:?}",
        fixes.iter().map(|f| f.n_sv).collect::<Vec<_>>()
    );
    let (h, v, _) = errors(&fixes, &truth_rows);
    eprintln!(
        "3 satellites + 1 landmark: {} fixes, H RMS {h:.2} m, V RMS {v:.2} m",
        fixes.len()
    );
    // PDOP is 4-5 with the landmark (3 satellites alone give no fix): metres, measured 1.3 m.
    assert!(h < 5.0 && v < 10.0, "H {h:.2} V {v:.2}");
    // Without the landmark: no fix at all.
    let none = run(
        &data,
        &dir.path().join("out2"),
        &["--nav", nav.to_str().unwrap_or_default()],
    );
    assert!(none.is_empty());
}

#[test]
fn the_broadcast_utc_weeks_are_resolved_with_the_decoded_week() {
    // 30 s without --week: the reference week is today's, years after the recording. The
    // 8-bit WN_t of subframe 4 page 18 must be resolved against the decoded 10-bit week, so
    // the RINEX header carries the week of the navigation file the simulator encoded (its
    // DELTA-UTC line), not one 256 weeks off.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(STATIC_BUSAN, 30.0, dir.path());
    let out = dir.path().join("out");
    run(&data, &out, &[]);
    let nav = gpsrx_nav::rinex_nav::read_rinex_nav(&nav_file()).unwrap_or_else(|e| panic!("{e}"));
    let utc = nav
        .utc
        .unwrap_or_else(|| panic!("no DELTA-UTC in the navigation file"));
    let text = std::fs::read_to_string(out.join("ephemeris.rnx")).unwrap_or_else(|e| panic!("{e}"));
    let gput = text
        .lines()
        .find(|l| l.starts_with("GPUT"))
        .unwrap_or_else(|| panic!("no GPUT line (page 18 not decoded?):\n{text}"));
    // "GPUT a0 a1 tot wnt" (RINEX 3 TIME SYSTEM CORR).
    let week: u32 = gput
        .split_whitespace()
        .nth(4)
        .and_then(|w| w.parse().ok())
        .unwrap_or_else(|| panic!("no week in `{gput}`"));
    assert_eq!(week, utc.wnt, "`{gput}`");
}

#[test]
fn the_almanac_broadcast_is_decoded_and_written_as_yuma() {
    // The simulator sends subframes 4 and 5 pages by frame number (IS-GPS-200 Table 20-V):
    // starting at TOW 538430 s, the frame of 538440 s carries subframe 5 page 24 (PRN 24) and
    // the next one page 25 (t_oa and WN_a), which dates it. Truth: the almanac the simulator
    // derives from the broadcast ephemerides (`Almanac::from_ephemeris`).
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let text = r#"
duration_s = 75.0
seed = 3
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538430.0
[output]
format = "ci8"
fs_hz = 2.048e6
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[satellites]
almanac = true
"#;
    let sc = Scenario::from_toml(text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let data = sim
        .run(dir.path(), &|_| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .data_path;
    let out = dir.path().join("out");
    run(
        &data,
        &out,
        &["--nav", nav_file().to_str().unwrap_or_default()],
    );
    let yuma = std::fs::read_to_string(out.join("almanac.yuma")).unwrap_or_else(|e| panic!("{e}"));
    let block = yuma
        .split("\n\n")
        .find(|b| b.contains("almanac for PRN-24"))
        .unwrap_or_else(|| panic!("no PRN 24 in {yuma}"));
    let field = |name: &str| -> f64 {
        block
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split(':').nth(1))
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(f64::NAN)
    };
    let nav = gpsrx_nav::rinex_nav::parse_rinex_nav(gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT)
        .unwrap_or_else(|e| panic!("{e}"));
    let t = gpsrx_nav::GpsTime::new(2190, 538440.0);
    let eph = nav
        .select_with(24, t, gpsrx_nav::HealthPolicy::PreferHealthy)
        .unwrap_or_else(|| panic!("no ephemeris of PRN 24"));
    let toa = gpsrx_nav::GpsTime::new(2190, field("Time of Applicability"));
    let want = gpsrx_nav::almanac::Almanac::from_ephemeris(eph, toa);
    // Within the ICD's quantisation (Table 20-VI: e 2^-21, sqrt A 2^-11, angles 2^-23 to
    // 2^-15 semicircles).
    assert!((field("Eccentricity") - want.e).abs() < 1e-6, "{block}");
    assert!(
        (field("SQRT(A)") - want.sqrt_a_sqrt_m).abs() < 1e-3,
        "{block}"
    );
    assert!(
        (field("Orbital Inclination") - want.inclination_rad()).abs() < 1e-5,
        "{block}"
    );
    assert!((field("Mean Anom") - want.m0_rad).abs() < 1e-6, "{block}");
    assert_eq!(field("week"), f64::from(2190 % 1024));
}

/// Valid fixes (quality not `none`) from `t_from_s` to `t_to_s` seconds after the start of a
/// [`simulate`]d recording (TOW 538198).
fn fixes_between(fixes: &[Fix], t_from_s: f64, t_to_s: f64) -> Vec<Fix> {
    fixes
        .iter()
        .filter(|f| f.quality != gpsrx_receiver::output::FixQuality::None)
        .filter(|f| (t_from_s..t_to_s).contains(&(f.time.tow_s - 538198.0)))
        .cloned()
        .collect()
}

/// 3D RMS error of `fixes` against the truth, m.
fn rms_3d(fixes: &[Fix], truth: &[(f64, [f64; 3], [f64; 3])]) -> f64 {
    let (h, v, _) = errors(fixes, truth);
    h.hypot(v)
}

#[test]
fn an_approximate_time_and_position_give_the_first_fix_within_two_seconds() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(STATIC_BUSAN, 8.0, dir.path());
    let truth = truth(dir.path());
    let nav = nav_file();
    let nav = nav.to_str().unwrap_or_default();
    let run_with = |name: &str, extra: &[&str]| {
        let mut args = vec!["--nav", nav];
        args.extend_from_slice(extra);
        let fixes = run(&data, &dir.path().join(name), &args);
        let valid = fixes_between(&fixes, 0.0, 100.0);
        let first = valid
            .first()
            .map_or(f64::INFINITY, |f| f.time.tow_s - 538198.0);
        let early = fixes_between(&fixes, first, first + 2.0);
        let worst = valid
            .iter()
            .map(|f| rms_3d(std::slice::from_ref(f), &truth))
            .fold(0.0, f64::max);
        let rms = rms_3d(&early, &truth);
        eprintln!(
            "{name}: first fix {first:.2} s, first 2 s of fixes 3D RMS {rms:.2} m, all {:.2} m, worst {worst:.2} m, {} fixes",
            rms_3d(&valid, &truth),
            valid.len()
        );
        (first, rms, worst, rms_3d(&valid, &truth))
    };
    // The normal path: frame sync from the first TLM and HOW (the subframe starting at 2 s),
    // confirmed across satellites.
    let (first_nav, _, _, rms_nav) = run_with("nav", &[]);
    assert!(
        first_nav < 3.2 + 0.5,
        "--nav alone: first fix at {first_nav:.2} s"
    );
    // Coarse time from the SigMF core:datetime (the simulator writes it) and the position 1 km
    // off; and from --time 25 s off, which overrides the recording's date.
    let llh = "35.185,129.085,0";
    for (name, extra) in [
        ("sigmf", vec!["--approx-llh", llh]),
        ("time", vec!["--approx-llh", llh, "--time", "2190:538223"]),
    ] {
        let (first, rms, worst, _) = run_with(name, &extra);
        assert!(first <= 2.0, "{name}: first fix at {first:.2} s");
        assert!(
            rms <= 2.0 * rms_nav,
            "{name}: the first 2 s of fixes {rms:.2} m against {rms_nav:.2} m of the normal path"
        );
        assert!(worst < 10.0, "{name}: a fix {worst:.2} m off");
    }
    // Wrong a-priori values give no fix from the code phases (and no wrong fix): the first
    // fix waits for frame sync.
    for (name, extra) in [
        ("500 km off", vec!["--approx-llh", "39.68,129.08,20"]),
        (
            "10 min off",
            vec!["--approx-llh", llh, "--time", "2190:538798"],
        ),
    ] {
        let (first, _, worst, _) = run_with(name, &extra);
        assert!(
            (3.2..3.2 + 0.5).contains(&first),
            "{name}: first fix at {first:.2} s"
        );
        assert!(worst < 10.0, "{name}: a fix {worst:.2} m off");
    }
}

#[test]
fn the_profile_accounts_for_the_run_stage_by_stage() {
    // 3 s at 2.048 MHz: the cold start, rounds with background searches (their deep levels
    // from 0.5 s on), the navigation and the outputs; no fix is needed.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let data = simulate(STATIC_BUSAN, 3.0, dir.path());
    let out = dir.path().join("out");
    let (report, _) = crate::common::run_report(&data, &out, &["--no-plots"]);
    let s = &report.receiver;
    let p = &s.profile;
    assert!(p.cold_start_s > 0.0 && p.rounds_s > 0.0, "{p:?}");
    assert!(
        p.tracking_s > 0.0 && p.navigation_s > 0.0 && p.read_s > 0.0,
        "{p:?}"
    );
    assert!(p.searches >= 1 && p.search_s > 0.0, "{p:?}");
    // The parts of the rounds lie within them (each timed inside its round), and the serial
    // stages within the run's wall time.
    assert!(p.tracking_s <= p.rounds_s + 1e-3, "{p:?}");
    assert!(p.search_s <= p.rounds_s + 1e-3, "{p:?}");
    assert!(
        p.accounted_s() <= s.wall_s + 1e-3,
        "{p:?} in {} s",
        s.wall_s
    );
    assert!(p.accounted_s() >= 0.5 * s.wall_s, "{p:?} in {} s", s.wall_s);
    // The table names every stage.
    let mut text = Vec::new();
    gpsrx_cli::commands::run::profile_table::write_profile(
        &mut text,
        p,
        s.duration_s,
        s.wall_s,
        gpsrx_cli::commands::run::profile_table::process_usage(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let text = String::from_utf8(text).unwrap_or_else(|e| panic!("{e}"));
    for stage in [
        "cold start",
        "channels",
        "background search",
        "navigation",
        "reading",
    ] {
        assert!(text.contains(stage), "{stage} missing:\n{text}");
    }
    // And `--profile` is an option of `gpsrx run`.
    let cli = <gpsrx_cli::cli::Cli as clap::Parser>::try_parse_from([
        "gpsrx",
        "run",
        "x.ci8",
        "--out",
        "o",
        "--profile",
    ])
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(matches!(cli.command, gpsrx_cli::cli::Command::Run(a) if a.profile));
}
