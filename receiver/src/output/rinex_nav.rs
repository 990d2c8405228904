//! RINEX 3.04 GPS navigation file writer (`ephemeris.rnx`).
//!
//! Header: RINEX 3.04 Table A5 (`IONOSPHERIC CORR` GPSA/GPSB as A4,1X,4D12.4;
//! `TIME SYSTEM CORR` GPUT as A4,1X,D17.10,D16.9,I7,I5; `LEAP SECONDS` as 4I6). Records:
//! Table A6 (epoch line `Gnn yyyy mm dd hh mm ss` + 3D19.12, then 7 broadcast-orbit lines of
//! 4X,4D19.12), in the Fortran `D19.12` form `0.dddddddddddD+ee` (12 significant digits).

use super::{create_file, fit_ascii, rinex_creation_date_now, OutputError};
use gpsrx_nav::ephemeris::ura_m_from_index;
use gpsrx_nav::{Ephemeris, KlobucharParams, UtcParams};
use std::io::Write;
use std::path::Path;

/// Value RINEX 3.04 (Table A6, transmission time of message) asks for when the transmission
/// time is not known.
pub const UNKNOWN_TRANSMISSION_TIME: f64 = 0.9999e9;

/// Largest URA written, m: the lower bound of index 15 ("no accuracy prediction").
const URA_INDEX_15_M: f64 = 6144.0;

/// Header contents of a navigation file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NavHeader {
    /// Program name (A20); empty gives `gpsrx <version>`.
    pub program: String,
    /// Who ran it (A20).
    pub run_by: String,
    /// Creation date `yyyymmdd hhmmss UTC`; `None` takes the current time.
    pub creation_date: Option<String>,
    /// Broadcast Klobuchar coefficients (`IONOSPHERIC CORR` GPSA and GPSB).
    pub iono: Option<KlobucharParams>,
    /// GPS-UTC parameters (`TIME SYSTEM CORR` GPUT and the leap-second event).
    pub utc: Option<UtcParams>,
    /// Current leap seconds, used for `LEAP SECONDS` when `utc` is `None`.
    pub leap_seconds: Option<i32>,
    /// `COMMENT` lines.
    pub comments: Vec<String>,
}

/// One ephemeris plus the RINEX field the [`Ephemeris`] type does not carry.
#[derive(Debug, Clone, PartialEq)]
pub struct NavRecord {
    /// The broadcast ephemeris.
    pub ephemeris: Ephemeris,
    /// Transmission time of message, s of the GPS week of toe (HOW time of subframe 1), if
    /// known; otherwise [`UNKNOWN_TRANSMISSION_TIME`] is written.
    pub transmission_tow_s: Option<f64>,
}

impl From<Ephemeris> for NavRecord {
    fn from(ephemeris: Ephemeris) -> NavRecord {
        NavRecord {
            ephemeris,
            transmission_tow_s: None,
        }
    }
}

/// Writes a complete navigation file to `path`.
pub fn write_rinex_nav_file(
    path: &Path,
    header: &NavHeader,
    records: &[NavRecord],
) -> Result<(), OutputError> {
    let mut out = create_file(path)?;
    let name = path.display().to_string();
    write_rinex_nav(&mut out, &name, header, records)?;
    out.flush().map_err(OutputError::io(&name))
}

/// Writes a complete navigation file (header, then the records in the given order) to `out`;
/// `file` names it in errors. Nothing is written if any record has a value the format cannot
/// hold (non-finite, or beyond 1e99).
pub fn write_rinex_nav<W: Write>(
    out: &mut W,
    file: &str,
    header: &NavHeader,
    records: &[NavRecord],
) -> Result<(), OutputError> {
    let mut text = header_text(file, header)?;
    for record in records {
        text.push_str(&record_text(file, record)?);
    }
    out.write_all(text.as_bytes())
        .map_err(OutputError::io(file))?;
    out.flush().map_err(OutputError::io(file))
}

