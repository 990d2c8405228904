//! Digital carrier (PLL, FLL, FLL-assisted PLL) and code (DLL) loop filters.
//!
//! # The analog prototypes (Kaplan & Hegarty Table 5.6, `oracles.md` "Loop filters")
//!
//! | order | omega0 | filter F(s) |
//! |---|---|---|
//! | 1 | Bn/0.25 | `omega0` |
//! | 2 | Bn/0.53 | `a2 omega0 + omega0^2/s`, a2 = 1.414 |
//! | 3 | Bn/0.7845 | `b3 omega0 + a3 omega0^2/s + omega0^3/s^2`, a3 = 1.1, b3 = 2.4 |
//!
//! Seed 004 eqs. (3)-(4) are the same 1st and 2nd-order filters (`omega_n`, `(2 zeta omega_n s +
//! omega_n^2)/s` with `2 zeta = a2`).
//!
//! # The digital realisation (Kaplan Fig. 5.20 block diagrams, Fig. 5.21 integrators)
//!
//! Every `1/s` inside the filter is a **bilinear** (trapezoidal) integrator,
//! `y[k] = y[k-1] + (T/2)(x[k] + x[k-1])`, i.e. `I(z) = (T/2)(1 + z^-1)/(1 - z^-1)`
//! (Kaplan Fig. 5.21b). The integrators are chained as in Kaplan Fig. 5.20:
//!
//! - 3rd order: `x1 = omega0^3 e`, `x2 = I(x1) + a3 omega0^2 e`, `out = I(x2) + b3 omega0 e`;
//! - 2nd order: `x1 = omega0^2 e`, `out = I(x1) + a2 omega0 e`;
//! - 1st order: `out = omega0 e`.
//!
//! An FLL enters the same chain as an *assist* input `e_f` (frequency error, Hz): a 1st-order FLL
//! adds `omega0f e_f` to the input of the last integrator, a 2nd-order FLL adds `omega0f^2 e_f` to
//! the first and `a2 omega0f e_f` to the second (Kaplan Fig. 5.20, FLL-assisted PLL). With no PLL
//! input this is a pure FLL: `out = I(omega0f e_f)` (1st order) or
//! `out = I(a2 omega0f e_f + I(omega0f^2 e_f))` (2nd order): the frequency loop of the table.
//!
//! # Units and what the output drives
//!
//! The output is a **frequency correction for the NCO**: Hz for a carrier loop whose phase error
//! is in cycles and frequency error in Hz; chips/s for a code loop whose error is in chips. The
//! gains are the table's because `omega0 * (cycles) = (cycles/s)`: the loop `NCO = (1/s) F(s)`
//! is unit-free. The NCO itself (the channel's phase accumulator, frequency held over the next
//! interval) is the loop's last integrator; see [`crate::loop_analysis`] for the closed loop it
//! forms and for the measured departure from the analog design as `Bn * T` grows.

use crate::config::{ConfigError, LoopConfig};
use crate::loop_analysis::TransferFunction;

/// `Bn / omega0` of the 1st, 2nd and 3rd-order loops (Kaplan Table 5.6).
pub const BN_OVER_OMEGA0: [f64; 3] = [0.25, 0.53, 0.7845];
/// 2nd-order damping coefficient a2 (= 2 zeta, zeta = 0.707; Kaplan Table 5.6).
pub const A2: f64 = 1.414;
/// 3rd-order coefficient a3 (Kaplan Table 5.6).
pub const A3: f64 = 1.1;
/// 3rd-order coefficient b3 (Kaplan Table 5.6).
pub const B3: f64 = 2.4;

/// Natural radian frequency omega0 (rad/s) of a loop of `order` (1-3) with noise bandwidth
/// `bn_hz` (Kaplan Table 5.6: omega0 = Bn/0.25, Bn/0.53, Bn/0.7845).
pub fn omega0(order: u8, bn_hz: f64) -> f64 {
    let idx = usize::from(order.clamp(1, 3)) - 1;
    bn_hz / BN_OVER_OMEGA0[idx]
}

