//! Street-level landmark ranges with 3 satellites (seed 001 section 3.3): every geometry whose
//! Jacobian at the truth fixes position and clock well (rank 4, PDOP at most
//! [`ALLOWS_PDOP`]) must give a fix in every epoch, with errors consistent with the noise.
//! Epochs come from brdc0010.22n and the independent forward model of `common.rs`; each
//! geometry is solved over consecutive noisy epochs from the previous fix, as the receiver
//! does.

use crate::common::{brdc, forward, Gauss, NO_ATMOS};
use gpsrx_nav::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::pvt::{
    solve, Landmark, PvtError, PvtOptions, PvtSolution, SatMeasurement, Weighting,
};
use gpsrx_nav::{enu_rotation, Ephemeris, GpsTime, Llh, Vector3};
use nalgebra::{Matrix3, Matrix4, Vector4};

/// A geometry "allows a fix" when the 4x4 Jacobian of 3 satellites + 1 landmark at the truth
/// has rank 4 and PDOP at most this. Beyond it the two solutions of the exactly determined
/// problem (100 |u.n| m apart, u the landmark direction, n the satellite curve's) come within
/// a few sigma of each other and the noisy curve can graze or miss the range sphere: some
/// epochs are then refused as weak geometry (PvtError::WeakGeometry) or jump to the other
/// solution.
const ALLOWS_PDOP: f64 = 3.0;
/// Pseudorange sigma, m (carrier-smoothed code).
const SIGMA_PR_M: f64 = 1.5;
/// Landmark distance, m, and its range sigma (2 %, seed 001).
const LANDMARK_M: f64 = 50.0;
/// Consecutive epochs per geometry.
const EPOCHS: usize = 12;

struct Sat {
    eph: Ephemeris,
    pr: f64,
    tx: GpsTime,
    los: Vector3<f64>,
}

/// Satellites above 10 deg at Seoul, 2022-01-01 05:30 GPS, exact pseudoranges.
fn sky(truth_pos: &Vector3<f64>, t: GpsTime, clock_m: f64) -> Vec<Sat> {
    let nav = brdc();
    nav.prns()
        .into_iter()
        .filter_map(|prn| {
            let eph = nav.select(prn, t)?.clone();
            let (pr, tx, el) = forward(&eph, truth_pos, t, clock_m, NO_ATMOS);
            let los = (eph.sv_state(tx).pos_m - truth_pos).normalize();
            (el.to_degrees() > 10.0).then_some(Sat { eph, pr, tx, los })
        })
        .collect()
}

/// Cofactor (G^T G)^-1 of 3 satellite rows and one landmark row along `u`, if rank 4.
fn truth_pdop(sats: &[&Sat], u: &Vector3<f64>) -> Option<f64> {
    let mut g = Matrix4::<f64>::zeros();
    for s in sats {
        let a = Vector4::new(-s.los.x, -s.los.y, -s.los.z, 1.0);
        g += a * a.transpose();
    }
    let a = Vector4::new(u.x, u.y, u.z, 0.0);
    g += a * a.transpose();
    let q = g.try_inverse()?;
    let p = q.fixed_view::<3, 3>(0, 0).trace();
    (p > 0.0 && p.is_finite()).then(|| p.sqrt())
}

fn opts() -> PvtOptions {
    PvtOptions {
        tropo: false,
        weighting: Weighting::Uniform {
            sigma_m: SIGMA_PR_M,
        },
        ..PvtOptions::default()
    }
}

/// Outcome of one geometry over [`EPOCHS`] epochs.
#[derive(Default)]
struct Tally {
    fixes: usize,
    weak: usize,
    other_errors: Vec<String>,
    /// Sum of e^T C^-1 e (3D position error against the reported covariance).
    nees_sum: f64,
    err_sq_sum: f64,
}

/// Noisy measurements of `sats`.
fn noisy<'a>(sats: &[&'a Sat], g: &mut Gauss) -> Vec<SatMeasurement<'a>> {
    sats.iter()
        .map(|s| SatMeasurement {
            prn: s.eph.prn,
            pseudorange_m: s.pr + SIGMA_PR_M * g.normal(),
            doppler_hz: None,
            cn0_dbhz: 45.0,
            tx_time: Some(s.tx),
            ephemeris: &s.eph,
        })
        .collect()
}

/// `sats` over [`EPOCHS`] epochs from `prior` (the last fix before the other satellites were
/// lost), each epoch from the previous fix.
fn run_geometry(
    sats: &[&Sat],
    lm: &Landmark,
    truth: &Vector3<f64>,
    t_rx: GpsTime,
    prior: Option<PvtSolution>,
    g: &mut Gauss,
) -> Tally {
    let opts = opts();
    let mut tally = Tally::default();
    let mut prior = prior;
    for _ in 0..EPOCHS {
        let meas = noisy(sats, g);
        let noisy = Landmark {
            range_m: lm.range_m + lm.sigma_m * g.normal(),
            ..*lm
        };
        match solve(t_rx, &meas, &[noisy], &opts, prior.as_ref()) {
            Ok(sol) => {
                let e = sol.pos_ecef_m - truth;
                let c: Matrix3<f64> = sol.covariance.fixed_view::<3, 3>(0, 0).into_owned();
                let nees = c
                    .try_inverse()
                    .map_or(f64::INFINITY, |ci| (e.transpose() * ci * e)[0]);
                tally.nees_sum += nees;
                tally.err_sq_sum += e.norm_squared();
                tally.fixes += 1;
                prior = Some(sol);
            }
            Err(PvtError::WeakGeometry { .. }) => tally.weak += 1,
            Err(e) => tally.other_errors.push(e.to_string()),
        }
    }
    tally
}

