//! The DLL sweep: code jitter of the receiver's carrier-aided code loop ([`CodeLoop`]: the
//! normalised early-minus-late envelope discriminator, d = 1 chip, the loop filter of its order
//! and Bn) at the level of 1 ms correlator outputs, against theory.
//!
//! # Model
//!
//! The carrier is tracked and the code aided by it, so the code loop sees only noise: the true
//! code phase is fixed, the replica moves by the DLL's correction `r_k` (chips/s) held over
//! interval k, and the code error (signal minus replica, chips) is `e`. Each 1 ms period gives
//! `E = A d R(d/2 - e) + n_E`, `P = A d R(e) + n_P`, `L = A d R(d/2 + e) + n_L` with the ideal
//! triangle `R(x) = max(0, 1 - |x|)`, `A = sqrt(2 CN0 1 ms)`, a data bit `d` per 20 ms and
//! complex Gaussian noise of unit variance per component correlated as the triangle at the
//! taps' separations (`R(d/2)` between neighbours, `R(d)` between E and L). `T` periods are
//! summed into [`CodeLoop::update`]. The RMS of `e` at the interval starts over 30 s after a
//! settling time is the measured jitter.
//!
//! # Theory
//!
//! - The oracle (Kaplan eq. 5.8 for non-coherent early-minus-late *power*, oracles.md "Noise"):
//!   `sigma = sqrt((Bn d/(2 CN0))(1 + 2/(T CN0 (2 - d))))` chips ([`dll_jitter_chips`]).
//! - The receiver's own discriminator: the envelope's slope `s` and output variance at the
//!   prompt SNR ([`envelope_dll_stats`]) through the linearised digital loop
//!   ([`LoopNoiseGains`] with slope `s`): `sigma^2 = var(D) sum h^2`. Its squaring loss is
//!   smaller than the power discriminator's, so below about 35 dB-Hz at T = 1 ms the oracle
//!   over-states the jitter; this is the theory the measurement must match.

use super::params::WINDOW_S;
use crate::bandwidth::{dll_jitter_chips, envelope_dll_stats, LoopNoiseGains};
use crate::report::{fmt, Table};
use gpsrx_tracking::phase_sim::{NoiseSource, SimRng};
use gpsrx_tracking::{CodeLoop, LoopConfig, LoopFilter};
use num_complex::Complex64;
use std::fmt::Write as _;

/// Early-late spacing of the sweep, chips (the receiver's default).
pub const DLL_SPACING_CHIPS: f64 = 1.0;
/// Settling time before the 30 s window, s (the slowest loop, 0.5 Hz, decays by `e^-6` in it).
pub const DLL_SETTLE_S: f64 = 3.0;
/// Measured and theoretical jitter agree within this fraction.
pub const DLL_TOLERANCE: f64 = 0.2;

/// One point of the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DllPoint {
    /// DLL order, 1-2.
    pub order: u8,
    /// DLL noise bandwidth, Hz.
    pub bn_hz: f64,
    /// Integration time, ms.
    pub t_coh_ms: u32,
    /// C/N0, dB-Hz.
    pub cn0_dbhz: f64,
}

/// A point's result, chips.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DllResult {
    /// The point.
    pub point: DllPoint,
    /// Measured RMS code error.
    pub measured_chips: f64,
    /// The oracle formula.
    pub formula_chips: f64,
    /// The envelope discriminator through the linearised digital loop.
    pub loop_chips: f64,
    /// The envelope discriminator's slope at the point's prompt SNR.
    pub slope: f64,
}

impl DllResult {
    /// Within [`DLL_TOLERANCE`] of the loop theory.
    pub fn agrees(&self) -> bool {
        (self.measured_chips / self.loop_chips - 1.0).abs() <= DLL_TOLERANCE
    }
}

/// The sweep's points: orders 1-2, Bn 0.5, 1 and 2 Hz, T 1 and 20 ms, C/N0 25-45 dB-Hz
/// (`quick`: Bn 1 Hz at 30 and 45 dB-Hz).
pub fn dll_points(quick: bool) -> Vec<DllPoint> {
    let (bns, cn0s): (&[f64], &[f64]) = if quick {
        (&[1.0], &[30.0, 45.0])
    } else {
        (&[0.5, 1.0, 2.0], &[25.0, 30.0, 35.0, 45.0])
    };
    let mut v = Vec::new();
    for order in [1u8, 2] {
        for &bn_hz in bns {
            for t_coh_ms in [1u32, 20] {
                for &cn0_dbhz in cn0s {
                    v.push(DllPoint {
                        order,
                        bn_hz,
                        t_coh_ms,
                        cn0_dbhz,
                    });
                }
            }
        }
    }
    v
}

