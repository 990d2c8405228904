//! Dilution of precision in the local East-North-Up frame.
//!
//! With G the unweighted design matrix (rows [-l^T, 1] for satellites, [u^T, 0] for
//! landmarks), Q = (G^T G)^-1 in ECEF is rotated to ENU, Q_enu = R Q_pos R^T, and
//! GDOP = sqrt(tr Q), PDOP = sqrt(Q_EE + Q_NN + Q_UU), HDOP = sqrt(Q_EE + Q_NN),
//! VDOP = sqrt(Q_UU), TDOP = sqrt(Q_tt) (Kaplan & Hegarty 2nd ed. 7.3.1). DOP depends on the
//! geometry only, not on the weights.

use crate::frames::{enu_rotation, Llh};
use nalgebra::{Matrix3, Matrix4, Vector4};

/// Dilution-of-precision factors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dop {
    /// Geometric DOP.
    pub gdop: f64,
    /// Position DOP.
    pub pdop: f64,
    /// Horizontal DOP.
    pub hdop: f64,
    /// Vertical DOP.
    pub vdop: f64,
    /// Time DOP.
    pub tdop: f64,
}

/// DOP of the design rows at `origin`; None when G^T G is singular (GDOP above
/// [`super::wls::MAX_GDOP`]) or the result not finite.
pub fn dop_enu(rows: &[[f64; 4]], origin: &Llh) -> Option<Dop> {
    let mut g = Matrix4::zeros();
    for r in rows {
        let a = Vector4::from(*r);
        g += a * a.transpose();
    }
    let q = g.try_inverse()?;
    if !(q.trace() >= 0.0 && q.trace().sqrt() <= super::wls::MAX_GDOP) {
        return None;
    }
    let qp: Matrix3<f64> = q.fixed_view::<3, 3>(0, 0).into_owned();
    dop_from_cofactor(&qp, q[(3, 3)], origin)
}

/// DOP from the cofactor matrix Q = (G^T G)^-1 of any solution with a position and a clock
/// unknown: `q_pos_ecef` the ECEF position block, `q_clock` the clock diagonal element (m^2
/// per m^2 of range variance). GDOP here covers position and clock only, also when the
/// solution has further unknowns. None when a value is not finite.
pub fn dop_from_cofactor(q_pos_ecef: &Matrix3<f64>, q_clock: f64, origin: &Llh) -> Option<Dop> {
    let r = enu_rotation(origin);
    let qe = r * q_pos_ecef * r.transpose();
    let (e, n, u, t) = (qe[(0, 0)], qe[(1, 1)], qe[(2, 2)], q_clock);
    let dop = Dop {
        gdop: (e + n + u + t).sqrt(),
        pdop: (e + n + u).sqrt(),
        hdop: (e + n).sqrt(),
        vdop: u.sqrt(),
        tdop: t.sqrt(),
    };
    let all_finite = [dop.gdop, dop.pdop, dop.hdop, dop.vdop, dop.tdop]
        .iter()
        .all(|v| v.is_finite());
    all_finite.then_some(dop)
}
