//! Vehicle motions (`kind = "motion"`): road grade, stops, target speeds and turn angles against
//! analytic truth, through the same scenario parsing and ECEF trajectory the simulator uses.

use gpsrx_nav::frames::{enu_rotation, Llh, Vector3};
use gpsrx_samples::sim::scenario::{Scenario, URBAN_DRIVE_TOML};
use gpsrx_samples::sim::trajectory::{MotionTable, Trajectory};
use std::path::Path;

const ORIGIN: [f64; 3] = [36.3665, 127.3446, 60.0];

/// A scenario whose receiver is `speed_mps`, heading 90 deg, with these segments.
fn motion_scenario(speed_mps: f64, segments: &str, duration_s: f64) -> Result<Scenario, String> {
    let text = format!(
        r#"
duration_s = {duration_s}
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci8"
fs_hz = 2.048e6
[receiver]
kind = "motion"
start_llh_deg = [{}, {}, {}]
heading_deg = 90.0
speed_mps = {speed_mps}
transition_s = 0.5
grade_transition_s = 3.0
segments = [{segments}]
"#,
        ORIGIN[0], ORIGIN[1], ORIGIN[2]
    );
    Scenario::from_toml(&text).map_err(|e| e.to_string())
}

fn trajectory(sc: &Scenario) -> Trajectory {
    Trajectory::from_config(&sc.receiver, Path::new("."), sc.duration_s)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn table(sc: &Scenario, step_s: f64) -> MotionTable {
    MotionTable::from_config(&sc.receiver, sc.duration_s, step_s).unwrap_or_else(|e| panic!("{e}"))
}

/// ENU position and velocity of an ECEF state, in the level frame of the start (what the
/// truth file's ECEF columns mean).
fn enu(traj: &Trajectory, t: f64) -> (Vector3<f64>, Vector3<f64>) {
    let origin = Llh::from_degrees(ORIGIN[0], ORIGIN[1], ORIGIN[2]);
    let r = enu_rotation(&origin);
    let s = traj.state(t);
    (r * (s.pos_m - origin.to_ecef()), r * s.vel_mps)
}

#[test]
fn graded_cruise_climbs_speed_times_sin_atan_grade() {
    // 15 m/s along the road on a 6 % grade (reached over 3 s), then 20 s at constant grade.
    let sc = motion_scenario(
        15.0,
        r#"{ type = "cruise", duration_s = 30.0, grade_percent = 6.0 }"#,
        30.0,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let traj = trajectory(&sc);
    let gamma = 0.06f64.atan();
    let (p5, v5) = enu(&traj, 5.0);
    let (p25, _) = enu(&traj, 25.0);
    // Up velocity speed sin(atan(grade)), horizontal speed cos: at the level of the ECEF
    // round trip (1e-9 relative on 6.4e6 m).
    assert!((v5[2] - 15.0 * gamma.sin()).abs() < 1e-6, "{v5}");
    assert!((v5.xy().norm() - 15.0 * gamma.cos()).abs() < 1e-6, "{v5}");
    // Over 20 s at constant grade: 20 v sin(gamma) = 17.97 m of climb, 20 v cos(gamma) of run.
    let d = p25 - p5;
    assert!((d[2] - 20.0 * 15.0 * gamma.sin()).abs() < 1e-5, "{d}");
    assert!(
        (d.xy().norm() - 20.0 * 15.0 * gamma.cos()).abs() < 1e-5,
        "{d}"
    );
    // During the smoothstep ramp the climb rate lies between 0 and the final one and rises.
    let mut prev = -1.0;
    for k in 0..=30 {
        let vz = enu(&traj, 0.1 * f64::from(k)).1[2];
        assert!(
            vz >= prev - 1e-9 && vz <= 15.0 * gamma.sin() + 1e-9,
            "{k}: {vz}"
        );
        prev = vz;
    }
    // The vehicle view carries the same slope.
    let vs = table(&sc, 0.01).vehicle_state(10.0);
    assert!((vs.pitch_rad - gamma).abs() < 1e-12);
    assert!((vs.speed_mps - 15.0).abs() < 1e-9);
}

#[test]
fn a_hill_returns_to_level_and_its_height_is_the_integral_of_the_climb_rate() {
    // Up 8 %, level, down 8 % for the same time: back to the start height (the smoothstep ramps
    // are symmetric, so the climb of one ramp is the descent of the other).
    let segs = r#"
        { type = "cruise", duration_s = 20.0, grade_percent = 8.0 },
        { type = "cruise", duration_s = 10.0, grade_percent = 0.0 },
        { type = "cruise", duration_s = 20.0, grade_percent = -8.0 },
        { type = "cruise", duration_s = 10.0, grade_percent = 0.0 }"#;
    let sc = motion_scenario(12.0, segs, 60.0).unwrap_or_else(|e| panic!("{e}"));
    let traj = trajectory(&sc);
    let gamma = 0.08f64.atan();
    let top = enu(&traj, 25.0).0[2];
    // Climb: 20 s of 12 sin(gamma) less what the ramp-in loses plus what the ramp-out keeps;
    // by symmetry of the smoothstep the two 3 s ramps together contribute 3 s of full climb.
    assert!((top - 20.0 * 12.0 * gamma.sin()).abs() < 0.05, "top {top}");
    let end = enu(&traj, 59.0).0[2];
    assert!(end.abs() < 1e-4, "end height {end}");
    // Speed along the road stays 12 m/s throughout.
    for k in 0..60 {
        let v = enu(&traj, f64::from(k)).1.norm();
        assert!((v - 12.0).abs() < 1e-6, "{k}: {v}");
    }
}

#[test]
fn stop_brakes_without_reversing_and_holds_position() {
    let segs = r#"
        { type = "cruise", duration_s = 5.0 },
        { type = "stop", duration_s = 20.0, decel_mps2 = 2.5, grade_percent = 5.0 },
        { type = "accelerate", accel_mps2 = 1.5, to_speed_mps = 10.0 },
        { type = "cruise", duration_s = 5.0 }"#;
    let sc = motion_scenario(14.0, segs, 50.0).unwrap_or_else(|e| panic!("{e}"));
    let m = table(&sc, MotionTable::DT_S);
    // Braking from 14 m/s at 2.5 m/s^2 takes 14/2.5 + 0.5 (ramp) = 6.1 s: at rest from ~11.1 s
    // to 31.1 s.
    let rest = m.enu_state(12.0);
    for t in [12.0, 20.0, 30.5] {
        let [p, v, a] = m.enu_state(t);
        assert!(
            (p - rest[0]).norm() < 1e-9,
            "moved while stopped at {t}: {p}"
        );
        assert!(v.norm() < 1e-9 && a.norm() < 1e-6, "{t}: {v} {a}");
        let vs = m.vehicle_state(t);
        assert!(vs.speed_mps < 1e-9 && vs.a_long_mps2 == 0.0, "{vs:?}");
        // Standing on a 5 % slope: the pitch is there even at rest (an accelerometer sees it).
        assert!((vs.pitch_rad - 0.05f64.atan()).abs() < 1e-12);
    }
    // Braking distance of the jerk-limited profile: v^2/(2 a) plus v r / 2 for the ramps.
    let start_brake = m.enu_state(5.0)[0];
    let dist = (rest[0] - start_brake).norm();
    let expected = 14.0 * 14.0 / (2.0 * 2.5) + 14.0 * 0.5 / 2.0;
    assert!((dist - expected).abs() < 0.05, "{dist} vs {expected}");
    // Speed never negative, every millisecond.
    let mut min_speed = f64::INFINITY;
    for k in 0..50_000 {
        min_speed = min_speed.min(m.vehicle_state(f64::from(k) * 1e-3).speed_mps);
    }
    assert!(min_speed >= 0.0, "{min_speed}");
    // It drives off and reaches 10 m/s exactly.
    let vs = m.vehicle_state(45.0);
    assert!((vs.speed_mps - 10.0).abs() < 1e-6, "{}", vs.speed_mps);
}

#[test]
fn accelerate_to_speed_and_turn_through_an_angle_land_on_their_targets() {
    let segs = r#"
        { type = "accelerate", accel_mps2 = -2.0, to_speed_mps = 7.5 },
        { type = "cruise", duration_s = 1.0 },
        { type = "turn", angle_deg = 90.0, radius_m = 15.0, direction = "left" },
        { type = "accelerate", accel_mps2 = 1.5, to_speed_mps = 16.0 },
        { type = "cruise", duration_s = 10.0 }"#;
    let sc = motion_scenario(14.0, segs, 30.0).unwrap_or_else(|e| panic!("{e}"));
    let m = table(&sc, MotionTable::DT_S);
    // The turn starts at 7.5 m/s with rate v / r = 0.5 rad/s: its centripetal acceleration is
    // v^2 / r = 3.75 m/s^2 once ramped in.
    let t_turn = (14.0 - 7.5) / 2.0 + 0.5 + 1.0;
    let a = m.enu_state(t_turn + 1.5)[2];
    assert!((a.norm() - 7.5 * 7.5 / 15.0).abs() < 1e-3, "{a}");
    let end = m.vehicle_state(29.0);
    assert!((end.speed_mps - 16.0).abs() < 1e-6, "{}", end.speed_mps);
    // Heading 90 deg (east) turned left by 90 deg: north, within one table step of turn rate.
    assert!(
        end.heading_rad.abs() < 0.5 * 1e-3 + 1e-9,
        "{}",
        end.heading_rad
    );
}

#[test]
fn vehicle_view_is_the_derivative_of_the_trajectory() {
    let sc = Scenario::from_toml(URBAN_DRIVE_TOML).unwrap_or_else(|e| panic!("{e}"));
    let m = table(&sc, 0.01);
    let h = 0.01;
    // Through the first block: acceleration, cruise, braking, a right turn, acceleration.
    let mut worst = [0.0f64; 4];
    let mut t = 1.0;
    while t < 60.0 {
        let (a, b, c) = (
            m.vehicle_state(t - h),
            m.vehicle_state(t),
            m.vehicle_state(t + h),
        );
        let heading_rate = wrap(c.heading_rad - a.heading_rad) / (2.0 * h);
        worst[0] = worst[0].max((heading_rate - b.yaw_rate_rad_s).abs());
        worst[1] = worst[1].max(((c.speed_mps - a.speed_mps) / (2.0 * h) - b.a_long_mps2).abs());
        let ve = (c.east_m - a.east_m) / (2.0 * h);
        let vn = (c.north_m - a.north_m) / (2.0 * h);
        if b.speed_mps > 1.0 {
            let course = ve.atan2(vn);
            worst[2] = worst[2].max(wrap(course - b.heading_rad).abs());
        }
        worst[3] = worst[3].max((ve.hypot(vn) - b.speed_mps * b.pitch_rad.cos()).abs());
        t += 0.37;
    }
    // Central differences over 20 ms: errors of order (rate of change) x h^2.
    assert!(worst[0] < 1e-3, "yaw rate {worst:?}");
    assert!(worst[1] < 1e-3, "a_long {worst:?}");
    assert!(worst[2] < 1e-4, "heading {worst:?}");
    assert!(worst[3] < 1e-3, "speed {worst:?}");
}

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

#[test]
fn acceleration_is_continuous_through_grade_and_stop_transitions() {
    // Bounded jerk everywhere in the urban drive's first 200 s (stops, turns, a hill): the
    // acceleration changes by at most jerk x dt between samples 1 ms apart. The largest jerks:
    // 2 m/s^2 braking ramped over 0.5 s (4 m/s^3), a 3.75 m/s^2 turn ramped over 0.5 s
    // (7.5 m/s^3) and a grade change of 6 % at 16 m/s over 3 s (peak vertical jerk
    // 6 v dgamma / T^2 = 0.64 m/s^3).
    let sc = Scenario::from_toml(URBAN_DRIVE_TOML).unwrap_or_else(|e| panic!("{e}"));
    let traj = trajectory(&sc);
    let dt = 1e-3;
    let mut prev = traj.state(0.0).acc_mps2;
    let mut worst = 0.0f64;
    for k in 1..200_000 {
        let a = traj.state(f64::from(k) * dt).acc_mps2;
        worst = worst.max((a - prev).norm() / dt);
        prev = a;
    }
    assert!(worst < 10.0, "largest jerk {worst} m/s^3");
}

#[test]
fn urban_drive_is_a_long_city_drive() {
    let sc = Scenario::from_toml(URBAN_DRIVE_TOML).unwrap_or_else(|e| panic!("{e}"));
    assert!((1200.0..=1800.0).contains(&sc.duration_s));
    let step = 0.01;
    let m = table(&sc, step);
    let (mut max_v, mut stopped_s, mut dist, mut max_grade) = (0.0f64, 0.0, 0.0, 0.0f64);
    let mut turned = 0.0;
    let (mut min_up, mut max_up) = (f64::INFINITY, f64::NEG_INFINITY);
    let n = (sc.duration_s / step) as usize;
    let mut prev_heading = m.vehicle_state(0.0).heading_rad;
    for k in 0..n {
        let s = m.vehicle_state(k as f64 * step);
        assert!(s.speed_mps >= 0.0);
        max_v = max_v.max(s.speed_mps);
        if s.speed_mps < 0.01 {
            stopped_s += step;
        }
        dist += s.speed_mps * step;
        max_grade = max_grade.max(s.pitch_rad.tan().abs() * 100.0);
        turned += wrap(s.heading_rad - prev_heading).abs();
        prev_heading = s.heading_rad;
        min_up = min_up.min(s.up_m);
        max_up = max_up.max(s.up_m);
    }
    assert!((16.9..17.01).contains(&max_v), "max speed {max_v}");
    assert!(stopped_s > 250.0, "stopped {stopped_s} s");
    assert!((12_000.0..18_000.0).contains(&dist), "distance {dist} m");
    assert!(
        (9.9..10.01).contains(&max_grade),
        "steepest grade {max_grade} %"
    );
    // 21 turns of 90 deg (1890 deg), each within one table step of turn rate (0.5 rad/s x
    // 10 ms = 0.29 deg).
    assert!(
        (turned.to_degrees() - 1890.0).abs() < 21.0 * 0.29,
        "{}",
        turned.to_degrees()
    );
    assert!(max_up - min_up > 20.0, "hills {min_up}..{max_up} m");
}

#[test]
fn bad_motions_are_clear_errors() {
    let err = |segs: &str, speed: f64| {
        motion_scenario(speed, segs, 30.0)
            .and_then(|sc| {
                MotionTable::from_config(&sc.receiver, 30.0, 0.01).map_err(|e| e.to_string())
            })
            .err()
            .unwrap_or_else(|| panic!("accepted {segs}"))
    };
    let e = err(
        r#"{ type = "accelerate", duration_s = 10.0, accel_mps2 = -2.0 }"#,
        10.0,
    );
    assert!(e.contains("reverses") && e.contains("stop"), "{e}");
    let e = err(r#"{ type = "accelerate", accel_mps2 = 1.0 }"#, 10.0);
    assert!(e.contains("segment 1") && e.contains("to_speed_mps"), "{e}");
    let e = err(
        r#"{ type = "accelerate", accel_mps2 = 1.0, to_speed_mps = 5.0 }"#,
        10.0,
    );
    assert!(e.contains("cannot take the speed"), "{e}");
    let e = err(
        r#"{ type = "cruise", duration_s = 1.0 }, { type = "cruise", duration_s = 5.0, grade_percent = 60.0 }"#,
        10.0,
    );
    assert!(
        e.contains("segment 2") && e.contains("grade_percent"),
        "{e}"
    );
    let e = err(r#"{ type = "stop", duration_s = -1.0 }"#, 10.0);
    assert!(e.contains("stop duration_s"), "{e}");
    let e = err(
        r#"{ type = "turn", angle_deg = 90.0, duration_s = 3.0, radius_m = 10.0 }"#,
        10.0,
    );
    assert!(e.contains("angle_deg"), "{e}");
    let e = err(
        r#"{ type = "stop", duration_s = 5.0 }, { type = "turn", angle_deg = 90.0, radius_m = 10.0 }"#,
        10.0,
    );
    assert!(e.contains("needs the vehicle moving"), "{e}");
    let e = err(
        r#"{ type = "cruise", duration_s = 5.0, grade = 3.0 }"#,
        10.0,
    );
    assert!(e.contains("grade"), "{e}");
}