/// The lower-triangular factor `[[1,0,0],[a,b,0],[0? ..]]` of the E, P, L noise covariance
/// `[[1, r1, r2], [r1, 1, r1], [r2, r1, 1]]` (`r1 = R(d/2)`, `r2 = R(d)`), rows E, P, L.
fn noise_factor(d: f64) -> [[f64; 3]; 3] {
    let tri = |x: f64| (1.0 - x.abs()).max(0.0);
    let (r1, r2) = (tri(d / 2.0), tri(d));
    let l21 = r1;
    let l22 = (1.0 - r1 * r1).sqrt();
    let l31 = r2;
    let l32 = (r1 - l31 * l21) / l22;
    let l33 = (1.0 - l31 * l31 - l32 * l32).max(0.0).sqrt();
    [[1.0, 0.0, 0.0], [l21, l22, 0.0], [l31, l32, l33]]
}

/// Runs one point with noise from `seed`: the measured RMS code error, chips.
///
/// Errors: the receiver refuses the loop.
pub fn run_dll(p: &DllPoint, seed: u64) -> anyhow::Result<f64> {
    let d = DLL_SPACING_CHIPS;
    let t_s = f64::from(p.t_coh_ms) * 1e-3;
    let cfg = LoopConfig {
        pll_order: 2,
        pll_bw_hz: 1.0,
        fll_order: 0,
        fll_bw_hz: 0.0,
        dll_order: p.order,
        dll_bw_hz: p.bn_hz,
        t_coh_s: t_s,
        el_spacing_chips: d,
        ..LoopConfig::default()
    };
    let mut code = CodeLoop::new(&cfg)?;
    let chol = noise_factor(d);
    let tri = |x: f64| (1.0 - x.abs()).max(0.0);
    let amp = (2.0 * 10f64.powf(p.cn0_dbhz / 10.0) * 1e-3).sqrt();
    let mut rng = SimRng::new(seed);
    let t_ms = p.t_coh_ms.max(1) as usize;
    let settle = (DLL_SETTLE_S * 1e3) as usize;
    let n_ms = settle + (WINDOW_S * 1e3) as usize;
    let (mut e, mut r) = (0.0_f64, 0.0_f64);
    let mut acc = [Complex64::new(0.0, 0.0); 3];
    let mut bit = 1.0;
    let (mut sum2, mut n) = (0.0, 0usize);
    for k in 0..n_ms {
        if k % 20 == 0 {
            bit = if rng.data_bit() { 1.0 } else { -1.0 };
        }
        if k % t_ms == 0 && k >= settle {
            sum2 += e * e;
            n += 1;
        }
        let em = e - 0.5 * r * 1e-3;
        let g: [Complex64; 3] = std::array::from_fn(|_| {
            let re = rng.gauss();
            Complex64::new(re, rng.gauss())
        });
        let sig = [tri(d / 2.0 - em), tri(em), tri(d / 2.0 + em)];
        for i in 0..3 {
            let noise = chol[i][0] * g[0] + chol[i][1] * g[1] + chol[i][2] * g[2];
            acc[i] += amp * bit * sig[i] + noise;
        }
        e -= r * 1e-3;
        if (k + 1) % t_ms == 0 {
            let [ea, pa, la] = acc;
            r = code.update(ea, pa, la, 0.0).dll_chips_s;
            acc = [Complex64::new(0.0, 0.0); 3];
        }
    }
    Ok((sum2 / n.max(1) as f64).sqrt())
}

/// The theory of a point: (oracle formula, envelope through the linearised loop, chips; the
/// envelope's slope).
pub fn dll_theory(p: &DllPoint) -> (f64, f64, f64) {
    let t_s = f64::from(p.t_coh_ms) * 1e-3;
    let formula = dll_jitter_chips(p.bn_hz, DLL_SPACING_CHIPS, p.cn0_dbhz, t_s);
    let stats = envelope_dll_stats(p.cn0_dbhz, t_s, DLL_SPACING_CHIPS);
    let lin = LoopFilter::dll(p.order, p.bn_hz)
        .map(|f| {
            let g = LoopNoiseGains::new(f, p.bn_hz, t_s, stats.slope);
            (stats.noise_var * g.phase_gain()).sqrt()
        })
        .unwrap_or(f64::NAN);
    (formula, lin, stats.slope)
}

/// The sweep's table (`dll.csv`).
pub fn dll_table(results: &[DllResult]) -> Table {
    let mut t = Table::new(&[
        "order",
        "bn_hz",
        "t_coh_ms",
        "cn0_dbhz",
        "measured_chips",
        "loop_theory_chips",
        "formula_chips",
        "measured_over_loop",
        "measured_over_formula",
        "within_20pct",
    ]);
    for r in results {
        let p = &r.point;
        t.push(vec![
            p.order.to_string(),
            fmt(p.bn_hz, 1),
            p.t_coh_ms.to_string(),
            fmt(p.cn0_dbhz, 1),
            fmt(r.measured_chips, 4),
            fmt(r.loop_chips, 4),
            fmt(r.formula_chips, 4),
            fmt(r.measured_chips / r.loop_chips, 2),
            fmt(r.measured_chips / r.formula_chips, 2),
            if r.agrees() { "yes" } else { "no" }.into(),
        ]);
    }
    t
}

