//! The simulator against its own truth and against independent references.
//!
//! The replica used here is built from the C/A code generator (checked against IS-GPS-200
//! Table 3-Ia) and the truth phases; the samples are read back from the written file through the
//! same `open_source` any recording goes through, so quantisation and file layout are included.

use gpsrx_dsp::constants::CA_CHIP_RATE_HZ;
use gpsrx_dsp::{CaCode, Prn};
use gpsrx_nav::lnav::{decode_subframe, SubframePayload};
use gpsrx_nav::rinex_nav::parse_rinex_nav;
use gpsrx_nav::rotate_for_earth_rotation as rotate_earth;
use gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT;
use gpsrx_samples::sim::{Scenario, SimSatellite, Simulator};
use gpsrx_samples::{open_source, SourceConfig};
use num_complex::Complex32;
use std::path::Path;

fn scenario(extra: &str, duration_s: f64, fs_hz: f64, format: &str) -> Scenario {
    scenario_with_if(extra, duration_s, fs_hz, format, 0.0)
}

fn scenario_with_if(
    extra: &str,
    duration_s: f64,
    fs_hz: f64,
    format: &str,
    if_hz: f64,
) -> Scenario {
    let text = format!(
        r#"
duration_s = {duration_s}
seed = 5
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "{format}"
fs_hz = {fs_hz}
if_hz = {if_hz}
[receiver]
kind = "static"
llh_deg = [37.5665, 126.9780, 40.0]
[clock]
bias_s = 2.0e-4
drift_s_s = 5.0e-8
{extra}
"#
    );
    Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"))
}