/// A digital loop filter with up to two bilinear integrators, a primary (phase or code) error
/// input and an optional assist (FLL frequency) input.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopFilter {
    /// Number of integrators in the chain (0, 1 or 2).
    n_int: usize,
    /// Gains into each integrator's input: `[primary, assist]`, innermost first.
    stage: [[f64; 2]; 2],
    /// Proportional gain of the primary error at the output.
    k_out: f64,
    /// Integrator outputs.
    y: [f64; 2],
    /// Integrator inputs at the previous update (bilinear rule).
    x_prev: [f64; 2],
    /// Whether the assist input is used (the FLL can be switched off once the PLL is locked).
    assist_on: bool,
}

impl LoopFilter {
    fn empty() -> Self {
        Self {
            n_int: 0,
            stage: [[0.0; 2]; 2],
            k_out: 0.0,
            y: [0.0; 2],
            x_prev: [0.0; 2],
            assist_on: true,
        }
    }

    /// The standard `order` (1-3) filter of noise bandwidth `bn_hz` without range checks.
    pub(crate) fn standard_unchecked(order: u8, bn_hz: f64) -> Self {
        let w = omega0(order, bn_hz);
        let mut f = Self::empty();
        match order {
            0 | 1 => f.k_out = w,
            2 => {
                f.n_int = 1;
                f.stage[0][0] = w * w;
                f.k_out = A2 * w;
            }
            _ => {
                f.n_int = 2;
                f.stage[0][0] = w * w * w;
                f.stage[1][0] = A3 * w * w;
                f.k_out = B3 * w;
            }
        }
        f
    }

    /// Adds an FLL of `order` (1-2) and bandwidth `bn_hz` on the assist input, without checks.
    fn with_fll_unchecked(mut self, order: u8, bn_hz: f64) -> Self {
        let w = omega0(order, bn_hz);
        if order <= 1 {
            // Into the last integrator's input.
            self.n_int = self.n_int.max(1);
            let last = self.n_int - 1;
            self.stage[last][1] = w;
        } else {
            self.n_int = 2;
            self.stage[0][1] = w * w;
            self.stage[1][1] = A2 * w;
        }
        self
    }

    /// The carrier filter of a configuration, assuming it has been validated.
    pub(crate) fn carrier_unchecked(cfg: &LoopConfig) -> Self {
        let base = if cfg.pll_order == 0 {
            Self::empty()
        } else {
            Self::standard_unchecked(cfg.pll_order, cfg.pll_bw_hz)
        };
        if cfg.fll_order == 0 {
            base
        } else {
            base.with_fll_unchecked(cfg.fll_order, cfg.fll_bw_hz)
        }
    }

    fn check_order(field: &'static str, order: u8, max: u8) -> Result<(), ConfigError> {
        if (1..=max).contains(&order) {
            Ok(())
        } else {
            Err(ConfigError::BadOrder {
                field,
                value: order,
                valid: if max == 3 { "1, 2, 3" } else { "1, 2" },
            })
        }
    }

    fn check_bw(field: &'static str, bn_hz: f64) -> Result<(), ConfigError> {
        if bn_hz.is_finite() && bn_hz > 0.0 {
            Ok(())
        } else {
            Err(ConfigError::OutOfRange {
                field,
                value: bn_hz,
                valid: "a finite bandwidth > 0 Hz".to_string(),
            })
        }
    }

    /// A PLL filter of `order` 1-3 and noise bandwidth `bn_hz` (input: phase error in cycles;
    /// output: NCO frequency correction in Hz).
    pub fn pll(order: u8, bn_hz: f64) -> Result<Self, ConfigError> {
        Self::check_order("pll_order", order, 3)?;
        Self::check_bw("pll_bw_hz", bn_hz)?;
        Ok(Self::standard_unchecked(order, bn_hz))
    }