/// The sweep's section of the report (Markdown), with conclusions computed from `results`.
pub fn dll_md(results: &[DllResult]) -> String {
    let n = results.len();
    let agree = results.iter().filter(|r| r.agrees()).count();
    let within_formula = results
        .iter()
        .filter(|r| (r.measured_chips / r.formula_chips - 1.0).abs() <= DLL_TOLERANCE)
        .count();
    let mut s = format!(
        "\n## DLL: code jitter against theory\n\nThe receiver's carrier-aided DLL (normalised \
         early-minus-late envelope, d = {} chip) at the level of 1 ms correlator outputs \
         (noise-only: the carrier tracked, the code aided), RMS code error over {} s after {} s \
         of settling, against the envelope discriminator's own statistics through the \
         linearised digital loop (`loop_theory_chips`) and the oracle formula for \
         early-minus-late power (`formula_chips`). Also in `dll.csv`.\n\n",
        fmt(DLL_SPACING_CHIPS, 0),
        fmt(WINDOW_S, 0),
        fmt(DLL_SETTLE_S, 0)
    );
    s += &dll_table(results).to_markdown();
    let _ = write!(
        s,
        "\n- **{agree} of {n} points within {:.0} % of the loop theory**; {within_formula} of {n} \
         within {:.0} % of the formula.",
        100.0 * DLL_TOLERANCE,
        100.0 * DLL_TOLERANCE
    );
    let worst = results.iter().max_by(|a, b| {
        a.formula_chips
            .total_cmp(&(b.formula_chips * a.measured_chips / b.measured_chips))
    });
    if let Some(w) = worst.filter(|w| w.measured_chips < w.formula_chips * (1.0 - DLL_TOLERANCE)) {
        let _ = write!(
            s,
            " The formula over-states the jitter most at order {}, Bn {} Hz, T {} ms, {} dB-Hz \
             (measured {} of it): the envelope discriminator's squaring loss is smaller than the \
             power discriminator's the formula assumes.",
            w.point.order,
            fmt(w.point.bn_hz, 1),
            w.point.t_coh_ms,
            fmt(w.point.cn0_dbhz, 0),
            fmt(w.measured_chips / w.formula_chips, 2)
        );
    }
    for r in results.iter().filter(|r| !r.agrees()) {
        let t_s = f64::from(r.point.t_coh_ms) * 1e-3;
        let snr_db = r.point.cn0_dbhz + 10.0 * t_s.log10();
        // The loop's gain, and with it its bandwidth, scale with the slope: its error
        // decorrelates over about 1/(4 Bn s), so the window holds this many independent values.
        let independent = WINDOW_S * 4.0 * r.point.bn_hz * r.slope;
        let _ = write!(
            s,
            "\n- Order {}, Bn {} Hz, T {} ms, {} dB-Hz: measured {} chip, {} of the loop theory; \
             prompt SNR {} dB, envelope slope {}{}; the window holds about {} independent \
             values of the error ({}).",
            r.point.order,
            fmt(r.point.bn_hz, 1),
            r.point.t_coh_ms,
            fmt(r.point.cn0_dbhz, 0),
            fmt(r.measured_chips, 4),
            fmt(r.measured_chips / r.loop_chips, 2),
            fmt(snr_db, 1),
            fmt(r.slope, 2),
            if r.slope < 0.5 {
                " (the linearisation of a bounded discriminator is least reliable there)"
            } else {
                ""
            },
            fmt(independent, 0),
            if independent < 30.0 {
                "too few for a 20 % estimate"
            } else {
                "enough for a 20 % estimate"
            }
        );
    }
    s + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The noise factor reproduces the triangle's covariances: for d = 1, E-P 0.5, E-L 0, P-L
    /// 0.5.
    #[test]
    fn noise_factor_gives_the_tap_covariances() {
        let l = noise_factor(1.0);
        let cov = |i: usize, j: usize| (0..3).map(|k| l[i][k] * l[j][k]).sum::<f64>();
        for (i, j, want) in [
            (0, 0, 1.0),
            (1, 1, 1.0),
            (2, 2, 1.0),
            (0, 1, 0.5),
            (0, 2, 0.0),
            (1, 2, 0.5),
        ] {
            assert!((cov(i, j) - want).abs() < 1e-12, "{i}{j}");
        }
    }

    /// At 45 dB-Hz, Bn 1 Hz, T = 1 ms the measured jitter is the formula's value within 20 %:
    /// `sqrt(Bn d/(2 CN0)) sqrt(1 + 2/(T CN0 (2 - d)))` = 0.003976 * 1.0311 = 0.0041 chip.
    #[test]
    fn high_cn0_jitter_matches_the_formula() -> anyhow::Result<()> {
        let p = DllPoint {
            order: 1,
            bn_hz: 1.0,
            t_coh_ms: 1,
            cn0_dbhz: 45.0,
        };
        let m = run_dll(&p, 7)?;
        let (formula, lin, _) = dll_theory(&p);
        assert!((formula - 0.0041).abs() < 0.00005, "{formula}");
        assert!((m / formula - 1.0).abs() < 0.2, "{m} vs {formula}");
        assert!((m / lin - 1.0).abs() < 0.2, "{m} vs {lin}");
        Ok(())
    }
}