fn header_text(file: &str, h: &NavHeader) -> Result<String, OutputError> {
    let mut out = String::new();
    let mut line = |content: String, label: &str| {
        out.push_str(&fit_ascii(&content, 60));
        out.push_str(label);
        out.push('\n');
    };
    line(
        format!(
            "{:9.2}{:11}{:20}{:20}",
            3.04, "", "N: GNSS NAV DATA", "G: GPS"
        ),
        "RINEX VERSION / TYPE",
    );
    let program = if h.program.is_empty() {
        format!("gpsrx {}", env!("CARGO_PKG_VERSION"))
    } else {
        h.program.clone()
    };
    let date = h
        .creation_date
        .clone()
        .unwrap_or_else(rinex_creation_date_now);
    line(
        format!(
            "{}{}{}",
            fit_ascii(&program, 20),
            fit_ascii(&h.run_by, 20),
            fit_ascii(&date, 20)
        ),
        "PGM / RUN BY / DATE",
    );
    for c in &h.comments {
        line(c.clone(), "COMMENT");
    }
    if let Some(iono) = h.iono {
        for (name, values) in [("GPSA", iono.alpha), ("GPSB", iono.beta)] {
            let mut content = format!("{name} ");
            for v in values {
                content.push_str(&fortran_d(v, 12, 4).ok_or_else(|| bad(file, name, v))?);
            }
            line(content, "IONOSPHERIC CORR");
        }
    }
    let leap = match h.utc {
        Some(utc) => {
            line(
                format!(
                    "GPUT {}{}{:7}{:5}",
                    fortran_d(utc.a0_s, 17, 10).ok_or_else(|| bad(file, "GPUT A0", utc.a0_s))?,
                    fortran_d(utc.a1_s_s, 16, 9).ok_or_else(|| bad(file, "GPUT A1", utc.a1_s_s))?,
                    utc.tot_s,
                    utc.wnt
                ),
                "TIME SYSTEM CORR",
            );
            Some(format!(
                "{:6}{:6}{:6}{:6}",
                utc.dt_ls_s, utc.dt_lsf_s, utc.wn_lsf, utc.dn
            ))
        }
        None => h.leap_seconds.map(|l| format!("{l:6}")),
    };
    if let Some(leap) = leap {
        line(leap, "LEAP SECONDS");
    }
    line(String::new(), "END OF HEADER");
    Ok(out)
}

fn bad(file: &str, field: &str, v: f64) -> OutputError {
    OutputError::invalid(
        file,
        format!("{field} = {v} cannot be written as a RINEX D-format number"),
    )
}

/// The 8 lines of one GPS record (RINEX 3.04 Table A6).
fn record_text(file: &str, record: &NavRecord) -> Result<String, OutputError> {
    let e = &record.ephemeris;
    if !(1..=99).contains(&e.prn) {
        return Err(OutputError::invalid(
            file,
            format!("ephemeris PRN {} out of range 1-99", e.prn),
        ));
    }
    let toc = super::calendar_rounded(e.toc, 0).ok_or_else(|| {
        OutputError::invalid(
            file,
            format!("ephemeris of G{:02}: toc {:?} is not valid", e.prn, e.toc),
        )
    })?;
    let ura_m = ura_m_from_index(e.ura_index).min(URA_INDEX_15_M);
    let fit_h = e.fit_interval_s() / 3600.0;
    let rows: [(&str, [f64; 4]); 7] = [
        (
            "IODE, Crs, Delta n, M0",
            [f64::from(e.iode), e.crs_m, e.delta_n_rad_s, e.m0_rad],
        ),
        (
            "Cuc, e, Cus, sqrt(A)",
            [e.cuc_rad, e.e, e.cus_rad, e.sqrt_a_sqrt_m],
        ),
        (
            "toe, Cic, OMEGA0, Cis",
            [e.toe.tow_s, e.cic_rad, e.omega0_rad, e.cis_rad],
        ),
        (
            "i0, Crc, omega, OMEGA DOT",
            [e.i0_rad, e.crc_m, e.omega_rad, e.omega_dot_rad_s],
        ),
        (
            "IDOT, codes on L2, week, L2 P flag",
            [
                e.idot_rad_s,
                f64::from(e.codes_on_l2),
                f64::from(e.toe.week),
                f64::from(u8::from(e.l2p_data_flag)),
            ],
        ),
        (
            "SV accuracy, health, TGD, IODC",
            [ura_m, f64::from(e.sv_health), e.tgd_s, f64::from(e.iodc)],
        ),
        (
            "transmission time, fit interval",
            [
                record
                    .transmission_tow_s
                    .unwrap_or(UNKNOWN_TRANSMISSION_TIME),
                fit_h,
                0.0,
                0.0,
            ],
        ),
    ];
    let field = |v: f64, what: &str| {
        fortran_d(v, 19, 12).ok_or_else(|| bad(file, &format!("G{:02} {what}", e.prn), v))
    };
    // A1,I2.2,1X,I4,5(1X,I2.2),3D19.12
    let mut text = format!(
        "G{:02} {:04} {:02} {:02} {:02} {:02} {:02}",
        e.prn, toc.year, toc.month, toc.day, toc.hour, toc.minute, toc.second
    );
    for (v, what) in [(e.af0_s, "af0"), (e.af1_s_s, "af1"), (e.af2_s_s2, "af2")] {
        text.push_str(&field(v, what)?);
    }
    text.push('\n');
    for (k, (what, values)) in rows.iter().enumerate() {
        text.push_str("    ");
        // The last line's two spares may be omitted (trailing blank fields).
        let n = if k == 6 { 2 } else { 4 };
        for v in &values[..n] {
            text.push_str(&field(*v, what)?);
        }
        text.push('\n');
    }
    Ok(text)
}