    /// A DLL filter of `order` 1-2 and noise bandwidth `bn_hz` (input: code phase error in chips;
    /// output: code NCO rate correction in chips/s). The same table and structure as the PLL.
    pub fn dll(order: u8, bn_hz: f64) -> Result<Self, ConfigError> {
        Self::check_order("dll_order", order, 2)?;
        Self::check_bw("dll_bw_hz", bn_hz)?;
        Ok(Self::standard_unchecked(order, bn_hz))
    }

    /// A pure FLL of `order` 1-2 (input: frequency error in Hz on the assist input; output: NCO
    /// frequency correction in Hz).
    pub fn fll(order: u8, bn_hz: f64) -> Result<Self, ConfigError> {
        Self::check_order("fll_order", order, 2)?;
        Self::check_bw("fll_bw_hz", bn_hz)?;
        Ok(Self::empty().with_fll_unchecked(order, bn_hz))
    }

    /// An FLL-assisted PLL (Kaplan Fig. 5.20): `(pll_order, fll_order)` = (2, 1) or (3, 2).
    pub fn fll_assisted_pll(
        pll_order: u8,
        pll_bw_hz: f64,
        fll_order: u8,
        fll_bw_hz: f64,
    ) -> Result<Self, ConfigError> {
        if !matches!((pll_order, fll_order), (2, 1) | (3, 2)) {
            return Err(ConfigError::Combination {
                pll_order,
                fll_order,
            });
        }
        Self::check_bw("pll_bw_hz", pll_bw_hz)?;
        Self::check_bw("fll_bw_hz", fll_bw_hz)?;
        Ok(Self::standard_unchecked(pll_order, pll_bw_hz).with_fll_unchecked(fll_order, fll_bw_hz))
    }

    /// The carrier-loop filter of a configuration (validated first).
    pub fn carrier(cfg: &LoopConfig) -> Result<Self, ConfigError> {
        cfg.validate()?;
        Ok(Self::carrier_unchecked(cfg))
    }

    /// The code-loop filter of a configuration (validated first).
    pub fn code(cfg: &LoopConfig) -> Result<Self, ConfigError> {
        cfg.validate()?;
        Ok(Self::standard_unchecked(cfg.dll_order, cfg.dll_bw_hz))
    }

    /// One update after an integration interval of `t_s` seconds.
    ///
    /// `primary_err`: phase error (cycles) or code error (chips); `assist_err`: FLL frequency error
    /// (Hz), ignored when the filter has no FLL or the assist is switched off. Returns the NCO
    /// correction (Hz or chips/s) to hold over the next interval. Non-finite errors are treated as
    /// zero so that one bad correlation cannot poison the integrators.
    pub fn update(&mut self, primary_err: f64, assist_err: f64, t_s: f64) -> f64 {
        let ep = if primary_err.is_finite() {
            primary_err
        } else {
            0.0
        };
        let ef = if assist_err.is_finite() && self.assist_on {
            assist_err
        } else {
            0.0
        };
        let t = if t_s.is_finite() && t_s > 0.0 {
            t_s
        } else {
            0.0
        };
        let mut carry = 0.0;
        for i in 0..self.n_int {
            let x = carry + self.stage[i][0] * ep + self.stage[i][1] * ef;
            // Bilinear integrator, Kaplan Fig. 5.21(b).
            self.y[i] += 0.5 * t * (x + self.x_prev[i]);
            self.x_prev[i] = x;
            carry = self.y[i];
        }
        carry + self.k_out * ep
    }

    /// Presets the inner integrator of a two-integrator filter (a 3rd-order PLL's frequency-rate
    /// memory, Hz/s) so that a loop started mid-track does not have to learn the rate through a
    /// ringing transient. No effect on filters with fewer than two integrators.
    pub fn preset_rate(&mut self, rate: f64) {
        if self.n_int == 2 && rate.is_finite() {
            self.y[0] = rate;
            self.x_prev[1] = rate;
        }
    }

