//! The length of lost time, from what the satellites show after it.
//!
//! Samples lost for a time `g` leave two traces:
//!
//! - the data-bit edges: SV time kept across the gap runs `g` late, so at a channel's new bit
//!   edge (a whole 20 ms of true SV time) the kept time is `-g` modulo 20 ms off a bit
//!   boundary: `g = o + 20 k` ms for the measured offset `o` in [0, 20) and an unknown `k`;
//! - the carrier phase: each channel's residual carrier phase steps by `2 pi f_i g` (modulo pi,
//!   the Costas ambiguity) for its carrier frequency `f_i`.
//!
//! - the code: SV time runs at `r_i = 1 - rho_dot_i / c` of receiver time (the code rate over
//!   1.023 MHz), so the kept time falls `g r_i` short, and the offsets of the satellites differ
//!   by `g (r_i - r_j)`: tens of nanoseconds for `g` = 20 ms, measured by the code loops to a
//!   few nanoseconds ([`estimate_from_code`]).
//!
//! The candidates `o + 20 k` are scored by how well they explain the phase steps `d_i`:
//! `S(g) = mean_i exp(-e_i^2 / (2 s^2))` with `e_i = 2 pi f_i g - d_i` folded into
//! (-pi/2, pi/2] and `s` = [`STEP_SIGMA_RAD`]. The right `g` scores near 1; a wrong one makes
//! the `e_i` uniform, each term about 0.2 on average. (Measured on the GPS-SDR-SIM recording
//! at 37-44 dB-Hz, six satellites: 31 ms lost scores 0.88, the best wrong candidate 0.50; with
//! `cos 2 e` instead the margin was 0.23, too small.) A length is returned only with at least [`MIN_STEPS`] steps, a
//! best score of at least [`MIN_SCORE`] and every other candidate [`MIN_MARGIN`] below it:
//! otherwise the length is unknown and the time must come from the navigation message.

use crate::pipeline::timing::carrier_step::PhaseStep;
use crate::pipeline::timing::modulo::nearest_remainder;

/// Spread of a measured phase step, rad.
pub const STEP_SIGMA_RAD: f64 = 0.25;

/// Fewest phase steps that can resolve a length.
pub const MIN_STEPS: usize = 4;
/// Fewest satellites whose code offsets can measure a length.
pub const MIN_CODE_OFFSETS: usize = 5;

/// Lowest score accepted.
pub const MIN_SCORE: f64 = 0.6;
/// Least margin of the best score over any other candidate.
pub const MIN_MARGIN: f64 = 0.3;

/// How well a lost time of `g_ms` explains the phase steps: the mean of
/// `exp(-e^2 / 2 sigma^2)` over the steps, `e` each step's error modulo pi (1: all explained).
pub fn phase_score(g_ms: f64, steps: &[PhaseStep]) -> f64 {
    if steps.is_empty() {
        return 0.0;
    }
    let g = g_ms * 1e-3;
    steps
        .iter()
        .map(|s| {
            let e = nearest_remainder(s.predicted_rad(g) - s.step_rad, std::f64::consts::PI);
            (-e * e / (2.0 * STEP_SIGMA_RAD * STEP_SIGMA_RAD)).exp()
        })
        .sum::<f64>()
        / steps.len() as f64
}

/// The lost time (ms) given its value modulo 20 ms (`offset_ms`, in [0, 20)) and the phase
/// steps, searched up to `max_ms`; `None` when not resolved.
pub fn resolve_gap_ms(offset_ms: f64, steps: &[PhaseStep], max_ms: f64) -> Option<f64> {
    if steps.len() < MIN_STEPS || !offset_ms.is_finite() || !max_ms.is_finite() {
        return None;
    }
    let score = |g_ms: f64| phase_score(g_ms, steps);
    // A length of (almost) zero is not a gap.
    let first_k = if offset_ms < 0.5 { 1 } else { 0 };
    let mut scored: Vec<(f64, f64)> = Vec::new();
    let mut k = first_k;
    loop {
        let g = offset_ms + 20.0 * f64::from(k);
        if g > max_ms {
            break;
        }
        scored.push((score(g), g));
        k += 1;
    }
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (best, g) = *scored.first()?;
    let runner_up = scored
        .iter()
        .skip(1)
        .find(|s| (s.1 - g).abs() > 1e-9)
        .map_or(f64::NEG_INFINITY, |s| s.0);
    (best >= MIN_SCORE && best - runner_up >= MIN_MARGIN).then_some(g)
}

