//! One GPS navigation record (epoch line + 7 broadcast-orbit lines), RINEX 2.11 Table A4 and
//! RINEX 3.0x Table A6, mapped to an [`Ephemeris`].

use super::fields::{column, float};
use super::header::Major;
use super::RinexError;
use crate::ephemeris::{ura_index_from_m, Ephemeris};
use crate::time::GpsTime;

/// Lines of a RINEX 3 record for a satellite system letter (epoch line included), or `None`
/// for an unknown letter (RINEX 3.0x Tables A6-A16).
pub(crate) fn record_lines_v3(system: char) -> Option<usize> {
    match system {
        'G' | 'E' | 'C' | 'J' | 'I' => Some(8),
        'R' | 'S' => Some(4),
        _ => None,
    }
}

/// Parses the 8 lines of a GPS record. `first_line_no` is the 1-based number of `lines[0]`.
pub(crate) fn parse_gps_record(
    lines: &[&str],
    first_line_no: usize,
    major: Major,
) -> Result<Ephemeris, RinexError> {
    let epoch_line = lines.first().copied().unwrap_or("");
    let n0 = first_line_no;
    let (date_cols, float_start, orbit_start) = match major {
        Major::V2 => (22, 22, 3),
        Major::V3 => (23, 23, 4),
    };
    let date_text = column(epoch_line, n0, 0, date_cols, "epoch")?;
    let (prn, toc) = parse_epoch(date_text, n0, major)?;
    let mut clock = [0.0; 3];
    for (k, v) in clock.iter_mut().enumerate() {
        *v = float(epoch_line, n0, float_start + 19 * k, 19, CLOCK_NAMES[k])?;
    }
    let mut orbit = [[0.0; 4]; 7];
    for (row, values) in orbit.iter_mut().enumerate() {
        let n = n0 + 1 + row;
        let line = lines.get(1 + row).copied().unwrap_or("");
        for (k, v) in values.iter_mut().enumerate() {
            *v = float(line, n, orbit_start + 19 * k, 19, ORBIT_NAMES[row][k])?;
        }
    }
    let line_of = |row: usize| n0 + 1 + row;

    let iode = integer_in(orbit[0][0], line_of(0), "IODE", 0.0, 255.0, "0..=255")?;
    let e = orbit[1][1];
    if !(0.0..1.0).contains(&e) {
        return Err(out_of_range(line_of(1), "eccentricity e", e, "0 <= e < 1"));
    }
    let sqrt_a = orbit[1][3];
    if sqrt_a.is_nan() || sqrt_a <= 1000.0 {
        return Err(out_of_range(
            line_of(1),
            "sqrt(A)",
            sqrt_a,
            "> 1000 sqrt(m)",
        ));
    }
    let toe_sow = orbit[2][0];
    if !(0.0..604_800.0).contains(&toe_sow) {
        return Err(out_of_range(
            line_of(2),
            "toe",
            toe_sow,
            "0 <= toe < 604800 s",
        ));
    }
    let codes_on_l2 = integer_in(orbit[4][1], line_of(4), "codes on L2", 0.0, 3.0, "0..=3")?;
    let week = integer_in(
        orbit[4][2],
        line_of(4),
        "GPS week",
        0.0,
        1.0e6,
        "0..=1000000",
    )?;
    let l2p = integer_in(
        orbit[4][3],
        line_of(4),
        "L2 P data flag",
        0.0,
        1.0,
        "0 or 1",
    )?;
    let ura_m = orbit[5][0];
    let health = integer_in(orbit[5][1], line_of(5), "SV health", 0.0, 255.0, "0..=255")?;
    let iodc = integer_in(orbit[5][3], line_of(5), "IODC", 0.0, 1023.0, "0..=1023")?;
    let fit_h = orbit[6][1];

    // The week goes with toe; keep toe within half a week of toc in case a writer used the
    // week of transmission for a toe in the next week.
    let mut toe = GpsTime::new(week as u32, toe_sow);
    let d = toe.diff_s(toc);
    if d > 302_400.0 {
        toe = GpsTime::new((week as u32).saturating_sub(1), toe_sow);
    } else if d < -302_400.0 {
        toe = GpsTime::new(week as u32 + 1, toe_sow);
    }

    Ok(Ephemeris {
        prn,
        toc,
        af0_s: clock[0],
        af1_s_s: clock[1],
        af2_s_s2: clock[2],
        iode: iode as u32,
        iodc: iodc as u32,
        crs_m: orbit[0][1],
        delta_n_rad_s: orbit[0][2],
        m0_rad: orbit[0][3],
        cuc_rad: orbit[1][0],
        e,
        cus_rad: orbit[1][2],
        sqrt_a_sqrt_m: sqrt_a,
        toe,
        cic_rad: orbit[2][1],
        omega0_rad: orbit[2][2],
        cis_rad: orbit[2][3],
        i0_rad: orbit[3][0],
        crc_m: orbit[3][1],
        omega_rad: orbit[3][2],
        omega_dot_rad_s: orbit[3][3],
        idot_rad_s: orbit[4][0],
        tgd_s: orbit[5][2],
        ura_index: ura_index_from_m(ura_m),
        sv_health: health as u8,
        codes_on_l2: codes_on_l2 as u8,
        l2p_data_flag: l2p != 0,
        // RINEX stores the fit interval in hours (0 = unknown, i.e. the 4 h default).
        fit_interval_flag: fit_h > 4.0,
    })
}