    /// The rate memory of a two-integrator filter (a 3rd-order PLL's Doppler rate, Hz/s, held
    /// by its inner integrator); `None` for filters with fewer integrators.
    pub fn rate_memory(&self) -> Option<f64> {
        (self.n_int == 2).then_some(self.y[0])
    }

    /// Moves the rate memory of a two-integrator filter by `delta` (Hz/s): when a
    /// feed-forward starts supplying a Doppler rate the loop had learned (or stops), the loop
    /// must stop (or start) holding it. No effect on filters with fewer integrators.
    pub fn shift_rate(&mut self, delta: f64) {
        if self.n_int == 2 && delta.is_finite() {
            self.y[0] += delta;
            self.x_prev[1] += delta;
        }
    }

    /// Forgets the last error input: the bilinear integrators would otherwise add half of it
    /// once more at the next update. Before a stretch of zero-error updates (a coast), so
    /// that they hold the memories exactly (a 20 ms 3rd-order loop's last noisy input carried
    /// on as 8 Hz/s of Doppler rate).
    pub fn forget_input(&mut self) {
        let mut carry = 0.0;
        for i in 0..self.n_int {
            self.x_prev[i] = carry;
            carry = self.y[i];
        }
    }

    /// Clears the integrators.
    pub fn reset(&mut self) {
        self.y = [0.0; 2];
        self.x_prev = [0.0; 2];
    }

    /// Whether the filter has an integrator (order >= 2, or an FLL assist).
    pub fn has_integrator(&self) -> bool {
        self.n_int > 0
    }

    /// The last integrator's output (the filter's frequency or rate memory), Hz or chips/s; zero
    /// for a 1st-order loop.
    pub fn integrator(&self) -> f64 {
        if self.n_int == 0 {
            0.0
        } else {
            self.y[self.n_int - 1]
        }
    }

    /// Whether the filter has an FLL (assist) input.
    pub fn has_assist(&self) -> bool {
        self.stage.iter().any(|s| s[1] != 0.0)
    }

    /// Whether the filter has a PLL/DLL (primary) input.
    pub fn has_primary(&self) -> bool {
        self.k_out != 0.0
    }

    /// Switches the FLL assist on or off, keeping the integrators (bumpless hand-over to the PLL
    /// once phase lock is detected).
    pub fn set_assist_enabled(&mut self, on: bool) {
        self.assist_on = on;
    }

    /// Whether the assist input is in use.
    pub fn assist_enabled(&self) -> bool {
        self.assist_on && self.has_assist()
    }