/// The lost time (ms) and its standard deviation from the code: each satellite's offset of
/// the kept SV time from its new bit edge (`off_i`, ms, all equal modulo 20 ms to within
/// microseconds) with its SV time rate `r_i`. Since `-off_i = g r_i` modulo 20 ms, the
/// differences `d_i = -(off_i - off_0)` against `y_i = r_i - r_0` give `g` by least squares
/// through the origin after removing the means. `None` with fewer than [`MIN_CODE_OFFSETS`]
/// satellites (the scatter that gives the standard deviation needs a few degrees of freedom)
/// or rates too alike.
pub fn estimate_from_code(offsets: &[(f64, f64)]) -> Option<(f64, f64)> {
    if offsets.len() < MIN_CODE_OFFSETS {
        return None;
    }
    let (o0, r0) = offsets[0];
    let pts: Vec<(f64, f64)> = offsets
        .iter()
        .map(|&(o, r)| {
            let d = -(o - o0);
            (r - r0, nearest_remainder(d, 20.0))
        })
        .collect();
    let n = pts.len() as f64;
    let (my, md) = pts
        .iter()
        .fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
    let syy: f64 = pts.iter().map(|p| (p.0 - my).powi(2)).sum();
    let syd: f64 = pts.iter().map(|p| (p.0 - my) * (p.1 - md)).sum();
    if syy <= 0.0 {
        return None;
    }
    let g = syd / syy;
    // Scatter of the offsets about the fit, with a floor of 3 ns (1 m of code).
    let rss: f64 = pts
        .iter()
        .map(|p| (p.1 - md - g * (p.0 - my)).powi(2))
        .sum();
    let sigma_d = (rss / (n - 2.0).max(1.0)).sqrt().max(3e-6);
    Some((g, sigma_d / syy.sqrt()))
}

/// The lost time (ms) from the offset modulo 20 ms (`offset_ms`), the phase steps and the
/// code's estimate `(g, sigma)`:
///
/// - the phase steps alone ([`resolve_gap_ms`]) or the code alone (one candidate `o + 20 k`
///   within 3 sigma, every other one beyond 6 sigma) single out a candidate; when both do they
///   must agree, and a phase candidate must be within 4 sigma of the code's estimate;
/// - otherwise, when the code leaves exactly one candidate within 3 sigma and the phase steps
///   explain it (score at least [`MIN_SCORE`]), that one: two independent measurements agree
///   on it although neither alone excludes every other;
/// - otherwise the candidates are weighed by both together ([`joint_choice`]): under a
///   Doppler ramp few phase steps pass their check and the code's estimate leaves two or
///   three candidates, which together they may still tell apart.
pub fn choose(offset_ms: f64, steps: &[PhaseStep], by_code: Option<(f64, f64)>) -> Option<f64> {
    let by_phase = resolve_gap_ms(offset_ms, steps, 1000.0);
    let near_code = |sigmas: f64| -> Vec<f64> {
        by_code.map_or(Vec::new(), |(g, sigma)| {
            let k_lo = ((g - sigmas * sigma - offset_ms) / 20.0).ceil() as i64;
            let k_hi = ((g + sigmas * sigma - offset_ms) / 20.0).floor() as i64;
            (k_lo.max(0)..=k_hi)
                .map(|k| offset_ms + 20.0 * k as f64)
                .filter(|&c| c > 0.25)
                .collect()
        })
    };
    let from_code = match (near_code(3.0).as_slice(), near_code(6.0).len()) {
        ([c], 1) => Some(*c),
        _ => None,
    };
    let code_allows = |p: f64| by_code.is_none_or(|(g, sigma)| (p - g).abs() <= 4.0 * sigma);
    match (by_phase, from_code) {
        (Some(p), Some(c)) => ((p - c).abs() < 1e-6).then_some(p),
        (Some(p), None) => code_allows(p).then_some(p),
        (None, Some(c)) => Some(c),
        (None, None) => match near_code(3.0).as_slice() {
            [c] if steps.len() >= MIN_STEPS && phase_score(*c, steps) >= MIN_SCORE => Some(*c),
            _ => by_code.and_then(|code| joint_choice(offset_ms, steps, code)),
        },
    }
}

