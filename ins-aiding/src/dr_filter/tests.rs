//! Tests of the fusion filter: F against finite differences, updates, heading initialisation.

use super::*;
use crate::dr_mechanization::dr_step;

/// The mechanization row as a function of the full state (position, heading, parameters):
/// returns (position, velocity, heading) after the row.
fn row(x: &[f64; 8], gyro_v: f64, pulses: f64, dt: f64) -> [f64; 5] {
    let p = DrParams {
        sf_g_dps_per_v: x[5],
        v_nom_v: x[6],
        sf_n_m_per_pulse: x[7],
    };
    let s = dr_step(&p, x[4], gyro_v, pulses, dt);
    [
        x[0] + s.dpos_m[0],
        x[1] + s.dpos_m[1],
        s.vel_mps[0],
        s.vel_mps[1],
        s.heading_rad,
    ]
}

/// F against central differences of the mechanization: each error state perturbed by
/// +-h, the row re-run, the outputs differenced. Agreement to 1e-6 relative (h^2 truncation
/// and rounding are far below), for a straight row, a gentle turn and a sharp turn.
#[test]
fn transition_matches_finite_differences_of_the_mechanization() {
    let base = [120.0, -40.0, 0.0, 0.0, 0.7, 47.9, 2.48, 0.098];
    let h = [1e-3, 1e-3, 1e-3, 1e-3, 1e-6, 1e-5, 1e-7, 1e-7];
    for (gyro_v, pulses, dt) in [
        (2.48, 150.0, 0.1),
        (2.48 + 1e-7, 150.0, 0.1),
        (2.53, 120.0, 0.1),
        (2.9, 80.0, 0.5),
    ] {
        let m = row_model(
            &DrParams {
                sf_g_dps_per_v: base[5],
                v_nom_v: base[6],
                sf_n_m_per_pulse: base[7],
            },
            base[4],
            gyro_v,
            pulses,
            dt,
        );
        for j in 0..8 {
            let mut xp = base;
            let mut xm = base;
            xp[j] += h[j];
            xm[j] -= h[j];
            let (fp, fm) = (row(&xp, gyro_v, pulses, dt), row(&xm, gyro_v, pulses, dt));
            for i in 0..5 {
                let fd = (fp[i] - fm[i]) / (2.0 * h[j]);
                let an = m.f[(i, j)];
                let tol = 1e-6 * (1.0 + an.abs());
                assert!(
                    (fd - an).abs() < tol,
                    "F[{i},{j}] = {an}, finite difference {fd} (gyro {gyro_v} V, {pulses} pulses, dt {dt})"
                );
            }
            // Parameters are random walks: identity rows.
            for i in 5..8 {
                assert_eq!(m.f[(i, j)], if i == j { 1.0 } else { 0.0 });
            }
        }
        // Noise inputs: a heading-increment error (through V_g) and a pulse error (velocity).
        let k = std::f64::consts::PI / 180.0 * base[5] * dt;
        let dv = 1e-7;
        let (fp, fm) = (
            row(&base, gyro_v + dv, pulses, dt),
            row(&base, gyro_v - dv, pulses, dt),
        );
        for i in 0..5 {
            let fd = (fp[i] - fm[i]) / (2.0 * dv * k);
            assert!(
                (fd - m.g_heading[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                "G_psi[{i}]"
            );
        }
        let (fp, fm) = (
            row(&base, gyro_v, pulses + 1e-3, dt),
            row(&base, gyro_v, pulses - 1e-3, dt),
        );
        for i in 2..4 {
            let fd = (fp[i] - fm[i]) / 2e-3;
            assert!(
                (fd - m.g_pulse_vel[i]).abs() < 1e-6 * (1.0 + fd.abs()),
                "G_N[{i}]"
            );
        }
    }
}

#[test]
fn course_over_ground_needs_speed() {
    let h = heading_from_velocity(10.0, -10.0, MIN_COURSE_SPEED_MPS);
    assert!(h.is_some_and(|h| (h - 135f64.to_radians()).abs() < 1e-12));
    assert!(heading_from_velocity(1.0, 1.0, MIN_COURSE_SPEED_MPS).is_none());
    assert!(heading_from_velocity(f64::NAN, 1.0, MIN_COURSE_SPEED_MPS).is_none());
}

#[test]
fn updates_check_their_input_and_the_4_state_filter_ignores_velocity() {
    let mut f = DrFusion::new(
        DrFilterKind::Conventional4,
        DrParams::default(),
        0.0,
        0.0,
        0.0,
        DrFilterConfig::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(f.covariance().nrows(), 4);
    let r = Matrix2::new(4.0, 0.0, 0.0, 4.0);
    assert!(f.update_velocity(1.0, 2.0, r).is_ok_and(|n| n.is_none()));
    assert!(f.update_position(f64::NAN, 0.0, r).is_err());
    assert!(f
        .update_position(0.0, 0.0, Matrix2::new(1.0, 2.0, 2.0, 1.0))
        .is_err());
    assert!(f
        .update_position(0.0, 0.0, Matrix2::new(1.0, 0.5, 0.0, 1.0))
        .is_err());
    assert_eq!(f.fix_source(1.5), FixSource::DrOnly);
    // A 3 m east offset with 10 m prior sigma and 2 m measurement sigma: gain 100/104.
    let nis = f
        .update_position(-3.0, 0.0, r)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!((nis - 9.0 / 104.0).abs() < 1e-12);
    assert!((f.state().east_m + 3.0 * 100.0 / 104.0).abs() < 1e-12);
    assert!((f.position_covariance()[(0, 0)] - 400.0 / 104.0).abs() < 1e-9);
    assert_eq!(f.state_variance(2), None);
    let bad = DrFilterConfig {
        init_pos_sigma_m: 0.0,
        ..DrFilterConfig::default()
    };
    assert!(DrFusion::new(
        DrFilterKind::Proposed8,
        DrParams::default(),
        0.0,
        0.0,
        0.0,
        bad
    )
    .is_err());
}