    /// The z-transfer functions of the filter, `(primary -> output, assist -> output)`, as
    /// polynomials in `z^-1` for an update interval `t_s`, exactly what [`Self::update`] computes.
    pub fn transfer_functions(&self, t_s: f64) -> (TransferFunction, TransferFunction) {
        let integ = TransferFunction::bilinear_integrator(t_s);
        let mut tf = [
            TransferFunction::constant(0.0),
            TransferFunction::constant(0.0),
        ];
        for (col, tf_col) in tf.iter_mut().enumerate() {
            let gain = if col == 1 && !self.assist_on {
                0.0
            } else {
                1.0
            };
            let mut carry = TransferFunction::constant(0.0);
            for i in 0..self.n_int {
                let x = carry.add(&TransferFunction::constant(gain * self.stage[i][col]));
                carry = x.mul(&integ);
            }
            let out = if col == 0 { self.k_out } else { 0.0 };
            *tf_col = carry.add(&TransferFunction::constant(out));
        }
        let [p, f] = tf;
        (p, f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn after_forget_input_zero_errors_hold_the_memories_exactly() {
        let t = 0.02;
        for order in [2u8, 3] {
            let mut f = LoopFilter::pll(order, 6.0).unwrap_or_else(|e| panic!("{e}"));
            for k in 0..50 {
                f.update(if k % 3 == 0 { 0.2 } else { -0.1 }, 0.0, t);
            }
            f.update(0.25, 0.0, t); // a last noisy error
            f.preset_rate(0.0);
            f.forget_input();
            let before = f.integrator();
            for _ in 0..150 {
                assert_eq!(f.update(0.0, 0.0, t), f.integrator());
            }
            assert!(
                (f.integrator() - before).abs() < 1e-12,
                "order {order}: memory moved from {before} to {}",
                f.integrator()
            );
        }
    }
    use num_complex::Complex64;

    /// `update` and `transfer_functions` describe the same filter: drive both with the same
    /// sequence (difference equation from the polynomials) and compare.
    #[test]
    fn update_matches_its_transfer_function() {
        let filters = [
            LoopFilter::pll(1, 10.0),
            LoopFilter::pll(2, 10.0),
            LoopFilter::pll(3, 10.0),
            LoopFilter::fll(1, 5.0),
            LoopFilter::fll(2, 5.0),
            LoopFilter::fll_assisted_pll(2, 10.0, 1, 4.0),
            LoopFilter::fll_assisted_pll(3, 12.0, 2, 6.0),
        ];
        let t = 2.0e-3;
        for f in filters.into_iter().flatten() {
            let (hp, hf) = f.transfer_functions(t);
            let mut g = f.clone();
            let ep: Vec<f64> = (0..50)
                .map(|k| ((k * 7919) % 13) as f64 * 0.01 - 0.06)
                .collect();
            let ef: Vec<f64> = (0..50)
                .map(|k| ((k * 104_729) % 11) as f64 * 0.3 - 1.5)
                .collect();
            let (yp, yf) = (hp.filter(&ep), hf.filter(&ef));
            let want: Vec<f64> = yp.iter().zip(&yf).map(|(a, b)| a + b).collect();
            for k in 0..50 {
                let got = g.update(ep[k], ef[k], t);
                assert!(
                    (got - want[k]).abs() < 1e-9 * (1.0 + want[k].abs()),
                    "{k}: {got} vs {}",
                    want[k]
                );
            }
        }
    }

    #[test]
    fn high_frequency_gain_is_the_proportional_gain() {
        // At z = 1 (DC) the integrators blow up; at z = -1 (Nyquist) the bilinear integrator is
        // zero, so F(-1) = the output gain: a2 omega0 for order 2.
        let f = LoopFilter::pll(2, 10.0).ok();
        let (hp, _) = f.map(|f| f.transfer_functions(1e-3)).unzip();
        let v = hp
            .map(|h| h.eval(Complex64::new(-1.0, 0.0)).re)
            .unwrap_or(0.0);
        assert!((v - A2 * 10.0 / 0.53).abs() < 1e-9);
    }

    #[test]
    fn non_finite_errors_do_not_poison_the_state() {
        let Ok(mut f) = LoopFilter::fll_assisted_pll(3, 10.0, 2, 5.0) else {
            panic!("valid filter")
        };
        f.update(0.01, 1.0, 1e-3);
        let out = f.update(f64::NAN, f64::INFINITY, 1e-3);
        assert!(out.is_finite());
        assert!(f.update(0.0, 0.0, f64::NAN).is_finite());
        assert!(f.integrator().is_finite());
    }

    #[test]
    fn rejects_bad_orders() {
        assert!(LoopFilter::pll(0, 1.0).is_err());
        assert!(LoopFilter::pll(4, 1.0).is_err());
        assert!(LoopFilter::dll(3, 1.0).is_err());
        assert!(LoopFilter::fll(3, 1.0).is_err());
        assert!(LoopFilter::fll_assisted_pll(3, 1.0, 1, 1.0).is_err());
        assert!(LoopFilter::pll(2, -1.0).is_err());
    }
}
