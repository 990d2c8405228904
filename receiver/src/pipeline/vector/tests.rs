//! Tests of the vector wing against independent truth: a synthetic constellation whose truth
//! follows the filter's own process model (consistency: NEES), a biased channel, a clock step.

use super::ekf::{
    ClockModel, Covariance, FilterParams, NavFilter, Row, RowKind, State, BIAS, DRIFT, N_STATES,
};
use crate::pipeline::test_support::Noise;
use nalgebra::{SVector, Vector3};

/// 8 satellites 26,560 km from the Earth's centre, all above the receiver's horizon.
fn constellation(rx: &Vector3<f64>) -> Vec<Vector3<f64>> {
    let up = rx.normalize();
    let east = Vector3::z().cross(&up).normalize();
    let north = up.cross(&east);
    [
        (0.0, 80.0),
        (40.0, 30.0),
        (100.0, 50.0),
        (160.0, 20.0),
        (210.0, 60.0),
        (260.0, 35.0),
        (310.0, 15.0),
        (350.0, 45.0),
    ]
    .iter()
    .map(|&(az, el): &(f64, f64)| {
        let (az, el) = (az.to_radians(), el.to_radians());
        let dir = (east * az.sin() + north * az.cos()) * el.cos() + up * el.sin();
        // The point 26,560 km from the centre along the line of sight from the receiver.
        let b = rx.dot(&dir);
        let c = rx.norm_squared() - 26_560e3f64.powi(2);
        let s = -b + (b * b - c).sqrt();
        rx + dir * s
    })
    .collect()
}

const CODE_SIGMA_M: f64 = 3.0;
const RATE_SIGMA_MPS: f64 = 0.05;

/// Rows of one epoch for a truth `t` seen about the prior `x` (static satellites), with an
/// extra error `bias(prn)` on a pseudorange.
fn rows(
    sats: &[Vector3<f64>],
    t: &State,
    x: &State,
    noise: &mut Noise,
    bias: &dyn Fn(u8) -> f64,
) -> Vec<Row> {
    let (rt, vt) = (
        t.fixed_rows::<3>(0).into_owned(),
        t.fixed_rows::<3>(3).into_owned(),
    );
    let (rx, vx) = (
        x.fixed_rows::<3>(0).into_owned(),
        x.fixed_rows::<3>(3).into_owned(),
    );
    let mut out = Vec::new();
    for (i, s) in sats.iter().enumerate() {
        let prn = i as u8 + 1;
        let ut = (s - rt).normalize();
        let z_code = (s - rt).norm() + t[BIAS] + CODE_SIGMA_M * noise.normal() + bias(prn);
        let z_rate = -ut.dot(&vt) + t[DRIFT] + RATE_SIGMA_MPS * noise.normal();
        let u = (s - rx).normalize();
        let mut h = SVector::<f64, N_STATES>::zeros();
        h.fixed_rows_mut::<3>(0).copy_from(&(-u));
        h[BIAS] = 1.0;
        out.push(Row {
            prn,
            kind: RowKind::Code,
            innovation: z_code - ((s - rx).norm() + x[BIAS]),
            h,
            var: CODE_SIGMA_M * CODE_SIGMA_M,
        });
        let mut h = SVector::<f64, N_STATES>::zeros();
        h.fixed_rows_mut::<3>(3).copy_from(&(-u));
        h[DRIFT] = 1.0;
        out.push(Row {
            prn,
            kind: RowKind::Doppler,
            innovation: z_rate - (-u.dot(&vx) + x[DRIFT]),
            h,
            var: RATE_SIGMA_MPS * RATE_SIGMA_MPS,
        });
    }
    out
}

fn params(gate: f64) -> FilterParams {
    FilterParams {
        accel_psd_m2_s3: 0.5,
        clock: ClockModel::TCXO,
        gate,
    }
}

/// A sample of `N(0, Q)` through the Cholesky factor of `Q`.
fn process_sample(q: &Covariance, noise: &mut Noise) -> State {
    let l = q
        .cholesky()
        .map(|c| c.l())
        .unwrap_or_else(Covariance::zeros);
    let w = State::from_fn(|_, _| noise.normal());
    l * w
}

fn start_truth() -> State {
    let r = gpsrx_core::Llh::from_degrees(37.5665, 126.978, 40.0).to_ecef();
    let mut t = State::zeros();
    t.fixed_rows_mut::<3>(0).copy_from(&r);
    t.fixed_rows_mut::<3>(3)
        .copy_from(&Vector3::new(12.0, -5.0, 3.0));
    t[BIAS] = 1500.0;
    t[DRIFT] = 30.0;
    t
}

/// One run: truth following the model's process noise, the filter started off truth by a draw
/// of its own initial covariance; returns the NEES at the end and the filter.
fn run(seed: u64, epochs: usize, dt: f64) -> (f64, NavFilter, State) {
    let mut noise = Noise(seed);
    let p0 = Covariance::from_diagonal(&SVector::from([
        400.0, 400.0, 400.0, 4.0, 4.0, 4.0, 1e4, 1.0,
    ]));
    let mut truth = start_truth();
    let x0 = truth
        + p0.map(f64::sqrt)
            .diagonal()
            .component_mul(&State::from_fn(|_, _| noise.normal()));
    let mut f = NavFilter::new(x0, p0, params(f64::INFINITY));
    let sats = constellation(&truth.fixed_rows::<3>(0).into_owned());
    let q = NavFilter::process_noise(&params(0.0), dt);
    for _ in 0..epochs {
        truth = NavFilter::transition(dt) * truth + process_sample(&q, &mut noise);
        f.predict(dt);
        let r = rows(&sats, &truth, f.state(), &mut noise, &|_| 0.0);
        f.update(&r);
    }
    let e = truth - f.state();
    let nees = (e.transpose()
        * f.covariance()
            .try_inverse()
            .unwrap_or_else(Covariance::zeros)
        * e)[(0, 0)];
    (nees, f, truth)
}

