//! Receiver autonomous integrity monitoring: chi-square fault detection and single-fault
//! exclusion (Kaplan & Hegarty 2nd ed. 7.5; the residual test of Sturza / Brown).
//!
//! Detection: the weighted residual sum of squares e^T P e of the fix is chi-square
//! distributed with n - 4 degrees of freedom when the a-priori sigmas are right and no
//! measurement is faulty. A fault is declared when it exceeds the (1 - pfa) quantile. This
//! needs n >= 5 observations (satellites + landmarks).
//!
//! Exclusion (n >= 6): the satellite with the largest normalised residual
//! |e_i| / sqrt((Q_e)_ii), Q_e = P^-1 - A N^-1 A^T (Baarda's w-test), is removed, the fix
//! recomputed and re-tested; if it passes, that satellite is reported as excluded, otherwise
//! the fault is detected but not excluded and the full solution is returned. Landmarks are
//! never excluded.

use super::wls::{solve_position, Context, Fix, N_UNKNOWNS};
use super::PvtError;
use nalgebra::{SMatrix, SVector};

/// Integrity status of a solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RaimStatus {
    /// The residual test passed.
    Ok,
    /// A fault was detected and removing this PRN made the test pass.
    FaultExcluded {
        /// The excluded satellite.
        prn: u8,
    },
    /// A fault was detected but could not be excluded (n = 5, or the test still failed).
    FaultDetectedNotExcluded,
    /// No redundancy (n = 4): integrity cannot be checked.
    Unavailable,
    /// RAIM switched off in the options.
    Disabled,
}

/// ln Gamma(x) for x > 0: the recurrence Gamma(x) = Gamma(x + 1)/x moves x to >= 10, then
/// Stirling's series to the x^-7 term (truncation error < 1e-12).
fn ln_gamma(x: f64) -> f64 {
    let mut x = x;
    let mut shift = 0.0;
    while x < 10.0 {
        shift -= x.ln();
        x += 1.0;
    }
    let x2 = x * x;
    let series = 1.0 / (12.0 * x) - 1.0 / (360.0 * x * x2) + 1.0 / (1260.0 * x * x2 * x2)
        - 1.0 / (1680.0 * x * x2 * x2 * x2);
    shift + (x - 0.5) * x.ln() - x + 0.5 * (2.0 * std::f64::consts::PI).ln() + series
}

