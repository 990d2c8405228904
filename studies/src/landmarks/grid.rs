//! One Monte Carlo cell: `n_sat` satellites drawn from those in view at a random epoch of the
//! broadcast day and `n_lm` street-level landmarks (bearing uniform, range uniform in
//! [`LANDMARK_RANGE_M`], at the antenna's height, so their rows [u^T, 0] are horizontal), with
//! noisy pseudoranges and 2 % landmark ranges. The geometry at the truth gives PDOP/HDOP (rank
//! 4 or no fix possible); [`gpsrx_nav::pvt::solve`] from the previous fix (all satellites in
//! view) says whether a fix is obtained.

use super::params::*;
use gpsrx_nav::constants::{OMEGA_E_DOT_RAD_S, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::pvt::dop::{dop_enu, Dop};
use gpsrx_nav::pvt::{solve, Landmark, PvtOptions, SatMeasurement, Weighting};
use gpsrx_nav::{azimuth_elevation, enu_rotation, Ephemeris, GpsTime, Llh, NavData, Vector3};
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// One cell of the grid.
#[derive(Debug, Clone, Copy)]
pub struct Cell {
    /// Satellites used.
    pub n_sat: usize,
    /// Landmarks used.
    pub n_lm: usize,
}

/// Outcome of one trial.
#[derive(Debug, Clone, Copy)]
pub struct Trial {
    /// DOP at the truth (None: rank < 4, no fix possible).
    pub dop: Option<Dop>,
    /// The solver gave a fix with PDOP <= [`USABLE_PDOP`]; its 3D error, m.
    pub fix_error_m: Option<f64>,
}

/// A satellite in view: ephemeris, exact pseudorange, raw transmit time, line of sight.
struct InView {
    eph: Ephemeris,
    pr_m: f64,
    tx: GpsTime,
    los: Vector3<f64>,
}

/// Exact pseudorange at `t` (true GPS time) with the light time and the Earth's rotation
/// (IS-GPS-200 20.3.3.4.3.4), receiver clock `clock_m`.
fn forward(eph: &Ephemeris, pos: &Vector3<f64>, t: GpsTime, clock_m: f64) -> Option<InView> {
    let mut tau = 0.07;
    let mut sv = eph.sv_state(t);
    let mut s_rot = sv.pos_m;
    for _ in 0..6 {
        sv = eph.sv_state(t.add_seconds(-tau));
        let th = OMEGA_E_DOT_RAD_S * tau;
        let p = sv.pos_m;
        s_rot = Vector3::new(
            th.cos() * p.x + th.sin() * p.y,
            -th.sin() * p.x + th.cos() * p.y,
            p.z,
        );
        tau = (s_rot - pos).norm() / SPEED_OF_LIGHT_MPS;
    }
    let (_, el) = azimuth_elevation(pos, &s_rot);
    (el.to_degrees() >= ELEVATION_MASK_DEG).then(|| InView {
        eph: eph.clone(),
        pr_m: SPEED_OF_LIGHT_MPS * tau + clock_m - SPEED_OF_LIGHT_MPS * sv.clock_bias_s,
        tx: t.add_seconds(-tau).add_seconds(sv.clock_bias_s),
        los: (s_rot - pos).normalize(),
    })
}

fn opts() -> PvtOptions {
    PvtOptions {
        tropo: false,
        weighting: Weighting::Uniform {
            sigma_m: PSEUDORANGE_SIGMA_M,
        },
        ..PvtOptions::default()
    }
}

fn measurements<'a>(sats: &[&'a InView], rng: &mut Xoshiro256PlusPlus) -> Vec<SatMeasurement<'a>> {
    let n = Normal::new(0.0, PSEUDORANGE_SIGMA_M).unwrap_or_else(|_| unreachable!());
    sats.iter()
        .map(|s| SatMeasurement {
            prn: s.eph.prn,
            pseudorange_m: s.pr_m + n.sample(rng),
            doppler_hz: None,
            cn0_dbhz: 45.0,
            tx_time: Some(s.tx),
            ephemeris: &s.eph,
        })
        .collect()
}

/// Runs `trials` geometries of `cell` from `seed` (the same seed gives the same numbers).
pub fn run_cell(nav: &NavData, cell: Cell, trials: usize, seed: u64) -> Vec<Trial> {
    let cell_seed = seed ^ ((cell.n_sat as u64) << 32) ^ ((cell.n_lm as u64) << 48);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(cell_seed);
    let site = Llh::from_degrees(SITE_LLH.0, SITE_LLH.1, SITE_LLH.2);
    let truth = site.to_ecef();
    let to_ecef = enu_rotation(&site).transpose();
    let clock_m = 1e-4 * SPEED_OF_LIGHT_MPS;
    let mut out = Vec::with_capacity(trials);
    while out.len() < trials {
        let t = GpsTime::new(WEEK, rng.random_range(TOW_RANGE_S.0..TOW_RANGE_S.1));
        let t_rx = t.add_seconds(clock_m / SPEED_OF_LIGHT_MPS);
        let in_view: Vec<InView> = nav
            .prns()
            .into_iter()
            .filter_map(|p| forward(nav.select(p, t)?, &truth, t, clock_m))
            .collect();
        if in_view.len() < cell.n_sat.max(4) {
            continue;
        }
        let all: Vec<&InView> = in_view.iter().collect();
        let chosen: Vec<&InView> = all.choose_multiple(&mut rng, cell.n_sat).copied().collect();
        let landmarks: Vec<(Vector3<f64>, Landmark)> = (0..cell.n_lm)
            .map(|_| {
                let az = rng.random_range(0.0..std::f64::consts::TAU);
                let range = rng.random_range(LANDMARK_RANGE_M.0..LANDMARK_RANGE_M.1);
                let u = to_ecef * Vector3::new(az.sin(), az.cos(), 0.0);
                let sigma = LANDMARK_SIGMA_FRACTION * range;
                let noisy =
                    range + sigma * Normal::new(0.0, 1.0).map_or(0.0, |n| n.sample(&mut rng));
                let lm = Landmark {
                    ecef_m: truth - range * u,
                    range_m: noisy,
                    sigma_m: sigma,
                };
                (u, lm)
            })
            .collect();
        let mut rows: Vec<[f64; 4]> = chosen
            .iter()
            .map(|s| [-s.los.x, -s.los.y, -s.los.z, 1.0])
            .collect();
        rows.extend(landmarks.iter().map(|(u, _)| [u.x, u.y, u.z, 0.0]));
        let dop = dop_enu(&rows, &site);
        let prior = solve(t_rx, &measurements(&all, &mut rng), &[], &opts(), None).ok();
        let lms: Vec<Landmark> = landmarks.iter().map(|(_, l)| *l).collect();
        let meas = measurements(&chosen, &mut rng);
        let fix_error_m = solve(t_rx, &meas, &lms, &opts(), prior.as_ref())
            .ok()
            .filter(|s| s.dop.pdop <= USABLE_PDOP)
            .map(|s| (s.pos_ecef_m - truth).norm());
        out.push(Trial { dop, fix_error_m });
    }
    out
}
