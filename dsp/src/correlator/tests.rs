//! Tests of the scalar reference kernel [`super::correlate`] against the f64 definition.

use super::*;
use crate::ca_code::{CaCode, Prn};
use rand::{Rng, SeedableRng};

/// f64 reference: the definition in the module doc, evaluated directly.
fn reference(
    samples: &[Complex32],
    fs: f64,
    code: &CaCode,
    s: &ReplicaState,
    taps: &[f64],
) -> Vec<(f64, f64)> {
    taps.iter()
        .map(|d| {
            let (mut re, mut im) = (0.0, 0.0);
            for (k, x) in samples.iter().enumerate() {
                let k = k as f64;
                let t = k / fs;
                let ph = s.carrier_phase_cycles
                    + s.carrier_freq_hz * t
                    + 0.5 * s.carrier_rate_hz_s * t * t;
                let ang = -2.0 * std::f64::consts::PI * ph;
                let c = f64::from(code.chip(
                    ((s.code_phase_chips + d + s.code_rate_chips_s * t).rem_euclid(1023.0))
                        as usize,
                ));
                let (xr, xi) = (f64::from(x.re), f64::from(x.im));
                re += c * (xr * ang.cos() - xi * ang.sin());
                im += c * (xr * ang.sin() + xi * ang.cos());
            }
            (re, im)
        })
        .collect()
}

#[test]
fn matches_the_f64_reference_on_random_input() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let code = CaCode::new(Prn::new(12).unwrap_or_else(|e| panic!("{e}")));
    for &n in &[1usize, 7, 1000, 4093] {
        let x: Vec<Complex32> = (0..n)
            .map(|_| Complex32::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)))
            .collect();
        let s = ReplicaState {
            code_phase_chips: rng.random_range(0.0..1023.0),
            code_rate_chips_s: 1.023e6 + rng.random_range(-5.0..5.0),
            carrier_phase_cycles: rng.random_range(0.0..1.0),
            carrier_freq_hz: rng.random_range(-5000.0..5000.0),
            carrier_rate_hz_s: rng.random_range(-2000.0..2000.0),
        };
        let taps = [-0.5, 0.0, 0.5];
        let mut out = [Complex32::new(0.0, 0.0); 3];
        correlate(&x, 4.0e6, code.chips(), &s, &taps, &mut out);
        let r = reference(&x, 4.0e6, &code, &s, &taps);
        for (o, (re, im)) in out.iter().zip(r) {
            // Error budget: table phase error <= pi/4096 rad per sample (random sign) plus
            // f32 accumulation; bound |err| <= 2e-3 * sqrt(n) * rms|x| + rare chip-edge
            // disagreements (fixed vs f64 code phase), each worth at most 2|x| <= 2.9.
            let err = ((f64::from(o.re) - re).powi(2) + (f64::from(o.im) - im).powi(2)).sqrt();
            assert!(err < 2e-3 * (n as f64).sqrt() + 6.0, "n {n}: err {err}");
        }
    }
}

#[test]
fn aligned_replica_collects_all_the_signal() {
    // A noise-free signal equal to the replica gives |P| = n; early/late at +-0.5 chip give
    // about n/2 (triangle correlation at 4 samples per chip).
    let code = CaCode::new(Prn::new(1).unwrap_or_else(|e| panic!("{e}")));
    let fs = 4.092e6;
    let s = ReplicaState {
        code_phase_chips: 100.25,
        code_rate_chips_s: 1.023e6,
        carrier_phase_cycles: 0.3,
        carrier_freq_hz: 1234.0,
        carrier_rate_hz_s: 0.0,
    };
    let n = 4092;
    let x: Vec<Complex32> = (0..n)
        .map(|k| {
            let t = k as f64 / fs;
            let ph = 2.0 * std::f64::consts::PI * (0.3 + 1234.0 * t);
            let c = f64::from(code.chip(((100.25 + 1.023e6 * t) % 1023.0) as usize));
            Complex32::new((c * ph.cos()) as f32, (c * ph.sin()) as f32)
        })
        .collect();
    let mut out = [Complex32::new(0.0, 0.0); 3];
    correlate(&x, fs, code.chips(), &s, &[-0.5, 0.0, 0.5], &mut out);
    assert!(
        (out[1].norm() / n as f32 - 1.0).abs() < 2e-3,
        "{}",
        out[1].norm()
    );
    assert!(out[1].arg().abs() < 2e-3);
    for e in [out[0], out[2]] {
        assert!(
            (e.norm() / n as f32 - 0.5).abs() < 0.01,
            "{}",
            e.norm() / n as f32
        );
    }
}

#[test]
fn advancing_the_state_is_consistent_with_correlating_in_two_halves() {
    let code = CaCode::new(Prn::new(7).unwrap_or_else(|e| panic!("{e}")));
    let mut rng = rand::rngs::StdRng::seed_from_u64(9);
    let x: Vec<Complex32> = (0..2000)
        .map(|_| Complex32::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)))
        .collect();
    let s = ReplicaState {
        code_phase_chips: 5.0,
        code_rate_chips_s: 1.023e6,
        carrier_phase_cycles: 0.1,
        carrier_freq_hz: 700.0,
        carrier_rate_hz_s: 300.0,
    };
    let mut whole = [Complex32::new(0.0, 0.0)];
    correlate(&x, 2.0e6, code.chips(), &s, &[0.0], &mut whole);
    let (mut a, mut b) = ([Complex32::new(0.0, 0.0)], [Complex32::new(0.0, 0.0)]);
    correlate(&x[..1000], 2.0e6, code.chips(), &s, &[0.0], &mut a);
    correlate(
        &x[1000..],
        2.0e6,
        code.chips(),
        &s.advanced(1000, 2.0e6),
        &[0.0],
        &mut b,
    );
    assert!(
        (whole[0] - (a[0] + b[0])).norm() < 0.5,
        "{} vs {}",
        whole[0],
        a[0] + b[0]
    );
}
