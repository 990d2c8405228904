//! Every [`Correlator`] kernel (ISA x arithmetic x sample format) against the f64 definition,
//! the scalar reference [`correlate`] and, for a carrier-free replica, an exact integer sum.
//!
//! Error budget per output (derived, then checked on random inputs):
//! - chip edges: the kernels' code phase is fixed point (2^-32 chip, step rounded to 2^-33 chip
//!   per sample), so a sample whose f64 code phase lies within `2^-32 + n 2^-33` chip of a chip
//!   edge may pick the neighbouring chip: each such sample is allowed `2|x_k|` (counted
//!   separately, against the f64 reference only; every kernel uses the same fixed-point code
//!   NCO, so against the scalar reference there is no edge allowance);
//! - carrier, relative to `sum |x_k|`: table (scalar) `pi/4096 < 7.7e-4` rad; rotator (SIMD)
//!   at most 256 steps between exact f64 re-seeds, each adding <= ~2.4e-7 rad (f32 rounding of
//!   `D` and of the product), plus with a rate the drift of `D` itself: bound `2e-4`;
//!   int16 kernels add the Q14 quantisation of the carrier, `2^-15` per component
//!   (`2^-14.5 < 4.5e-5` relative), and ci16 the rounding of `w` to multiples of 2^8 in Q14
//!   units, `2^-7 sqrt 2` sample units per sample; the AVX2 16-lane ci8 kernel rounds each
//!   of the two products of a component to 2^-7 sample (`vpmulhrsw`), also at most
//!   `2^-7 sqrt 2` per sample, and its carrier, rotated in i16 between f32 steps, is off by
//!   at most `4.1e-4` relative (avx2_i16 module doc); the int16-lane kernels on ci16 round
//!   each product to `2^-sh` sample with `sh` the block's headroom (int16_lanes module doc),
//!   at most `2^(1 - sh) sqrt 2` per sample;
//! - f32 accumulation: `n 2^-24` relative (worst case, sequential sums).

use super::*;
use crate::ca_code::{CaCode, Prn};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Fmt {
    Cf32,
    Ci16,
    Ci8,
}

/// A random block in all three formats' storage, with `offset` extra samples in front.
struct Block {
    cf32: Vec<Complex32>,
    ci16: Vec<[i16; 2]>,
    ci8: Vec<[i8; 2]>,
}

impl Block {
    fn random(rng: &mut StdRng, len: usize) -> Self {
        Self {
            cf32: (0..len)
                .map(|_| Complex32::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)))
                .collect(),
            ci16: (0..len).map(|_| [rng.random(), rng.random()]).collect(),
            ci8: (0..len).map(|_| [rng.random(), rng.random()]).collect(),
        }
    }

    fn slice(&self, fmt: Fmt, r: std::ops::Range<usize>) -> SampleSlice<'_> {
        match fmt {
            Fmt::Cf32 => SampleSlice::Cf32(&self.cf32[r]),
            Fmt::Ci16 => SampleSlice::Ci16(&self.ci16[r]),
            Fmt::Ci8 => SampleSlice::Ci8(&self.ci8[r]),
        }
    }
}

fn as_f64(s: SampleSlice<'_>) -> Vec<(f64, f64)> {
    match s {
        SampleSlice::Cf32(x) => x
            .iter()
            .map(|c| (f64::from(c.re), f64::from(c.im)))
            .collect(),
        SampleSlice::Ci16(x) => x
            .iter()
            .map(|c| (f64::from(c[0]), f64::from(c[1])))
            .collect(),
        SampleSlice::Ci8(x) => x
            .iter()
            .map(|c| (f64::from(c[0]), f64::from(c[1])))
            .collect(),
    }
}

fn as_cf32(x: &[(f64, f64)]) -> Vec<Complex32> {
    x.iter()
        .map(|&(r, i)| Complex32::new(r as f32, i as f32))
        .collect()
}

