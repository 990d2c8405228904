//! Shared helpers: fixture paths, a small CSV table reader, a seeded Gaussian generator and
//! an independent forward model of the pseudorange (for the PVT and coarse-time tests).

use gpsrx_nav::constants::{OMEGA_E_DOT_RAD_S, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::{
    azimuth_elevation, klobuchar_delay_s, saastamoinen_delay_m, Ephemeris, GpsTime,
    KlobucharParams, Llh, Vector3,
};
use std::collections::HashMap;
use std::path::PathBuf;

/// Path of a data file that the repository ships in `samples/data` (the broadcast file of
/// 2022-01-01 is the IGS product that `../shared/data` also holds, byte for byte).
pub fn shipped_data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../samples/data")
        .join(name)
}

/// Path of a committed fixture in `nav/tests/data`.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The broadcast file of 2022-01-01 used throughout.
pub fn brdc() -> gpsrx_nav::NavData {
    gpsrx_nav::read_rinex_nav(&shipped_data("brdc0010.22n")).expect("brdc0010.22n parses")
}

/// A CSV fixture with named columns.
pub struct Table {
    index: HashMap<String, usize>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn read(name: &str) -> Table {
        let mut rdr = csv::Reader::from_path(fixture(name)).expect("fixture exists");
        let headers = rdr.headers().expect("header row").clone();
        let index = headers
            .iter()
            .enumerate()
            .map(|(i, h)| (h.to_string(), i))
            .collect();
        let rows = rdr
            .records()
            .map(|r| r.expect("csv row").iter().map(str::to_string).collect())
            .collect();
        Table { index, rows }
    }

    pub fn str<'a>(&self, row: &'a [String], col: &str) -> &'a str {
        &row[self.index[col]]
    }

    pub fn f64(&self, row: &[String], col: &str) -> f64 {
        self.str(row, col).parse().expect("number")
    }
}

/// Seeded standard normal generator (splitmix64 + Box-Muller).
pub struct Gauss(pub u64);

impl Gauss {
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// Atmosphere of the forward model.
#[derive(Clone, Copy)]
pub struct Atmos<'a> {
    pub iono: Option<&'a KlobucharParams>,
    pub tropo: bool,
}

pub const NO_ATMOS: Atmos<'static> = Atmos {
    iono: None,
    tropo: false,
};

/// Rotation of the ECEF frame about z by `theta` (the frame at reception is rotated by
/// OmegaE * tau with respect to the frame at transmission).
pub fn rot_z(v: &Vector3<f64>, theta: f64) -> Vector3<f64> {
    Vector3::new(
        theta.cos() * v.x + theta.sin() * v.y,
        -theta.sin() * v.x + theta.cos() * v.y,
        v.z,
    )
}

/// Exact pseudorange received at true GPS time `t` at `pos` with clock bias `clock_m`; returns
/// (P, raw SV transmit time, elevation rad).
pub fn forward(
    eph: &Ephemeris,
    pos: &Vector3<f64>,
    t: GpsTime,
    clock_m: f64,
    atm: Atmos<'_>,
) -> (f64, GpsTime, f64) {
    let mut tau = 0.07;
    let mut sv = eph.sv_state(t);
    let mut s_rot = sv.pos_m;
    for _ in 0..10 {
        sv = eph.sv_state(t.add_seconds(-tau));
        s_rot = rot_z(&sv.pos_m, OMEGA_E_DOT_RAD_S * tau);
        tau = (s_rot - pos).norm() / SPEED_OF_LIGHT_MPS;
    }
    let t_tx = t.add_seconds(-tau);
    let (az, el) = azimuth_elevation(pos, &s_rot);
    let llh = Llh::from_ecef(pos);
    let mut p = SPEED_OF_LIGHT_MPS * tau + clock_m - SPEED_OF_LIGHT_MPS * sv.clock_bias_s;
    if let Some(k) = atm.iono {
        p += SPEED_OF_LIGHT_MPS * klobuchar_delay_s(k, t.tow_s, &llh, az, el);
    }
    if atm.tropo {
        p += saastamoinen_delay_m(&llh, el);
    }
    (p, t_tx.add_seconds(sv.clock_bias_s), el)
}
