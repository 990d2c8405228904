//! PVT solver against synthetic epochs built from the real broadcast ephemerides of
//! brdc0010.22n with the independent forward model of `common.rs` (light-time iteration, Earth
//! rotation by an explicit z rotation, SV clock from `sv_state`, optional Klobuchar and
//! Saastamoinen, receiver clock bias and drift; Dopplers by numerical differentiation of that
//! model in time). Noise comes from the seeded splitmix64 + Box-Muller generator of
//! `common.rs`, so every statistic below is reproducible.

use crate::common::{brdc, forward, Atmos, Gauss, NO_ATMOS};
use gpsrx_nav::constants::{F_L1_HZ, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::pvt::{
    chi_square_quantile, solve, Landmark, PvtError, PvtOptions, PvtSolution, RaimStatus,
    SatMeasurement, Weighting,
};
use gpsrx_nav::{enu_rotation, Ephemeris, GpsTime, Llh, NavData, Vector3};

const C: f64 = SPEED_OF_LIGHT_MPS;

/// The receiver's true state; `t_true` is GPS time of reception.
#[derive(Clone, Copy)]
struct Truth {
    pos: Vector3<f64>,
    vel: Vector3<f64>,
    clock_m: f64,
    drift_mps: f64,
    t_true: GpsTime,
}

/// One simulated satellite observation (owning the ephemeris).
struct Obs {
    eph: Ephemeris,
    pr: f64,
    doppler: f64,
    tx: GpsTime,
    el: f64,
}

fn seoul() -> Llh {
    Llh::from_degrees(37.5665, 126.978, 40.0)
}

fn epoch() -> GpsTime {
    GpsTime::new(2190, 538_200.0)
}

fn static_truth() -> Truth {
    Truth {
        pos: seoul().to_ecef(),
        vel: Vector3::zeros(),
        clock_m: 1e-4 * C,
        drift_mps: 0.0,
        t_true: epoch(),
    }
}

/// All satellites above 5 deg at the truth, with exact pseudoranges and Dopplers.
fn simulate(nav: &NavData, truth: &Truth, atm: Atmos<'_>) -> Vec<Obs> {
    let h = 0.05;
    let at = |eph: &Ephemeris, dt: f64| {
        let pos = truth.pos + truth.vel * dt;
        let clock = truth.clock_m + truth.drift_mps * dt;
        forward(eph, &pos, truth.t_true.add_seconds(dt), clock, atm)
    };
    let mut out = Vec::new();
    for prn in nav.prns() {
        let Some(eph) = nav.select(prn, truth.t_true) else {
            continue;
        };
        let (pr, tx, el) = at(eph, 0.0);
        if el.to_degrees() <= 5.0 {
            continue;
        }
        let rate = (at(eph, h).0 - at(eph, -h).0) / (2.0 * h);
        out.push(Obs {
            eph: eph.clone(),
            pr,
            doppler: -rate * F_L1_HZ / C,
            tx,
            el,
        });
    }
    out
}

fn measurements<'a>(obs: &'a [Obs], noise: &[f64]) -> Vec<SatMeasurement<'a>> {
    obs.iter()
        .enumerate()
        .map(|(i, o)| SatMeasurement {
            prn: o.eph.prn,
            pseudorange_m: o.pr + noise.get(i).copied().unwrap_or(0.0),
            doppler_hz: Some(o.doppler),
            cn0_dbhz: 45.0,
            tx_time: Some(o.tx),
            ephemeris: &o.eph,
        })
        .collect()
}

fn rx_epoch(truth: &Truth) -> GpsTime {
    truth.t_true.add_seconds(truth.clock_m / C)
}

fn uniform_opts(sigma_m: f64) -> PvtOptions {
    PvtOptions {
        tropo: false,
        weighting: Weighting::Uniform { sigma_m },
        ..PvtOptions::default()
    }
}

