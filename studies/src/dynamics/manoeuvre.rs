//! The manoeuvres: a level turn or a longitudinal acceleration step after the lead-in.

use super::params::{RAMP_S, STEP_S, TAIL_S, TURN_S};
use gpsrx_samples::sim::trajectory::G0_MPS2;

/// A manoeuvre after the lead-in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Manoeuvre {
    /// Level turn to the left at this centripetal acceleration, g.
    Turn(f64),
    /// Longitudinal acceleration step of this size, g.
    Step(f64),
}

impl Manoeuvre {
    /// Acceleration, g.
    pub fn g(&self) -> f64 {
        match self {
            Self::Turn(g) | Self::Step(g) => *g,
        }
    }

    /// Short name: `10 g turn`.
    pub fn label(&self) -> String {
        match self {
            Self::Turn(g) => format!("{g} g turn"),
            Self::Step(g) => format!("{g} g step"),
        }
    }

    /// Length of the manoeuvre segment (ramp-in included), s.
    pub(super) fn segment_s(&self) -> f64 {
        match self {
            Self::Turn(_) => TURN_S,
            Self::Step(_) => STEP_S,
        }
    }

    /// The simulator's `segments`: a cruise of `lead_in_s`, the manoeuvre, a cruise past the
    /// end of the recording (ramp-out and [`TAIL_S`]).
    pub(super) fn segments_toml(&self, lead_in_s: f64) -> String {
        let seg = match self {
            Self::Turn(g) => format!(
                "{{ type = \"turn\", duration_s = {TURN_S:?}, accel_g = {g:?}, direction = \"left\" }}"
            ),
            Self::Step(g) => format!(
                "{{ type = \"accelerate\", duration_s = {STEP_S:?}, accel_mps2 = {:?} }}",
                g * G0_MPS2
            ),
        };
        let rest = RAMP_S + TAIL_S + 2.0;
        format!(
            "[{{ type = \"cruise\", duration_s = {lead_in_s:?} }}, {seg}, {{ type = \"cruise\", duration_s = {rest:?} }}]"
        )
    }
}