/// The f64 definition for one tap, and the allowance for chip-edge samples (`2|x|` each) with
/// their count.
fn reference(
    x: &[(f64, f64)],
    fs: f64,
    code: &[i8; 1023],
    s: &ReplicaState,
    d: f64,
) -> ((f64, f64), f64, usize) {
    let eps = 2f64.powi(-32) + x.len() as f64 * 2f64.powi(-33) + 1e-9;
    let (mut re, mut im, mut edge, mut count) = (0.0, 0.0, 0.0, 0);
    for (k, &(xr, xi)) in x.iter().enumerate() {
        let t = k as f64 / fs;
        let ph = s.carrier_phase_cycles + s.carrier_freq_hz * t + 0.5 * s.carrier_rate_hz_s * t * t;
        let ang = -2.0 * std::f64::consts::PI * ph.rem_euclid(1.0);
        let c = (s.code_phase_chips + d + s.code_rate_chips_s * t).rem_euclid(1023.0);
        let chip = f64::from(code[(c as usize).min(1022)]);
        re += chip * (xr * ang.cos() - xi * ang.sin());
        im += chip * (xr * ang.sin() + xi * ang.cos());
        let frac = c - c.floor();
        if frac.min(1.0 - frac) < eps {
            edge += 2.0 * xr.hypot(xi);
            count += 1;
        }
    }
    ((re, im), edge, count)
}

/// Carrier error bound relative to `sum |x|`, per kernel (module doc).
fn carrier_bound(c: &Correlator, fmt: Fmt) -> f64 {
    let base = if c.isa() == Isa::Scalar { 7.7e-4 } else { 2e-4 };
    match (c.isa(), c.arithmetic(), fmt) {
        // The int16-lane kernels rotate 3 of 4 carrier vectors in i16 (avx2_i16 module doc).
        (Isa::Avx2Fma | Isa::Avx512, Arithmetic::I16, Fmt::Ci8 | Fmt::Ci16) => base + 4.1e-4,
        (_, Arithmetic::I16, Fmt::Ci16 | Fmt::Ci8) => base + 4.5e-5,
        _ => base,
    }
}

struct Case {
    fs: f64,
    state: ReplicaState,
    taps: Vec<f64>,
}

fn random_case(rng: &mut StdRng, n: usize) -> Case {
    let fs = rng.random_range(1.1e6..25e6);
    let n_taps = rng.random_range(1..=10usize);
    let taps = (0..n_taps).map(|_| rng.random_range(-2.5..2.5)).collect();
    // Half the cases start close to the end of the code so the block wraps past chip 1023.
    let span = 1.023e6 * n as f64 / fs;
    let code_phase_chips = if rng.random_bool(0.5) {
        1023.0 - rng.random_range(0.0..span.clamp(0.5, 1023.0))
    } else {
        rng.random_range(-2000.0..2000.0)
    };
    let carrier_rate_hz_s = if rng.random_bool(0.3) {
        0.0
    } else {
        rng.random_range(-5000.0..5000.0)
    };
    Case {
        fs,
        taps,
        state: ReplicaState {
            code_phase_chips,
            code_rate_chips_s: 1.023e6 + rng.random_range(-5.0..5.0),
            carrier_phase_cycles: rng.random_range(-3.0..3.0),
            carrier_freq_hz: rng.random_range(-0.3..0.3) * fs,
            carrier_rate_hz_s,
        },
    }
}

/// The headroom shift of a ci16 block as the int16-lane kernels take it (int16_lanes module
/// doc), found by trial: the largest `sh <= 15` with every `|v| < 2^(15 - sh)` (`|v|` of
/// -32768 read as 32768: then 0).
fn headroom_shift(x: &[(f64, f64)]) -> i32 {
    let m = x
        .iter()
        .fold(0.0f64, |m, &(r, i)| m.max(r.abs()).max(i.abs()));
    (0..=15)
        .rev()
        .find(|&sh| m < 2f64.powi(15 - sh))
        .unwrap_or(0)
}

/// The absolute rounding allowance of the integer kernels that round the wiped samples
/// (module doc): `2^-7 sqrt 2` sample units per sample, on ci16 with the int16-lane kernels
/// `2^(1 - sh) sqrt 2` if that is more.
fn rounding_allowance(c: &Correlator, fmt: Fmt, x: &[(f64, f64)]) -> f64 {
    let simd = c.isa() != Isa::Scalar;
    let per_sample = match (c.arithmetic(), fmt) {
        (Arithmetic::I16, Fmt::Ci16) if simd => 2f64.powi(-7).max(2f64.powi(1 - headroom_shift(x))),
        (Arithmetic::I16, Fmt::Ci16) => 2f64.powi(-7),
        (Arithmetic::I16, Fmt::Ci8) if simd => 2f64.powi(-7),
        _ => 0.0,
    };
    x.len() as f64 * per_sample * 2f64.sqrt()
}