#[test]
fn noise_free_fix_with_atmosphere_is_exact() {
    let nav = brdc();
    let iono = nav.iono.expect("brdc has Klobuchar coefficients");
    let truth = static_truth();
    let atm = Atmos {
        iono: Some(&iono),
        tropo: true,
    };
    let obs = simulate(&nav, &truth, atm);
    assert!(obs.len() >= 6, "{} satellites", obs.len());
    let opts = PvtOptions {
        iono: Some(iono),
        tropo: true,
        ..PvtOptions::default()
    };
    let sol = solve(rx_epoch(&truth), &measurements(&obs, &[]), &[], &opts, None)
        .expect("noise-free epoch solves");
    let pos_err = (sol.pos_ecef_m - truth.pos).norm();
    let clk_err = (sol.clock_bias_m - truth.clock_m).abs();
    println!(
        "noise-free: {} SV, pos err {pos_err:.2e} m, clock err {clk_err:.2e} m, {} iterations, \
         DOP g/p/h/v {:.3}/{:.3}/{:.3}/{:.3}",
        sol.n_sv, sol.iterations, sol.dop.gdop, sol.dop.pdop, sol.dop.hdop, sol.dop.vdop
    );
    assert!(pos_err < 1e-3 && clk_err < 1e-3);
    assert!(sol.time.diff_s(truth.t_true).abs() < 1e-9);
    assert_eq!(sol.raim, RaimStatus::Ok);
    assert_eq!(sol.n_sv, obs.len());
    assert!((sol.llh.h_m - 40.0).abs() < 1e-3);
    // Ignoring the atmosphere the solver must be off by metres: the corrections matter.
    let bare = PvtOptions {
        raim: false,
        ..uniform_opts(3.0)
    };
    let off = solve(rx_epoch(&truth), &measurements(&obs, &[]), &[], &bare, None)
        .expect("solves without corrections");
    assert!((off.pos_ecef_m - truth.pos).norm() > 2.0);
    // A prior gives the same answer.
    let again = solve(
        rx_epoch(&truth),
        &measurements(&obs, &[]),
        &[],
        &opts,
        Some(&sol),
    )
    .expect("solves from prior");
    assert!((again.pos_ecef_m - truth.pos).norm() < 1e-3);
    assert!(again.iterations < sol.iterations);
}

#[test]
fn moving_receiver_velocity_and_drift_noise_free() {
    let nav = brdc();
    let r = enu_rotation(&seoul()).transpose();
    let truth = Truth {
        vel: r * Vector3::new(12.0, 16.0, 1.0), // 20 m/s horizontal, 1 m/s up
        drift_mps: 45.0,                        // 1.5e-7 s/s
        ..static_truth()
    };
    let obs = simulate(&nav, &truth, NO_ATMOS);
    let sol = solve(
        rx_epoch(&truth),
        &measurements(&obs, &[]),
        &[],
        &uniform_opts(3.0),
        None,
    )
    .expect("solves");
    let vel = sol.vel_ecef_mps.expect("velocity from Dopplers");
    let drift = sol.clock_drift_mps.expect("drift");
    let v_err = (vel - truth.vel).norm();
    let d_err = (drift - truth.drift_mps).abs();
    let pos_err = (sol.pos_ecef_m - truth.pos).norm();
    println!("velocity: err {v_err:.2e} m/s, drift err {d_err:.2e} m/s, pos err {pos_err:.2e} m");
    assert!(v_err < 1e-3 && d_err < 1e-3 && pos_err < 1e-3);
    // The 1 mm/s bound is tight enough to catch a missing light-time factor k in the
    // range-rate model (dropping it gave 2.0 mm/s velocity and 1.9 mm/s drift errors).
    let cov = sol.vel_covariance.expect("velocity covariance");
    assert!((0..4).all(|i| cov[(i, i)] > 0.0));
    // No Dopplers: no velocity, position still fine.
    let mut m = measurements(&obs, &[]);
    m.iter_mut().for_each(|x| x.doppler_hz = None);
    let s2 = solve(rx_epoch(&truth), &m, &[], &uniform_opts(3.0), None).expect("solves");
    assert!(s2.vel_ecef_mps.is_none() && s2.clock_drift_mps.is_none());
}

