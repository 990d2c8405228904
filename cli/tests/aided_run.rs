//! INS aiding end to end: the feed-forward Doppler against the simulator's truth, and
//! `gpsrx run --ins` through a 5 g turn with narrow loops, aided and unaided.

use crate::common::{run, run_report, truth};
use gpsrx_ins_aiding::error_model::InsErrorConfig;
use gpsrx_ins_aiding::read_ins_csv;
use gpsrx_nav::rinex_nav::parse_rinex_nav;
use gpsrx_receiver::output::Fix;
use gpsrx_receiver::pipeline::aiding::InsFeedForward;
use gpsrx_receiver::simulate::write_ins_for;
use gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT;
use gpsrx_samples::sim::{Scenario, Simulator};
use std::path::{Path, PathBuf};

/// A vehicle at 30 m/s that turns at 5 g (jerk-limited over 1 s) from `turn_at_s` for
/// `turn_s`, 2.048 MHz ci8, receiver clock drifting at 4e-8 (63 Hz on every Doppler).
fn turn_scenario(duration_s: f64, turn_at_s: f64, turn_s: f64) -> Scenario {
    turn_scenario_with(duration_s, turn_at_s, turn_s, 30.0, 5.0)
}

/// [`turn_scenario`] at `speed_mps` turning at `accel_g`.
fn turn_scenario_with(
    duration_s: f64,
    turn_at_s: f64,
    turn_s: f64,
    speed_mps: f64,
    accel_g: f64,
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
format = "ci8"
fs_hz = 2.048e6
[clock]
bias_s = 2.0e-4
drift_s_s = 4.0e-8
[truth]
rate_hz = 10.0
[receiver]
kind = "motion"
start_llh_deg = [37.5665, 126.9780, 40.0]
heading_deg = 30.0
speed_mps = {speed_mps}
transition_s = 1.0
segments = [
  {{ type = "cruise", duration_s = {turn_at_s} }},
  {{ type = "turn", duration_s = {turn_s}, accel_g = {accel_g}, direction = "left" }},
  {{ type = "cruise", duration_s = 60.0 }},
]
"#
    );
    Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"))
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"))
}