#[test]
fn street_level_landmark_and_three_satellites_fix_wherever_the_geometry_allows() {
    let origin = Llh::from_degrees(37.5665, 126.978, 40.0);
    let truth = origin.to_ecef();
    let clock_m = 1e-4 * SPEED_OF_LIGHT_MPS;
    let t_true = GpsTime::new(2190, 538_200.0);
    let t_rx = t_true.add_seconds(clock_m / SPEED_OF_LIGHT_MPS);
    let all = sky(&truth, t_true, clock_m);
    assert!(all.len() >= 6, "{} satellites", all.len());
    let to_ecef = enu_rotation(&origin).transpose();
    let mut g = Gauss(2011);
    // Bins of truth PDOP: (upper edge, geometries, epochs, fixes, weak, nees sum, err^2 sum).
    let edges = [ALLOWS_PDOP, 4.0, 5.0, 10.0, 20.0, 50.0, f64::INFINITY];
    let mut bins = vec![(0usize, 0usize, 0usize, 0usize, 0.0f64, 0.0f64); edges.len()];
    let mut failures = Vec::new();
    let mut diverged = 0;
    for i in 0..all.len() {
        for j in i + 1..all.len() {
            for k in j + 1..all.len() {
                let three = [&all[i], &all[j], &all[k]];
                for b in 0..12 {
                    let (sb, cb) = (f64::from(b) * 30f64.to_radians()).sin_cos();
                    // u points from the landmark to the receiver, horizontally.
                    let u = to_ecef * Vector3::new(sb, cb, 0.0);
                    let Some(pdop) = truth_pdop(&three, &u) else {
                        continue;
                    };
                    let lm = Landmark {
                        ecef_m: truth - LANDMARK_M * u,
                        range_m: LANDMARK_M,
                        sigma_m: 0.02 * LANDMARK_M,
                    };
                    // The fix before: all satellites in view.
                    let everyone: Vec<&Sat> = all.iter().collect();
                    let before = solve(t_rx, &noisy(&everyone, &mut g), &[], &opts(), None).ok();
                    let tally = run_geometry(&three, &lm, &truth, t_rx, before, &mut g);
                    let bin = edges
                        .iter()
                        .position(|e| pdop <= *e)
                        .unwrap_or(edges.len() - 1);
                    let s = &mut bins[bin];
                    s.0 += 1;
                    s.1 += EPOCHS;
                    s.2 += tally.fixes;
                    s.3 += tally.weak;
                    s.4 += tally.nees_sum;
                    s.5 += tally.err_sq_sum;
                    diverged += tally.other_errors.len();
                    if pdop <= ALLOWS_PDOP && tally.fixes < EPOCHS {
                        failures.push(format!(
                            "PRNs {} {} {} bearing {} deg PDOP {pdop:.1}: {} fixes, {} weak, {:?}",
                            three[0].eph.prn,
                            three[1].eph.prn,
                            three[2].eph.prn,
                            30 * b,
                            tally.fixes,
                            tally.weak,
                            tally.other_errors.first()
                        ));
                    }
                }
            }
        }
    }
    println!("truth PDOP <=  geometries  epochs  fixes  weak  NEES/3  3D RMS (m)");
    for (e, s) in edges.iter().zip(&bins) {
        println!(
            "{e:>12.0}  {:>10}  {:>6}  {:>5}  {:>4}  {:>6.2}  {:>9.2}",
            s.0,
            s.1,
            s.2,
            s.3,
            s.4 / (3.0 * s.2.max(1) as f64),
            (s.5 / s.2.max(1) as f64).sqrt()
        );
    }
    for f in failures.iter().take(20) {
        println!("{f}");
    }
    assert!(failures.is_empty(), "{} geometries failed", failures.len());
    // Errors consistent with the reported covariance where the geometry allows a fix: the
    // normalised squared error e^T C^-1 e averages 3 (chi-square, 3 degrees of freedom).
    let (n_ok, nees) = bins[..1]
        .iter()
        .fold((0, 0.0), |(n, s), b| (n + b.2, s + b.4));
    let nees_per_dof = nees / (3.0 * n_ok as f64);
    assert!(
        n_ok >= 300 && (0.75..1.33).contains(&nees_per_dof),
        "NEES/3 {nees_per_dof:.2} over {n_ok} fixes"
    );
    // Up to PDOP 10: at least 97 % of the epochs give a fix, and almost none fails to converge
    // (the rest is refused as weak geometry with a message saying so).
    let (epochs, fixes) = bins[..4]
        .iter()
        .fold((0, 0), |(e, f), b| (e + b.1, f + b.2));
    let availability = fixes as f64 / epochs as f64;
    let total: usize = bins.iter().map(|b| b.1).sum();
    println!("PDOP <= 10: {fixes} fixes in {epochs} epochs; not converged {diverged} of {total}");
    assert!(availability > 0.97, "availability {availability:.3}");
    assert!(
        (diverged as f64) < 0.005 * total as f64,
        "{diverged} not converged"
    );
}
