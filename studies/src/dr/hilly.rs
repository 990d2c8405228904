//! Seed 002's test road for the speed filter: a ~15-minute drive at irregular speed (6-17 m/s,
//! changing every 10-30 s, with stops) over long, gentle hills (grades of -3.5 to +4 % held for
//! 2-4 minutes, changing over 20 s vertical curves), as "a road with ups and downs driven at
//! irregular speed" (seed 002 Sec. III). Generated once with a seeded script and kept here as
//! the scenario text the simulator's motion model reads.

/// The scenario (only `[receiver]` matters to the study).
pub const HILLY_TOML: &str = r#"
description = "hilly road at irregular speed, 15 min (seed 002's speed-filter test)"
duration_s = 880.0
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538194.0
[output]
format = "ci8"
fs_hz = 2.048e6
[receiver]
kind = "motion"
start_llh_deg = [35.1595, 126.8526, 50.0]
heading_deg = 30.0
speed_mps = 0.0
transition_s = 1.0
grade_percent = 0.0
grade_transition_s = 20.0
segments = [
  { type = "accelerate", accel_mps2 = 0.7, to_speed_mps = 16.4 },
  { type = "cruise", duration_s = 7.0 },
  { type = "accelerate", accel_mps2 = -1.3, to_speed_mps = 7.9 },
  { type = "cruise", duration_s = 19.0 },
  { type = "accelerate", accel_mps2 = 1.1, to_speed_mps = 12.7 },
  { type = "cruise", duration_s = 15.0 },
  { type = "accelerate", accel_mps2 = 1.1, to_speed_mps = 15.5, grade_percent = 3.0 },
  { type = "cruise", duration_s = 11.0 },
  { type = "accelerate", accel_mps2 = -0.9, to_speed_mps = 10.9 },
  { type = "cruise", duration_s = 6.0 },
  { type = "accelerate", accel_mps2 = 1.3, to_speed_mps = 16.3 },
  { type = "cruise", duration_s = 12.0 },
  { type = "accelerate", accel_mps2 = -1.1, to_speed_mps = 11.8 },
  { type = "cruise", duration_s = 9.0 },
  { type = "accelerate", accel_mps2 = -0.8, to_speed_mps = 7.9 },
  { type = "cruise", duration_s = 14.0 },
  { type = "accelerate", accel_mps2 = 1.2, to_speed_mps = 17.0 },
  { type = "cruise", duration_s = 8.0 },
  { type = "accelerate", accel_mps2 = -1.0, to_speed_mps = 10.9 },
  { type = "cruise", duration_s = 14.0 },
  { type = "accelerate", accel_mps2 = 1.3, to_speed_mps = 14.4 },
  { type = "cruise", duration_s = 11.0 },
  { type = "accelerate", accel_mps2 = -1.4, to_speed_mps = 10.9 },
  { type = "cruise", duration_s = 12.0 },
  { type = "accelerate", accel_mps2 = 1.1, to_speed_mps = 16.2 },
  { type = "cruise", duration_s = 19.0 },
  { type = "accelerate", accel_mps2 = -1.0, to_speed_mps = 13.3 },
  { type = "cruise", duration_s = 20.0 },
  { type = "accelerate", accel_mps2 = 1.2, to_speed_mps = 16.1, grade_percent = 1.0 },
  { type = "cruise", duration_s = 13.0 },
  { type = "accelerate", accel_mps2 = -1.2, to_speed_mps = 12.8 },
  { type = "cruise", duration_s = 13.0 },
  { type = "accelerate", accel_mps2 = 1.2, to_speed_mps = 16.5 },
  { type = "cruise", duration_s = 14.0 },
  { type = "accelerate", accel_mps2 = -1.1, to_speed_mps = 11.6 },
  { type = "cruise", duration_s = 12.0 },
  { type = "accelerate", accel_mps2 = -1.1, to_speed_mps = 8.3 },
  { type = "cruise", duration_s = 20.0 },
  { type = "accelerate", accel_mps2 = 1.2, to_speed_mps = 15.7 },
  { type = "cruise", duration_s = 11.0 },
  { type = "accelerate", accel_mps2 = -1.2, to_speed_mps = 8.1 },
  { type = "cruise", duration_s = 6.0 },
  { type = "accelerate", accel_mps2 = 1.2, to_speed_mps = 12.5 },
  { type = "cruise", duration_s = 20.0 },
  { type = "stop", duration_s = 20.0, decel_mps2 = 1.5 },
  { type = "accelerate", accel_mps2 = 1.4, to_speed_mps = 15.1, grade_percent = -2.0 },
  { type = "cruise", duration_s = 6.0 },
  { type = "accelerate", accel_mps2 = -1.0, to_speed_mps = 6.4 },
  { type = "cruise", duration_s = 8.0 },
  { type = "accelerate", accel_mps2 = 1.0, to_speed_mps = 16.1 },
  { type = "cruise", duration_s = 8.0 },
  { type = "accelerate", accel_mps2 = -0.8, to_speed_mps = 7.7 },
  { type = "cruise", duration_s = 17.0 },
  { type = "stop", duration_s = 20.0, decel_mps2 = 1.5 },
  { type = "accelerate", accel_mps2 = 0.8, to_speed_mps = 16.9 },
  { type = "cruise", duration_s = 6.0 },
  { type = "stop", duration_s = 20.0, decel_mps2 = 1.5 },
  { type = "accelerate", accel_mps2 = 1.0, to_speed_mps = 9.1, grade_percent = -3.5 },
  { type = "cruise", duration_s = 10.0 },
  { type = "accelerate", accel_mps2 = 1.2, to_speed_mps = 14.4 },
  { type = "cruise", duration_s = 20.0 },
  { type = "accelerate", accel_mps2 = -1.1, to_speed_mps = 10.4 },
  { type = "cruise", duration_s = 8.0 },
  { type = "accelerate", accel_mps2 = 0.9, to_speed_mps = 13.3 },
  { type = "cruise", duration_s = 7.0 },
  { type = "stop", duration_s = 10.0, decel_mps2 = 1.5 },
  { type = "accelerate", accel_mps2 = 1.0, to_speed_mps = 14.6 },
  { type = "cruise", duration_s = 11.0 },
  { type = "accelerate", accel_mps2 = -1.1, to_speed_mps = 8.9 },
  { type = "cruise", duration_s = 12.0 },
  { type = "accelerate", accel_mps2 = 1.4, to_speed_mps = 13.7 },
  { type = "cruise", duration_s = 16.0 },
  { type = "stop", duration_s = 10.0, decel_mps2 = 1.5 },
  { type = "accelerate", accel_mps2 = 1.0, to_speed_mps = 7.9 },
  { type = "cruise", duration_s = 9.0 },
  { type = "accelerate", accel_mps2 = 1.4, to_speed_mps = 16.3, grade_percent = 0.0 },
  { type = "cruise", duration_s = 9.0 },
  { type = "accelerate", accel_mps2 = -0.8, to_speed_mps = 6.8 },
  { type = "cruise", duration_s = 9.0 },
  { type = "accelerate", accel_mps2 = 1.2, to_speed_mps = 14.8 },
  { type = "cruise", duration_s = 10.0 },
  { type = "accelerate", accel_mps2 = -1.2, to_speed_mps = 9.1 },
  { type = "cruise", duration_s = 8.0 },
]
"#;
