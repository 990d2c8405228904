//! LNAV field layout and scaling: bit positions from IS-GPS-200 Figure 20-1 (subframes 1-3,
//! subframe 4 page 18, the almanac pages and pages 25 of subframes 4 and 5), scale factors and
//! two's-complement conventions from Tables 20-I, 20-III, 20-VI and 20-X. Quantisation to the
//! ICD LSBs ([`Ephemeris::quantized_to_icd`], [`Almanac::quantized_to_icd`]) uses exactly the
//! arithmetic the decoder uses, so `decode(encode(x)) == x.quantized_to_icd()` bit for bit.

use crate::almanac::{Almanac, AlmanacSet};
use crate::atmosphere::KlobucharParams;
use crate::constants::GPS_PI;
use crate::ephemeris::Ephemeris;
use crate::time::GpsTime;
use crate::utc::UtcParams;

/// One message field: where its bits are (ICD bit numbers 1..=300 of the subframe, MSB part
/// first), whether it is two's complement, its LSB and whether the LSB is in semicircles.
#[derive(Debug, Clone, Copy)]
pub struct Field {
    /// Name used in error messages.
    pub name: &'static str,
    /// (first ICD bit number, number of bits) of each part, most significant part first.
    pub parts: &'static [(u16, u8)],
    /// Two's complement (true) or unsigned (false).
    pub signed: bool,
    /// Scale factor of the LSB in the field's ICD unit.
    pub lsb: f64,
    /// The ICD unit is semicircles (multiply by pi for radians).
    pub semicircles: bool,
}

const fn f(
    name: &'static str,
    parts: &'static [(u16, u8)],
    signed: bool,
    lsb: f64,
    sc: bool,
) -> Field {
    Field {
        name,
        parts,
        signed,
        lsb,
        semicircles: sc,
    }
}

/// 2^n for the scale factors.
const fn p2(n: i32) -> f64 {
    if n >= 0 {
        (1u64 << n) as f64
    } else {
        1.0 / (1u64 << -n) as f64
    }
}

// Subframe 1 (Figure 20-1 sheet 1, Table 20-I).
pub const WN: Field = f("week number", &[(61, 10)], false, 1.0, false);
pub const CODES_ON_L2: Field = f("codes on L2", &[(71, 2)], false, 1.0, false);
pub const URA: Field = f("URA index", &[(73, 4)], false, 1.0, false);
pub const HEALTH: Field = f("SV health", &[(77, 6)], false, 1.0, false);
pub const IODC: Field = f("IODC", &[(83, 2), (211, 8)], false, 1.0, false);
pub const L2P: Field = f("L2 P data flag", &[(91, 1)], false, 1.0, false);
pub const TGD: Field = f("T_GD", &[(197, 8)], true, p2(-31), false);
pub const TOC: Field = f("t_oc", &[(219, 16)], false, p2(4), false);
pub const AF2: Field = f("a_f2", &[(241, 8)], true, p2(-55), false);
pub const AF1: Field = f("a_f1", &[(249, 16)], true, p2(-43), false);
pub const AF0: Field = f("a_f0", &[(271, 22)], true, p2(-31), false);

// Subframe 2 (Figure 20-1 sheet 2, Table 20-III).
pub const IODE2: Field = f("IODE (subframe 2)", &[(61, 8)], false, 1.0, false);
pub const CRS: Field = f("C_rs", &[(69, 16)], true, p2(-5), false);
pub const DELTA_N: Field = f("delta n", &[(91, 16)], true, p2(-43), true);
pub const M0: Field = f("M_0", &[(107, 8), (121, 24)], true, p2(-31), true);
pub const CUC: Field = f("C_uc", &[(151, 16)], true, p2(-29), false);
pub const ECC: Field = f("e", &[(167, 8), (181, 24)], false, p2(-33), false);
pub const CUS: Field = f("C_us", &[(211, 16)], true, p2(-29), false);
pub const SQRT_A: Field = f("sqrt(A)", &[(227, 8), (241, 24)], false, p2(-19), false);
pub const TOE: Field = f("t_oe", &[(271, 16)], false, p2(4), false);
pub const FIT: Field = f("fit interval flag", &[(287, 1)], false, 1.0, false);
pub const AODO: Field = f("AODO", &[(288, 5)], false, 1.0, false);