/// Regularised upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a), a > 0, x >= 0.
/// For x < a + 1 the power series of the lower function,
/// P(a, x) = e^-x x^a / Gamma(a + 1) times the sum of x^n / ((a + 1)...(a + n)), is used and
/// Q = 1 - P (no cancellation: Q is not small there); otherwise the continued fraction for Q, evaluated by the modified Lentz method.
pub fn upper_regularized_gamma(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let log_prefactor = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        let mut term = 1.0 / a;
        let mut sum = term;
        let mut ap = a;
        for _ in 0..1000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        1.0 - sum * log_prefactor.exp()
    } else {
        const TINY: f64 = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / TINY;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -f64::from(i) * (f64::from(i) - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < TINY {
                d = TINY;
            }
            c = b + an / c;
            if c.abs() < TINY {
                c = TINY;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        log_prefactor.exp() * h
    }
}

/// Chi-square upper tail probability Pr(X > x) for `dof` degrees of freedom.
pub fn chi_square_sf(x: f64, dof: f64) -> f64 {
    upper_regularized_gamma(0.5 * dof, 0.5 * x)
}

/// Quantile of the chi-square distribution: the x with Pr(X <= x) = `p`, for `dof` > 0
/// degrees of freedom. None for p outside (0, 1) or a non-positive dof.
///
/// Solves Q(dof/2, x/2) = 1 - p (the upper tail, accurate for p close to 1) by Newton's method
/// on x, safeguarded by bisection inside a bracket, from the Wilson-Hilferty start
/// x0 = dof (1 - 2/(9 dof) + z sqrt(2/(9 dof)))^3, with the normal quantile z from the rational
/// approximation of Abramowitz & Stegun 26.2.23 (|error| < 4.5e-4; only the start needs it). Converges to 1e-12 relative.
pub fn chi_square_quantile(p: f64, dof: f64) -> Option<f64> {
    if !(p > 0.0 && p < 1.0 && dof > 0.0 && dof.is_finite()) {
        return None;
    }
    let tail = 1.0 - p;
    let a = 0.5 * dof;
    // Normal quantile for the start, Abramowitz & Stegun 26.2.23.
    let t = (-2.0 * tail.min(p).ln()).sqrt();
    let z_abs = t
        - (2.515517 + 0.802853 * t + 0.010328 * t * t)
            / (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
    let z = if p >= 0.5 { z_abs } else { -z_abs };
    let h = 2.0 / (9.0 * dof);
    let mut x = (dof * (1.0 - h + z * h.sqrt()).powi(3)).max(1e-8);
    // Bracket [lo, hi] with sf(lo) >= tail >= sf(hi).
    let mut lo = 0.0;
    let mut hi = x.max(1.0);
    let mut guard = 0;
    while chi_square_sf(hi, dof) > tail && guard < 200 {
        lo = hi;
        hi *= 2.0;
        guard += 1;
    }
    for _ in 0..200 {
        let f = chi_square_sf(x, dof) - tail; // decreasing in x
        if f > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        // pdf of chi-square(dof) at x = -(d sf / dx).
        let ln_pdf = (a - 1.0) * x.ln() - 0.5 * x - a * 2f64.ln() - ln_gamma(a);
        let pdf = ln_pdf.exp();
        let mut next = x + f / pdf;
        if !(next.is_finite() && next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 1e-12 * x.max(1e-300) {
            return Some(next);
        }
        x = next;
        if hi - lo <= 1e-13 * hi {
            return Some(x);
        }
    }
    Some(x)
}

/// Baarda's normalised residuals |e_i| / sqrt(sigma_i^2 - a_i N^-1 a_i^T) of a weighted least
/// squares with design rows `rows` (any number D of unknowns), a-priori sigmas `sigmas_m`,
/// post-fit residuals `residuals_m` (same order) and N^-1 = (A^T P A)^-1. An observation with
/// no redundancy (the variance of its residual vanishes) gets 0.
pub fn normalised_residuals<'a, const D: usize>(
    rows: &[[f64; D]],
    sigmas_m: &[f64],
    residuals_m: impl IntoIterator<Item = &'a f64>,
    n_inv: &SMatrix<f64, D, D>,
) -> Vec<f64> {
    rows.iter()
        .zip(sigmas_m)
        .zip(residuals_m)
        .map(|((r, s), e)| {
            let a = SVector::<f64, D>::from(*r);
            let qe = s * s - (a.transpose() * n_inv * a)[(0, 0)];
            if qe > 1e-12 * s * s {
                e.abs() / qe.sqrt()
            } else {
                0.0
            }
        })
        .collect()
}

/// Whether a weighted residual sum of squares e^T P e = `wsse` with `dof` degrees of freedom
/// passes the chi-square test at false-alarm probability `pfa` (true when dof = 0: there is
/// nothing to test).
pub fn chi_square_passes(wsse: f64, dof: usize, pfa: f64) -> bool {
    match chi_square_quantile(1.0 - pfa, dof as f64) {
        Some(threshold) => wsse <= threshold,
        None => true,
    }
}

/// Normalised residual of each observation of `fix`.
fn fix_normalised_residuals(fix: &Fix) -> Vec<f64> {
    let resid = fix.sat_residuals_m.iter().chain(&fix.landmark_residuals_m);
    normalised_residuals(&fix.geometry_rows, &fix.sigmas_m, resid, &fix.n_inv)
}

/// Whether the fix passes the chi-square test at false-alarm probability `pfa`.
fn passes(fix: &Fix, pfa: f64) -> bool {
    chi_square_passes(fix.wsse, fix.dof, pfa)
}

/// Runs detection and, with enough redundancy, exclusion of one satellite.
pub fn check_and_exclude(ctx: &Context<'_>, fix: Fix) -> Result<(Fix, RaimStatus), PvtError> {
    if !ctx.opts.raim {
        return Ok((fix, RaimStatus::Disabled));
    }
    if fix.dof < 1 {
        return Ok((fix, RaimStatus::Unavailable));
    }
    let pfa = ctx.opts.raim_pfa;
    if passes(&fix, pfa) {
        return Ok((fix, RaimStatus::Ok));
    }
    if fix.dof + N_UNKNOWNS < 6 {
        return Ok((fix, RaimStatus::FaultDetectedNotExcluded));
    }
    let w = fix_normalised_residuals(&fix);
    let worst =
        w[..fix.used.len()]
            .iter()
            .enumerate()
            .fold(None, |best: Option<(usize, f64)>, (j, &v)| match best {
                Some((_, bv)) if bv >= v => best,
                _ => Some((j, v)),
            });
    let Some((j, _)) = worst else {
        return Ok((fix, RaimStatus::FaultDetectedNotExcluded));
    };
    let excluded = fix.used[j];
    let mut active = vec![true; ctx.sats.len()];
    active[excluded] = false;
    match solve_position(ctx, &active) {
        Ok(refix) if refix.dof >= 1 && passes(&refix, pfa) => {
            let prn = ctx.sats[excluded].prn;
            Ok((refix, RaimStatus::FaultExcluded { prn }))
        }
        _ => Ok((fix, RaimStatus::FaultDetectedNotExcluded)),
    }
}