/// Simulates a scenario into a temporary directory (kept alive by the returned handle) and
/// reads the recording back.
fn simulate_and_read(
    sc: &Scenario,
) -> (
    Simulator,
    tempfile::TempDir,
    gpsrx_samples::sim::SimReport,
    Vec<Complex32>,
) {
    let sim = Simulator::new(sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let report = sim
        .run(dir.path(), &|_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    let x = read_all(&report.data_path);
    (sim, dir, report, x)
}

/// Reads a whole (small) recording back as complex baseband.
fn read_all(path: &Path) -> Vec<Complex32> {
    let mut src =
        open_source(&SourceConfig::new(path.to_path_buf())).unwrap_or_else(|e| panic!("{e}"));
    let mut all = Vec::new();
    let mut buf = vec![Complex32::new(0.0, 0.0); 1 << 16];
    loop {
        let (_, n) = src.read(&mut buf).unwrap_or_else(|e| panic!("{e}"));
        if n == 0 {
            break;
        }
        all.extend_from_slice(&buf[..n]);
    }
    all
}

/// Prompt correlation over samples `[k0, k0 + n)` with a replica of `prn` placed at the truth
/// code phase and carrier phase (plus `code_offset_chips`), using the simulator's propagation
/// model as truth.
fn correlate(
    sim: &Simulator,
    sat: &SimSatellite,
    rec: (&[Complex32], f64),
    k0: usize,
    n: usize,
    code_offset_chips: f64,
    replica_prn: Prn,
) -> Complex32 {
    let (x, fs) = rec;
    let code = CaCode::new(replica_prn);
    let t0 = k0 as f64 / fs;
    let t1 = (k0 + n) as f64 / fs;
    let (o0, _) = sim.observe(sat, t0);
    let (o1, _) = sim.observe(sat, t1);
    let mut acc = Complex32::new(0.0, 0.0);
    for i in 0..n {
        let u = i as f64 / n as f64;
        let chips = o0.chips + u * (o1.chips - o0.chips) + code_offset_chips;
        let ph = o0.carrier_cycles + u * (o1.carrier_cycles - o0.carrier_cycles);
        let c = f32::from(code.chip(chips.rem_euclid(1023.0) as usize));
        let rot = Complex32::from_polar(
            1.0,
            (-2.0 * std::f64::consts::PI * ph.rem_euclid(1.0)) as f32,
        );
        acc += x[k0 + i] * rot * c;
    }
    acc
}

#[test]
fn correlation_at_truth_gives_the_configured_cn0_and_phase() {
    // Two satellites at fixed C/N0 (45 and 35 dB-Hz), 1.5 s at 2.048 MHz ci8.
    let sc = scenario(
        "[satellites]\nprns = [16, 26, 31]\ncn0 = [{ prn = 16, dbhz = 45.0 }, { prn = 26, dbhz = 35.0 }, { prn = 31, dbhz = 40.0 }]\n[truth]\nrate_hz = 10.0",
        1.5,
        2.048e6,
        "ci8",
    );
    let (sim, _dir, _report, x) = simulate_and_read(&sc);
    let fs = 2.048e6;
    let n = (fs * 1e-3) as usize; // 1 ms coherent
    let unused = Prn::new(1).unwrap_or_else(|e| panic!("{e}"));
    for (prn, cn0_set) in [(16u8, 45.0), (26, 35.0), (31, 40.0)] {
        let sat = sim
            .satellites
            .iter()
            .find(|s| s.prn.get() == prn)
            .unwrap_or_else(|| panic!("G{prn}"));
        let mut sig = 0.0f64;
        let mut noise = 0.0f64;
        let mut phase_err = Vec::new();
        let blocks = 1400;
        for b in 0..blocks {
            let k0 = 20 * n + b * n;
            let p = correlate(&sim, sat, (&x, fs), k0, n, 0.0, sat.prn);
            sig += f64::from(p.norm_sqr());
            // The noise floor: the same samples against a PRN that is not transmitted.
            noise += f64::from(correlate(&sim, sat, (&x, fs), k0, n, 0.0, unused).norm_sqr());
            // Data bits flip the sign: fold the phase into (-90, 90] degrees.
            let mut ph = f64::from(p.arg()).to_degrees();
            if ph > 90.0 {
                ph -= 180.0;
            } else if ph <= -90.0 {
                ph += 180.0;
            }
            phase_err.push(ph);
        }
        let (sig, noise) = (sig / blocks as f64, noise / blocks as f64);
        // E|P|^2 = A^2 N^2 + 2 sigma^2 N and E|noise|^2 = 2 sigma^2 N, so
        // C/N0 = (E|P|^2 - noise) / noise / T with T = 1 ms.
        let cn0 = 10.0 * ((sig - noise) / noise / 1e-3).log10();
        // Tolerance 1 dB (the issue's requirement); the estimate's own scatter over 1400 ms is
        // 0.1-0.3 dB, quantisation to 8 bits at sigma = 20 LSB costs < 0.01 dB.
        assert!(
            (cn0 - cn0_set).abs() < 1.0,
            "G{prn}: measured {cn0:.2} dB-Hz, configured {cn0_set}"
        );
        // The truth carrier phase is the signal's: the prompt phase error is thermal only.
        let mean = phase_err.iter().sum::<f64>() / phase_err.len() as f64;
        assert!(mean.abs() < 3.0, "G{prn}: mean prompt phase {mean:.2} deg");
    }
}

#[test]
fn code_phase_follows_truth_over_time() {
    // Early-minus-late at +-0.5 chip around the truth code phase must be balanced at the start
    // and 8 s later: the signal's code phase drifts exactly as the truth code rate says.
    let sc = scenario(
        "[satellites]\nprns = [3, 22]\ncn0_all_dbhz = 50.0\n[truth]\nrate_hz = 10.0",
        8.2,
        2.6e6,
        "ci16_le",
    );
    let (sim, _dir, _report, x) = simulate_and_read(&sc);
    let fs = 2.6e6;
    let n = 2600;
    for sat in &sim.satellites {
        for start_ms in [0usize, 8000] {
            let (mut e, mut l) = (0.0f64, 0.0f64);
            for b in 0..100 {
                let k0 = (start_ms + b) * n;
                e += f64::from(correlate(&sim, sat, (&x, fs), k0, n, -0.5, sat.prn).norm());
                l += f64::from(correlate(&sim, sat, (&x, fs), k0, n, 0.5, sat.prn).norm());
            }
            // Normalised E-L envelope: (E-L)/(E+L) = tau_err / (1 - 0.5) for an ideal
            // triangle with 1-chip spacing, so |tau_err| = 0.5 * |D|.
            let tau_err_chips = 0.5 * (e - l) / (e + l);
            assert!(
                tau_err_chips.abs() < 0.03,
                "{} at {start_ms} ms: code error {tau_err_chips:.4} chip",
                sat.prn
            );
        }
        // Code Doppler is carrier Doppler / 1540 (up to ionospheric divergence, < 1 mm/s here).
        let (o0, _) = sim.observe(sat, 1.0);
        let (o1, _) = sim.observe(sat, 1.001);
        let code_doppler = (o1.chips - o0.chips) / 0.001 - CA_CHIP_RATE_HZ;
        let doppler = (o1.carrier_cycles - o0.carrier_cycles) / 0.001;
        assert!(
            (code_doppler - doppler / 1540.0).abs() < 1e-3,
            "{}: {code_doppler} vs {}",
            sat.prn,
            doppler / 1540.0
        );
    }
}

#[test]
fn navigation_message_decodes_from_the_samples() {
    // Demodulate 20 ms bits at the truth phases and decode the LNAV subframes with the nav
    // crate: TOW and subframe IDs must follow the truth transmit time; ephemeris fields must
    // be those of the RINEX file.
    let sc = scenario(
        "[satellites]\nprns = [31]\ncn0_all_dbhz = 45.0\n[truth]\nrate_hz = 10.0",
        13.0,
        2.048e6,
        "ci2",
    );
    let (sim, _dir, _report, x) = simulate_and_read(&sc);
    let fs = 2.048e6;
    let sat = &sim.satellites[0];
    // Find the first bit edge after the start from the truth code phase.
    let (o, _) = sim.observe(sat, 0.0);
    let chips_to_edge = 20460.0 - o.chips.rem_euclid(20460.0);
    let t_edge = chips_to_edge / CA_CHIP_RATE_HZ;
    let mut bits = Vec::new();
    let mut t = t_edge + 0.0005;
    while t + 0.021 < 13.0 {
        let k0 = (t * fs) as usize;
        let p = correlate(&sim, sat, (&x, fs), k0, (0.019 * fs) as usize, 0.0, sat.prn);
        bits.push(u8::from(p.re < 0.0));
        t += 0.02;
    }
    // Look for preambles; a decoded subframe must pass parity in all 10 words.
    let mut decoded = 0;
    for start in 0..bits.len().saturating_sub(300) {
        let mut sf = [0u8; 300];
        sf.copy_from_slice(&bits[start..start + 300]);
        if let Ok(d) = decode_subframe(&sf, false, false) {
            decoded += 1;
            // The HOW's TOW count is the TOW of the next subframe start, in 6 s units.
            let t_sf_start = t_edge + 0.02 * start as f64;
            let (o, _) = sim.observe(sat, t_sf_start + 0.0005);
            let tx_tow = sim
                .env
                .start
                .add_seconds(t_sf_start - o.pseudorange_m / 299_792_458.0)
                .tow_s;
            assert_eq!(
                f64::from(d.how.tow_count) * 6.0,
                (tx_tow / 6.0).round() * 6.0 + 6.0,
                "TOW of subframe at bit {start}"
            );
        }
    }
    assert!(decoded >= 1, "no subframe decoded from {} bits", bits.len());
}

#[test]
fn satellite_positions_match_the_rinex_ephemeris() {
    let sc = scenario("[truth]\nrate_hz = 1.0", 0.2, 2.048e6, "ci8");
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let nav = parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        sim.satellites.len() >= 8,
        "only {} satellites above 5 deg",
        sim.satellites.len()
    );
    for sat in &sim.satellites {
        let (o, _) = sim.observe(sat, 0.1);
        let rinex = nav
            .ephemerides
            .iter()
            .filter(|e| e.prn == sat.prn.get())
            .min_by(|a, b| {
                let (da, db) = (sim.env.start.diff_s(a.toe), sim.env.start.diff_s(b.toe));
                da.abs().total_cmp(&db.abs())
            })
            .unwrap_or_else(|| panic!("{}", sat.prn));
        let t_tx = sim.env.start.add_seconds(o.t_true_s - o.tau_s);
        let p = rotate_earth(&rinex.sv_state(t_tx).pos_m, o.tau_s);
        // The simulator transmits the ephemeris quantised to IS-GPS-200 LSBs; the difference
        // from the RINEX (double precision) orbit stays at the centimetre level.
        assert!(
            (p - o.sv_pos_m).norm() < 0.05,
            "{}: {} m",
            sat.prn,
            (p - o.sv_pos_m).norm()
        );
        // Geometric range and travel time agree.
        assert!((o.range_m - (o.sv_pos_m - o.rx.pos_m).norm()).abs() < 1e-6);
        assert!((o.tau_s * 299_792_458.0 - o.range_m).abs() < 1e-3);
    }
}

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let sc = scenario("[satellites]\nprns = [16]", 0.3, 2.048e6, "ci8");
    let mut other = sc.clone();
    other.seed = 6;
    let run = |s: &Scenario| {
        let sim = Simulator::new(s, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
        let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
        let r = sim
            .run(dir.path(), &|_| {})
            .unwrap_or_else(|e| panic!("{e}"));
        std::fs::read(&r.data_path).unwrap_or_else(|e| panic!("{e}"))
    };
    let a = run(&sc);
    assert_eq!(a.len(), 2 * 614_400);
    assert_eq!(a, run(&sc));
    assert_ne!(a, run(&other));
}

#[test]
fn scenario_errors_are_clear() {
    let bad = |extra: &str, needle: &str| {
        let text = format!("duration_s = 1.0\nnav = \"builtin:brdc0010.22n\"\n[start]\nweek = 2190\ntow_s = 538194.0\n[output]\nformat = \"ci8\"\nfs_hz = 2.048e6\n[receiver]\nkind = \"static\"\nllh_deg = [0.0, 0.0, 0.0]\n{extra}");
        match Scenario::from_toml(&text) {
            Ok(_) => panic!("accepted: {extra}"),
            Err(e) => assert!(e.to_string().contains(needle), "{e} (wanted {needle})"),
        }
    };
    bad("[satellites]\nprnz = [1]", "unknown field");
    bad("[satellites]\nprns = [40]", "not a GPS PRN");
    bad(
        "[[outages]]\nstart_s = 5.0\nend_s = 2.0",
        "end must follow start",
    );
    let text = "duration_s = 1.0\nnav = \"builtin:brdc0010.22n\"\n[start]\nweek = 2190\ntow_s = 538194.0\n[output]\nformat = \"ci8\"\nfs_hz = 0.5e6\n[receiver]\nkind = \"static\"\nllh_deg = [0.0, 0.0, 0.0]";
    let e = Scenario::from_toml(text)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(e.contains("too low"), "{e}");
}

/// Mean C/N0 (dB-Hz) measured by 1 ms prompt correlations at the truth phases over `blocks`
/// code periods from `first_ms`, with the noise floor from a PRN that is not transmitted.
fn measured_cn0(
    sim: &Simulator,
    sat: &SimSatellite,
    rec: (&[Complex32], f64),
    first_ms: usize,
    blocks: usize,
) -> f64 {
    let n = (rec.1 * 1e-3).round() as usize;
    let unused = Prn::new(1).unwrap_or_else(|e| panic!("{e}"));
    let (mut sig, mut noise) = (0.0f64, 0.0f64);
    for b in 0..blocks {
        let k0 = (first_ms + b) * n;
        sig += f64::from(correlate(sim, sat, rec, k0, n, 0.0, sat.prn).norm_sqr());
        noise += f64::from(correlate(sim, sat, rec, k0, n, 0.0, unused).norm_sqr());
    }
    10.0 * (((sig - noise) / noise).max(1e-6) / 1e-3).log10()
}

#[test]
fn real_if_output_carries_the_configured_cn0() {
    // Real 16-bit samples at IF 4.092 MHz, fs 16.368 MHz: read back through the SigMF metadata
    // (which carries the IF), mixed down by the sample layer, correlated at truth.
    let sc = scenario_with_if(
        "[satellites]\nprns = [26]\ncn0_all_dbhz = 42.0\n[truth]\nrate_hz = 10.0",
        0.6,
        16.368e6,
        "ri16_le",
        4.092e6,
    );
    let (sim, _dir, _report, x) = simulate_and_read(&sc);
    let cn0 = measured_cn0(&sim, &sim.satellites[0], (&x, 16.368e6), 10, 500);
    assert!((cn0 - 42.0).abs() < 1.0, "measured {cn0:.2} dB-Hz at IF");
}

/// G31 alone at 45 dB-Hz for 0.9 s of ci8 at 2.048 MHz with `table` (an `[[outages]]` or a
/// `[[fades]]` entry): its C/N0 measured over 200 ms from each of `from_ms`, and the rows of
/// truth_sv.csv as `(t_s, signal_on, C/N0)`.
fn g31_with(table: &str, from_ms: &[usize]) -> (Vec<f64>, Vec<(f64, bool, f64)>) {
    let sc = scenario(
        &format!(
            "[satellites]\nprns = [31]\ncn0_all_dbhz = 45.0\n{table}\n[truth]\nrate_hz = 10.0"
        ),
        0.9,
        2.048e6,
        "ci8",
    );
    let (sim, _dir, report, x) = simulate_and_read(&sc);
    let sat = &sim.satellites[0];
    let cn0 = from_ms
        .iter()
        .map(|&ms| measured_cn0(&sim, sat, (&x, 2.048e6), ms, 200))
        .collect();
    let truth = std::fs::read_to_string(&report.truth_sv_path).unwrap_or_else(|e| panic!("{e}"));
    let rows = truth
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].parse().unwrap_or(f64::NAN),
                f[2] == "1",
                f[7].parse().unwrap_or(f64::NAN),
            )
        })
        .collect();
    (cn0, rows)
}

