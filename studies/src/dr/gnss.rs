//! Simulated GNSS solutions (the fast path: no IF, no tracking), from the vehicle truth:
//!
//! - **position** (east, north) at [`GNSS_RATE_HZ`]: truth + `b(t)` + white noise of the
//!   section's `white_sigma_m` per axis; `b` is a first-order Gauss-Markov bias per axis,
//!   `b_k = phi b_{k-1} + sqrt(1 - phi^2) sigma_b w_k`, `phi = exp(-dt / tau)`
//!   ([`BIAS_TAU_S`]), the section's `bias_sigma_m`, which **jumps** to a new independent draw
//!   `N(0, sigma_b^2)` at every satellite-set change (seed 000 Fig. 1: the code solution's bias
//!   changes with the satellites in view);
//! - **velocity** (east, north, up): truth + white noise ([`GNSS_VEL_SIGMA_MPS`] per horizontal
//!   axis, [`GNSS_VEL_UP_SIGMA_MPS`] up), no bias: carrier-based velocity (seed 000 Sec. 2.2).
//!
//! The satellite-set changes follow each section's `set_change_every_s` and do not depend on the
//! seed, so outage placements are the same for every noise realisation.

use super::drive::Drive;
use super::params::{
    Section, BIAS_TAU_S, GNSS_RATE_HZ, GNSS_VEL_SIGMA_MPS, GNSS_VEL_UP_SIGMA_MPS, SECTIONS,
};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// One GNSS solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssEpoch {
    /// Time, s.
    pub t_s: f64,
    /// Measured east, north position, m.
    pub pos_en_m: [f64; 2],
    /// Measured east, north, up velocity, m/s.
    pub vel_enu_mps: [f64; 3],
    /// Total position error sigma per axis the solution reports, m (`sqrt(white^2 + bias^2)`).
    pub pos_sigma_m: f64,
    /// Index of the course section ([`SECTIONS`]).
    pub section: usize,
}

/// A drive's GNSS solutions and its satellite-set change times.
#[derive(Debug, Clone)]
pub struct GnssTrack {
    /// One solution per epoch from t = 0, at [`GNSS_RATE_HZ`].
    pub epochs: Vec<GnssEpoch>,
    /// Satellite-set change times, s.
    pub set_changes_s: Vec<f64>,
}

/// The section index of `t_s` on a drive of `duration_s` (eight equal parts).
pub fn section_of(t_s: f64, duration_s: f64) -> usize {
    let k = (t_s / (duration_s / SECTIONS.len() as f64)).floor();
    (k.max(0.0) as usize).min(SECTIONS.len() - 1)
}

/// Section `k`'s time span, s.
pub fn section_span(k: usize, duration_s: f64) -> (f64, f64) {
    let len = duration_s / SECTIONS.len() as f64;
    (k as f64 * len, (k + 1) as f64 * len)
}

/// Satellite-set change times: every `set_change_every_s` of the section the previous change
/// is in, from the start.
pub fn set_change_times(duration_s: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut t = 0.0;
    loop {
        let s: &Section = &SECTIONS[section_of(t, duration_s)];
        t += s.set_change_every_s;
        if t >= duration_s {
            return out;
        }
        out.push(t);
    }
}

/// The natural signal blockages of the drive (each section's `blockage_s` every
/// `blockage_every_s`, the first half a period into the section).
pub fn blockages(duration_s: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for (k, s) in SECTIONS.iter().enumerate() {
        if s.blockage_every_s <= 0.0 {
            continue;
        }
        let (a, b) = section_span(k, duration_s);
        let mut t = a + 0.5 * s.blockage_every_s;
        while t + s.blockage_s <= b {
            out.push((t, t + s.blockage_s));
            t += s.blockage_every_s;
        }
    }
    out
}

/// Simulates the drive's GNSS solutions with noise seed `seed`.
pub fn simulate_gnss(drive: &Drive, seed: u64) -> GnssTrack {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x6e55_0000);
    let mut gauss = move || -> f64 { rng.sample(StandardNormal) };
    let changes = set_change_times(drive.duration_s);
    let dt = 1.0 / GNSS_RATE_HZ;
    let phi = (-dt / BIAS_TAU_S).exp();
    let n = (drive.duration_s * GNSS_RATE_HZ).floor() as usize;
    let mut epochs = Vec::with_capacity(n + 1);
    let mut bias = [0.0; 2];
    let mut next_change = 0;
    for k in 0..=n {
        let t = k as f64 * dt;
        let section = section_of(t, drive.duration_s);
        let s = &SECTIONS[section];
        let mut jumped = k == 0;
        while next_change < changes.len() && changes[next_change] <= t + 1e-9 {
            next_change += 1;
            jumped = true;
        }
        for b in &mut bias {
            *b = if jumped {
                s.bias_sigma_m * gauss()
            } else {
                phi * *b + (1.0 - phi * phi).sqrt() * s.bias_sigma_m * gauss()
            };
        }
        let truth = drive.at(t);
        let (sp, cp) = truth.heading_rad.sin_cos();
        let (sg, cg) = truth.pitch_rad.sin_cos();
        let v = truth.speed_mps;
        epochs.push(GnssEpoch {
            t_s: t,
            pos_en_m: [
                truth.east_m + bias[0] + s.white_sigma_m * gauss(),
                truth.north_m + bias[1] + s.white_sigma_m * gauss(),
            ],
            vel_enu_mps: [
                v * cg * sp + GNSS_VEL_SIGMA_MPS * gauss(),
                v * cg * cp + GNSS_VEL_SIGMA_MPS * gauss(),
                v * sg + GNSS_VEL_UP_SIGMA_MPS * gauss(),
            ],
            pos_sigma_m: s.white_sigma_m.hypot(s.bias_sigma_m),
            section,
        });
    }
    GnssTrack {
        epochs,
        set_changes_s: changes,
    }
}

