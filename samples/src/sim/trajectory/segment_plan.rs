//! The segments of a built-in motion resolved into control phases: what acceleration and turn
//! rate each commands and for how long, including the stop and target-speed planning (module
//! doc of [`super::motion`]).

use super::G0_MPS2;
use crate::sim::scenario::{Segment, TurnDirection, DEFAULT_STOP_DECEL_MPS2};
use crate::sim::SimError;

/// Longitudinal acceleration and turn rate commanded at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Controls {
    pub(super) accel_mps2: f64,
    pub(super) yaw_rate_rad_s: f64,
}

pub(super) const IDLE: Controls = Controls {
    accel_mps2: 0.0,
    yaw_rate_rad_s: 0.0,
};

/// A segment resolved to absolute times and control laws.
#[derive(Debug, Clone, Copy)]
pub(super) struct Phase {
    pub(super) t0: f64,
    pub(super) t1: f64,
    pub(super) from: Controls,
    pub(super) to: Controls,
    pub(super) jerk_mps3: f64,
    pub(super) ramp_s: f64,
    /// Standing still: the speed is held at >= 0 (it reaches 0 during the ramp).
    pub(super) standstill: bool,
}

impl Phase {
    pub(super) fn controls(&self, t: f64) -> Controls {
        let tau = (t - self.t0).max(0.0);
        let w = if self.ramp_s > 0.0 {
            (tau / self.ramp_s).min(1.0)
        } else {
            1.0
        };
        Controls {
            accel_mps2: self.from.accel_mps2
                + w * (self.to.accel_mps2 - self.from.accel_mps2)
                + self.jerk_mps3 * tau,
            yaw_rate_rad_s: self.from.yaw_rate_rad_s
                + w * (self.to.yaw_rate_rad_s - self.from.yaw_rate_rad_s),
        }
    }
}

/// A smoothstep change of the road angle from `from_rad` to `to_rad` over `dur_s` from `t0`.
#[derive(Debug, Clone, Copy)]
pub(super) struct GradeRamp {
    pub(super) t0: f64,
    pub(super) dur_s: f64,
    pub(super) from_rad: f64,
    pub(super) to_rad: f64,
}

impl GradeRamp {
    /// Road angle and its rate at `t`.
    pub(super) fn at(&self, t: f64) -> (f64, f64) {
        let tau = t - self.t0;
        if self.dur_s <= 0.0 || tau >= self.dur_s {
            return (self.to_rad, 0.0);
        }
        let w = (tau / self.dur_s).max(0.0);
        let d = self.to_rad - self.from_rad;
        (
            self.from_rad + d * w * w * (3.0 - 2.0 * w),
            d * 6.0 * w * (1.0 - w) / self.dur_s,
        )
    }
}

/// One phase of a segment before its start time is known.
#[derive(Debug, Clone, Copy)]
pub(super) struct PhaseSpec {
    pub(super) dur_s: f64,
    pub(super) to: Controls,
    pub(super) jerk_mps3: f64,
    pub(super) standstill: bool,
}

impl PhaseSpec {
    pub(super) fn new(dur_s: f64, to: Controls) -> Self {
        Self {
            dur_s,
            to,
            jerk_mps3: 0.0,
            standstill: false,
        }
    }
}

/// Solves for the constant-acceleration phase that takes the speed from `v0` to `v_target`
/// when the acceleration is ramped in from `a0` and out to 0 over `ramp_s` each (module doc).
/// `None`: already there.
fn speed_change(
    k: usize,
    v0: f64,
    v_target: f64,
    accel_mps2: f64,
    a0: f64,
    ramp_s: f64,
    step_s: f64,
) -> Result<Option<PhaseSpec>, SimError> {
    let dv = v_target - v0 - a0 * ramp_s / 2.0;
    if dv.abs() < 1e-9 {
        return Ok(None);
    }
    if dv * accel_mps2 <= 0.0 {
        return Err(SimError::Scenario(format!(
            "segment {k}: an acceleration of {accel_mps2} m/s^2 cannot take the speed from \
             {v0:.2} to {v_target:.2} m/s (check the sign of accel_mps2 / decel_mps2)"
        )));
    }
    let hold = (dv / accel_mps2 - ramp_s).max(0.0);
    let hold = (hold / step_s - 1e-6).ceil().max(0.0) * step_s;
    let dur_s = hold + ramp_s;
    Ok(Some(PhaseSpec::new(
        dur_s,
        Controls {
            accel_mps2: dv / dur_s,
            yaw_rate_rad_s: 0.0,
        },
    )))
}