/// Seed 004 eq. 6 with a perfect INS: the feed-forward equals the Doppler of the simulated
/// signal (carrier-phase rate in receiver time, `truth_sv.csv`'s definition) within 0.1 Hz,
/// through a 5 g turn, for every satellite. The receiver clock drift at the first fix is not
/// in it (the loops hold it already; see `pipeline::aiding`), so the comparison adds it back;
/// a later change of the drift is fed forward.
#[test]
fn feedforward_doppler_matches_truth_for_a_perfect_ins() {
    let dir = tmp();
    let sc = turn_scenario(12.0, 4.0, 6.0);
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let ins_path = dir.path().join("ins.csv");
    write_ins_for(&sim, &InsErrorConfig::default(), &ins_path).unwrap_or_else(|e| panic!("{e}"));
    let ins = read_ins_csv(&ins_path, 0.5).unwrap_or_else(|e| panic!("{e}"));
    let nav = parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}"));
    let ff = InsFeedForward::new(ins, Some(nav), Some(2190), None).allow_unhealthy(true);
    // The clock drift, as a fix's velocity solution would give it (m/s).
    let drift_mps = 4.0e-8 * 299_792_458.0;
    let (_, rx0) = sim.receiver_truth(0.5);
    ff.set_fix(0.5, rx0.pos_m, Some(drift_mps), None);
    let drift_hz = 4.0e-8 * 1575.42e6;
    let h = 0.5e-3;
    let (mut worst, mut n, mut max_abs) = (0.0f64, 0, 0.0f64);
    for k in 1..=20 {
        let t = 0.55 * f64::from(k);
        for sat in &sim.satellites {
            let (a, _) = sim.observe(sat, t - h);
            let (b, _) = sim.observe(sat, t + h);
            let truth_hz = (b.carrier_cycles - a.carrier_cycles) / (2.0 * h);
            let aid = ff
                .aid(sat.prn.get(), t)
                .unwrap_or_else(|| panic!("no aid for {} at {t}", sat.prn));
            worst = worst.max((aid.doppler_hz - drift_hz - truth_hz).abs());
            max_abs = max_abs.max(truth_hz.abs());
            n += 1;
            // The rate: 10 ms ahead.
            let (c, _) = sim.observe(sat, t + 0.01 - h);
            let (d, _) = sim.observe(sat, t + 0.01 + h);
            let truth_next = (d.carrier_cycles - c.carrier_cycles) / (2.0 * h);
            let rate_truth = (truth_next - truth_hz) / 0.01;
            assert!(
                (aid.doppler_rate_hz_s - rate_truth).abs() < 2.0,
                "{} at {t}: rate {} vs {rate_truth} Hz/s",
                sat.prn,
                aid.doppler_rate_hz_s
            );
        }
    }
    assert!(n >= 100, "{n} comparisons");
    assert!(max_abs > 1000.0, "Dopplers of real size ({max_abs} Hz)");
    assert!(worst < 0.1, "worst feed-forward error {worst} Hz");
    eprintln!("worst feed-forward error {worst:.4} Hz over {n} comparisons");

    // 31 ms of samples lost (measured by the receiver): stream time `t` is now elapsed time
    // `t + 0.031`, and the aid follows the truth there, also in the turn, where 31 ms of 5 g
    // move the Doppler by several Hz (so the check can fail).
    let lost = 0.031;
    ff.note_samples_lost(lost);
    let (mut worst_after, mut moved) = (0.0f64, 0.0f64);
    for k in 1..=20 {
        let t = 0.55 * f64::from(k);
        for sat in &sim.satellites {
            let truth_at = |t: f64| {
                let (a, _) = sim.observe(sat, t - h);
                let (b, _) = sim.observe(sat, t + h);
                (b.carrier_cycles - a.carrier_cycles) / (2.0 * h)
            };
            let aid = ff
                .aid(sat.prn.get(), t)
                .unwrap_or_else(|| panic!("no aid for {} at {t}", sat.prn));
            worst_after = worst_after.max((aid.doppler_hz - drift_hz - truth_at(t + lost)).abs());
            moved = moved.max((truth_at(t + lost) - truth_at(t)).abs());
        }
    }
    assert!(
        moved > 1.0,
        "31 ms of the turn move the Doppler by {moved} Hz"
    );
    assert!(
        worst_after < 0.1,
        "after the gap: worst feed-forward error {worst_after} Hz"
    );

    // The drift rises by 1e-9 (1.58 Hz): after 5 smoothing time constants of 10 Hz fixes
    // (at the same place: the aid's position comes from the fix) the drift fed forward has
    // risen by 1e-9 (to 1 %), and the feed-forward by -f_L1 1e-9 = -1.58 Hz.
    let before = ff.clock_drift_fed_forward_s_s();
    let fixes = (5.0 * gpsrx_receiver::pipeline::aiding::DRIFT_SMOOTHING_S / 0.1).ceil() as u32;
    for k in 1..=fixes {
        let t = 0.5 + 0.1 * f64::from(k);
        ff.set_fix(t, rx0.pos_m, Some(drift_mps + 1e-9 * 299_792_458.0), None);
    }
    let step = ff.clock_drift_fed_forward_s_s() - before;
    assert!(
        (step - 1e-9).abs() < 1e-11,
        "drift change fed forward: {step} s/s"
    );
}