/// Whether `t_s` falls in one of the `[start, end)` windows.
pub fn in_windows(t_s: f64, windows: &[(f64, f64)]) -> bool {
    windows.iter().any(|&(a, b)| t_s >= a && t_s < b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_ins_aiding::VehicleTruth;

    /// A vehicle standing still for `duration_s` (truth at 1 Hz).
    fn parked(duration_s: f64) -> Drive {
        let n = duration_s as usize;
        let truth = (0..=n)
            .map(|k| VehicleTruth {
                t_s: k as f64,
                east_m: 10.0,
                north_m: -5.0,
                up_m: 0.0,
                speed_mps: 0.0,
                heading_rad: 0.3,
                yaw_rate_rad_s: 0.0,
                a_long_mps2: 0.0,
                pitch_rad: 0.0,
            })
            .collect();
        Drive {
            truth,
            duration_s,
            description: "parked".into(),
        }
    }

    #[test]
    fn set_changes_and_blockages_follow_the_sections() {
        let d = 1710.0;
        let ch = set_change_times(d);
        let mut prev = 0.0;
        for &t in &ch {
            let s = &SECTIONS[section_of(prev, d)];
            assert!(
                (t - prev - s.set_change_every_s).abs() < 1e-9,
                "{prev} -> {t}"
            );
            prev = t;
        }
        assert!(prev + SECTIONS[section_of(prev, d)].set_change_every_s >= d);
        for &(a, b) in &blockages(d) {
            let k = section_of(a, d);
            let (s0, s1) = section_span(k, d);
            assert!(a >= s0 && b <= s1 && (b - a - SECTIONS[k].blockage_s).abs() < 1e-9);
            assert!(SECTIONS[k].blockage_every_s > 0.0);
        }
        assert!(in_windows(5.0, &[(4.0, 6.0)]) && !in_windows(6.0, &[(4.0, 6.0)]));
    }

    #[test]
    fn errors_have_the_section_variance_and_the_bias_jumps_at_set_changes() {
        // Parked for 8 x 8000 s: the position error per axis is bias + white noise, variance
        // sigma_b^2 + sigma_w^2 (the Gauss-Markov bias is stationary at sigma_b and redrawn at
        // each set change). Pooled by environment (over 200 bias draws per axis), 20 % is about
        // 3 standard errors of the variance estimate.
        let d = 64_000.0;
        let track = simulate_gnss(&parked(d), 11);
        for env in ["open road", "apartment blocks"] {
            let (mut sum2, mut n, mut expected) = (0.0, 0.0, 0.0);
            for e in &track.epochs {
                let s = &SECTIONS[e.section];
                if s.environment == env {
                    sum2 += (e.pos_en_m[0] - 10.0).powi(2) + (e.pos_en_m[1] + 5.0).powi(2);
                    n += 2.0;
                    expected = s.white_sigma_m.powi(2) + s.bias_sigma_m.powi(2);
                }
            }
            let var = sum2 / n;
            assert!(
                (var / expected - 1.0).abs() < 0.3,
                "{env}: {var} vs {expected}"
            );
        }
        // Epoch-to-epoch differences: 2 sigma_w^2 inside a bias segment, 2 (sigma_w^2 +
        // sigma_b^2) across a satellite-set change (a new independent bias).
        let (mut across, mut na, mut within, mut nw) = (0.0, 0.0, 0.0, 0.0);
        for w in track.epochs.windows(2) {
            let s = &SECTIONS[w[1].section];
            if s.environment != "open road" || w[0].section != w[1].section {
                continue;
            }
            let dx = w[1].pos_en_m[0] - w[0].pos_en_m[0];
            if track
                .set_changes_s
                .iter()
                .any(|&c| c > w[0].t_s && c <= w[1].t_s)
            {
                across += dx * dx;
                na += 1.0;
            } else {
                within += dx * dx;
                nw += 1.0;
            }
        }
        let (across, within) = (across / na, within / nw);
        assert!((within / (2.0 * 4.0) - 1.0).abs() < 0.1, "within {within}");
        assert!(across > 2.0 * within, "across {across} within {within}");
        // Velocity noise: 0.05 m/s per horizontal axis, no bias.
        let v: Vec<f64> = track.epochs.iter().map(|e| e.vel_enu_mps[0]).collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
        assert!(mean.abs() < 0.002 && (sd / GNSS_VEL_SIGMA_MPS - 1.0).abs() < 0.03);
    }
}