#[test]
fn noisy_epochs_match_pdop_and_covariance() {
    let nav = brdc();
    let truth = static_truth();
    let obs = simulate(&nav, &truth, NO_ATMOS);
    let opts = uniform_opts(3.0);
    let mut g = Gauss(1);
    let (mut sum_sq, mut sum_pred, mut sum_s0) = (0.0, 0.0, 0.0);
    let mut pdop = 0.0;
    let n_epochs = 200;
    for _ in 0..n_epochs {
        let noise: Vec<f64> = obs.iter().map(|_| 3.0 * g.normal()).collect();
        let sol = solve(
            rx_epoch(&truth),
            &measurements(&obs, &noise),
            &[],
            &opts,
            None,
        )
        .expect("fix");
        sum_sq += (sol.pos_ecef_m - truth.pos).norm_squared();
        sum_pred += sol.covariance.fixed_view::<3, 3>(0, 0).trace();
        sum_s0 += sol.sigma0 * sol.sigma0;
        pdop = sol.dop.pdop;
    }
    let rms = (sum_sq / f64::from(n_epochs)).sqrt();
    let expected = 3.0 * pdop;
    let pred = (sum_pred / f64::from(n_epochs)).sqrt();
    let s0 = (sum_s0 / f64::from(n_epochs)).sqrt();
    println!(
        "noise 3 m, {} SV: 3D RMS {rms:.3} m, sigma*PDOP {expected:.3} m (PDOP {pdop:.3}), \
         covariance-predicted {pred:.3} m, rms sigma0 {s0:.3}",
        obs.len()
    );
    assert!((rms / expected - 1.0).abs() < 0.3);
    assert!((pred / rms - 1.0).abs() < 0.3);
    assert!((s0 - 1.0).abs() < 0.15);
}

#[test]
fn raim_excludes_a_100_m_fault_on_any_satellite() {
    let nav = brdc();
    let truth = static_truth();
    let obs = simulate(&nav, &truth, NO_ATMOS);
    assert!(obs.len() >= 6);
    let opts = uniform_opts(1.0);
    // Noise-free: every satellite in turn.
    for k in 0..obs.len() {
        let mut bias = vec![0.0; obs.len()];
        bias[k] = 100.0;
        let sol = solve(
            rx_epoch(&truth),
            &measurements(&obs, &bias),
            &[],
            &opts,
            None,
        )
        .expect("fix");
        let prn = obs[k].eph.prn;
        assert_eq!(
            sol.raim,
            RaimStatus::FaultExcluded { prn },
            "fault on PRN {prn}"
        );
        assert!(!sol.used_prns.contains(&prn));
        assert!((sol.pos_ecef_m - truth.pos).norm() < 1e-3);
    }
    // With 1 m noise, 50 seeded trials on random satellites.
    let mut g = Gauss(7);
    let mut worst = 0.0f64;
    for trial in 0..50 {
        let k = trial % obs.len();
        let mut e: Vec<f64> = obs.iter().map(|_| g.normal()).collect();
        e[k] += 100.0;
        let sol = solve(rx_epoch(&truth), &measurements(&obs, &e), &[], &opts, None).expect("fix");
        let prn = obs[k].eph.prn;
        assert_eq!(sol.raim, RaimStatus::FaultExcluded { prn }, "trial {trial}");
        worst = worst.max((sol.pos_ecef_m - truth.pos).norm());
    }
    println!("RAIM 100 m fault, 1 m noise: worst error after exclusion {worst:.2} m");
    assert!(worst < 6.0);
}

#[test]
fn raim_with_five_satellites_detects_but_cannot_exclude() {
    let nav = brdc();
    let truth = static_truth();
    let mut obs = simulate(&nav, &truth, NO_ATMOS);
    obs.sort_by(|a, b| b.el.total_cmp(&a.el));
    obs.truncate(5);
    let opts = uniform_opts(1.0);
    let clean = solve(rx_epoch(&truth), &measurements(&obs, &[]), &[], &opts, None).expect("fix");
    assert_eq!(clean.raim, RaimStatus::Ok);
    let bias = [100.0, 0.0, 0.0, 0.0, 0.0];
    let sol = solve(
        rx_epoch(&truth),
        &measurements(&obs, &bias),
        &[],
        &opts,
        None,
    )
    .expect("fix");
    assert_eq!(sol.raim, RaimStatus::FaultDetectedNotExcluded);
    assert_eq!(sol.n_sv, 5);
    // Four satellites: no redundancy.
    let four = solve(
        rx_epoch(&truth),
        &measurements(&obs[..4], &bias),
        &[],
        &opts,
        None,
    )
    .expect("fix");
    assert_eq!(four.raim, RaimStatus::Unavailable);
}

