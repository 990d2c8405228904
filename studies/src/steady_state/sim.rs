//! Running one cell's loop on its phase-domain input and measuring the steady state or growth
//! rate.

use anyhow::Context;
use gpsrx_tracking::loop_filter::LoopFilter;
use gpsrx_tracking::phase_sim::{self, NcoStart, Signal, SimRng, Step};
use gpsrx_tracking::{discriminator, CarrierLoop};

use super::aid::Aid;
use super::fit::{eval_fit, polyfit};
use super::{agrees, Cell, ClosedForm};

// Targets of intra-doc links.
#[cfg(doc)]
use super::Input;
#[cfg(doc)]
use gpsrx_tracking::LoopConfig;

/// Points per plotted curve.
const PLOT_POINTS: usize = 250;

/// The measured outcome of one cell.
#[derive(Debug, Clone)]
pub struct CellResult {
    /// The cell.
    pub cell: Cell,
    /// Input magnitude, in [`Input::unit`].
    pub magnitude: f64,
    /// The closed form.
    pub closed: ClosedForm,
    /// Measured value comparable with [`ClosedForm::value`]: the mean error over the window
    /// (bounded) or the fitted `d^p e/dt^p` (growing).
    pub measured: f64,
    /// Bounded cells: the fitted error at the window's start and end, cycles.
    pub window_ends_cycles: (f64, f64),
    /// Measurement window, s.
    pub window: (f64, f64),
    /// Largest |error| over the run, cycles.
    pub max_abs_error_cycles: f64,
    /// Whether measurement and closed form agree ([`agrees`]).
    pub agree: bool,
    /// (t, error) at interval centres, decimated to about `PLOT_POINTS`.
    pub trace: Vec<(f64, f64)>,
    /// Polynomial fitted over the window: coefficients of `(t - t_c)^i` and `t_c`.
    pub fit: (Vec<f64>, f64),
}

/// The loop under test: [`CarrierLoop`] when [`LoopConfig`] accepts the cell's loop; beyond its
/// `Bn T` limit, the same computation spelled out (Costas atan discriminator into the PLL
/// [`LoopFilter`], NCO = feed-forward + filter output) as long as the digital loop is stable.
#[derive(Debug)]
enum Pll {
    Carrier(CarrierLoop),
    Filter(LoopFilter, f64),
}

impl Pll {
    fn new(cell: &Cell) -> anyhow::Result<Self> {
        let what = || format!("PLL order {} at Bn {} Hz", cell.order, cell.bn_hz);
        if cell.accepted_by_config() {
            return Ok(Pll::Carrier(
                CarrierLoop::new(&cell.config(), 0.0).with_context(what)?,
            ));
        }
        let f = LoopFilter::pll(cell.order, cell.bn_hz).with_context(what)?;
        if !cell.is_stable() {
            anyhow::bail!("{} is unstable at T = {} s", what(), cell.t_coh_s);
        }
        Ok(Pll::Filter(f, cell.t_coh_s))
    }

    /// NCO frequency (Hz) for the next interval from this prompt and feed-forward.
    fn update(&mut self, prompt: num_complex::Complex64, ff_hz: f64) -> f64 {
        match self {
            Pll::Carrier(c) => c.update(prompt, ff_hz).nco_freq_hz,
            Pll::Filter(f, t) => ff_hz + f.update(discriminator::costas_atan(prompt), 0.0, *t),
        }
    }
}

/// Runs one cell in closed loop (module docs) and measures it.
pub fn simulate(cell: &Cell) -> anyhow::Result<CellResult> {
    let mut pll = Pll::new(cell)?;
    let magnitude = cell.magnitude();
    let closed = cell.closed_form(magnitude);
    let traj = cell.input.trajectory(magnitude);
    let t = cell.t_coh_s;
    let window = cell.window();
    let n = (window.1 / t).ceil() as usize;
    let mut aid = Aid::new(&traj, cell);
    let start = NcoStart {
        phase_cycles: 0.0,
        freq_hz: aid.next(0.0),
    };
    let steps: Vec<Step> = phase_sim::run_with(
        &traj,
        Signal::clean(),
        t,
        n,
        start,
        &mut SimRng::new(0),
        |s| pll.update(s.prompt, aid.next(s.t0 + t)),
    );
    let pts: Vec<(f64, f64)> = steps
        .iter()
        .map(|s| (s.t0 + 0.5 * t, s.err_cycles))
        .collect();
    let in_window: Vec<(f64, f64)> = pts.iter().copied().filter(|p| p.0 >= window.0).collect();
    let deg = match closed {
        ClosedForm::Bounded(_) | ClosedForm::Growing { p: 1, .. } => 1,
        ClosedForm::Growing { .. } => 2,
    };
    let fit = polyfit(&in_window, deg);
    let ends = (eval_fit(&fit, window.0), eval_fit(&fit, window.1));
    let (measured, agree) = match closed {
        ClosedForm::Bounded(c) => {
            let m = phase_sim::mean(&in_window.iter().map(|p| p.1).collect::<Vec<_>>());
            (m, agrees(c, m) && agrees(c, ends.0) && agrees(c, ends.1))
        }
        ClosedForm::Growing { p, rate } => {
            let m = fit.0[p as usize] * f64::from((1..=p).product::<u32>());
            (m, agrees(rate, m))
        }
    };
    let stride = pts.len().div_ceil(PLOT_POINTS).max(1);
    Ok(CellResult {
        cell: *cell,
        magnitude,
        closed,
        measured,
        window_ends_cycles: ends,
        window,
        max_abs_error_cycles: pts.iter().fold(0.0, |m, p| m.max(p.1.abs())),
        agree,
        trace: pts.iter().step_by(stride).copied().collect(),
        fit,
    })
}