#[test]
fn outage_blocks_the_signal_and_it_returns() {
    let (cn0, truth) = g31_with("[[outages]]\nstart_s = 0.3\nend_s = 0.6", &[50, 350, 650]);
    let (before, during, after) = (cn0[0], cn0[1], cn0[2]);
    assert!(
        (before - 45.0).abs() < 1.0 && (after - 45.0).abs() < 1.0,
        "{before} {after}"
    );
    // During the outage there is no signal: the estimate is at the noise floor (the 200-block
    // estimate of zero signal scatters around 1e-6..25 dB-Hz, far below 45).
    assert!(during < 30.0, "during the outage: {during:.1} dB-Hz");
    // And the truth file says so.
    assert!(
        truth.iter().all(|&(t, s, _)| s != (0.3..0.6).contains(&t)),
        "{truth:?}"
    );
}

#[test]
fn a_fade_lowers_the_cn0_at_its_rate_and_holds_the_level_reached() {
    // 45 dB-Hz, faded by 20 dB/s from 0.3 to 0.6 s: 45 before, 39 at the end and after it.
    let (cn0, truth) = g31_with(
        "[[fades]]\nstart_s = 0.3\nend_s = 0.6\ndb_per_s = -20.0",
        &[50, 650],
    );
    let (before, after) = (cn0[0], cn0[1]);
    assert!(
        (before - 45.0).abs() < 1.0 && (after - 39.0).abs() < 1.0,
        "{before} {after}"
    );
    // The truth file's C/N0 column follows the ramp.
    for (t, _, c) in truth {
        let want = 45.0 - 20.0 * (t.min(0.6) - 0.3).max(0.0);
        assert!(
            (c - want).abs() < 1e-3,
            "t {t}: truth C/N0 {c}, want {want}"
        );
    }
}