/// An INS file with its own time of week and a recording whose GPS week is not known at the
/// start (no SigMF date, no `--week`): no feed-forward until the navigation message gives the
/// week, then the same feed-forward as with the week known from the start (the INS file's
/// time of week kept, not the decoded one, which is off by the receiver clock bias). Before,
/// the INS time was put in the system clock's week and the aid never came.
#[test]
fn an_ins_time_of_week_waits_for_the_decoded_week() {
    let dir = tmp();
    let sc = turn_scenario(4.0, 1.0, 2.0);
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let ins_path = dir.path().join("ins.csv");
    write_ins_for(&sim, &InsErrorConfig::default(), &ins_path).unwrap_or_else(|e| panic!("{e}"));
    let ins = read_ins_csv(&ins_path, 0.5).unwrap_or_else(|e| panic!("{e}"));
    let nav = parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}"));
    let known =
        InsFeedForward::new(ins.clone(), Some(nav.clone()), Some(2190), None).allow_unhealthy(true);
    let waiting = InsFeedForward::new(ins, Some(nav), None, None).allow_unhealthy(true);
    let prn = sim.satellites[0].prn.get();
    assert!(waiting.aid(prn, 1.0).is_none(), "no week yet, no aid");
    // The decoded origin: the same time of week 0.2 ms off (a receiver clock bias of 2e-4 s).
    waiting.set_time_origin(gpsrx_nav::time::GpsTime::new(2190, 538194.0002));
    let (_, rx) = sim.receiver_truth(0.5);
    for ff in [&known, &waiting] {
        ff.set_fix(0.5, rx.pos_m, Some(4.0e-8 * 299_792_458.0), None);
    }
    for sat in &sim.satellites {
        let p = sat.prn.get();
        let (a, b) = (known.aid(p, 2.0), waiting.aid(p, 2.0));
        let (a, b) = (
            a.unwrap_or_else(|| panic!("no aid for {p} with the week known")),
            b.unwrap_or_else(|| panic!("no aid for {p} once the week is decoded")),
        );
        assert!(
            (a.doppler_hz - b.doppler_hz).abs() < 1e-6,
            "G{p:02}: {} vs {} Hz",
            a.doppler_hz,
            b.doppler_hz
        );
    }
}

/// Without the GPS time or the ephemeris there is no feed-forward (never a made-up one).
#[test]
fn no_feedforward_without_time_or_ephemeris() {
    let dir = tmp();
    let text = "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n0,-3.0e6,4.0e6,3.9e6,1,2,3\n0.1,-3.0e6,4.0e6,3.9e6,1,2,3\n";
    let p = dir.path().join("ins.csv");
    std::fs::write(&p, text).unwrap_or_else(|e| panic!("{e}"));
    let ins = read_ins_csv(&p, 0.5).unwrap_or_else(|e| panic!("{e}"));
    let ff = InsFeedForward::new(ins, None, Some(2190), None);
    assert!(ff.aid(5, 0.05).is_none(), "no GPS time yet");
    ff.set_time_origin(gpsrx_nav::time::GpsTime::new(2190, 538194.0));
    assert!(ff.aid(5, 0.05).is_none(), "no ephemeris for G05");
}

