//! The line-of-sight dynamics a cell's loop must follow: the *residual* motion left after the
//! feed-forward (the whole motion when unaided, the INS error when aided).

use gpsrx_tracking::phase_sim::{G_MPS2, LAMBDA_M};

/// A stated dynamic: a constant line-of-sight velocity, acceleration or jerk residual.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Dynamics {
    /// No residual motion (a static receiver, or an aided one with a perfect INS).
    Static,
    /// Unaided, a constant LOS acceleration of `g` (in g) for the whole run.
    AccelUnaided {
        /// LOS acceleration, g.
        g: f64,
    },
    /// Unaided, a constant LOS jerk of `g_per_s` (g/s): the entry of a turn that reaches 10 g in
    /// 1 s, held for the whole run.
    JerkUnaided {
        /// LOS jerk, g/s.
        g_per_s: f64,
    },
    /// Aided by an INS whose LOS accelerometer bias is `mg` milli-g: the feed-forward's velocity
    /// error grows as `B t` (seed 004 eqs. 12-16), a constant Doppler-rate residual, whatever
    /// the manoeuvre (a 10 g turn included).
    InsBias {
        /// LOS accelerometer bias, mg.
        mg: f64,
    },
    /// Aided by an INS with a constant LOS velocity error of `mps` m/s: a constant Doppler
    /// residual (for the 1st-order loop, which has no integrator to absorb it).
    InsVelocity {
        /// LOS velocity error, m/s.
        mps: f64,
    },
}

impl Dynamics {
    /// Short name (the CSV's `dynamics` column).
    pub fn name(&self) -> String {
        match self {
            Self::Static => "static".into(),
            Self::AccelUnaided { g } => format!("accel {g} g"),
            Self::JerkUnaided { g_per_s } => format!("jerk {g_per_s} g/s"),
            Self::InsBias { mg } => format!("INS bias {mg} mg"),
            Self::InsVelocity { mps } => format!("INS vel {mps} m/s"),
        }
    }

    /// Whether the loop is aided (`aided` column): "yes" for the INS cases, "no" for the unaided
    /// dynamics, "-" for static (aided by a perfect INS and unaided are the same).
    pub fn aided(&self) -> &'static str {
        match self {
            Self::Static => "-",
            Self::AccelUnaided { .. } | Self::JerkUnaided { .. } => "no",
            Self::InsBias { .. } | Self::InsVelocity { .. } => "yes",
        }
    }

    /// The residual LOS motion `(velocity m/s, acceleration m/s^2, jerk m/s^3)` at `t = 0`
    /// (acceleration and jerk constant afterwards, except that a jerk ramps the acceleration).
    pub fn residual_mks(&self) -> (f64, f64, f64) {
        match *self {
            Self::Static => (0.0, 0.0, 0.0),
            Self::AccelUnaided { g } => (0.0, g * G_MPS2, 0.0),
            Self::JerkUnaided { g_per_s } => (0.0, 0.0, g_per_s * G_MPS2),
            Self::InsBias { mg } => (0.0, mg * 1e-3 * G_MPS2, 0.0),
            Self::InsVelocity { mps } => (mps, 0.0, 0.0),
        }
    }

    /// The residual carrier-phase derivatives `[d theta/dt (Hz), d2 theta/dt2 (Hz/s),
    /// d3 theta/dt3 (Hz/s^2)]` at `t = 0`: the motion over the wavelength.
    pub fn phase_derivatives(&self) -> [f64; 3] {
        let (v, a, j) = self.residual_mks();
        [v / LAMBDA_M, a / LAMBDA_M, j / LAMBDA_M]
    }

    /// The highest derivative of the residual phase that is non-zero (1 velocity, 2
    /// acceleration, 3 jerk; 0 for none): a loop of lower order has an unbounded error
    /// (oracles.md "Loop filters").
    pub fn degree(&self) -> u8 {
        let d = self.phase_derivatives();
        (1..=3u8)
            .rev()
            .find(|&n| d[usize::from(n) - 1] != 0.0)
            .unwrap_or(0)
    }

    /// The orders this dynamic is run with: those with a bounded error (order >= degree), and
    /// for the INS velocity error only order 1 (orders 2 and 3 absorb a constant Doppler
    /// residual in their integrators and are then the static case).
    pub fn orders(&self) -> &'static [u8] {
        match self {
            Self::Static => &[1, 2, 3],
            Self::AccelUnaided { .. } | Self::InsBias { .. } => &[2, 3],
            Self::JerkUnaided { .. } => &[3],
            Self::InsVelocity { .. } => &[1],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_g_is_51_53_hz_per_s() {
        let d = Dynamics::AccelUnaided { g: 1.0 }.phase_derivatives();
        assert!((d[1] - 51.53).abs() < 0.01, "{}", d[1]);
        assert_eq!(Dynamics::AccelUnaided { g: 1.0 }.degree(), 2);
        assert_eq!(Dynamics::JerkUnaided { g_per_s: 10.0 }.degree(), 3);
        assert_eq!(Dynamics::Static.degree(), 0);
        for d in [
            Dynamics::Static,
            Dynamics::AccelUnaided { g: 1.0 },
            Dynamics::JerkUnaided { g_per_s: 10.0 },
            Dynamics::InsBias { mg: 1.0 },
            Dynamics::InsVelocity { mps: 0.05 },
        ] {
            assert!(d.orders().iter().all(|&o| o >= d.degree()), "{}", d.name());
        }
    }
}