fn check(c: &Correlator, fmt: Fmt, x: SampleSlice<'_>, code: &CaCode, case: &Case) -> f64 {
    let n = x.len();
    let xf = as_f64(x);
    let sum_abs: f64 = xf.iter().map(|&(r, i)| r.hypot(i)).sum();
    let mut out = vec![Complex32::new(f32::NAN, 0.0); case.taps.len()];
    c.correlate(x, case.fs, code.chips(), &case.state, &case.taps, &mut out);
    let mut scalar = vec![Complex32::new(0.0, 0.0); case.taps.len()];
    correlate(
        &as_cf32(&xf),
        case.fs,
        code.chips(),
        &case.state,
        &case.taps,
        &mut scalar,
    );
    let rel = carrier_bound(c, fmt) + n as f64 * 6e-8;
    let ci16_round = rounding_allowance(c, fmt, &xf);
    let mut worst = 0.0f64;
    for ((o, sc), &d) in out.iter().zip(&scalar).zip(&case.taps) {
        let ((re, im), edge, _) = reference(&xf, case.fs, code.chips(), &case.state, d);
        let err = (f64::from(o.re) - re).hypot(f64::from(o.im) - im);
        let bound = edge + rel * sum_abs + ci16_round + 1e-6;
        assert!(
            err <= bound,
            "{} {fmt:?} n {n} fs {} tap {d}: err {err} > {bound} (edge {edge})",
            c.name(),
            case.fs
        );
        worst = worst.max((err - edge).max(0.0) / sum_abs.max(1e-30));
        let diff = (o - sc).norm();
        let bound_sc = (rel + 7.7e-4 + n as f64 * 6e-8) * sum_abs + ci16_round + 1e-6;
        assert!(
            f64::from(diff) <= bound_sc,
            "{} {fmt:?} n {n}: vs scalar {diff} > {bound_sc}",
            c.name()
        );
    }
    worst
}

#[test]
fn every_kernel_matches_the_references_on_random_blocks() {
    let mut rng = StdRng::seed_from_u64(2024);
    let code = CaCode::new(Prn::new(17).unwrap_or_else(|e| panic!("{e}")));
    let kernels = Correlator::available();
    assert!(kernels.iter().any(|c| c.isa() == Isa::Scalar));
    let mut worst = vec![0.0f64; kernels.len()];
    for &n in &[1usize, 7, 8, 15, 16, 17, 31, 33, 1001, 4093] {
        let block = Block::random(&mut rng, n + 3);
        for _ in 0..2 {
            let case = random_case(&mut rng, n);
            let offset = rng.random_range(0..=3usize);
            for (c, w) in kernels.iter().zip(worst.iter_mut()) {
                for fmt in [Fmt::Cf32, Fmt::Ci16, Fmt::Ci8] {
                    let e = check(c, fmt, block.slice(fmt, offset..offset + n), &code, &case);
                    *w = w.max(e);
                }
            }
        }
    }
    for (c, w) in kernels.iter().zip(worst) {
        println!("{}: worst |err - edge| / sum|x| = {w:.2e}", c.name());
    }
}

#[test]
fn long_blocks_do_not_drift() {
    // 40000 samples (10 ms at 4 MHz, 156 rotator re-seeds of the AVX-512 kernel, 2500 steps):
    // the error stays within the per-sample carrier bound, it does not grow with n.
    let mut rng = StdRng::seed_from_u64(77);
    let code = CaCode::new(Prn::new(3).unwrap_or_else(|e| panic!("{e}")));
    let n = 40_000;
    let block = Block::random(&mut rng, n + 1);
    for rate in [0.0, 4000.0] {
        let case = Case {
            fs: 4.0e6,
            taps: vec![-0.5, 0.0, 0.5],
            state: ReplicaState {
                code_phase_chips: 1000.3,
                code_rate_chips_s: 1.023e6 + 3.1,
                carrier_phase_cycles: 0.37,
                carrier_freq_hz: 1.25e6 + 3456.7,
                carrier_rate_hz_s: rate,
            },
        };
        for c in Correlator::available() {
            for fmt in [Fmt::Cf32, Fmt::Ci16, Fmt::Ci8] {
                let worst = check(&c, fmt, block.slice(fmt, 1..n + 1), &code, &case);
                // Rotator kernels: far below the table's pi/4096 after 2500 vector steps.
                if c.isa() != Isa::Scalar {
                    assert!(worst < 1e-4, "{} {fmt:?}: {worst}", c.name());
                }
                println!("rate {rate}: {} {fmt:?}: {worst:.2e}", c.name());
            }
        }
    }
}

