//! The phase inputs, the aidings and the INS parameters of a cell.

use gpsrx_tracking::phase_sim::Trajectory;

/// The phase input (a polynomial from t = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    /// Phase step `P` cycles at t = 0 (the NCO starts `P` behind).
    Step,
    /// Phase ramp: a frequency offset `df` Hz (constant LOS velocity).
    Ramp,
    /// Phase parabola: a Doppler rate `a` Hz/s (constant LOS acceleration).
    Parabola,
    /// Phase cubic: a Doppler jerk `j` Hz/s^2 (constant LOS jerk).
    Cubic,
}

impl Input {
    /// All inputs, in table order.
    pub const ALL: [Input; 4] = [Input::Step, Input::Ramp, Input::Parabola, Input::Cubic];

    /// Polynomial degree `m` of the phase.
    pub fn degree(self) -> u32 {
        match self {
            Input::Step => 0,
            Input::Ramp => 1,
            Input::Parabola => 2,
            Input::Cubic => 3,
        }
    }

    /// Name in the table.
    pub fn name(self) -> &'static str {
        ["step", "ramp", "parabola", "cubic"][self.degree() as usize]
    }

    /// Unit of the magnitude `d^m theta/dt^m`.
    pub fn unit(self) -> &'static str {
        ["cycle", "Hz", "Hz/s", "Hz/s^2"][self.degree() as usize]
    }

    /// The phase trajectory of magnitude `mag` (in [`Self::unit`]); for a step the signal phase
    /// is `mag` and the NCO starts at 0.
    pub fn trajectory(self, mag: f64) -> Trajectory {
        match self {
            Input::Step => Trajectory::new(mag, 0.0, 0.0, &[]),
            Input::Ramp => Trajectory::new(0.0, mag, 0.0, &[]),
            Input::Parabola => Trajectory::new(0.0, 0.0, mag, &[]),
            Input::Cubic => Trajectory::new(0.0, 0.0, 0.0, &[(0.0, mag)]),
        }
    }
}

/// The feed-forward into the NCO (seed 004 Fig. 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aiding {
    /// No feed-forward.
    Unaided,
    /// The true Doppler (its mean over each interval).
    Perfect,
    /// The true Doppler through `alpha/(s + alpha)`.
    BandLimited,
    /// The true Doppler plus `B_V t / lambda`.
    BiasedIns,
}

impl Aiding {
    /// All aidings, in table order.
    pub const ALL: [Aiding; 4] = [
        Aiding::Unaided,
        Aiding::Perfect,
        Aiding::BandLimited,
        Aiding::BiasedIns,
    ];

    /// Name in the table.
    pub fn name(self) -> &'static str {
        match self {
            Aiding::Unaided => "unaided",
            Aiding::Perfect => "perfect",
            Aiding::BandLimited => "band-limited",
            Aiding::BiasedIns => "biased INS",
        }
    }
}

/// The INS parameters of the aided cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AidParams {
    /// Band-limiter corner alpha, rad/s.
    pub alpha_rad_s: f64,
    /// LOS accelerometer bias B_V, m/s^2.
    pub b_v_mps2: f64,
}