#[test]
fn csv_trajectory_is_smooth_and_follows_the_points() {
    // A circle of radius 200 m at 20 m/s (2 m/s^2 centripetal) given as LLH points at 10 Hz.
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let origin = gpsrx_nav::frames::Llh::from_degrees(37.5, 127.0, 50.0);
    let r_enu = gpsrx_nav::frames::enu_rotation(&origin).transpose();
    let o = origin.to_ecef();
    let (r, w) = (200.0, 0.1);
    let pos = |t: f64| {
        o + r_enu * gpsrx_nav::frames::Vector3::new(r * (w * t).cos(), r * (w * t).sin(), 0.0)
    };
    let mut csv = String::from("t_s,x_m,y_m,z_m\n");
    for i in -20..=60 {
        let t = f64::from(i) * 0.1;
        let p = pos(t);
        csv.push_str(&format!("{t},{},{},{}\n", p.x, p.y, p.z));
    }
    std::fs::write(dir.path().join("traj.csv"), csv).unwrap_or_else(|e| panic!("{e}"));
    let text = "duration_s = 4.0\nnav = \"builtin:brdc0010.22n\"\n[start]\nweek = 2190\ntow_s = 538194.0\n[output]\nformat = \"ci8\"\nfs_hz = 2.048e6\n[receiver]\nkind = \"csv\"\npath = \"traj.csv\"\n".to_string();
    let sc = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, dir.path()).unwrap_or_else(|e| panic!("{e}"));
    for &t in &[0.55, 1.234, 2.0, 3.71] {
        let s = sim.env.trajectory.state(t);
        // Spline through 10 Hz points of a circle: position error ~ r (w h)^4 / 384 < 1 um,
        // velocity ~ 1e-4 m/s, acceleration ~ 1e-3 of 2 m/s^2.
        assert!(
            (s.pos_m - pos(t)).norm() < 1e-3,
            "t {t}: {}",
            (s.pos_m - pos(t)).norm()
        );
        assert!(
            (s.vel_mps.norm() - 20.0).abs() < 0.01,
            "t {t}: speed {}",
            s.vel_mps.norm()
        );
        assert!(
            (s.acc_mps2.norm() - 2.0).abs() < 0.05,
            "t {t}: accel {}",
            s.acc_mps2.norm()
        );
    }
    // A trajectory that does not cover the recording is refused.
    let short = text.replace("duration_s = 4.0", "duration_s = 10.0");
    let sc = Scenario::from_toml(&short).unwrap_or_else(|e| panic!("{e}"));
    let err = Simulator::new(&sc, dir.path())
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(err.contains("covers"), "{err}");
}

