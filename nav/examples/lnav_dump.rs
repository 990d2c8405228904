//! Dumps the LNAV subframes our encoder transmits for every ephemeris of a RINEX nav file, as
//! CSV with the 300 bits of each subframe in hex (MSB first, padded to 304 bits). Used to
//! produce `tests/data/lnav_subframes.csv`, which RTKLIB then decodes independently
//! (`tests/data/gen_fixtures.py`).
//!
//! `cargo run --release -p gpsrx-nav --example lnav_dump -- ../shared/data/brdc0010.22n`

use gpsrx_nav::lnav::LnavEncoder;
use gpsrx_nav::{read_rinex_nav, GpsTime};
use std::fmt::Write as _;
use std::path::PathBuf;

fn hex(bits: &[u8; 300]) -> String {
    let mut padded = bits.to_vec();
    padded.extend([0u8; 4]);
    padded.chunks(4).fold(String::new(), |mut s, c| {
        let v = c.iter().fold(0u8, |a, &b| (a << 1) | b);
        let _ = write!(s, "{v:X}");
        s
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path: PathBuf = std::env::args_os()
        .nth(1)
        .ok_or("usage: lnav_dump <rinex nav file>")?
        .into();
    let nav = read_rinex_nav(&path)?;
    println!("index,prn,iode,toe_week,toe_tow_s,start_week,start_tow_s,sf1,sf2,sf3,sf4,sf5");
    for (index, eph) in nav.ephemerides.iter().enumerate() {
        let enc = LnavEncoder::new(eph, nav.iono.as_ref(), nav.utc.as_ref())?;
        // Frame (subframe 1) boundary about one hour before toe.
        let tx = eph.toe.add_seconds(-3600.0);
        let start = GpsTime::new(tx.week, f64::from((tx.tow_s as u32) / 30 * 30));
        let sfs: Vec<String> = (0..5)
            .map(|k| {
                let t = start.add_seconds(6.0 * f64::from(k));
                hex(&enc.subframe_bits(t.tow_s as u32, t.week))
            })
            .collect();
        println!(
            "{index},{},{},{},{},{},{},{}",
            eph.prn,
            eph.iode,
            eph.toe.week,
            eph.toe.tow_s,
            start.week,
            start.tow_s,
            sfs.join(",")
        );
    }
    Ok(())
}