/// Probability that a measured phase step is an outlier (a slip after the jump), in
/// [`joint_choice`]'s likelihood.
pub const STEP_OUTLIER_PROB: f64 = 0.05;
/// Fewest phase steps [`joint_choice`] weighs.
pub const MIN_JOINT_STEPS: usize = 2;
/// Least log-likelihood ratio of the best candidate over the next in [`joint_choice`]
/// (`ln 1000`).
pub const MIN_JOINT_LOG_RATIO: f64 = 6.9;

/// The candidate `o + 20 k` within 5 sigma of the code's estimate `(g, sigma)` that the code
/// and the phase steps together make at least 1000 times likelier than any other:
/// `L(c) = -(c - g)^2 / (2 sigma^2) + sum_i ln((1 - rho) exp(-e_i^2 / (2 s^2)) + rho)`, with
/// `e_i` step `i`'s error for `c` (modulo pi), `s` = [`STEP_SIGMA_RAD`] and `rho` =
/// [`STEP_OUTLIER_PROB`] (each step moves `L` by at most `ln rho` = -3.0, so two steps and the
/// code are needed to reach the ratio). The best must also explain the steps (score at least
/// [`MIN_SCORE`]).
pub fn joint_choice(offset_ms: f64, steps: &[PhaseStep], code: (f64, f64)) -> Option<f64> {
    let (g, sigma) = code;
    if steps.len() < MIN_JOINT_STEPS || !(g.is_finite() && sigma > 0.0 && sigma.is_finite()) {
        return None;
    }
    let k_lo = ((g - 5.0 * sigma - offset_ms) / 20.0).ceil().max(0.0) as i64;
    let k_hi = ((g + 5.0 * sigma - offset_ms) / 20.0).floor() as i64;
    let s2 = 2.0 * STEP_SIGMA_RAD * STEP_SIGMA_RAD;
    let mut scored: Vec<(f64, f64)> = (k_lo..=k_hi)
        .map(|k| offset_ms + 20.0 * k as f64)
        .filter(|&c| c > 0.25)
        .map(|c| {
            let phase: f64 = steps
                .iter()
                .map(|st| {
                    let e = nearest_remainder(
                        st.predicted_rad(c * 1e-3) - st.step_rad,
                        std::f64::consts::PI,
                    );
                    ((1.0 - STEP_OUTLIER_PROB) * (-e * e / s2).exp() + STEP_OUTLIER_PROB).ln()
                })
                .sum();
            (phase - (c - g).powi(2) / (2.0 * sigma * sigma), c)
        })
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (best, c) = *scored.first()?;
    let next = scored.get(1).map_or(f64::NEG_INFINITY, |x| x.0);
    (best - next >= MIN_JOINT_LOG_RATIO && phase_score(c, steps) >= MIN_SCORE).then_some(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps `2 pi (f g + f' g^2 / 2)` folded into (-pi/2, pi/2], with a little noise.
    fn steps_for(g_ms: f64, freqs: &[f64], noise: &[f64]) -> Vec<PhaseStep> {
        freqs
            .iter()
            .zip(noise.iter().cycle())
            .enumerate()
            .map(|(i, (&f, &n))| {
                let mut s = PhaseStep {
                    prn: i as u8 + 1,
                    step_rad: 0.0,
                    freq_hz: f,
                    rate_hz_s: 0.9 - 0.25 * i as f64,
                };
                let phi = s.predicted_rad(g_ms * 1e-3) + n;
                s.step_rad = nearest_remainder(phi, std::f64::consts::PI);
                s
            })
            .collect()
    }

    const FREQS: [f64; 8] = [
        -3120.4, -1877.9, -640.2, 199.1, 874.6, 1502.3, 2280.8, 3411.7,
    ];
    const NOISE: [f64; 5] = [0.08, -0.12, 0.05, -0.03, 0.1];

    #[test]
    fn the_lengths_of_whole_millisecond_gaps_are_found() {
        for g in [1.0, 11.0, 20.0, 31.0, 60.0, 500.0] {
            let steps = steps_for(g, &FREQS, &NOISE);
            let offset = g % 20.0;
            assert_eq!(resolve_gap_ms(offset, &steps, 1000.0), Some(g), "{g} ms");
        }
    }

    #[test]
    fn the_code_offsets_give_the_length_from_the_satellites_code_rates() {
        // Rates 1 + f_D / f_L1 for Dopplers of -3.1 to +3.4 kHz; offsets -g r_i modulo 20 ms
        // with 2 ns of noise.
        for g in [1.25, 20.0, 31.0, 500.0] {
            let noise = [2e-6, -1e-6, 0.0, 1.5e-6, -2e-6, 1e-6, -0.5e-6, 0.5e-6];
            let offsets: Vec<(f64, f64)> = FREQS
                .iter()
                .zip(noise)
                .map(|(&f, n)| {
                    let r = 1.0 + f / 1.57542e9;
                    let o = -g * r;
                    (nearest_remainder(o, 20.0) + n, r)
                })
                .collect();
            let (est, sigma) = estimate_from_code(&offsets).expect("estimate");
            assert!(
                (est - g).abs() < 4.0 * sigma && sigma < 2.0,
                "{g}: {est} +- {sigma}"
            );
            let offset = (-offsets[0].0).rem_euclid(20.0);
            let chosen = choose(offset, &[], Some((est, sigma)));
            assert!(
                chosen.is_some_and(|c| (c - g).abs() < 1e-3),
                "{g}: {chosen:?}"
            );
        }
    }

    #[test]
    fn too_few_or_inconsistent_steps_resolve_nothing() {
        let steps = steps_for(31.0, &FREQS[..3], &NOISE);
        assert_eq!(resolve_gap_ms(11.0, &steps, 1000.0), None);
        // Steps that no length explains (random phases).
        let random: Vec<PhaseStep> = FREQS
            .iter()
            .zip([1.2, -0.7, 0.3, 1.5, -1.1, 0.9, -0.2, 0.6])
            .map(|(&f, d)| PhaseStep {
                prn: 1,
                step_rad: d,
                freq_hz: f,
                rate_hz_s: 0.0,
            })
            .collect();
        assert_eq!(resolve_gap_ms(11.0, &random, 1000.0), None);
    }

    #[test]
    fn two_phase_steps_and_the_code_together_resolve_what_neither_does_alone() {
        // A 31 ms gap under a 4.3 g climb (the dyn-gaps rocket): two steps passed their check,
        // at 488 and 2164 Hz with Doppler rates of 19 and 13 Hz/s, and the code said
        // 24.5 +- 6 ms (11, 31 and 51 ms all within 3 sigma).
        let mut steps = steps_for(31.0, &[487.7, 2164.1], &[0.08, -0.05]);
        steps[0].rate_hz_s = 19.2;
        steps[1].rate_hz_s = 13.2;
        for s in &mut steps {
            let phi = s.predicted_rad(0.031) + 0.05;
            s.step_rad = nearest_remainder(phi, std::f64::consts::PI);
        }
        assert_eq!(resolve_gap_ms(11.0, &steps, 1000.0), None);
        assert_eq!(choose(11.0, &steps, Some((24.5, 6.0))), Some(31.0));
        // Steps that 11 and 31 ms explain alike (whole cycles in 20 ms at 1000 and 1500 Hz):
        // the code alone prefers 31 by too little.
        let alike = steps_for(31.0, &[1000.0, 1500.0], &[0.0]);
        assert_eq!(joint_choice(11.0, &alike, (24.5, 6.0)), None);
        // One step is not enough, however well it fits.
        assert_eq!(joint_choice(11.0, &steps[..1], (24.5, 6.0)), None);
    }
}
