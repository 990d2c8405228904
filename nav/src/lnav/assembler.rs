//! Collects subframes 1-3 of one satellite into an [`Ephemeris`] (IS-GPS-200 20.3.4.1: a data
//! set is consistent when IODE of subframes 2 and 3 equal the 8 LSBs of IODC in subframe 1).

use super::decoder::{DecodedSubframe, How, Subframe1, Subframe2, Subframe3, SubframePayload};
use crate::ephemeris::Ephemeris;
use crate::time::GpsTime;

/// Builds ephemerides for one PRN from decoded subframes.
///
/// The 10-bit week number of subframe 1 is resolved to the full week nearest
/// `reference_week` ([`GpsTime::resolve_week_10bit`]); t_oe and t_oc get the week (transmission
/// week - 1, same or + 1) that puts them nearest to the transmission time of subframe 1.
#[derive(Debug, Clone, PartialEq)]
pub struct EphemerisAssembler {
    prn: u8,
    reference_week: u32,
    sf1: Option<(How, Subframe1)>,
    sf2: Option<Subframe2>,
    sf3: Option<Subframe3>,
    last: Option<Ephemeris>,
}

impl EphemerisAssembler {
    /// A new assembler for satellite `prn`; `reference_week` is any full week within 512
    /// weeks of the data (e.g. the build date or an approximate clock).
    pub fn new(prn: u8, reference_week: u32) -> EphemerisAssembler {
        EphemerisAssembler {
            prn,
            reference_week,
            sf1: None,
            sf2: None,
            sf3: None,
            last: None,
        }
    }

    /// Feeds one decoded subframe. Returns a new ephemeris when subframes 1, 2 and 3 with
    /// matching issue of data are all present and the result differs from the last one
    /// returned; otherwise `None`. Subframes 4 and 5 are ignored.
    pub fn push(&mut self, sf: &DecodedSubframe) -> Option<Ephemeris> {
        match sf.payload {
            SubframePayload::Subframe1(s) => self.sf1 = Some((sf.how, s)),
            SubframePayload::Subframe2(s) => self.sf2 = Some(s),
            SubframePayload::Subframe3(s) => self.sf3 = Some(s),
            _ => return None,
        }
        let ((how, s1), s2, s3) = (self.sf1?, self.sf2?, self.sf3?);
        if s2.iode != s3.iode || (s1.iodc & 0xFF) != s2.iode {
            return None;
        }
        let eph = ephemeris_from_subframes(self.prn, self.reference_week, &how, &s1, &s2, &s3);
        if self.last.as_ref() == Some(&eph) {
            return None;
        }
        self.last = Some(eph.clone());
        Some(eph)
    }

    /// The last ephemeris returned by [`EphemerisAssembler::push`].
    pub fn latest(&self) -> Option<&Ephemeris> {
        self.last.as_ref()
    }
}

/// Full GPS time of a seconds-of-week value `sow` taken from the week (-1, 0 or +1 around
/// `near`) that puts it nearest to `near`.
fn nearest_week_time(sow: f64, near: GpsTime) -> GpsTime {
    let candidates = [
        GpsTime::new(near.week.saturating_sub(1), sow),
        GpsTime::new(near.week, sow),
        GpsTime::new(near.week.saturating_add(1), sow),
    ];
    let mut best = candidates[1];
    for c in candidates {
        if c.diff_s(near).abs() < best.diff_s(near).abs() {
            best = c;
        }
    }
    best
}

/// Combines a consistent set of subframes 1-3 into an [`Ephemeris`] (no consistency check).
pub fn ephemeris_from_subframes(
    prn: u8,
    reference_week: u32,
    how1: &How,
    s1: &Subframe1,
    s2: &Subframe2,
    s3: &Subframe3,
) -> Ephemeris {
    let week = GpsTime::resolve_week_10bit(s1.week_mod_1024, reference_week);
    let tx = GpsTime::new(week, f64::from(how1.subframe_start_tow_s()));
    Ephemeris {
        prn,
        toc: nearest_week_time(s1.toc_s, tx),
        af0_s: s1.af0_s,
        af1_s_s: s1.af1_s_s,
        af2_s_s2: s1.af2_s_s2,
        iode: s2.iode,
        iodc: s1.iodc,
        crs_m: s2.crs_m,
        delta_n_rad_s: s2.delta_n_rad_s,
        m0_rad: s2.m0_rad,
        cuc_rad: s2.cuc_rad,
        e: s2.e,
        cus_rad: s2.cus_rad,
        sqrt_a_sqrt_m: s2.sqrt_a_sqrt_m,
        toe: nearest_week_time(s2.toe_s, tx),
        cic_rad: s3.cic_rad,
        omega0_rad: s3.omega0_rad,
        cis_rad: s3.cis_rad,
        i0_rad: s3.i0_rad,
        crc_m: s3.crc_m,
        omega_rad: s3.omega_rad,
        omega_dot_rad_s: s3.omega_dot_rad_s,
        idot_rad_s: s3.idot_rad_s,
        tgd_s: s1.tgd_s,
        ura_index: s1.ura_index,
        sv_health: s1.sv_health,
        codes_on_l2: s1.codes_on_l2,
        l2p_data_flag: s1.l2p_data_flag,
        fit_interval_flag: s2.fit_interval_flag,
    }
}