// Subframe 3 (Figure 20-1 sheet 3, Table 20-III).
pub const CIC: Field = f("C_ic", &[(61, 16)], true, p2(-29), false);
pub const OMEGA0: Field = f("OMEGA_0", &[(77, 8), (91, 24)], true, p2(-31), true);
pub const CIS: Field = f("C_is", &[(121, 16)], true, p2(-29), false);
pub const I0: Field = f("i_0", &[(137, 8), (151, 24)], true, p2(-31), true);
pub const CRC: Field = f("C_rc", &[(181, 16)], true, p2(-5), false);
pub const OMEGA: Field = f("omega", &[(197, 8), (211, 24)], true, p2(-31), true);
pub const OMEGA_DOT: Field = f("OMEGA DOT", &[(241, 24)], true, p2(-43), true);
pub const IODE3: Field = f("IODE (subframe 3)", &[(271, 8)], false, 1.0, false);
pub const IDOT: Field = f("IDOT", &[(279, 14)], true, p2(-43), true);

// Subframes 4 and 5 page header (Figure 20-1 sheets 4-11).
pub const DATA_ID: Field = f("data ID", &[(61, 2)], false, 1.0, false);
pub const SV_ID: Field = f("SV (page) ID", &[(63, 6)], false, 1.0, false);

// Subframe 4 page 18 (Figure 20-1 sheet 8, Tables 20-IX and 20-X).
pub const ALPHA: [Field; 4] = [
    f("alpha_0", &[(69, 8)], true, p2(-30), false),
    f("alpha_1", &[(77, 8)], true, p2(-27), false),
    f("alpha_2", &[(91, 8)], true, p2(-24), false),
    f("alpha_3", &[(99, 8)], true, p2(-24), false),
];
pub const BETA: [Field; 4] = [
    f("beta_0", &[(107, 8)], true, p2(11), false),
    f("beta_1", &[(121, 8)], true, p2(14), false),
    f("beta_2", &[(129, 8)], true, p2(16), false),
    f("beta_3", &[(137, 8)], true, p2(16), false),
];
pub const A1: Field = f("A_1", &[(151, 24)], true, p2(-50), false);
pub const A0: Field = f("A_0", &[(181, 24), (211, 8)], true, p2(-30), false);
pub const TOT: Field = f("t_ot", &[(219, 8)], false, p2(12), false);
pub const WNT: Field = f("WN_t", &[(227, 8)], false, 1.0, false);
pub const DT_LS: Field = f("delta t_LS", &[(241, 8)], true, 1.0, false);
pub const WN_LSF: Field = f("WN_LSF", &[(249, 8)], false, 1.0, false);
pub const DN: Field = f("DN", &[(257, 8)], false, 1.0, false);
pub const DT_LSF: Field = f("delta t_LSF", &[(271, 8)], true, 1.0, false);

// Almanac pages: subframe 5 pages 1-24 and subframe 4 pages 2-5, 7-10 (Figure 20-1 sheet 4,
// IS-GPS-200 20.3.3.5.1.2 and Table 20-VI). Cross-checked against Table 20-VI:
//   e        16 bits  unsigned  2^-21               (range 0 .. 0.03125)
//   t_oa      8 bits  unsigned  2^12 s              (0 .. 602112 s)
//   delta_i  16 bits* signed    2^-19 semicircles   (i = 0.30 semicircles + delta_i)
//   OMEGADOT 16 bits* signed    2^-38 semicircles/s
//   sqrt(A)  24 bits  unsigned  2^-11 sqrt(m)
//   OMEGA_0, omega, M_0  24 bits* signed  2^-23 semicircles
//   a_f0     11 bits* signed    2^-20 s  (8 MSBs in word 10 bits 1-8, 3 LSBs in bits 20-22)
//   a_f1     11 bits* signed    2^-38 s/s (word 10 bits 9-19)
// and the 8-bit SV health in word 5 bits 17-24 (20.3.3.5.1.3).
pub const ALM_E: Field = f("almanac e", &[(69, 16)], false, p2(-21), false);
pub const ALM_TOA: Field = f("almanac t_oa", &[(91, 8)], false, p2(12), false);
pub const ALM_DELTA_I: Field = f("almanac delta_i", &[(99, 16)], true, p2(-19), true);
pub const ALM_OMEGA_DOT: Field = f("almanac OMEGA DOT", &[(121, 16)], true, p2(-38), true);
pub const ALM_HEALTH: Field = f("almanac SV health", &[(137, 8)], false, 1.0, false);
pub const ALM_SQRT_A: Field = f("almanac sqrt(A)", &[(151, 24)], false, p2(-11), false);
pub const ALM_OMEGA0: Field = f("almanac OMEGA_0", &[(181, 24)], true, p2(-23), true);
pub const ALM_OMEGA: Field = f("almanac omega", &[(211, 24)], true, p2(-23), true);
pub const ALM_M0: Field = f("almanac M_0", &[(241, 24)], true, p2(-23), true);
pub const ALM_AF0: Field = f("almanac a_f0", &[(271, 8), (290, 3)], true, p2(-20), false);
pub const ALM_AF1: Field = f("almanac a_f1", &[(279, 11)], true, p2(-38), false);