/// (state, carrier_lock) of every channels.csv row within [t0, t1] s of receive time.
fn channel_rows(out: &Path, t0_tow: f64, t1_tow: f64) -> Vec<(String, bool)> {
    let mut rdr =
        csv::Reader::from_path(out.join("channels.csv")).unwrap_or_else(|e| panic!("{e}"));
    let headers = rdr.headers().unwrap_or_else(|e| panic!("{e}")).clone();
    let col = |name: &str| {
        headers
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (ct, cs, cl) = (col("tow_s"), col("state"), col("carrier_lock"));
    rdr.records()
        .map(|r| r.unwrap_or_else(|e| panic!("{e}")))
        .filter(|r| {
            let t: f64 = r[ct].parse().unwrap_or(f64::NAN);
            (t0_tow..=t1_tow).contains(&t)
        })
        .map(|r| (r[cs].to_string(), &r[cl] == "1" || &r[cl] == "true"))
        .collect()
}

/// 3D error of a fix against truth interpolated at its time.
fn error_3d_m(f: &Fix, truth: &[(f64, [f64; 3], [f64; 3])]) -> f64 {
    let t = f.time.tow_s;
    let i = truth
        .partition_point(|r| r.0 <= t)
        .clamp(1, truth.len() - 1);
    let (a, b) = (&truth[i - 1], &truth[i]);
    let u = (t - a.0) / (b.0 - a.0);
    (0..3)
        .map(|k| (f.ecef_m[k] - (a.1[k] + u * (b.1[k] - a.1[k]))).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Simulates `sc` with the INS table `ins_toml` into `dir`: the recording's path and the
/// `ins.csv` written through the INS error model.
fn simulate_with_ins(sc: &mut Scenario, ins_toml: &str, dir: &Path) -> (PathBuf, PathBuf) {
    sc.ins = Some(toml::from_str(ins_toml).unwrap_or_else(|e| panic!("{e}")));
    let sim = Simulator::new(sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let report = sim.run(dir, &|_| {}).unwrap_or_else(|e| panic!("{e}"));
    let ins_path = dir.join("ins.csv");
    let cfg: InsErrorConfig = toml::Value::Table(sc.ins.clone().unwrap_or_default())
        .try_into()
        .unwrap_or_else(|e| panic!("{e}"));
    write_ins_for(&sim, &cfg, &ins_path).unwrap_or_else(|e| panic!("{e}"));
    (report.data_path, ins_path)
}

/// Seed 004 end to end: a 3 Hz 2nd-order PLL cannot follow a 5 g turn (dynamic stress
/// 0.2809 a / Bn^2 = 2900 deg for the full 5 g on the line of sight); fed forward with the INS
/// velocity (biased accelerometers, 0.01 m/s^2) it keeps phase lock on every satellite and the
/// receiver keeps giving fixes through the turn.
#[test]
fn ins_aiding_keeps_a_3hz_pll_locked_through_a_5g_turn() {
    let dir = tmp();
    let (turn_at, turn_s) = (16.0, 8.0);
    let mut sc = turn_scenario(30.0, turn_at, turn_s);
    let (data_path, ins_path) = simulate_with_ins(
        &mut sc,
        "accel_bias_enu_mps2 = [0.01, 0.01, 0.0]\nrate_hz = 100.0",
        dir.path(),
    );
    let nav = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n");
    let nav = nav.to_str().unwrap_or_default();
    let ins = ins_path.to_str().unwrap_or_default();
    let common = [
        "--nav",
        nav,
        "--pll-order",
        "2",
        "--pll-bw",
        "3",
        "--allow-unhealthy",
    ];
    let aided_out = dir.path().join("aided");
    let unaided_out = dir.path().join("unaided");
    let mut aided_args = common.to_vec();
    aided_args.extend_from_slice(&["--ins", ins]);
    let (aided_report, aided) = run_report(&data_path, &aided_out, &aided_args);
    let mut unaided_args = common.to_vec();
    unaided_args.extend_from_slice(&["--ins", ins, "--no-aiding"]);
    let unaided = run(&data_path, &unaided_out, &unaided_args);

    // The turn in GPS time (plus the 1 s ramps).
    let t0 = 538194.0 + turn_at;
    let t1 = t0 + turn_s;
    let locked_fraction = |out: &Path| {
        let rows = channel_rows(out, t0, t1);
        let locked = rows.iter().filter(|(s, l)| s == "track" && *l).count();
        (locked as f64 / rows.len().max(1) as f64, rows.len())
    };
    let (fa, na) = locked_fraction(&aided_out);
    let (fu, nu) = locked_fraction(&unaided_out);
    eprintln!("phase-locked rows in the turn: aided {fa:.3} of {na}, unaided {fu:.3} of {nu}");
    assert!(fa > 0.97, "aided channels keep phase lock ({fa})");
    assert!(
        fu < 0.7,
        "unaided 3 Hz loops lose lock in a 5 g turn ({fu})"
    );
    // channels.csv: the aided 2nd-order 3 Hz loop's predicted static phase offset under the
    // nominal bias (1 mg per axis, sqrt 3 mg on the line of sight): B / (lambda w0^2),
    // w0 = Bn / 0.53 (seed 004 Table 1), on the aided rows; empty without the aid.
    let lambda = 299_792_458.0 / 1575.42e6;
    let w0: f64 = 3.0 / 0.53;
    let want = 3f64.sqrt() * 9.80665e-3 / (lambda * w0 * w0);
    let offsets = |out: &Path| -> (usize, Vec<f64>) {
        let mut rdr =
            csv::Reader::from_path(out.join("channels.csv")).unwrap_or_else(|e| panic!("{e}"));
        let h = rdr.headers().unwrap_or_else(|e| panic!("{e}")).clone();
        let c = h
            .iter()
            .position(|x| x == "predicted_offset_cycles")
            .unwrap_or_else(|| panic!("no predicted_offset_cycles column"));
        let rows: Vec<csv::StringRecord> = rdr.records().map_while(Result::ok).collect();
        let v = rows
            .iter()
            .filter(|r| !r[c].is_empty())
            .map(|r| r[c].parse().unwrap_or(f64::NAN))
            .collect();
        (rows.len(), v)
    };
    let (na_rows, na_vals) = offsets(&aided_out);
    assert!(
        na_vals.len() * 4 > na_rows,
        "{} of {na_rows} aided rows have an offset",
        na_vals.len()
    );
    for v in &na_vals {
        assert!((v - want).abs() < 6e-5, "predicted offset {v} vs {want}");
    }
    let (nu_rows, nu_vals) = offsets(&unaided_out);
    assert!(
        nu_rows > 0 && nu_vals.is_empty(),
        "unaided rows with an offset: {nu_vals:?}"
    );

    let truth = truth(dir.path());
    let in_turn = |f: &&Fix| (t0..=t1).contains(&f.time.tow_s);
    let aided_turn: Vec<&Fix> = aided.iter().filter(in_turn).collect();
    let unaided_turn: Vec<&Fix> = unaided.iter().filter(in_turn).collect();
    let errs: Vec<f64> = aided_turn.iter().map(|f| error_3d_m(f, &truth)).collect();
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len().max(1) as f64).sqrt();
    eprintln!(
        "fixes in the turn: aided {} (3D RMS {rms:.2} m, max {:.2} m), unaided {}",
        aided_turn.len(),
        errs.iter().copied().fold(0.0, f64::max),
        unaided_turn.len()
    );
    // 10 Hz fixes over the 8 s turn.
    assert!(
        aided_turn.len() >= 75,
        "aided fixes through the turn: {}",
        aided_turn.len()
    );
    assert!(rms < 2.0, "aided fix error in the turn {rms} m RMS");

    // A good INS passes the integrity monitor: admitted within 2 s of the start, never
    // rejected (not in the turn either), aiding the rest of the run.
    let a = aided_report
        .receiver
        .ins_aiding
        .unwrap_or_else(|| panic!("no INS summary"));
    eprintln!("good INS: {a:?}");
    assert_eq!(a.rejections, 0, "a good INS rejected: {a:?}");
    assert!(a.aided_fraction > 0.93, "{a:?}");
}

/// Seed 004 at its own bandwidth (Figs. 12 and 15): a 250 m/s aircraft turning at 10 g
/// (jerk-limited over 1 s) with an INS whose accelerometers are biased by 1 or 2 mg per axis.
/// Aided 3rd-order loops at Bn = 0.4 Hz (reached in stages from the tracking loops, with no
/// steady-state error from the bias's Doppler ramp) keep every satellite phase-locked through
/// the turn and the fixes have no gap; the same loops unaided lose satellites.
#[test]
fn aided_0p4_hz_loops_keep_every_satellite_through_a_10g_turn_with_a_1_or_2_mg_ins() {
    let (turn_at, turn_s) = (11.0, 4.0);
    for bias_mg in [1.0, 2.0] {
        let dir = tmp();
        let mut sc = turn_scenario_with(18.0, turn_at, turn_s, 250.0, 10.0);
        let b = bias_mg * 9.80665e-3;
        let ins_toml = format!("accel_bias_enu_mps2 = [{b}, {b}, {b}]\nrate_hz = 100.0");
        let (data_path, ins_path) = simulate_with_ins(&mut sc, &ins_toml, dir.path());
        let nav = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n");
        let (nav, ins) = (
            nav.to_str().unwrap_or_default(),
            ins_path.to_str().unwrap_or_default(),
        );
        let loops = ["--nav", nav, "--allow-unhealthy", "--ins", ins];
        let aided_out = dir.path().join("aided");
        let mut aided_args = loops.to_vec();
        aided_args.extend_from_slice(&["--aided-pll-order", "3", "--aided-pll-bw", "0.4"]);
        let aided = run(&data_path, &aided_out, &aided_args);
        let unaided_out = dir.path().join("unaided");
        let mut unaided_args = loops.to_vec();
        unaided_args.extend_from_slice(&["--pll-order", "3", "--pll-bw", "0.4", "--no-aiding"]);
        let unaided = run(&data_path, &unaided_out, &unaided_args);

        let t0 = 538194.0 + turn_at;
        let t1 = t0 + turn_s + 1.0;
        let locked = |out: &Path| {
            let rows = channel_rows(out, t0, t1);
            let n = rows.iter().filter(|(s, l)| s == "track" && *l).count();
            (n as f64 / rows.len().max(1) as f64, rows.len())
        };
        let (fa, na) = locked(&aided_out);
        let (fu, nu) = locked(&unaided_out);
        let in_turn = |fixes: &[Fix]| {
            fixes
                .iter()
                .filter(|f| (t0..=t1).contains(&f.time.tow_s))
                .count()
        };
        let (xa, xu) = (in_turn(&aided), in_turn(&unaided));
        eprintln!(
            "{bias_mg} mg: phase-locked rows in the turn: aided {fa:.3} of {na}, unaided {fu:.3} of {nu}; fixes aided {xa}, unaided {xu}"
        );
        assert!(
            fa > 0.97,
            "{bias_mg} mg: aided 0.4 Hz loops keep phase lock ({fa})"
        );
        // 10 Hz fixes, no gap, over the 5 s of turn and ramp.
        assert!(xa >= 50, "{bias_mg} mg: aided fixes in the turn: {xa}");
        assert!(
            fu < 0.8,
            "{bias_mg} mg: unaided 0.4 Hz loops lose lock ({fu})"
        );
    }
}

/// A 2nd-order aided loop has no Doppler-rate integrator: an INS biased by 2 mg per axis
/// (up to 3.5 mg, a 0.18 Hz/s Doppler ramp on a diagonal line of sight) would leave it a static
/// phase offset of `B / (lambda w0^2)` = 0.31 cycle at Bn 0.4 Hz, past the Costas loop's
/// 0.25-cycle slip point (before the calibration: 4 of 8 satellites held through the 10 g turn
/// of `turn-10g-ins-2mg.toml`). The receiver follows the INS velocity error from the fixes
/// outside the manoeuvre and takes the drift out of the feed-forward, so the loops hold
/// through a 10 g turn.
#[test]
fn a_2nd_order_aided_loop_holds_a_2_mg_ins_once_its_drift_is_calibrated() {
    let (turn_at, turn_s) = (16.0, 4.0);
    let dir = tmp();
    let mut sc = turn_scenario_with(23.0, turn_at, turn_s, 250.0, 10.0);
    let b = 2.0 * 9.80665e-3;
    let ins_toml = format!("accel_bias_enu_mps2 = [{b}, {b}, {b}]\nrate_hz = 100.0");
    let (data_path, ins_path) = simulate_with_ins(&mut sc, &ins_toml, dir.path());
    let nav = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n");
    let out = dir.path().join("aided");
    let fixes = run(
        &data_path,
        &out,
        &[
            "--nav",
            nav.to_str().unwrap_or_default(),
            "--allow-unhealthy",
            "--ins",
            ins_path.to_str().unwrap_or_default(),
            "--aided-pll-order",
            "2",
            "--aided-pll-bw",
            "0.4",
        ],
    );
    let t0 = 538194.0 + turn_at;
    let t1 = t0 + turn_s + 1.0;
    let rows = channel_rows(&out, t0, t1);
    let locked = rows.iter().filter(|(s, l)| s == "track" && *l).count();
    let fa = locked as f64 / rows.len().max(1) as f64;
    let in_turn = fixes
        .iter()
        .filter(|f| (t0..=t1).contains(&f.time.tow_s))
        .count();
    eprintln!(
        "2 mg, 2nd order 0.4 Hz: phase-locked rows in the turn {fa:.3} of {}; fixes {in_turn}",
        rows.len()
    );
    assert!(
        fa > 0.97,
        "calibrated 2nd-order loops keep phase lock ({fa})"
    );
    assert!(in_turn >= 50, "fixes in the turn: {in_turn}");
}

/// Issue 13: an INS whose time base is 1 s late (the output stamped `t` is the INS solution of
/// `t - 1`) agrees with the loops while the vehicle cruises, but in a 5 g turn its velocity is
/// up to 49 m/s off: the integrity monitor must drop it there (the default 18 Hz loops, which
/// hold a 5 g turn unaided, then run unaided), re-admit it once it agrees again for 5 s after
/// the turn, and the fixes must be those of a run without `--ins` (same first fix, as many and
/// as accurate in the turn).
#[test]
fn an_ins_1s_late_is_dropped_in_a_turn_and_the_fixes_are_the_unaided_ones() {
    let dir = tmp();
    // The turn after the first fix (about 12 s: frame sync), 10 s left after it.
    let (turn_at, turn_s) = (13.0, 4.0);
    let sc = turn_scenario(28.0, turn_at, turn_s);
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let report = sim
        .run(dir.path(), &|_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    let ins_path = dir.path().join("ins_late.csv");
    let late = InsErrorConfig {
        latency_s: 1.0,
        ..InsErrorConfig::default()
    };
    write_ins_for(&sim, &late, &ins_path).unwrap_or_else(|e| panic!("{e}"));
    let nav = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/data/brdc0010.22n");
    let nav = nav.to_str().unwrap_or_default();
    let ins = ins_path.to_str().unwrap_or_default();
    let common = ["--nav", nav, "--allow-unhealthy"];
    let mut late_args = common.to_vec();
    late_args.extend_from_slice(&["--ins", ins]);
    let (late_report, late_fixes) =
        run_report(&report.data_path, &dir.path().join("late"), &late_args);
    let (plain_report, plain_fixes) =
        run_report(&report.data_path, &dir.path().join("plain"), &common);
    let a = late_report
        .receiver
        .ins_aiding
        .unwrap_or_else(|| panic!("no INS summary"));
    let (l, p) = (&late_report.receiver, &plain_report.receiver);
    eprintln!(
        "INS 1 s late: {a:?}; {} fixes, first {:?}; without --ins: {} fixes, first {:?}",
        l.fixes, l.first_fix_s, p.fixes, p.first_fix_s
    );
    // Admitted while cruising, dropped in the turn, back 5 s after it.
    assert!(a.rejections >= 1, "the late INS was not rejected: {a:?}");
    assert!(
        a.admissions >= 2,
        "not admitted before the turn and again after it: {a:?}"
    );
    let not_aided_s = l.duration_s - a.aided_s;
    assert!(
        (4.0..=12.0).contains(&not_aided_s),
        "unaided for {not_aided_s:.1} s (the turn and the 5 s of re-admission)"
    );

    // The fixes: as without --ins.
    let first = |s: &gpsrx_receiver::RunSummary| s.first_fix_s.unwrap_or(f64::INFINITY);
    assert!(p.fixes > 50, "without --ins: {} fixes", p.fixes);
    assert!(
        (first(l) - first(p)).abs() <= 1.0,
        "first fix {:?} vs {:?}",
        l.first_fix_s,
        p.first_fix_s
    );
    let truth = truth(dir.path());
    let (t0, t1) = (538194.0 + turn_at, 538194.0 + turn_at + turn_s + 2.0);
    let in_turn = |fixes: &[Fix]| -> (usize, f64) {
        let e: Vec<f64> = fixes
            .iter()
            .filter(|f| (t0..=t1).contains(&f.time.tow_s))
            .map(|f| error_3d_m(f, &truth))
            .collect();
        let rms = (e.iter().map(|x| x * x).sum::<f64>() / e.len().max(1) as f64).sqrt();
        (e.len(), rms)
    };
    let ((nl, rl), (np, rp)) = (in_turn(&late_fixes), in_turn(&plain_fixes));
    eprintln!(
        "fixes in the turn: INS 1 s late {nl} (3D RMS {rl:.2} m), without --ins {np} ({rp:.2} m)"
    );
    assert!(np >= 55, "without --ins, fixes in the turn: {np}");
    assert!(
        nl + 3 >= np,
        "fixes in the turn: {nl} vs {np} without --ins"
    );
    assert!(
        rl < rp + 1.0,
        "3D RMS in the turn {rl:.2} m vs {rp:.2} m without --ins"
    );
}

/// `aided_track`: while the aid is on, the channel runs the narrower aided loops (Doppler noise
/// of a 2 Hz loop), and when the aid goes it returns to its unaided 15 Hz loops, in lock.
#[test]
fn aided_loops_are_used_while_the_aid_is_on() {
    use gpsrx_receiver::pipeline::channels::track;
    use gpsrx_samples::{open_source, SourceConfig};
    use gpsrx_tracking::{Channel, ChannelConfig, ChannelStart, ChannelState, DopplerAid};

    let dir = tmp();
    let mut sc = turn_scenario(8.0, 60.0, 1.0); // straight at 30 m/s throughout
    sc.satellites.cn0_all_dbhz = Some(45.0);
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let report = sim
        .run(dir.path(), &|_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    let fs = 2.048e6;
    let truth_doppler = |prn: u8, t: f64| -> Option<f64> {
        let sat = sim.satellites.iter().find(|s| s.prn.get() == prn)?;
        let (a, _) = sim.observe(sat, t - 0.5e-3);
        let (b, _) = sim.observe(sat, t + 0.5e-3);
        Some((b.carrier_cycles - a.carrier_cycles) / 1e-3)
    };
    let mut cfg = ChannelConfig::default();
    cfg.track.pll_order = 2;
    cfg.track.pll_bw_hz = 15.0;
    let mut aided = cfg.track;
    aided.pll_bw_hz = 2.0;
    cfg.aided_track = Some(aided);
    let sat = &sim.satellites[0];
    let (o, _) = sim.observe(sat, 0.0);
    let (o2, _) = sim.observe(sat, 1e-3);
    let to_start = (1023.0 - o.chips.rem_euclid(1023.0)) / ((o2.chips - o.chips) / 1e-3) * fs;
    let start = ChannelStart {
        prn: sat.prn,
        code_start_sample: to_start.round() as u64,
        doppler_hz: truth_doppler(sat.prn.get(), 0.0).unwrap_or(0.0),
        cn0_dbhz: f64::NAN,
    };
    let ch = Channel::new(&start, fs, &cfg).unwrap_or_else(|e| panic!("{e}"));
    let aid = |prn: gpsrx_dsp::Prn, t: f64| {
        (t < 5.0).then(|| DopplerAid {
            doppler_hz: truth_doppler(prn.get(), t).unwrap_or(0.0),
            doppler_rate_hz_s: 0.0,
            coast: false,
            checked: false,
            source: gpsrx_tracking::AidSource::Ins,
        })
    };
    let mut src =
        open_source(&SourceConfig::new(report.data_path.clone())).unwrap_or_else(|e| panic!("{e}"));
    let mut err_aided = Vec::new();
    let mut err_unaided = Vec::new();
    let out = track(src.as_mut(), vec![ch], Some(&aid), |_, e| {
        if e.state != ChannelState::Track {
            return;
        }
        let Some(truth) = truth_doppler(e.prn, e.t_rx_s + 0.5e-3) else {
            return;
        };
        // The hand-over (bit sync) comes at about 2 s; the 2 Hz loop settles within 1 s.
        if (3.5..4.9).contains(&e.t_rx_s) {
            err_aided.push(e.doppler_hz - truth);
        } else if e.t_rx_s > 6.0 {
            err_unaided.push(e.doppler_hz - truth);
        }
    })
    .unwrap_or_else(|e| panic!("{e}"));
    let std = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len().max(1) as f64).sqrt()
    };
    let (sa, su) = (std(&err_aided), std(&err_unaided));
    eprintln!(
        "NCO Doppler noise: aided 2 Hz loop {sa:.3} Hz ({} epochs), unaided 15 Hz loop {su:.3} Hz ({} epochs)",
        err_aided.len(),
        err_unaided.len()
    );
    assert!(err_aided.len() > 1000 && err_unaided.len() > 1000);
    assert!(
        su > 4.0 * sa,
        "the aided loop is the narrow one ({sa} vs {su} Hz)"
    );
    assert_eq!(
        out[0].state(),
        ChannelState::Track,
        "in lock after the aid went"
    );
    assert!(!out[0].aided_loops(), "back on the unaided loops");
}