const CLOCK_NAMES: [&str; 3] = ["af0", "af1", "af2"];
const ORBIT_NAMES: [[&str; 4]; 7] = [
    ["IODE", "Crs", "Delta n", "M0"],
    ["Cuc", "e", "Cus", "sqrt(A)"],
    ["toe", "Cic", "OMEGA0", "Cis"],
    ["i0", "Crc", "omega", "OMEGA DOT"],
    ["IDOT", "codes on L2", "GPS week", "L2 P data flag"],
    ["SV accuracy", "SV health", "TGD", "IODC"],
    ["transmission time", "fit interval", "spare", "spare"],
];

fn out_of_range(line: usize, field: &'static str, value: f64, allowed: &'static str) -> RinexError {
    RinexError::OutOfRange {
        line,
        field,
        value,
        allowed,
    }
}

/// Checks that a float read from RINEX is an integer in `[lo, hi]` (within 1e-6, as writers
/// print integers as `0.390000000000D+02`).
fn integer_in(
    v: f64,
    line: usize,
    field: &'static str,
    lo: f64,
    hi: f64,
    allowed: &'static str,
) -> Result<i64, RinexError> {
    let r = v.round();
    if (v - r).abs() > 1e-6 || r < lo || r > hi {
        return Err(out_of_range(line, field, v, allowed));
    }
    Ok(r as i64)
}

/// Reads the PRN and toc from the date part of an epoch line:
/// RINEX 2 `PP YY MM DD HH MM SS.S`, RINEX 3 `GPP YYYY MM DD HH MM SS`.
fn parse_epoch(text: &str, line: usize, major: Major) -> Result<(u8, GpsTime), RinexError> {
    let bad = |reason: &'static str| RinexError::Field {
        line,
        col_start: 1,
        col_end: if major == Major::V2 { 22 } else { 23 },
        field: "epoch (PRN and toc)",
        text: text.to_string(),
        reason,
    };
    let tokens: Vec<&str> = text.split_whitespace().collect();
    let (prn_text, date) = match major {
        Major::V2 => (tokens.first().copied().unwrap_or(""), tokens.get(1..)),
        Major::V3 => {
            // `G01`, or `G 1` written with a blank.
            let sat = tokens.first().copied().unwrap_or("");
            if sat.len() == 1 {
                (tokens.get(1).copied().unwrap_or(""), tokens.get(2..))
            } else {
                (sat.get(1..).unwrap_or(""), tokens.get(1..))
            }
        }
    };
    let date = date
        .filter(|d| d.len() == 6)
        .ok_or_else(|| bad("expected satellite, year, month, day, hour, minute and second"))?;
    let prn: u8 = prn_text
        .trim()
        .parse()
        .ok()
        .filter(|p| (1..=63).contains(p))
        .ok_or_else(|| bad("PRN must be 1..=63"))?;
    let mut ints = [0u32; 5];
    for (k, v) in ints.iter_mut().enumerate() {
        *v = date[k]
            .parse()
            .map_err(|_| bad("date fields must be integers"))?;
    }
    let sec =
        super::fields::parse_fortran_f64(date[5]).ok_or_else(|| bad("seconds must be a number"))?;
    let [yy, month, day, hour, min] = ints;
    let year = match (major, yy) {
        (Major::V2, y) if y < 80 => 2000 + y as i32,
        (Major::V2, y) if y < 100 => 1900 + y as i32,
        (_, y) => y as i32,
    };
    if !(1980..=2200).contains(&year)
        || !(1..=12).contains(&month)
        || !(1..=31).contains(&day)
        || hour > 24
        || min > 59
        || !(0.0..=60.0).contains(&sec)
    {
        return Err(bad("date or time out of range"));
    }
    Ok((
        prn,
        GpsTime::from_calendar(year, month, day, hour, min, sec),
    ))
}