// Subframe 5 page 25, SV ID 51 (Figure 20-1 sheet 10, 20.3.3.5.1.5): t_oa and WN_a in word 3;
// the 6-bit health of SV 1-24 in the 24 MSBs of words 4-9 ([`sf5_page25_health_bit`]).
pub const P25_TOA: Field = f("page 25 t_oa", &[(69, 8)], false, p2(12), false);
pub const P25_WNA: Field = f("WN_a", &[(77, 8)], false, 1.0, false);

/// First ICD bit of the 6-bit health of `prn` (1-24) in subframe 5 page 25: four per word in
/// the 24 MSBs of words 4-9 (20.3.3.5.1.3).
pub fn sf5_page25_health_bit(prn: u8) -> Option<u16> {
    let k = u16::from(prn).checked_sub(1).filter(|&k| k < 24)?;
    Some(91 + 30 * (k / 4) + 6 * (k % 4))
}

/// First ICD bit of the 6-bit health of `prn` (25-32) in subframe 4 page 25: bits 19-24 of
/// word 8, the 24 MSBs of word 9 and the 18 MSBs of word 10 (20.3.3.5.1.3).
pub fn sf4_page25_health_bit(prn: u8) -> Option<u16> {
    match prn {
        25 => Some(229),
        26..=29 => Some(241 + 6 * (u16::from(prn) - 26)),
        30..=32 => Some(271 + 6 * (u16::from(prn) - 30)),
        _ => None,
    }
}

/// First ICD bit of the 4-bit A-S flag / SV configuration of `prn` (1-32) in subframe 4 page
/// 25 (20.3.3.5.1.4): SV 1-4 in bits 9-24 of word 3, six per word in the 24 MSBs of words 4-7,
/// SV 29-32 in the 16 MSBs of word 8 (then 2 reserved bits and the health of SV 25).
pub fn sf4_page25_config_bit(prn: u8) -> Option<u16> {
    match prn {
        1..=4 => Some(69 + 4 * (u16::from(prn) - 1)),
        5..=32 => {
            let k = u16::from(prn) - 5;
            Some(91 + 30 * (k / 6) + 4 * (k % 6))
        }
        _ => None,
    }
}

/// Reads `len` (1..=24) bits starting at ICD bit `start` (within one word's data bits) as an
/// unsigned count.
pub fn get_bits(words: &[u32; 10], start: u16, len: u8) -> u32 {
    (0..u32::from(len)).fold(0u32, |acc, b| {
        let (w, shift) = locate(u32::from(start) + b);
        (acc << 1) | ((words[w] >> shift) & 1)
    })
}

/// Writes the `len` (1..=24) LSBs of `value` starting at ICD bit `start`.
pub fn put_bits(words: &mut [u32; 10], start: u16, len: u8, value: u32) {
    for b in 0..u32::from(len) {
        let bit = (value >> (u32::from(len) - 1 - b)) & 1;
        let (w, shift) = locate(u32::from(start) + b);
        words[w] = (words[w] & !(1 << shift)) | (bit << shift);
    }
}

impl Field {
    /// Total number of bits.
    pub fn bits(&self) -> u32 {
        self.parts.iter().map(|&(_, n)| u32::from(n)).sum()
    }

    /// Smallest and largest raw count the field can hold.
    pub fn count_range(&self) -> (i64, i64) {
        let n = self.bits();
        if self.signed {
            (-(1i64 << (n - 1)), (1i64 << (n - 1)) - 1)
        } else {
            (0, (1i64 << n) - 1)
        }
    }

    /// SI value of a raw count: count * LSB (* pi for semicircles).
    pub fn to_si(&self, count: i64) -> f64 {
        let v = count as f64 * self.lsb;
        if self.semicircles {
            v * GPS_PI
        } else {
            v
        }
    }