/// Fortran `Dw.d` formatting: `0.` followed by `decimals` mantissa digits and a two-digit
/// exponent, right-justified in `width` columns (e.g. D19.12: ` 0.469126738608D-03`).
/// `None` if the value is not finite, does not fit, or needs a three-digit exponent;
/// magnitudes below 1e-99 are written as zero.
pub fn fortran_d(v: f64, width: usize, decimals: usize) -> Option<String> {
    if !v.is_finite() || decimals == 0 {
        return None;
    }
    let (sign, digits, exp) = if v == 0.0 || v.abs() < 1e-99 {
        ("", "0".repeat(decimals), 0i32)
    } else {
        // {:.(d-1)e} rounds to d significant digits: m.mmm e X, i.e. 0.mmmm x 10^(X+1).
        let sci = format!("{:.*e}", decimals - 1, v.abs());
        let (mantissa, exp) = sci.split_once('e')?;
        let exp: i32 = exp.parse().ok()?;
        let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
        (if v < 0.0 { "-" } else { "" }, digits, exp + 1)
    };
    if exp.abs() > 99 {
        return None;
    }
    let exp_sign = if exp < 0 { '-' } else { '+' };
    let body = format!("{sign}0.{digits}D{exp_sign}{:02}", exp.abs());
    if body.len() > width {
        return None;
    }
    Some(format!("{body:>width$}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_d_matches_the_igs_file_style() {
        assert_eq!(
            fortran_d(0.469126738608e-3, 19, 12).as_deref(),
            Some(" 0.469126738608D-03")
        );
        assert_eq!(
            fortran_d(-0.100044417195e-10, 19, 12).as_deref(),
            Some("-0.100044417195D-10")
        );
        assert_eq!(
            fortran_d(0.0, 19, 12).as_deref(),
            Some(" 0.000000000000D+00")
        );
        assert_eq!(
            fortran_d(518_400.0, 19, 12).as_deref(),
            Some(" 0.518400000000D+06")
        );
        // Rounding that carries into a new digit moves the exponent.
        assert_eq!(
            fortran_d(0.99999999999999, 12, 4).as_deref(),
            Some("  0.1000D+01")
        );
        assert_eq!(fortran_d(0.1211e-7, 12, 4).as_deref(), Some("  0.1211D-07"));
        assert_eq!(fortran_d(f64::NAN, 19, 12), None);
        assert_eq!(fortran_d(1e120, 19, 12), None);
        assert_eq!(
            fortran_d(1e-120, 19, 12).as_deref(),
            Some(" 0.000000000000D+00")
        );
    }
}