#[test]
fn moving_receiver_doppler_matches_the_line_of_sight_velocity() {
    // 5 g turn: the truth Doppler equals -(v_sv - v_rx).los / lambda up to the clock drift
    // (5e-8 s/s -> -78.8 Hz) and the satellite clock drift.
    let text = r#"
duration_s = 12.0
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci8"
fs_hz = 2.048e6
[receiver]
kind = "motion"
start_llh_deg = [37.5, 127.0, 50.0]
heading_deg = 30.0
speed_mps = 80.0
segments = [{ type = "cruise", duration_s = 2.0 }, { type = "turn", duration_s = 10.0, accel_g = 5.0 }]
[clock]
drift_s_s = 5.0e-8
"#;
    let sc = Scenario::from_toml(text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    for sat in &sim.satellites {
        for &t in &[1.0, 6.0, 9.5] {
            let (a, _) = sim.observe(sat, t - 5e-4);
            let (b, _) = sim.observe(sat, t + 5e-4);
            let (o, _) = sim.observe(sat, t);
            let doppler = (b.carrier_cycles - a.carrier_cycles) / 1e-3;
            let t_tx = sim.env.start.add_seconds(o.t_true_s - o.tau_s);
            let sv = sat.ephemeris.sv_state(t_tx);
            let los = (o.sv_pos_m - o.rx.pos_m) / o.range_m;
            let v_sv = rotate_earth(&sv.vel_mps, o.tau_s);
            // Range rate in the rotating frame also includes the Earth-rotation term of the
            // satellite position; at 1e-3 relative accuracy the plain form suffices with 2 Hz.
            let range_rate = (v_sv - o.rx.vel_mps).dot(&los);
            let expected = -(range_rate + 299_792_458.0 * (5.0e-8 - sv.clock_drift_s_s))
                / gpsrx_dsp::constants::LAMBDA_L1_M;
            assert!(
                (doppler - expected).abs() < 3.0,
                "{} t {t}: {doppler:.2} vs {expected:.2}",
                sat.prn
            );
        }
    }
}

#[test]
fn almanac_pages_are_sent_when_asked_for() {
    // [satellites] almanac = true: subframe 5 pages carry the almanac of PRN = page (1-24,
    // IS-GPS-200 Table 20-V) derived from the nav file, decoded here from the bit stream.
    let duration_s = 70.0;
    for almanac in [false, true] {
        let sc = scenario(
            &format!("[satellites]\nprns = [31]\nalmanac = {almanac}"),
            duration_s,
            2.048e6,
            "ci2",
        );
        let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
        let sat = &sim.satellites[0];
        let bits: Vec<u8> = sat.bits.iter().map(|&b| u8::from(b < 0)).collect();
        let mut almanac_pages = 0;
        let mut prev = (false, false);
        for chunk in bits.chunks_exact(300) {
            let mut sf = [0u8; 300];
            sf.copy_from_slice(chunk);
            let d = decode_subframe(&sf, prev.0, prev.1).unwrap_or_else(|e| panic!("{e}"));
            prev = d.last_d29_d30;
            if let SubframePayload::Almanac(p) = d.payload {
                let page = (d.how.subframe_start_tow_s() / 30) % 25 + 1;
                if d.how.subframe_id == 5 {
                    assert_eq!(u32::from(p.sv_id), page);
                }
                assert!((p.sqrt_a_sqrt_m - 5153.6).abs() < 10.0, "{p:?}");
                almanac_pages += 1;
            }
        }
        assert_eq!(almanac_pages > 0, almanac, "almanac = {almanac}");
    }
}
