//! YUMA almanac file writer (`almanac.yuma`): the almanac decoded from subframes 4 and 5, in the
//! text format the US Coast Guard Navigation Center publishes and planning tools read.
//!
//! One block per satellite; angles in radians (the ICD's semicircles times pi), the inclination
//! as the full angle `0.3 pi + delta_i` (IS-GPS-200 Table 20-VI), the week modulo 1024.

use super::OutputError;
use gpsrx_nav::almanac::{Almanac, AlmanacSet};
use std::io::Write;

/// Writes every almanac of `set` in YUMA format to `w` (`file` names it in errors).
pub fn write_yuma<W: Write>(w: &mut W, file: &str, set: &AlmanacSet) -> Result<(), OutputError> {
    for prn in 1..=32u8 {
        if let Some(a) = set.get(prn) {
            write_block(w, a).map_err(OutputError::io(file))?;
        }
    }
    w.flush().map_err(OutputError::io(file))
}

fn write_block<W: Write>(w: &mut W, a: &Almanac) -> std::io::Result<()> {
    let week = a.toa.week % 1024;
    writeln!(
        w,
        "******** Week {week:4} almanac for PRN-{:02} ********",
        a.prn
    )?;
    writeln!(w, "ID:                         {:02}", a.prn)?;
    writeln!(w, "Health:                     {:03}", a.health)?;
    writeln!(w, "Eccentricity:               {}", sci(a.e))?;
    writeln!(w, "Time of Applicability(s):  {:.4}", a.toa.tow_s)?;
    writeln!(
        w,
        "Orbital Inclination(rad):   {}",
        sci(a.inclination_rad())
    )?;
    writeln!(w, "Rate of Right Ascen(r/s):  {}", sci(a.omega_dot_rad_s))?;
    writeln!(w, "SQRT(A)  (m 1/2):           {:.6}", a.sqrt_a_sqrt_m)?;
    writeln!(w, "Right Ascen at Week(rad):  {}", sci(a.omega0_rad))?;
    writeln!(w, "Argument of Perigee(rad):  {}", sci(a.omega_rad))?;
    writeln!(w, "Mean Anom(rad):            {}", sci(a.m0_rad))?;
    writeln!(w, "Af0(s):                    {}", sci(a.af0_s))?;
    writeln!(w, "Af1(s/s):                  {}", sci(a.af1_s_s))?;
    writeln!(w, "week:                       {week:4}")?;
    writeln!(w)
}

/// `x` as YUMA writes numbers: a signed mantissa in [0.1, 1) with ten digits and a signed
/// three-digit exponent (`-0.1234567890E-008`).
fn sci(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return " 0.0000000000E+000".to_string();
    }
    let exp = x.abs().log10().floor() as i32 + 1;
    let mut m = x / 10f64.powi(exp);
    let mut e = exp;
    // Rounding may carry the mantissa to 1.0.
    if (m.abs() * 1e10).round() >= 1e10 {
        m /= 10.0;
        e += 1;
    }
    let sign = if m < 0.0 { '-' } else { ' ' };
    let esign = if e < 0 { '-' } else { '+' };
    format!("{sign}{:.10}E{esign}{:03}", m.abs(), e.abs())
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_nav::GpsTime;

    #[test]
    fn numbers_read_back_and_blocks_carry_every_field() {
        for x in [
            0.0123456789,
            -7.7e-9,
            0.97,
            5153.123,
            -1.0,
            1.0,
            0.099_999_999_999_9,
        ] {
            let s = sci(x);
            let back: f64 = s.trim().parse().unwrap_or(f64::NAN);
            assert!(
                (back - x).abs() <= 1e-10 * x.abs().max(1e-30),
                "{x} -> {s} -> {back}"
            );
        }
        let a = Almanac {
            prn: 7,
            health: 0,
            e: 0.0123,
            toa: GpsTime::new(2190, 589_824.0),
            delta_i_rad: 0.0089,
            omega_dot_rad_s: -7.9e-9,
            sqrt_a_sqrt_m: 5153.6,
            omega0_rad: 1.2,
            omega_rad: -0.4,
            m0_rad: 2.9,
            af0_s: 1.2e-4,
            af1_s_s: 3.6e-12,
        };
        let mut set = AlmanacSet::new(a.toa);
        set.insert(a.clone());
        let mut out = Vec::new();
        write_yuma(&mut out, "almanac.yuma", &set).unwrap_or_else(|e| panic!("{e}"));
        let text = String::from_utf8(out).unwrap_or_default();
        assert!(
            text.starts_with("******** Week  142 almanac for PRN-07 ********"),
            "{text}"
        );
        let field = |name: &str| -> f64 {
            text.lines()
                .find(|l| l.starts_with(name))
                .and_then(|l| l.split(':').nth(1))
                .and_then(|v| v.trim().parse().ok())
                .unwrap_or(f64::NAN)
        };
        assert_eq!(field("ID"), 7.0);
        assert!((field("Orbital Inclination") - a.inclination_rad()).abs() < 1e-9);
        assert!((field("Mean Anom") - 2.9).abs() < 1e-9);
        assert!((field("Time of Applicability") - 589_824.0).abs() < 1e-6);
        assert_eq!(field("week"), 142.0);
    }
}