#[test]
fn carrier_free_replica_gives_the_exact_integer_sum() {
    // With phase, frequency and rate 0 the rotator is exactly 1 (and Q14 exactly 2^14), so on
    // integer samples a SIMD kernel must return exactly sum_k x[k] code(p(k) >> 32) with the
    // fixed-point code NCO below: a bit-exact check of the vectorised code generation (carries,
    // wraps past chip 1023, negative taps, any fs).
    let mut rng = StdRng::seed_from_u64(5);
    let code = CaCode::new(Prn::new(29).unwrap_or_else(|e| panic!("{e}")));
    for _ in 0..40 {
        let n = rng.random_range(1..3000usize);
        let block = Block::random(&mut rng, n + 2);
        let fs = rng.random_range(0.6e6..25e6);
        let state = ReplicaState {
            code_phase_chips: rng.random_range(-1023.0..2046.0),
            code_rate_chips_s: 1.023e6 + rng.random_range(-10.0..10.0),
            carrier_phase_cycles: 0.0,
            carrier_freq_hz: 0.0,
            carrier_rate_hz_s: 0.0,
        };
        let taps: Vec<f64> = (0..rng.random_range(1..=8))
            .map(|_| rng.random_range(-3.0..3.0))
            .collect();
        let step = (state.code_rate_chips_s / fs * 4_294_967_296.0).round() as u64;
        let len = 1023u64 << 32;
        for fmt in [Fmt::Ci16, Fmt::Ci8] {
            let x = block.slice(fmt, 2..n + 2);
            let xf = as_f64(x);
            let exact: Vec<(f64, f64)> = taps
                .iter()
                .map(|d| {
                    let c = (state.code_phase_chips + d).rem_euclid(1023.0);
                    let mut p = ((c * 4_294_967_296.0) as u64) % len;
                    let (mut re, mut im) = (0.0, 0.0);
                    for &(xr, xi) in &xf {
                        let chip = f64::from(code.chip((p >> 32) as usize));
                        re += chip * xr;
                        im += chip * xi;
                        p = (p + step) % len;
                    }
                    (re, im)
                })
                .collect();
            for c in Correlator::available() {
                if c.isa() == Isa::Scalar {
                    continue;
                }
                let mut out = vec![Complex32::new(0.0, 0.0); taps.len()];
                c.correlate(x, fs, code.chips(), &state, &taps, &mut out);
                for (o, &(re, im)) in out.iter().zip(&exact) {
                    // Integer sums below 2^24 are exact in f32; ci16 sums are larger, and the
                    // f32 lane sums round: allow the f32 rounding of the lane sums. The
                    // int16-lane kernels on full-scale ci16 (headroom shift 0) work in units
                    // of 2 samples: an odd component is off by 1 (int16_lanes module doc).
                    let tol = if fmt == Fmt::Ci8 && c.arithmetic() == Arithmetic::F32 {
                        0.0
                    } else {
                        let halves = match (c.arithmetic(), headroom_shift(&xf)) {
                            (Arithmetic::I16, 0) if fmt == Fmt::Ci16 => n as f64,
                            _ => 0.0,
                        };
                        (re.abs() + im.abs() + 32768.0 * n as f64) * 2e-7 + halves
                    };
                    assert!(
                        (f64::from(o.re) - re).abs() <= tol && (f64::from(o.im) - im).abs() <= tol,
                        "{} {fmt:?} n {n} fs {fs}: {o} vs ({re}, {im})",
                        c.name()
                    );
                }
            }
        }
    }
}

