//! The re-derived closed forms (residual phase, steady state) and the agreement rule.

use gpsrx_tracking::phase_sim::LAMBDA_M;

use super::{AidParams, Aiding, Input};

/// Relative agreement tolerance (of `|closed|`).
pub const REL_TOL: f64 = 0.05;
/// Absolute agreement tolerance where the closed form is 0, cycles.
pub const ABS_TOL_CYCLES: f64 = 0.005;

/// The residual phase the loop must track (module docs): `(m, R)`, polynomial degree `m` and
/// `R = d^m r/dt^m` (cycles/s^m) of its polynomial part; `None` when nothing remains.
///
/// Unaided `(deg, mag)`; perfect `None`; band-limited `(deg - 1, mag/alpha)` for `deg >= 2`,
/// else `None`; biased INS `(2, -B_V/lambda)`.
pub fn residual(
    input: Input,
    aiding: Aiding,
    magnitude: f64,
    aid: AidParams,
) -> Option<(u32, f64)> {
    let m = input.degree();
    match aiding {
        Aiding::Unaided => Some((m, magnitude)),
        Aiding::Perfect => None,
        Aiding::BandLimited if m >= 2 => Some((m - 1, magnitude / aid.alpha_rad_s)),
        Aiding::BandLimited => None,
        Aiding::BiasedIns => Some((2, -aid.b_v_mps2 / LAMBDA_M)),
    }
}

/// A closed-form steady state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClosedForm {
    /// The error settles at this value, cycles.
    Bounded(f64),
    /// The error grows without bound: `d^p e/dt^p -> rate` cycles/s^p.
    Growing {
        /// Derivative order `p = m - n` (1 or 2).
        p: u32,
        /// The limit of `d^p e/dt^p`, cycles/s^p.
        rate: f64,
    },
}

impl ClosedForm {
    /// The number compared with the measurement (value or rate).
    pub fn value(self) -> f64 {
        match self {
            ClosedForm::Bounded(v) | ClosedForm::Growing { rate: v, .. } => v,
        }
    }

    /// Unit of [`Self::value`].
    pub fn unit(self) -> &'static str {
        match self {
            ClosedForm::Bounded(_) => "cycles",
            ClosedForm::Growing { p: 1, .. } => "cycles/s",
            ClosedForm::Growing { .. } => "cycles/s^2",
        }
    }
}

/// Steady state of an order-`order` loop of natural frequency `omega0_rad_s` for a residual
/// `(m, R)` (module docs): `m < n` -> 0; `m = n` -> `R/omega0^n`; `m > n` ->
/// `d^(m-n) e/dt^(m-n) = R/omega0^n`.
pub fn closed_form(order: u8, omega0_rad_s: f64, residual: Option<(u32, f64)>) -> ClosedForm {
    let n = u32::from(order);
    match residual {
        Some((m, r)) if m >= n => {
            let v = r / omega0_rad_s.powi(n as i32);
            if m == n {
                ClosedForm::Bounded(v)
            } else {
                ClosedForm::Growing { p: m - n, rate: v }
            }
        }
        _ => ClosedForm::Bounded(0.0),
    }
}

/// The agreement rule: `|measured - closed| <= REL_TOL |closed|`, or `|measured| <=
/// ABS_TOL_CYCLES` when `closed == 0`.
pub fn agrees(closed: f64, measured: f64) -> bool {
    if closed == 0.0 {
        measured.abs() <= ABS_TOL_CYCLES
    } else {
        (measured - closed).abs() <= REL_TOL * closed.abs()
    }
}