    /// Nearest raw count of an SI value (not range-checked; saturates at i64 limits).
    pub fn to_count(&self, si: f64) -> i64 {
        let v = if self.semicircles { si / GPS_PI } else { si };
        (v / self.lsb).round() as i64
    }

    /// The SI value rounded to the field's LSB.
    pub fn quantize(&self, si: f64) -> f64 {
        self.to_si(self.to_count(si))
    }

    /// Nearest raw count of an angle (semicircle field of the full +-1 semicircle range, e.g.
    /// the almanac OMEGA_0, omega, M_0) folded into the field's two's-complement range: angles
    /// are modulo 2 semicircles, so +pi is sent as -pi. Other fields: [`Field::to_count`].
    pub fn to_count_wrapped(&self, si: f64) -> i64 {
        let count = self.to_count(si);
        let n = self.bits();
        let full_circle =
            self.signed && self.semicircles && self.lsb * (1u64 << (n - 1)) as f64 == 1.0;
        if !full_circle || !si.is_finite() {
            return count;
        }
        let modulus = 1i64 << n;
        let folded = count.rem_euclid(modulus);
        if folded >= modulus / 2 {
            folded - modulus
        } else {
            folded
        }
    }

    /// An angle rounded to the field's LSB and folded like [`Field::to_count_wrapped`].
    pub fn quantize_wrapped(&self, si: f64) -> f64 {
        self.to_si(self.to_count_wrapped(si))
    }

    /// SI value range the field can hold.
    pub fn si_range(&self) -> (f64, f64) {
        let (lo, hi) = self.count_range();
        (self.to_si(lo), self.to_si(hi))
    }

    /// Writes `count` (two's complement for signed fields) into the 24-bit source words
    /// `words[0..10]` (word k holds ICD bits 30k+1..30k+24, d1 in bit 23).
    pub fn put(&self, words: &mut [u32; 10], count: i64) {
        let total = self.bits();
        let raw = (count as u64) & ((1u64 << total) - 1);
        let mut remaining = total;
        for &(start, len) in self.parts {
            remaining -= u32::from(len);
            let part = (raw >> remaining) & ((1u64 << len) - 1);
            for b in 0..u32::from(len) {
                let bit = (part >> (u32::from(len) - 1 - b)) & 1;
                let (w, shift) = locate(u32::from(start) + b);
                words[w] = (words[w] & !(1 << shift)) | ((bit as u32) << shift);
            }
        }
    }

    /// Reads the raw count (sign-extended for signed fields) from 24-bit source words.
    pub fn get(&self, words: &[u32; 10]) -> i64 {
        let mut raw: u64 = 0;
        for &(start, len) in self.parts {
            for b in 0..u32::from(len) {
                let (w, shift) = locate(u32::from(start) + b);
                raw = (raw << 1) | u64::from((words[w] >> shift) & 1);
            }
        }
        let n = self.bits();
        if self.signed && raw & (1 << (n - 1)) != 0 {
            raw as i64 - (1i64 << n)
        } else {
            raw as i64
        }
    }

    /// Reads the field as an SI value.
    pub fn get_si(&self, words: &[u32; 10]) -> f64 {
        self.to_si(self.get(words))
    }
}

/// Word index (0-based) and bit shift in the 24-bit source word of ICD bit number `bit`
/// (1..=300; must be a data bit, position 1..=24 within its word).
fn locate(bit: u32) -> (usize, u32) {
    let w = ((bit - 1) / 30) as usize;
    let pos = (bit - 1) % 30; // 0 = d1
    (w.min(9), 23 - pos.min(23))
}

/// ICD quantisation of a GPS time carried as t_oc / t_oe (16 s LSB), keeping the week.
fn quantize_time(field: &Field, t: GpsTime) -> GpsTime {
    GpsTime::new(t.week, field.quantize(t.tow_s))
}