#[test]
fn api_names_and_choice() {
    let best = Correlator::best();
    assert_eq!(best.arithmetic(), Arithmetic::F32);
    let all = Correlator::available();
    assert!(all.iter().any(|c| c.isa() == best.isa()));
    let scalar = Correlator::new(Isa::Scalar, Arithmetic::I16)
        .unwrap_or_else(|| panic!("scalar is always available"));
    assert_eq!(scalar.name(), "scalar/i16");
    for c in &all {
        assert_eq!(
            Correlator::new(c.isa(), c.arithmetic()).map(|k| k.name()),
            Some(c.name())
        );
    }
    // An empty block sums to zero.
    let mut out = [Complex32::new(1.0, 1.0); 2];
    let s = ReplicaState {
        code_phase_chips: 0.0,
        code_rate_chips_s: 1.023e6,
        carrier_phase_cycles: 0.0,
        carrier_freq_hz: 0.0,
        carrier_rate_hz_s: 0.0,
    };
    let code = CaCode::new(Prn::new(1).unwrap_or_else(|e| panic!("{e}")));
    for c in all {
        out = [Complex32::new(1.0, 1.0); 2];
        c.correlate(
            SampleSlice::Ci8(&[]),
            4e6,
            code.chips(),
            &s,
            &[0.0, 1.0],
            &mut out,
        );
        assert_eq!(out, [Complex32::new(0.0, 0.0); 2], "{}", c.name());
    }
    assert_eq!(out.len(), 2);
}

#[test]
fn steps_beyond_the_code_window_fall_back_to_the_scalar_kernel() {
    // At fs = 0.2 MHz the code advances 5.1 chips per sample: an 8-lane vector would span 36
    // chips, more than the 32-bit code window, so the SIMD correlators must hand the block to
    // the scalar kernel of the same arithmetic and return exactly its sums.
    let mut rng = StdRng::seed_from_u64(11);
    let code = CaCode::new(Prn::new(9).unwrap_or_else(|e| panic!("{e}")));
    let block = Block::random(&mut rng, 500);
    let s = ReplicaState {
        code_phase_chips: 10.5,
        code_rate_chips_s: 1.023e6,
        carrier_phase_cycles: 0.2,
        carrier_freq_hz: 1000.0,
        carrier_rate_hz_s: 0.0,
    };
    let taps = [-0.5, 0.0, 0.5];
    for c in Correlator::available() {
        let scalar = Correlator::new(Isa::Scalar, c.arithmetic())
            .unwrap_or_else(|| panic!("scalar is always available"));
        for fmt in [Fmt::Cf32, Fmt::Ci16, Fmt::Ci8] {
            let x = block.slice(fmt, 0..500);
            let (mut a, mut b) = ([Complex32::new(0.0, 0.0); 3], [Complex32::new(0.0, 0.0); 3]);
            c.correlate(x, 0.2e6, code.chips(), &s, &taps, &mut a);
            scalar.correlate(x, 0.2e6, code.chips(), &s, &taps, &mut b);
            assert_eq!(a, b, "{} {fmt:?}", c.name());
        }
    }
}

#[test]
fn meaningless_states_give_nan_not_a_panic() {
    // fs = 0 or a NaN carrier phase is a caller's bug upstream; no kernel may panic or return
    // plausible numbers: every output is NaN (the reference too).
    let code = CaCode::new(Prn::new(2).unwrap_or_else(|e| panic!("{e}")));
    let x = vec![[3i8, -4]; 100];
    let good = ReplicaState {
        code_phase_chips: 5.0,
        code_rate_chips_s: 1.023e6,
        carrier_phase_cycles: 0.0,
        carrier_freq_hz: 100.0,
        carrier_rate_hz_s: 0.0,
    };
    for c in Correlator::available() {
        for (fs, s) in [
            (
                4e6,
                ReplicaState {
                    carrier_phase_cycles: f64::NAN,
                    ..good
                },
            ),
            (0.0, good),
        ] {
            let mut out = [Complex32::new(0.0, 0.0); 2];
            c.correlate(
                SampleSlice::Ci8(&x),
                fs,
                code.chips(),
                &s,
                &[0.0, 0.5],
                &mut out,
            );
            if c.isa() != Isa::Scalar {
                assert!(
                    out.iter().all(|o| o.re.is_nan()),
                    "{} fs {fs}: {out:?}",
                    c.name()
                );
            }
        }
    }
}

/// The SIMD int16 correlators this CPU runs (the int16-lane kernels: AVX2 16 lanes, AVX-512
/// 32 lanes).
fn simd_i16() -> Vec<Correlator> {
    [Isa::Avx2Fma, Isa::Avx512]
        .into_iter()
        .filter_map(|isa| Correlator::new(isa, Arithmetic::I16))
        .collect()
}

