//! LNAV subframe encoder (IS-GPS-200 20.3.2 message structure, 20.3.3 content, 20.3.5 parity):
//! turns an ephemeris (and optionally Klobuchar/UTC parameters and an almanac) into the
//! transmitted bit stream of subframes 1-5.

use super::fields::{self as fd, Field};
use super::parity::{last_two_bits, parity_encode, solve_trailing_bits};
use super::LnavError;
use crate::almanac::{Almanac, AlmanacSet};
use crate::atmosphere::KlobucharParams;
use crate::ephemeris::Ephemeris;
use crate::utc::UtcParams;

/// TLM preamble 1000 1011 (20.3.3.1).
pub const PREAMBLE: u32 = 0x8B;
/// Subframe 4 page 18 SV (page) ID (20.3.3.5.1, Table 20-V).
pub const PAGE18_SV_ID: u32 = 56;
/// Subframe 4 page 25 SV (page) ID.
pub const PAGE25_SV_ID: u32 = 63;
/// Subframe 5 page 25 SV (page) ID (Table 20-V).
pub const SF5_PAGE25_SV_ID: u32 = 51;
/// Number of pages of subframes 4 and 5 (20.3.3.5.1: a 12.5-min cycle of 25 frames).
pub const PAGES_PER_CYCLE: u32 = 25;
/// SV (page) ID of subframe 4 pages 1-25 (Table 20-V): 57 reserved, 25-32 almanac of those SVs,
/// 52 NMCT, 53-54 system use, 55 special messages, 56 ionosphere/UTC, 58-62 reserved, 63 A-S
/// flags, configurations and health of SV 25-32.
pub const SF4_PAGE_SV_IDS: [u32; 25] = [
    57, 25, 26, 27, 28, 57, 29, 30, 31, 32, 57, 62, 52, 53, 54, 57, 55, 56, 58, 59, 57, 60, 61, 62,
    63,
];
/// Data ID of the LNAV message (20.3.3.5.1.1).
pub const LNAV_DATA_ID: u32 = 0b01;
/// Number of 6-s subframes, i.e. HOW TOW counts, in a week.
pub const SUBFRAMES_PER_WEEK: u32 = 100_800;

/// Source data (24 bits per word, words 3-10 filled; TLM and HOW added per subframe) of the
/// five subframes of one 30-s frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LnavEncoder {
    frames: [[u32; 10]; 5],
    /// Subframe 4 carries page 18 (true) or the page-25 style page (false) in `frames[3]`.
    has_page18: bool,
    /// Source words of subframe 4 and 5 pages 1-25 when an almanac is sent.
    pages: Option<Box<PageCycle>>,
    /// Alert flag sent in every HOW (20.3.3.2); default false.
    pub alert: bool,
    /// Anti-spoof flag sent in every HOW (20.3.3.2); default false.
    pub anti_spoof: bool,
    /// 14-bit TLM message (20.3.3.1); default 0.
    pub tlm_message: u16,
}