#[test]
fn raim_false_alarm_rate_matches_pfa() {
    let nav = brdc();
    let truth = static_truth();
    let obs = simulate(&nav, &truth, NO_ATMOS);
    let opts = PvtOptions {
        raim_pfa: 1e-2,
        ..uniform_opts(3.0)
    };
    let mut g = Gauss(2024);
    let n = 2000;
    let mut alarms = 0;
    for _ in 0..n {
        let noise: Vec<f64> = obs.iter().map(|_| 3.0 * g.normal()).collect();
        let sol = solve(
            rx_epoch(&truth),
            &measurements(&obs, &noise),
            &[],
            &opts,
            None,
        )
        .expect("fix");
        if sol.raim != RaimStatus::Ok {
            alarms += 1;
        }
    }
    let rate = f64::from(alarms) / f64::from(n);
    println!("RAIM false-alarm rate {rate:.4} at pfa 0.01 ({alarms}/{n})");
    assert!((0.005..=0.02).contains(&rate));
}

#[test]
fn chi_square_quantile_matches_tables() {
    // Standard table values (e.g. NIST/SEMATECH e-Handbook, 1.3.6.7.4), 3 decimals.
    let cases = [
        (0.999, 1.0, 10.828),
        (0.999, 4.0, 18.467),
        (0.99, 10.0, 23.209),
        (0.95, 2.0, 5.991),
        (0.95, 30.0, 43.773),
        (0.999, 100.0, 149.449),
        (0.5, 1.0, 0.455),
        (0.01, 5.0, 0.554),
    ];
    for (p, k, want) in cases {
        let got = chi_square_quantile(p, k).expect("valid arguments");
        assert!(
            (got - want).abs() < 1.5e-3,
            "chi2({p}, {k}) = {got}, table {want}"
        );
    }
    assert!(chi_square_quantile(1.0, 3.0).is_none());
    assert!(chi_square_quantile(0.5, 0.0).is_none());
    assert!(chi_square_quantile(f64::NAN, 3.0).is_none());
}

/// Unit line of sight from `pos` to the satellite of `o` (geometry only, for the test setup).
fn los(o: &Obs, pos: &Vector3<f64>) -> Vector3<f64> {
    (o.eph.sv_state(o.tx).pos_m - pos).normalize()
}

/// Position DOP of 3 satellite rows plus one landmark row along `u`.
fn pdop_3sv_landmark(l: &[Vector3<f64>; 3], u: &Vector3<f64>) -> f64 {
    let mut g = nalgebra::Matrix4::<f64>::zeros();
    let rows = [
        nalgebra::Vector4::new(-l[0].x, -l[0].y, -l[0].z, 1.0),
        nalgebra::Vector4::new(-l[1].x, -l[1].y, -l[1].z, 1.0),
        nalgebra::Vector4::new(-l[2].x, -l[2].y, -l[2].z, 1.0),
        nalgebra::Vector4::new(u.x, u.y, u.z, 0.0),
    ];
    for a in rows {
        g += a * a.transpose();
    }
    g.try_inverse()
        .map_or(f64::INFINITY, |q| q.fixed_view::<3, 3>(0, 0).trace().sqrt())
}