/// ci16 samples with headroom (the ci8 values times 16: shift 4), on which the int16-lane
/// kernels' carrier-free sums are exact.
fn ci16_with_headroom(x: &[[i8; 2]]) -> Vec<[i16; 2]> {
    x.iter()
        .map(|&[i, q]| [i16::from(i) * 16, i16::from(q) * 16])
        .collect()
}

#[test]
fn int16_lane_kernels_match_the_references_from_1p1_to_40_mhz() {
    // The 16-lane (AVX2) and 32-lane (AVX-512) kernels (16 chips per window) run from about
    // 1.1 and 2.27 MHz up; below, the 8- or 16-lane i32 kernels. Log-uniform rates over the
    // whole range, every tap count (9 and 10: two chunks), block lengths around the vector
    // steps and past the 8192-sample flush/re-seed, ci8 and full-scale ci16.
    let kernels = simd_i16();
    let mut rng = StdRng::seed_from_u64(1640);
    let code = CaCode::new(Prn::new(24).unwrap_or_else(|e| panic!("{e}")));
    for c in &kernels {
        let mut worst = 0.0f64;
        for &n in &[
            1usize, 15, 16, 17, 31, 33, 255, 4095, 4096, 4113, 8192, 8200, 9000,
        ] {
            let block = Block::random(&mut rng, n + 3);
            for taps in 1..=10usize {
                let mut case = random_case(&mut rng, n);
                case.fs = (rng.random_range(1.1e6f64.ln()..40e6f64.ln())).exp();
                case.state.carrier_freq_hz = rng.random_range(-0.3..0.3) * case.fs;
                case.taps = (0..taps).map(|_| rng.random_range(-2.5..2.5)).collect();
                let offset = rng.random_range(0..=3usize);
                for fmt in [Fmt::Ci8, Fmt::Ci16] {
                    let x = block.slice(fmt, offset..offset + n);
                    worst = worst.max(check(c, fmt, x, &code, &case));
                }
            }
        }
        println!("{}: worst |err - edge| / sum|x| = {worst:.2e}", c.name());
    }
}

/// `sum_k x[k] code(p(k) >> 32)` with the fixed-point code NCO (no carrier), exact in f64.
fn integer_sum(x: &[[i8; 2]], fs: f64, code: &CaCode, s: &ReplicaState, d: f64) -> (f64, f64) {
    let step = (s.code_rate_chips_s / fs * 4_294_967_296.0).round() as u64;
    let len = 1023u64 << 32;
    let c = (s.code_phase_chips + d).rem_euclid(1023.0);
    let mut p = ((c * 4_294_967_296.0) as u64) % len;
    let (mut re, mut im) = (0.0, 0.0);
    for v in x {
        let chip = f64::from(code.chip((p >> 32) as usize));
        re += chip * f64::from(v[0]);
        im += chip * f64::from(v[1]);
        p = (p + step) % len;
    }
    (re, im)
}