#[test]
fn the_filter_is_consistent_on_a_synthetic_constellation() {
    // 40 runs of 10 s at 10 Hz: the mean NEES of a consistent 8-state filter is chi-square of
    // 320 degrees of freedom over 40: 8 +- 0.63 (1 sigma); 99.9 %: 6.1 to 10.2.
    let runs = 40;
    let mut sum = 0.0;
    let mut pos_err_over_sigma: f64 = 0.0;
    for k in 0..runs {
        let (nees, f, truth) = run(0x5eed_0000 + k, 100, 0.1);
        sum += nees;
        let err = (truth.fixed_rows::<3>(0) - f.position_m()).norm();
        pos_err_over_sigma = pos_err_over_sigma.max(err / f.position_sigma_m());
    }
    let mean = sum / runs as f64;
    eprintln!("mean NEES {mean:.2} over {runs} runs, largest position error {pos_err_over_sigma:.2} sigma");
    assert!((6.1..=10.2).contains(&mean), "mean NEES {mean}");
    // Every run's position within 4 of its 3-D sigmas (an 8-satellite fix: about 2 m).
    assert!(pos_err_over_sigma < 4.0, "{pos_err_over_sigma}");
}

#[test]
fn a_biased_channel_is_excluded_and_does_not_drag_the_rest() {
    let dt = 0.1;
    let (_, mut f, mut truth) = run(7, 100, dt);
    let sats = constellation(&truth.fixed_rows::<3>(0).into_owned());
    let mut unguarded = f.clone();
    let gate = params(10.83);
    f = NavFilter::new(*f.state(), *f.covariance(), gate);
    let mut noise = Noise(99);
    let q = NavFilter::process_noise(&gate, dt);
    let mut excluded = 0;
    let mut others = 0;
    for _ in 0..50 {
        truth = NavFilter::transition(dt) * truth + process_sample(&q, &mut noise);
        let bias = |prn: u8| if prn == 3 { 80.0 } else { 0.0 };
        let mut n2 = Noise(noise.0);
        f.predict(dt);
        unguarded.predict(dt);
        let out = f.update(&rows(&sats, &truth, f.state(), &mut noise, &bias));
        unguarded.update(&rows(&sats, &truth, unguarded.state(), &mut n2, &bias));
        excluded += out
            .rejected
            .iter()
            .filter(|(p, k, _)| *p == 3 && *k == RowKind::Code)
            .count();
        others += out.rejected.iter().filter(|(p, _, _)| *p != 3).count();
    }
    assert_eq!(excluded, 50, "the 80 m bias is caught at every epoch");
    // The other 750 rows: false alarms at the gate's 1e-3 only (Poisson mean 0.75: 5 or more
    // has probability 1e-3).
    assert!(others < 5, "{others} rows of healthy channels excluded");
    let err = (truth.fixed_rows::<3>(0) - f.position_m()).norm();
    let err_unguarded = (truth.fixed_rows::<3>(0) - unguarded.position_m()).norm();
    assert!(
        err < 3.0 * f.position_sigma_m(),
        "{err} m, sigma {}",
        f.position_sigma_m()
    );
    // Without the test the same bias drags the position (the test can fail).
    assert!(
        err_unguarded > 2.0 * err.max(1.0),
        "{err_unguarded} vs {err}"
    );
}

#[test]
fn a_receiver_clock_step_goes_to_the_clock_bias() {
    let (_, mut f, truth) = run(11, 50, 0.1);
    let sats = constellation(&truth.fixed_rows::<3>(0).into_owned());
    let mut stepped = truth;
    stepped[BIAS] += 299_792.458; // a 1 ms step of the receiver clock
    let mut noise = Noise(5);
    let out = f.update(&rows(&sats, &stepped, f.state(), &mut noise, &|_| 0.0));
    let step = out.clock_step_m.unwrap_or(0.0);
    assert!((step - 299_792.458).abs() < 50.0, "{step}");
    assert!(out.rejected.is_empty(), "{:?}", out.rejected);
    assert!((f.state()[BIAS] - stepped[BIAS]).abs() < 20.0);
}

#[test]
fn process_noise_is_the_closed_form() {
    // Clock: c^2 (h0/2 dt + 2 pi^2 h-2 dt^3 / 3) for the bias, c^2 2 pi^2 h-2 dt for the drift.
    let p = params(10.0);
    let q = NavFilter::process_noise(&p, 1.0);
    let c2 = 299_792_458.0f64.powi(2);
    let sg = 2.0 * std::f64::consts::PI.powi(2) * 2e-20;
    assert!((q[(BIAS, BIAS)] - c2 * (1e-19 + sg / 3.0)).abs() < 1e-9 * q[(BIAS, BIAS)]);
    assert!((q[(DRIFT, DRIFT)] - c2 * sg).abs() < 1e-9 * q[(DRIFT, DRIFT)]);
    assert!((q[(0, 0)] - 0.5 / 3.0).abs() < 1e-12 && (q[(0, 3)] - 0.25).abs() < 1e-12);
}