/// The phases segment `k` (from 1) expands to, entered at `t` with speed `v0` and controls
/// `current`.
pub(super) fn plan(
    k: usize,
    seg: &Segment,
    t: f64,
    v0: f64,
    current: Controls,
    ramp_s: f64,
    step_s: f64,
) -> Result<Vec<PhaseSpec>, SimError> {
    Ok(match seg {
        Segment::Cruise { duration_s, .. } => vec![PhaseSpec::new(*duration_s, IDLE)],
        Segment::Accelerate {
            duration_s: Some(d),
            accel_mps2,
            ..
        } => vec![PhaseSpec::new(
            *d,
            Controls {
                accel_mps2: *accel_mps2,
                yaw_rate_rad_s: 0.0,
            },
        )],
        Segment::Accelerate {
            to_speed_mps,
            accel_mps2,
            ..
        } => {
            let target = to_speed_mps.unwrap_or(v0);
            speed_change(
                k,
                v0,
                target,
                *accel_mps2,
                current.accel_mps2,
                ramp_s,
                step_s,
            )?
            .into_iter()
            .collect()
        }
        Segment::Jerk {
            duration_s,
            jerk_mps3,
            ..
        } => vec![PhaseSpec {
            dur_s: *duration_s,
            to: Controls {
                accel_mps2: current.accel_mps2,
                yaw_rate_rad_s: 0.0,
            },
            jerk_mps3: *jerk_mps3,
            standstill: false,
        }],
        Segment::Turn {
            duration_s,
            angle_deg,
            radius_m,
            accel_g,
            direction,
            ..
        } => {
            if v0 <= 0.1 {
                return Err(SimError::Scenario(format!(
                    "segment {k}: a turn starting at t = {t:.1} s needs the vehicle moving (speed {v0:.2} m/s)"
                )));
            }
            let rate = match (radius_m, accel_g) {
                (Some(r), _) if *r > 0.0 => v0 / r,
                (None, Some(g)) if *g > 0.0 => g * G0_MPS2 / v0,
                _ => {
                    return Err(SimError::Scenario(format!(
                        "segment {k}: turn radius_m / accel_g must be positive"
                    )))
                }
            };
            let sign = if *direction == TurnDirection::Right {
                1.0
            } else {
                -1.0
            };
            // Ramping in and out over equal times, the heading changes by rate x duration.
            let dur_s = match (duration_s, angle_deg) {
                (Some(d), _) => *d,
                (None, Some(a)) => a.to_radians() / rate,
                (None, None) => f64::NAN,
            };
            vec![PhaseSpec::new(
                dur_s,
                Controls {
                    accel_mps2: 0.0,
                    yaw_rate_rad_s: sign * rate,
                },
            )]
        }
        Segment::Stop {
            duration_s,
            decel_mps2,
            ..
        } => {
            let decel = decel_mps2.unwrap_or(DEFAULT_STOP_DECEL_MPS2);
            let mut v = Vec::new();
            if v0 > 1e-9 {
                v.extend(speed_change(
                    k,
                    v0,
                    0.0,
                    -decel,
                    current.accel_mps2,
                    ramp_s,
                    step_s,
                )?);
            }
            v.push(PhaseSpec {
                dur_s: ramp_s + duration_s,
                to: IDLE,
                jerk_mps3: 0.0,
                standstill: true,
            });
            v
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_change_lands_on_the_target_from_a_nonzero_acceleration() {
        // From a0 = 1 m/s^2 at 10 m/s to 4 m/s at up to -2 m/s^2 with 0.5 s ramps.
        let p = speed_change(1, 10.0, 4.0, -2.0, 1.0, 0.5, 1e-3)
            .unwrap_or_else(|e| panic!("{e}"))
            .unwrap_or_else(|| panic!("no phase"));
        let a = p.to.accel_mps2;
        let hold = p.dur_s - 0.5;
        // a0 r/2 + a (h + r) = dv, with the hold a whole number of steps.
        assert!((1.0 * 0.25 + a * (hold + 0.5) - (4.0 - 10.0)).abs() < 1e-12);
        assert!((-2.0..0.0).contains(&a));
        assert!(((hold / 1e-3) - (hold / 1e-3).round()).abs() < 1e-6);
        // The wrong sign is an error naming the segment.
        let e = speed_change(3, 10.0, 4.0, 2.0, 0.0, 0.5, 1e-3)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("segment 3"), "{e}");
    }
}