#[test]
fn int16_lane_kernels_and_their_fallbacks_pick_the_chips_exactly() {
    // Carrier-free (the Q14 carrier is exactly 2^14, the products exact at a headroom shift
    // of 1 or more): the output must be the exact integer sum, on ci8 and on ci16 with
    // headroom, on both sides of the 16- and 32-lane kernels' limits (about 1.1 and 2.2 MHz)
    // and at the common front-end rates 4.092 and 16.368 MHz (S a simple fraction of 2^32:
    // several lanes share a threshold).
    let mut rng = StdRng::seed_from_u64(99);
    let code = CaCode::new(Prn::new(5).unwrap_or_else(|e| panic!("{e}")));
    for c in simd_i16() {
        for fs in [
            0.7e6, 1.0e6, 1.07e6, 1.1e6, 1.2e6, 2.046e6, 2.2e6, 2.3e6, 4.092e6, 16.368e6, 40e6,
        ] {
            for _ in 0..6 {
                let n = rng.random_range(1..5000usize);
                let block = Block::random(&mut rng, n);
                let ci16 = ci16_with_headroom(&block.ci8);
                let state = ReplicaState {
                    code_phase_chips: rng.random_range(-1023.0..2046.0),
                    code_rate_chips_s: 1.023e6 + [0.0, rng.random_range(-10.0..10.0)][n % 2],
                    carrier_phase_cycles: 0.0,
                    carrier_freq_hz: 0.0,
                    carrier_rate_hz_s: 0.0,
                };
                let taps: Vec<f64> = (0..rng.random_range(1..=8))
                    .map(|_| rng.random_range(-3.0..3.0))
                    .collect();
                for (scale, x) in [
                    (1.0, SampleSlice::Ci8(&block.ci8)),
                    (16.0, SampleSlice::Ci16(&ci16)),
                ] {
                    let mut out = vec![Complex32::new(0.0, 0.0); taps.len()];
                    c.correlate(x, fs, code.chips(), &state, &taps, &mut out);
                    for (o, &d) in out.iter().zip(&taps) {
                        let (re, im) = integer_sum(&block.ci8, fs, &code, &state, d);
                        assert_eq!(
                            (f64::from(o.re), f64::from(o.im)),
                            (re * scale, im * scale),
                            "{} {x:?} fs {fs} n {n} tap {d}",
                            c.name()
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn a_lane_plan_kept_between_calls_carries_nothing_over() {
    // The int16-lane kernels keep one code plan per thread and rewrite only the taps of each
    // call: after a call with 8 taps on ci16, one on ci8 whose 32-lane plan fails part-way
    // (at 2.187 MHz a step spans 14.5 chips: the first tap fits, the one 0.9 chip further
    // does not; the 16-lane kernel then runs), a 3-tap call must give exactly the integer
    // sums of a fresh plan.
    let mut rng = StdRng::seed_from_u64(2026);
    let code = CaCode::new(Prn::new(17).unwrap_or_else(|e| panic!("{e}")));
    let block = Block::random(&mut rng, 4000);
    let ci16 = ci16_with_headroom(&block.ci8);
    let state = |phase: f64| ReplicaState {
        code_phase_chips: phase,
        code_rate_chips_s: 1.023e6 + 3.5,
        carrier_phase_cycles: 0.0,
        carrier_freq_hz: 0.0,
        carrier_rate_hz_s: 0.0,
    };
    let wide_taps = [-2.9, -1.7, -0.6, 0.0, 0.45, 1.3, 2.2, 2.95];
    let taps = [-0.5, 0.0, 0.5];
    for c in simd_i16() {
        let mut out8 = [Complex32::new(0.0, 0.0); 8];
        c.correlate(
            SampleSlice::Ci16(&ci16),
            4.092e6,
            code.chips(),
            &state(811.3),
            &wide_taps,
            &mut out8,
        );
        c.correlate(
            SampleSlice::Ci8(&block.ci8),
            2.187e6,
            code.chips(),
            &state(5.0),
            &wide_taps,
            &mut out8,
        );
        for fs in [4.092e6, 16.368e6] {
            let s = state(97.25);
            let mut out = [Complex32::new(0.0, 0.0); 3];
            c.correlate(
                SampleSlice::Ci8(&block.ci8),
                fs,
                code.chips(),
                &s,
                &taps,
                &mut out,
            );
            for (o, &d) in out.iter().zip(&taps) {
                let (re, im) = integer_sum(&block.ci8, fs, &code, &s, d);
                assert_eq!(
                    (f64::from(o.re), f64::from(o.im)),
                    (re, im),
                    "{} fs {fs} tap {d}",
                    c.name()
                );
            }
        }
    }
}

mod prop {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The carrier-free sums of the int16-lane kernels on ci8 and on ci16 with headroom
        /// are exact for any code phase, rate, taps and block length.
        #[test]
        fn int16_lane_carrier_free_sums_are_exact(
            seed in any::<u64>(),
            n in 1usize..2500,
            fs in 1.0e6f64..40e6,
            code_phase in -1023.0f64..2046.0,
            doppler in -10.0f64..10.0,
            taps in proptest::collection::vec(-3.0f64..3.0, 1..=8),
        ) {
            let mut rng = StdRng::seed_from_u64(seed);
            let code = CaCode::new(Prn::new(11).unwrap_or_else(|e| panic!("{e}")));
            let block = Block::random(&mut rng, n);
            let state = ReplicaState {
                code_phase_chips: code_phase,
                code_rate_chips_s: 1.023e6 + doppler,
                carrier_phase_cycles: 0.0,
                carrier_freq_hz: 0.0,
                carrier_rate_hz_s: 0.0,
            };
            let ci16 = ci16_with_headroom(&block.ci8);
            for c in simd_i16() {
                for (scale, x) in [
                    (1.0, SampleSlice::Ci8(&block.ci8)),
                    (16.0, SampleSlice::Ci16(&ci16)),
                ] {
                    let mut out = vec![Complex32::new(0.0, 0.0); taps.len()];
                    c.correlate(x, fs, code.chips(), &state, &taps, &mut out);
                    for (o, &d) in out.iter().zip(&taps) {
                        let (re, im) = integer_sum(&block.ci8, fs, &code, &state, d);
                        prop_assert_eq!((f64::from(o.re), f64::from(o.im)), (re * scale, im * scale));
                    }
                }
            }
        }
    }
}

#[test]
fn auto_arithmetic_runs_the_faster_kernel_of_each_format() {
    // Auto = I16 of the correlator's own ISA on ci8 and ci16 where the int16-lane kernels run
    // (AVX2 or wider, fs >= 1.1 MHz), F32 otherwise (cf32, lower rates, scalar):
    // bit-identical outputs to the explicit kernel, and the same name for what runs.
    let mut rng = StdRng::seed_from_u64(404);
    let code = CaCode::new(Prn::new(8).unwrap_or_else(|e| panic!("{e}")));
    let block = Block::random(&mut rng, 3001);
    assert!(!Correlator::available()
        .iter()
        .any(|c| c.arithmetic() == Arithmetic::Auto));
    for fs in [1.0e6, 2.048e6, 4.0e6, 16.368e6] {
        let mut case = random_case(&mut rng, 3001);
        case.fs = fs;
        for isa in Isa::ALL.into_iter().filter(|i| i.is_available()) {
            let auto = Correlator::best_up_to(isa, Arithmetic::Auto);
            assert_eq!(auto.isa(), isa);
            assert_eq!(auto.arithmetic(), Arithmetic::Auto);
            for fmt in [Fmt::Ci8, Fmt::Ci16, Fmt::Cf32] {
                let int16 = fmt != Fmt::Cf32 && isa >= Isa::Avx2Fma && fs >= 1.1e6;
                let arithmetic = if int16 {
                    Arithmetic::I16
                } else {
                    Arithmetic::F32
                };
                let explicit = Correlator::new(isa, arithmetic)
                    .unwrap_or_else(|| panic!("{isa:?} is available"));
                let x = block.slice(fmt, 0..3001);
                let mut a = vec![Complex32::new(0.0, 0.0); case.taps.len()];
                let mut b = a.clone();
                auto.correlate(x, case.fs, code.chips(), &case.state, &case.taps, &mut a);
                explicit.correlate(x, case.fs, code.chips(), &case.state, &case.taps, &mut b);
                assert_eq!(a, b, "{isa:?} {fmt:?} fs {fs}");
                let name = match fmt {
                    Fmt::Ci8 => "ci8",
                    Fmt::Ci16 => "ci16",
                    Fmt::Cf32 => "cf32",
                };
                assert_eq!(auto.resolved_for(name, fs).name(), explicit.name());
                assert_eq!(auto.kernel_for(name, fs), explicit.kernel_for(name, fs));
            }
        }
    }
}

#[test]
fn kernel_names_say_how_many_lanes_run() {
    // The int16-lane kernels: AVX2 16 lanes from 1.1 MHz on ci8 and ci16; AVX-512 32 lanes
    // from 2.27 MHz where the CPU has VNNI (else the AVX2 16-lane kernel); cf32 runs f32.
    if let Some(c) = Correlator::new(Isa::Avx2Fma, Arithmetic::I16) {
        assert_eq!(c.kernel_for("ci16", 4e6), "avx2+fma/i16 (16 lanes)");
        assert_eq!(c.kernel_for("ci8", 1.0e6), "avx2+fma/i16 (8 lanes)");
        assert_eq!(c.kernel_for("cf32", 4e6), "avx2+fma/f32 (8 lanes)");
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(c) = Correlator::new(Isa::Avx512, Arithmetic::I16) {
        let wide = if std::arch::is_x86_feature_detected!("avx512vnni") {
            "avx512/i16 (32 lanes)"
        } else {
            "avx2+fma/i16 (16 lanes)"
        };
        assert_eq!(c.kernel_for("ci8", 4e6), wide);
        assert_eq!(c.kernel_for("ci16", 2.048e6), "avx2+fma/i16 (16 lanes)");
        assert_eq!(c.kernel_for("ci16", 1.0e6), "avx512/i16 (16 lanes)");
        assert_eq!(c.kernel_for("cf32", 4e6), "avx512/f32 (16 lanes)");
    }
}