/// Source words (words 3-10) of the 25 pages of subframes 4 and 5.
#[derive(Debug, Clone, PartialEq)]
struct PageCycle {
    sf4: [[u32; 10]; 25],
    sf5: [[u32; 10]; 25],
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
            has_page18: iono.is_some() || utc.is_some(),
            pages: None,
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
        // 20.3.3.5.1: subframes 4 and 5 page through 25 pages, one per 30-s frame, counted
        // from the start of the week: page = (frame index mod 25) + 1, frame index = TOW / 30.
        let page = ((index / 5) % PAGES_PER_CYCLE) as usize;
        let mut words = match (&self.pages, subframe_id) {
            (Some(cycle), 4) => cycle.sf4[page],
            (Some(cycle), 5) => cycle.sf5[page],
            _ => self.frames[(subframe_id - 1) as usize],
        };
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

impl LnavEncoder {
    /// Sends `almanac` in subframes 4 and 5, paging through the 25 pages of each by frame
    /// (IS-GPS-200 20.3.3.5.1, Table 20-V): subframe 5 pages 1-24 carry the almanac of SV 1-24
    /// and page 25 (SV ID 51) t_oa, WN_a and the health of SV 1-24; subframe 4 pages 2-5 and
    /// 7-10 carry SV 25-32, page 18 the ionosphere/UTC page given to [`LnavEncoder::new`] and
    /// page 25 (SV ID 63) the A-S/configuration words and the health of SV 25-32. A PRN without
    /// almanac gets a dummy page (SV ID 0, alternating ones and zeros, 20.3.3.5.1.2); reserved,
    /// NMCT, system-use and special-message pages carry their Table 20-V SV ID and the
    /// alternating pattern. Without iono/UTC, page 18 is sent as a reserved page (SV ID 57), so
    /// that no receiver takes zeros for a broadcast ionosphere.
    ///
    /// Page 18 then comes once per 12.5 min instead of in every frame. Fails with
    /// [`LnavError::FieldRange`] when an almanac value does not fit its field.
    pub fn with_almanac(mut self, almanac: &AlmanacSet) -> Result<LnavEncoder, LnavError> {
        let dummy = dummy_page(0);
        let mut sf4 = [dummy; 25];
        let mut sf5 = [dummy; 25];
        for (page, slot) in sf5.iter_mut().enumerate().take(24) {
            let prn = page as u8 + 1;
            if let Some(alm) = almanac.get(prn) {
                *slot = almanac_page(alm)?;
            }
        }
        sf5[24] = sf5_page25(almanac);
        for (slot, &sv_id) in sf4.iter_mut().zip(SF4_PAGE_SV_IDS.iter()) {
            *slot = match sv_id {
                25..=32 => match almanac.get(sv_id as u8) {
                    Some(alm) => almanac_page(alm)?,
                    None => dummy,
                },
                PAGE18_SV_ID if self.has_page18 => self.frames[3],
                PAGE18_SV_ID => dummy_page(57),
                PAGE25_SV_ID => sf4_page25(almanac),
                other => dummy_page(other),
            };
        }
        self.pages = Some(Box::new(PageCycle { sf4, sf5 }));
        Ok(self)
    }
}

/// Writes an angle of the full +-1 semicircle range, folded into the field (never fails on
/// range; a non-finite value does).
fn put_angle(words: &mut [u32; 10], field: &Field, si: f64, prn: u8) -> Result<(), LnavError> {
    if !si.is_finite() {
        return put_si(words, field, si, prn);
    }
    field.put(words, field.to_count_wrapped(si));
    Ok(())
}

/// Source words of the almanac page of `alm` (Figure 20-1 sheet 4, Table 20-VI).
fn almanac_page(alm: &Almanac) -> Result<[u32; 10], LnavError> {
    let prn = alm.prn;
    let mut w = [0u32; 10];
    fd::DATA_ID.put(&mut w, i64::from(LNAV_DATA_ID));
    put_int(&mut w, &fd::SV_ID, i64::from(prn), prn)?;
    put_si(&mut w, &fd::ALM_E, alm.e, prn)?;
    put_si(&mut w, &fd::ALM_TOA, alm.toa.tow_s, prn)?;
    put_si(&mut w, &fd::ALM_DELTA_I, alm.delta_i_rad, prn)?;
    put_si(&mut w, &fd::ALM_OMEGA_DOT, alm.omega_dot_rad_s, prn)?;
    put_int(&mut w, &fd::ALM_HEALTH, i64::from(alm.health), prn)?;
    put_si(&mut w, &fd::ALM_SQRT_A, alm.sqrt_a_sqrt_m, prn)?;
    put_angle(&mut w, &fd::ALM_OMEGA0, alm.omega0_rad, prn)?;
    put_angle(&mut w, &fd::ALM_OMEGA, alm.omega_rad, prn)?;
    put_angle(&mut w, &fd::ALM_M0, alm.m0_rad, prn)?;
    put_si(&mut w, &fd::ALM_AF0, alm.af0_s, prn)?;
    put_si(&mut w, &fd::ALM_AF1, alm.af1_s_s, prn)?;
    Ok(w)
}

/// Subframe 5 page 25 (SV ID 51): t_oa, WN_a mod 256, 6-bit health of SV 1-24; the reserved
/// bits of word 10 are zero.
fn sf5_page25(set: &AlmanacSet) -> [u32; 10] {
    let mut w = [0u32; 10];
    fd::DATA_ID.put(&mut w, i64::from(LNAV_DATA_ID));
    fd::SV_ID.put(&mut w, i64::from(SF5_PAGE25_SV_ID));
    let toa_count = fd::P25_TOA.to_count(set.toa.tow_s).clamp(0, 255);
    fd::P25_TOA.put(&mut w, toa_count);
    fd::P25_WNA.put(&mut w, i64::from(set.toa.week % 256));
    for (prn, &h) in (1u8..=24).zip(set.health6.iter()) {
        if let Some(bit) = fd::sf5_page25_health_bit(prn) {
            fd::put_bits(&mut w, bit, 6, u32::from(h));
        }
    }
    w
}

/// Subframe 4 page 25 (SV ID 63): A-S/configuration of SV 1-32, health of SV 25-32; the
/// reserved bits are zero.
fn sf4_page25(set: &AlmanacSet) -> [u32; 10] {
    let mut w = [0u32; 10];
    fd::DATA_ID.put(&mut w, i64::from(LNAV_DATA_ID));
    fd::SV_ID.put(&mut w, i64::from(PAGE25_SV_ID));
    for (prn, (&c, &h)) in (1u8..=32).zip(set.sv_config.iter().zip(set.health6.iter())) {
        if let Some(bit) = fd::sf4_page25_config_bit(prn) {
            fd::put_bits(&mut w, bit, 4, u32::from(c));
        }
        if let Some(bit) = fd::sf4_page25_health_bit(prn) {
            fd::put_bits(&mut w, bit, 6, u32::from(h));
        }
    }
    w
}

/// A page with SV ID `sv_id` and the alternating pattern (dummy almanac page for SV ID 0,
/// 20.3.3.5.1.2; filler for the reserved and system-use pages).
fn dummy_page(sv_id: u32) -> [u32; 10] {
    let mut w = [0u32; 10];
    fill_alternating(&mut w);
    fd::DATA_ID.put(&mut w, i64::from(LNAV_DATA_ID));
    fd::SV_ID.put(&mut w, i64::from(sv_id));
    w
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
