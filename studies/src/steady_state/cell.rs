//! One cell of the table: its loop, settling time, measurement window, input magnitude and
//! closed form.

use gpsrx_tracking::loop_analysis;
use gpsrx_tracking::loop_filter::{omega0, LoopFilter};
use gpsrx_tracking::LoopConfig;

use super::stability::spectral_radius;
use super::{closed_form, residual, AidParams, Aiding, ClosedForm, Input};

/// Predicted error the bounded cells' magnitudes are scaled to, cycles.
pub const TARGET_ERROR_CYCLES: f64 = 0.03;
/// Error the growing cells reach at the end of their window, cycles.
pub const TARGET_END_ERROR_CYCLES: f64 = 0.05;
/// Transients must have decayed to this fraction before the window starts.
const SETTLE_DECAY: f64 = 1e-5;
/// Longest settling time simulated, s.
const MAX_SETTLE_S: f64 = 600.0;

/// One cell of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Loop noise bandwidth, Hz.
    pub bn_hz: f64,
    /// Integration time, s.
    pub t_coh_s: f64,
    /// Phase input.
    pub input: Input,
    /// PLL order 1-3.
    pub order: u8,
    /// Feed-forward.
    pub aiding: Aiding,
    /// INS parameters.
    pub aid: AidParams,
}

impl Cell {
    pub(super) fn config(&self) -> LoopConfig {
        LoopConfig {
            pll_order: self.order,
            pll_bw_hz: self.bn_hz,
            fll_order: 0,
            t_coh_s: self.t_coh_s,
            ..LoopConfig::default()
        }
    }

    /// Whether [`LoopConfig::validate`] accepts this loop (else it is simulated through the
    /// filter directly, if stable).
    pub fn accepted_by_config(&self) -> bool {
        self.config().validate().is_ok()
    }

    /// Whether the digital loop is stable ([`loop_analysis::is_stable`]).
    pub fn is_stable(&self) -> bool {
        LoopFilter::pll(self.order, self.bn_hz)
            .map(|f| loop_analysis::is_stable(&f, self.t_coh_s))
            .unwrap_or(false)
    }

    /// `omega0` of the implemented filter, rad/s.
    pub fn omega0_rad_s(&self) -> f64 {
        omega0(self.order, self.bn_hz)
    }

    /// Time for the transients to decay to `SETTLE_DECAY`: the slowest closed-loop pole radius
    /// `rho` gives `T ln(1/decay)/ln(1/rho)`; the band-limited aid adds `ln(1/decay)/alpha`.
    pub fn settle_s(&self) -> f64 {
        let k = (1.0 / SETTLE_DECAY).ln();
        let t = self.t_coh_s;
        let filter = LoopFilter::pll(self.order, self.bn_hz).ok();
        let rho = filter.and_then(|f| spectral_radius(&f, t)).unwrap_or(1.0);
        let mut s = if rho <= 0.0 {
            5.0 * t
        } else {
            t * k / (-rho.ln())
        };
        if self.aiding == Aiding::BandLimited {
            s = s.max(k / self.aid.alpha_rad_s);
        }
        s.clamp(5.0 * t, MAX_SETTLE_S)
    }

    /// Measurement window length `max(1 s, 50 T)`, s.
    pub fn window_s(&self) -> f64 {
        (50.0 * self.t_coh_s).max(1.0)
    }

    /// The measurement window `(start, end)`, s: a growing cell measures right after its own
    /// settling time (so that its error is still small); a bounded cell runs as long as the
    /// slowest order of its (input, aiding) group and measures over the last window (all curves
    /// of a group then span the same time in the plots).
    pub fn window(&self) -> (f64, f64) {
        let w = self.window_s();
        if matches!(self.closed_form(1.0), ClosedForm::Growing { .. }) {
            let s = self.settle_s();
            (s, s + w)
        } else {
            let end = (1..=3u8)
                .map(|order| Cell { order, ..*self })
                .filter(Cell::is_stable)
                .map(|c| c.settle_s())
                .fold(self.settle_s(), f64::max)
                + w;
            (end - w, end)
        }
    }

    /// The input magnitude of this cell (module docs): the residual `(m, R)` per unit magnitude
    /// (unaided scale `(deg, 1)` except band-limited `deg >= 2`: `(deg - 1, 1/alpha)`) scaled so
    /// that `R/omega0^m = TARGET_ERROR_CYCLES` if `m <= n`, or so that the growing error
    /// `R t_end^p/(p! omega0^n)` reaches `TARGET_END_ERROR_CYCLES` at the window end if `m > n`.
    /// Perfect and biased aiding take the unaided cell's input (the aid cancels it).
    pub fn magnitude(&self) -> f64 {
        if matches!(self.aiding, Aiding::Perfect | Aiding::BiasedIns) {
            let unaided = Cell {
                aiding: Aiding::Unaided,
                ..*self
            };
            return unaided.magnitude();
        }
        let deg = self.input.degree();
        let (m, k) = if self.aiding == Aiding::BandLimited && deg >= 2 {
            (deg - 1, 1.0 / self.aid.alpha_rad_s)
        } else {
            (deg, 1.0)
        };
        let n = u32::from(self.order);
        let w = self.omega0_rad_s();
        let r = if m <= n {
            TARGET_ERROR_CYCLES * w.powi(m as i32)
        } else {
            let p = m - n;
            let t_end = self.window().1;
            let fact = f64::from((1..=p).product::<u32>());
            TARGET_END_ERROR_CYCLES * w.powi(n as i32) * fact / t_end.powi(p as i32)
        };
        r / k
    }

    /// The closed form of this cell at `magnitude`.
    pub fn closed_form(&self, magnitude: f64) -> ClosedForm {
        closed_form(
            self.order,
            self.omega0_rad_s(),
            residual(self.input, self.aiding, magnitude, self.aid),
        )
    }
}
