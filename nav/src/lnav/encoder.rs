//! LNAV subframe encoder (IS-GPS-200 20.3.2 message structure, 20.3.3 content, 20.3.5 parity):
//! turns an ephemeris (and optionally Klobuchar/UTC parameters) into the transmitted bit
//! stream of subframes 1-5.

use super::fields::{self as fd, Field};
use super::parity::{last_two_bits, parity_encode, solve_trailing_bits};
use super::LnavError;
use crate::atmosphere::KlobucharParams;
use crate::ephemeris::Ephemeris;
use crate::utc::UtcParams;

/// TLM preamble 1000 1011 (20.3.3.1).
pub const PREAMBLE: u32 = 0x8B;
/// Subframe 4 page 18 SV (page) ID (20.3.3.5.1, Table 20-V).
pub const PAGE18_SV_ID: u32 = 56;
/// Subframe 4 page 25 SV (page) ID.
pub const PAGE25_SV_ID: u32 = 63;
/// Data ID of the LNAV message (20.3.3.5.1.1).
pub const LNAV_DATA_ID: u32 = 0b01;
/// Number of 6-s subframes, i.e. HOW TOW counts, in a week.
pub const SUBFRAMES_PER_WEEK: u32 = 100_800;

/// Source data (24 bits per word, words 3-10 filled; TLM and HOW added per subframe) of the
/// five subframes of one 30-s frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LnavEncoder {
    frames: [[u32; 10]; 5],
    /// Alert flag sent in every HOW (20.3.3.2); default false.
    pub alert: bool,
    /// Anti-spoof flag sent in every HOW (20.3.3.2); default false.
    pub anti_spoof: bool,
    /// 14-bit TLM message (20.3.3.1); default 0.
    pub tlm_message: u16,
}

/// Writes `si` quantised into `field`, failing if it does not fit.
fn put_si(words: &mut [u32; 10], field: &Field, si: f64, prn: u8) -> Result<(), LnavError> {
    let (lo, hi) = field.count_range();
    let count = field.to_count(si);
    if !si.is_finite() || count < lo || count > hi {
        let (min, max) = field.si_range();
        return Err(LnavError::FieldRange {
            prn,
            field: field.name,
            value: si,
            min,
            max,
        });
    }
    field.put(words, count);
    Ok(())
}

/// Writes an integer field, failing if it does not fit.
fn put_int(words: &mut [u32; 10], field: &Field, v: i64, prn: u8) -> Result<(), LnavError> {
    put_si(words, field, v as f64, prn)
}

impl LnavEncoder {
    /// Prepares subframes 1-5 for `eph`. Subframe 4 carries page 18 (SV ID 56) with `iono`
    /// and `utc` when either is given (a missing one is sent as zeros), otherwise a page-25
    /// style page (SV ID 63, all data zero). Subframe 5 is a dummy almanac page (SV ID 0,
    /// alternating ones and zeros, 20.3.3.5.1.2).
    ///
    /// Fails with [`LnavError::FieldRange`] naming the first parameter that does not fit its
    /// ICD field after rounding to the LSB.
    pub fn new(
        eph: &Ephemeris,
        iono: Option<&KlobucharParams>,
        utc: Option<&UtcParams>,
    ) -> Result<LnavEncoder, LnavError> {
        let prn = eph.prn;
        let mut sf1 = [0u32; 10];
        put_int(&mut sf1, &fd::CODES_ON_L2, i64::from(eph.codes_on_l2), prn)?;
        put_int(&mut sf1, &fd::URA, i64::from(eph.ura_index), prn)?;
        put_int(&mut sf1, &fd::HEALTH, i64::from(eph.sv_health), prn)?;
        put_int(&mut sf1, &fd::IODC, i64::from(eph.iodc), prn)?;
        put_int(&mut sf1, &fd::L2P, i64::from(eph.l2p_data_flag), prn)?;
        put_si(&mut sf1, &fd::TGD, eph.tgd_s, prn)?;
        put_si(&mut sf1, &fd::TOC, eph.toc.tow_s, prn)?;
        put_si(&mut sf1, &fd::AF2, eph.af2_s_s2, prn)?;
        put_si(&mut sf1, &fd::AF1, eph.af1_s_s, prn)?;
        put_si(&mut sf1, &fd::AF0, eph.af0_s, prn)?;

        let mut sf2 = [0u32; 10];
        put_int(&mut sf2, &fd::IODE2, i64::from(eph.iode), prn)?;
        put_si(&mut sf2, &fd::CRS, eph.crs_m, prn)?;
        put_si(&mut sf2, &fd::DELTA_N, eph.delta_n_rad_s, prn)?;
        put_si(&mut sf2, &fd::M0, eph.m0_rad, prn)?;
        put_si(&mut sf2, &fd::CUC, eph.cuc_rad, prn)?;
        put_si(&mut sf2, &fd::ECC, eph.e, prn)?;
        put_si(&mut sf2, &fd::CUS, eph.cus_rad, prn)?;
        put_si(&mut sf2, &fd::SQRT_A, eph.sqrt_a_sqrt_m, prn)?;
        put_si(&mut sf2, &fd::TOE, eph.toe.tow_s, prn)?;
        put_int(&mut sf2, &fd::FIT, i64::from(eph.fit_interval_flag), prn)?;

        let mut sf3 = [0u32; 10];
        put_si(&mut sf3, &fd::CIC, eph.cic_rad, prn)?;
        put_si(&mut sf3, &fd::OMEGA0, eph.omega0_rad, prn)?;
        put_si(&mut sf3, &fd::CIS, eph.cis_rad, prn)?;
        put_si(&mut sf3, &fd::I0, eph.i0_rad, prn)?;
        put_si(&mut sf3, &fd::CRC, eph.crc_m, prn)?;
        put_si(&mut sf3, &fd::OMEGA, eph.omega_rad, prn)?;
        put_si(&mut sf3, &fd::OMEGA_DOT, eph.omega_dot_rad_s, prn)?;
        put_int(&mut sf3, &fd::IODE3, i64::from(eph.iode), prn)?;
        put_si(&mut sf3, &fd::IDOT, eph.idot_rad_s, prn)?;

        let mut sf4 = [0u32; 10];
        fd::DATA_ID.put(&mut sf4, i64::from(LNAV_DATA_ID));
        if iono.is_some() || utc.is_some() {
            fd::SV_ID.put(&mut sf4, i64::from(PAGE18_SV_ID));
            if let Some(p) = iono {
                for k in 0..4 {
                    put_si(&mut sf4, &fd::ALPHA[k], p.alpha[k], prn)?;
                    put_si(&mut sf4, &fd::BETA[k], p.beta[k], prn)?;
                }
            }
            if let Some(u) = utc {
                put_si(&mut sf4, &fd::A0, u.a0_s, prn)?;
                put_si(&mut sf4, &fd::A1, u.a1_s_s, prn)?;
                put_si(&mut sf4, &fd::TOT, f64::from(u.tot_s), prn)?;
                put_int(&mut sf4, &fd::WNT, i64::from(u.wnt % 256), prn)?;
                put_int(&mut sf4, &fd::DT_LS, i64::from(u.dt_ls_s), prn)?;
                put_int(&mut sf4, &fd::WN_LSF, i64::from(u.wn_lsf % 256), prn)?;
                put_int(&mut sf4, &fd::DN, i64::from(u.dn), prn)?;
                put_int(&mut sf4, &fd::DT_LSF, i64::from(u.dt_lsf_s), prn)?;
            }
        } else {
            fd::SV_ID.put(&mut sf4, i64::from(PAGE25_SV_ID));
        }

        let mut sf5 = [0u32; 10];
        fill_alternating(&mut sf5);
        fd::DATA_ID.put(&mut sf5, i64::from(LNAV_DATA_ID));
        fd::SV_ID.put(&mut sf5, 0);

        Ok(LnavEncoder {
            frames: [sf1, sf2, sf3, sf4, sf5],
            alert: false,
            anti_spoof: false,
            tlm_message: 0,
        })
    }