/// Three satellites and a landmark 50 m away horizontally (a building seen by a camera): the
/// triple and the landmark bearing (every 10 deg) with the smallest PDOP. Also returns the
/// satellites not chosen.
fn landmark_setup() -> (Vec<Obs>, Truth, Landmark, Vec<Obs>) {
    let nav = brdc();
    let truth = static_truth();
    let all = simulate(&nav, &truth, NO_ATMOS);
    let to_ecef = enu_rotation(&seoul()).transpose();
    let n = all.len();
    let mut best = (f64::INFINITY, [0, 1, 2], Vector3::zeros());
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let l = [
                    los(&all[i], &truth.pos),
                    los(&all[j], &truth.pos),
                    los(&all[k], &truth.pos),
                ];
                for b in 0..36 {
                    let (sb, cb) = (f64::from(b) * 10f64.to_radians()).sin_cos();
                    let u = to_ecef * Vector3::new(sb, cb, 0.0);
                    let pdop = pdop_3sv_landmark(&l, &u);
                    if pdop < best.0 {
                        best = (pdop, [i, j, k], u);
                    }
                }
            }
        }
    }
    let (_, idx, u) = best;
    let mut three = Vec::new();
    let mut rest = Vec::new();
    for (i, o) in all.into_iter().enumerate() {
        if idx.contains(&i) {
            three.push(o);
        } else {
            rest.push(o);
        }
    }
    // u points from the landmark to the receiver.
    let lm_pos = truth.pos - 50.0 * u;
    let lm = Landmark {
        ecef_m: lm_pos,
        range_m: 50.0,
        sigma_m: 0.02 * 50.0,
    };
    (three, truth, lm, rest)
}

#[test]
fn three_satellites_and_a_landmark_fix() {
    let (three, truth, lm, rest) = landmark_setup();
    let opts = uniform_opts(3.0);
    let sol = solve(
        rx_epoch(&truth),
        &measurements(&three, &[]),
        &[lm],
        &opts,
        None,
    )
    .expect("3 SV + 1 landmark fix");
    let err = (sol.pos_ecef_m - truth.pos).norm();
    println!(
        "3 SV + landmark noise-free: err {err:.2e} m, PDOP {:.2}, without landmark {:?}",
        sol.dop.pdop, sol.dop_without_landmarks
    );
    assert!(err < 1e-3);
    assert!(sol.dop_without_landmarks.is_none());
    assert_eq!(sol.raim, RaimStatus::Unavailable);
    assert!(solve(
        rx_epoch(&truth),
        &measurements(&three, &[]),
        &[],
        &opts,
        None
    )
    .is_err());

    // Noisy: 3 m satellites, 2 % landmark; errors against the reported covariance.
    let mut g = Gauss(99);
    let (mut sum_sq, mut sum_pred) = (0.0, 0.0);
    let n = 200;
    let mut lm_noisy = lm;
    for _ in 0..n {
        let noise: Vec<f64> = three.iter().map(|_| 3.0 * g.normal()).collect();
        lm_noisy.range_m = lm.range_m + lm.sigma_m * g.normal();
        let s = solve(
            rx_epoch(&truth),
            &measurements(&three, &noise),
            &[lm_noisy],
            &opts,
            None,
        )
        .expect("noisy fix");
        sum_sq += (s.pos_ecef_m - truth.pos).norm_squared();
        // No redundancy: the covariance is the a-priori N^-1.
        sum_pred += s.covariance.fixed_view::<3, 3>(0, 0).trace();
    }
    let rms = (sum_sq / f64::from(n)).sqrt();
    let pred = (sum_pred / f64::from(n)).sqrt();
    println!("3 SV + landmark, noisy: 3D RMS {rms:.2} m, predicted {pred:.2} m");
    assert!((rms / pred - 1.0).abs() < 0.3);

    // Four satellites + the landmark: DOP with and without it.
    let mut four = three;
    four.push(rest.into_iter().next().expect("a fourth satellite"));
    let s4 = solve(
        rx_epoch(&truth),
        &measurements(&four, &[]),
        &[lm],
        &opts,
        None,
    )
    .expect("fix");
    let without = s4.dop_without_landmarks.expect("4 SV alone fix");
    println!(
        "4 SV + landmark: PDOP {:.2} (HDOP {:.2}, VDOP {:.2}); without landmark PDOP {:.2} \
         (HDOP {:.2}, VDOP {:.2})",
        s4.dop.pdop, s4.dop.hdop, s4.dop.vdop, without.pdop, without.hdop, without.vdop
    );
    assert!(s4.dop.pdop < without.pdop);
    assert!((s4.pos_ecef_m - truth.pos).norm() < 1e-3);
}