impl Ephemeris {
    /// This ephemeris with every field rounded to the LSB it has in the LNAV message
    /// (IS-GPS-200 Tables 20-I and 20-III): exactly what an [`crate::lnav::LnavEncoder`]
    /// transmits and a decoder recovers. Integer fields are unchanged.
    pub fn quantized_to_icd(&self) -> Ephemeris {
        Ephemeris {
            toc: quantize_time(&TOC, self.toc),
            af0_s: AF0.quantize(self.af0_s),
            af1_s_s: AF1.quantize(self.af1_s_s),
            af2_s_s2: AF2.quantize(self.af2_s_s2),
            crs_m: CRS.quantize(self.crs_m),
            delta_n_rad_s: DELTA_N.quantize(self.delta_n_rad_s),
            m0_rad: M0.quantize(self.m0_rad),
            cuc_rad: CUC.quantize(self.cuc_rad),
            e: ECC.quantize(self.e),
            cus_rad: CUS.quantize(self.cus_rad),
            sqrt_a_sqrt_m: SQRT_A.quantize(self.sqrt_a_sqrt_m),
            toe: quantize_time(&TOE, self.toe),
            cic_rad: CIC.quantize(self.cic_rad),
            omega0_rad: OMEGA0.quantize(self.omega0_rad),
            cis_rad: CIS.quantize(self.cis_rad),
            i0_rad: I0.quantize(self.i0_rad),
            crc_m: CRC.quantize(self.crc_m),
            omega_rad: OMEGA.quantize(self.omega_rad),
            omega_dot_rad_s: OMEGA_DOT.quantize(self.omega_dot_rad_s),
            idot_rad_s: IDOT.quantize(self.idot_rad_s),
            tgd_s: TGD.quantize(self.tgd_s),
            ..self.clone()
        }
    }
}

impl KlobucharParams {
    /// Coefficients rounded to their subframe 4 page 18 LSBs (Table 20-X).
    pub fn quantized_to_icd(&self) -> KlobucharParams {
        let mut out = *self;
        for k in 0..4 {
            out.alpha[k] = ALPHA[k].quantize(self.alpha[k]);
            out.beta[k] = BETA[k].quantize(self.beta[k]);
        }
        out
    }
}

impl UtcParams {
    /// A0, A1 and t_ot rounded to their subframe 4 page 18 LSBs (Table 20-IX). Weeks are kept
    /// in full (only their 8 LSBs are transmitted).
    pub fn quantized_to_icd(&self) -> UtcParams {
        UtcParams {
            a0_s: A0.quantize(self.a0_s),
            a1_s_s: A1.quantize(self.a1_s_s),
            tot_s: TOT.to_count(f64::from(self.tot_s)).clamp(0, 255) as u32 * 4096,
            ..*self
        }
    }
}

impl Almanac {
    /// This almanac with every field rounded to its subframe 4/5 LSB (Table 20-VI), angles
    /// OMEGA_0, omega and M_0 folded into +-1 semicircle: exactly what an
    /// [`crate::lnav::LnavEncoder`] with this almanac transmits and the decoder recovers once
    /// WN_a is known. t_oa is rounded to 4096 s within its week; PRN and health are unchanged.
    pub fn quantized_to_icd(&self) -> Almanac {
        Almanac {
            e: ALM_E.quantize(self.e),
            toa: GpsTime::new(self.toa.week, ALM_TOA.quantize(self.toa.tow_s)),
            delta_i_rad: ALM_DELTA_I.quantize(self.delta_i_rad),
            omega_dot_rad_s: ALM_OMEGA_DOT.quantize(self.omega_dot_rad_s),
            sqrt_a_sqrt_m: ALM_SQRT_A.quantize(self.sqrt_a_sqrt_m),
            omega0_rad: ALM_OMEGA0.quantize_wrapped(self.omega0_rad),
            omega_rad: ALM_OMEGA.quantize_wrapped(self.omega_rad),
            m0_rad: ALM_M0.quantize_wrapped(self.m0_rad),
            af0_s: ALM_AF0.quantize(self.af0_s),
            af1_s_s: ALM_AF1.quantize(self.af1_s_s),
            ..self.clone()
        }
    }
}

impl AlmanacSet {
    /// Every almanac quantised ([`Almanac::quantized_to_icd`]) and the page-25 t_oa rounded to
    /// 4096 s; health and configuration words keep their 6 and 4 LSBs.
    pub fn quantized_to_icd(&self) -> AlmanacSet {
        AlmanacSet {
            toa: GpsTime::new(self.toa.week, P25_TOA.quantize(self.toa.tow_s)),
            almanacs: self
                .almanacs
                .iter()
                .map(|(&prn, a)| (prn, a.quantized_to_icd()))
                .collect(),
            health6: self.health6.map(|h| h & 0x3F),
            sv_config: self.sv_config.map(|c| c & 0x0F),
        }
    }
}