    /// Transmitted bits (0/1, transmission order, parity applied) of the subframe whose first
    /// bit leaves the SV at `subframe_start_tow_s` (a multiple of 6; other values are
    /// truncated to the subframe containing them) in full GPS week `week`.
    ///
    /// Subframe ID = (tow/6) % 5 + 1; HOW TOW count = (tow/6 + 1) mod 100800, the truncated
    /// TOW of the next subframe's leading edge (20.3.3.2); subframe 1 carries `week % 1024`.
    /// Words 2 and 10 use their two non-information bits so that D29 = D30 = 0, hence every
    /// subframe starts from D29* = D30* = 0 (20.3.5.2).
    pub fn subframe_bits(&self, subframe_start_tow_s: u32, week: u32) -> [u8; 300] {
        let index = (subframe_start_tow_s / 6) % SUBFRAMES_PER_WEEK;
        let subframe_id = index % 5 + 1;
        let tow_count = (index + 1) % SUBFRAMES_PER_WEEK;
        let mut words = self.frames[(subframe_id - 1) as usize];
        if subframe_id == 1 {
            fd::WN.put(&mut words, i64::from(week % 1024));
        }
        words[0] = (PREAMBLE << 16) | (u32::from(self.tlm_message & 0x3FFF) << 2);
        words[1] = (tow_count << 7)
            | (u32::from(self.alert) << 6)
            | (u32::from(self.anti_spoof) << 5)
            | (subframe_id << 2);
        let mut bits = [0u8; 300];
        let (mut d29, mut d30) = (false, false);
        for (k, &data) in words.iter().enumerate() {
            let data = if k == 1 || k == 9 {
                solve_trailing_bits(data, d29, d30)
            } else {
                data
            };
            let word = parity_encode(data, d29, d30);
            for b in 0..30 {
                bits[30 * k + b] = ((word >> (29 - b)) & 1) as u8;
            }
            (d29, d30) = last_two_bits(word);
        }
        bits
    }
}

/// Fills data bits 69-292 (after data ID and SV ID) with 1010... per word, as dummy almanac
/// pages carry (20.3.3.5.1.2); the two non-information bits of word 10 are left for parity.
fn fill_alternating(words: &mut [u32; 10]) {
    const PATTERN_24: u32 = 0xAA_AAAA;
    for w in words.iter_mut().take(9).skip(3) {
        *w = PATTERN_24;
    }
    words[2] = (words[2] & 0xFF_0000) | (PATTERN_24 & 0xFFFF);
    words[9] = PATTERN_24 & 0xFF_FFFC;
}