#[test]
fn bad_input_is_rejected_with_clear_errors() {
    let nav = brdc();
    let truth = static_truth();
    let obs = simulate(&nav, &truth, NO_ATMOS);
    let opts = uniform_opts(3.0);
    let t = rx_epoch(&truth);
    let m = measurements(&obs, &[]);

    let err = solve(t, &m[..3], &[], &opts, None).expect_err("3 satellites");
    assert!(matches!(
        err,
        PvtError::TooFewObservations { available: 3, .. }
    ));
    assert!(err.to_string().contains("need at least 4"));

    let mut nan = m.clone();
    nan[1].pseudorange_m = f64::NAN;
    let err = solve(t, &nan, &[], &opts, None).expect_err("NaN pseudorange");
    assert!(matches!(
        err,
        PvtError::InvalidMeasurement {
            field: "pseudorange_m",
            ..
        }
    ));
    assert!(err.to_string().contains(&format!("PRN {}", obs[1].eph.prn)));

    let mut dup = m.clone();
    dup.push(m[0]);
    let err = solve(t, &dup, &[], &opts, None).expect_err("duplicate");
    assert_eq!(
        err,
        PvtError::DuplicatePrn {
            prn: obs[0].eph.prn
        }
    );

    let mut mismatch = m.clone();
    mismatch[0].ephemeris = &obs[1].eph;
    assert!(matches!(
        solve(t, &mismatch, &[], &opts, None),
        Err(PvtError::EphemerisMismatch { .. })
    ));

    let mut inf_doppler = m.clone();
    inf_doppler[0].doppler_hz = Some(f64::INFINITY);
    assert!(solve(t, &inf_doppler, &[], &opts, None).is_err());

    let lm = Landmark {
        ecef_m: truth.pos,
        range_m: 10.0,
        sigma_m: 0.0,
    };
    assert!(matches!(
        solve(t, &m, &[lm], &opts, None),
        Err(PvtError::InvalidLandmark {
            field: "sigma_m",
            ..
        })
    ));

    let bad_pfa = PvtOptions {
        raim_pfa: 0.0,
        ..opts
    };
    assert!(matches!(
        solve(t, &m, &[], &bad_pfa, None),
        Err(PvtError::InvalidOption { .. })
    ));

    let high_mask = PvtOptions {
        elevation_mask_deg: 89.0,
        ..opts
    };
    assert!(matches!(
        solve(t, &m, &[], &high_mask, None),
        Err(PvtError::TooFewObservations {
            stage: "elevation mask",
            ..
        })
    ));

    // Identical lines of sight cannot be solved: the same satellite under four PRN labels.
    let mut clones: Vec<Ephemeris> = Vec::new();
    for prn in 1..=4u8 {
        let mut e = obs[0].eph.clone();
        e.prn = prn;
        clones.push(e);
    }
    let same: Vec<SatMeasurement<'_>> = clones
        .iter()
        .map(|e| SatMeasurement {
            prn: e.prn,
            ephemeris: e,
            ..m[0]
        })
        .collect();
    let r: Result<PvtSolution, PvtError> = solve(t, &same, &[], &opts, None);
    assert!(matches!(r, Err(PvtError::SingularGeometry { .. })));
}

#[test]
fn elevation_cn0_sigma_model() {
    let w = Weighting::ElevationCn0 {
        a_m: 1.5,
        b_m: 1.5,
        cn0_ref_dbhz: 45.0,
    };
    // sigma^2 = (a^2 + b^2 / sin^2 el) 10^((45 - cn0)/10)
    let zenith = w.sigma_m(90f64.to_radians(), 45.0);
    assert!((zenith - 4.5f64.sqrt()).abs() < 1e-12);
    let low_weak = w.sigma_m(30f64.to_radians(), 35.0);
    assert!((low_weak - (11.25f64 * 10.0).sqrt()).abs() < 1e-9);
    assert!((w.cn0_scale(42.0) - 10f64.powf(0.3)).abs() < 1e-12);
    let u = Weighting::Uniform { sigma_m: 3.0 };
    assert_eq!(u.sigma_m(0.1, 20.0), 3.0);
}
