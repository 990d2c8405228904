//! Collects the almanac from decoded subframes 4 and 5 of any satellites (IS-GPS-200
//! 20.3.3.5.1.2 - 20.3.3.5.1.5).
//!
//! An almanac page carries t_oa but not the week: WN_a (8 bits) is in subframe 5 page 25
//! together with the t_oa it belongs to. A page is therefore kept pending until a page 25 with
//! the same t_oa has been seen, then dated (WN_a resolved to the full week nearest the reference
//! week) and kept if it is not older than the almanac already held for that PRN.

use std::collections::BTreeMap;

use super::decoder::{AlmanacPage, DecodedSubframe, Sf4Page25, Sf5Page25, SubframePayload};
use crate::almanac::{Almanac, AlmanacSet};
use crate::time::{resolve_week_modulo, GpsTime};

/// How many distinct (t_oa, WN_a) pairs of subframe 5 page 25 are remembered: two uploads
/// overlap at most briefly, a few cover satellites not yet switched to the new one.
const MAX_REFERENCES: usize = 4;

/// Keeps the newest almanac per PRN from the subframes of all tracked satellites.
#[derive(Debug, Clone, PartialEq)]
pub struct AlmanacCollector {
    reference_week: u32,
    /// t_oa (s) -> full WN_a, from subframe 5 pages 25, and which was seen last.
    references: BTreeMap<u32, u32>,
    latest_reference: Option<GpsTime>,
    /// Pages whose t_oa has no page 25 yet, per PRN (the last one received).
    pending: BTreeMap<u8, AlmanacPage>,
    almanacs: BTreeMap<u8, Almanac>,
    health6: [Option<u8>; 32],
    sv_config: [Option<u8>; 32],
}

impl AlmanacCollector {
    /// A new collector; `reference_week` is any full week within 128 weeks of the almanac
    /// (WN_a is 8 bits): the week decoded from subframe 1 is the right choice once known
    /// ([`AlmanacCollector::set_reference_week`]).
    pub fn new(reference_week: u32) -> AlmanacCollector {
        AlmanacCollector {
            reference_week,
            references: BTreeMap::new(),
            latest_reference: None,
            pending: BTreeMap::new(),
            almanacs: BTreeMap::new(),
            health6: [None; 32],
            sv_config: [None; 32],
        }
    }

    /// Changes the week WN_a is resolved against (pages dated from now on).
    pub fn set_reference_week(&mut self, week: u32) {
        self.reference_week = week;
    }

    /// Feeds one decoded subframe (any satellite). Returns the PRNs whose almanac was added
    /// or replaced by this subframe (several when a page 25 dates pending pages).
    pub fn push(&mut self, sf: &DecodedSubframe) -> Vec<u8> {
        match &sf.payload {
            SubframePayload::Almanac(page) => self.push_page(page).into_iter().collect(),
            SubframePayload::Sf5Page25(p) => self.push_sf5_page25(p),
            SubframePayload::Sf4Page25(p) => {
                self.push_sf4_page25(p);
                Vec::new()
            }
            _ => Vec::new(),
        }
    }

    fn push_page(&mut self, page: &AlmanacPage) -> Option<u8> {
        if !(1..=32).contains(&page.sv_id) {
            return None;
        }
        match self.references.get(&page.toa_s) {
            Some(&week) => self.keep(page.to_almanac(week)),
            None => {
                self.pending.insert(page.sv_id, *page);
                None
            }
        }
    }

    /// Keeps `alm` unless the almanac held for its PRN has a later t_oa; returns the PRN if
    /// the held almanac changed.
    fn keep(&mut self, alm: Almanac) -> Option<u8> {
        if let Some(held) = self.almanacs.get(&alm.prn) {
            if held.toa.diff_s(alm.toa) > 0.0 || *held == alm {
                return None;
            }
        }
        let prn = alm.prn;
        self.almanacs.insert(prn, alm);
        Some(prn)
    }

    fn push_sf5_page25(&mut self, p: &Sf5Page25) -> Vec<u8> {
        let week = resolve_week_modulo(p.wna_mod_256, self.reference_week, 256);
        self.references.insert(p.toa_s, week);
        while self.references.len() > MAX_REFERENCES {
            // Forget the oldest reference time.
            let oldest = self
                .references
                .iter()
                .min_by(|a, b| {
                    let ta = GpsTime::new(*a.1, f64::from(*a.0));
                    let tb = GpsTime::new(*b.1, f64::from(*b.0));
                    ta.diff_s(tb).total_cmp(&0.0)
                })
                .map(|(&toa, _)| toa);
            match oldest {
                Some(toa) => self.references.remove(&toa),
                None => break,
            };
        }
        self.latest_reference = Some(GpsTime::new(week, f64::from(p.toa_s)));
        for (slot, &h) in self.health6.iter_mut().zip(p.health6.iter()) {
            *slot = Some(h);
        }
        let dated: Vec<AlmanacPage> = self
            .pending
            .values()
            .filter(|page| page.toa_s == p.toa_s)
            .copied()
            .collect();
        let mut changed = Vec::new();
        for page in dated {
            self.pending.remove(&page.sv_id);
            changed.extend(self.keep(page.to_almanac(week)));
        }
        changed
    }

    fn push_sf4_page25(&mut self, p: &Sf4Page25) {
        for (slot, &c) in self.sv_config.iter_mut().zip(p.sv_config.iter()) {
            *slot = Some(c);
        }
        for (slot, &h) in self.health6[24..].iter_mut().zip(p.health6.iter()) {
            *slot = Some(h);
        }
    }

    /// The almanac held for `prn`.
    pub fn almanac(&self, prn: u8) -> Option<&Almanac> {
        self.almanacs.get(&prn)
    }

    /// All almanacs held, by PRN.
    pub fn almanacs(&self) -> &BTreeMap<u8, Almanac> {
        &self.almanacs
    }

    /// Number of almanac pages waiting for their subframe 5 page 25.
    pub fn pending_count(&self) -> usize {
        self.pending.len()
    }

    /// The 6-bit page-25 health of `prn` (1-32), once its page 25 has been received.
    pub fn health6(&self, prn: u8) -> Option<u8> {
        usize::from(prn)
            .checked_sub(1)
            .and_then(|i| self.health6.get(i).copied().flatten())
    }

    /// The 4-bit A-S/configuration word of `prn` (1-32), once subframe 4 page 25 has been
    /// received.
    pub fn sv_config(&self, prn: u8) -> Option<u8> {
        usize::from(prn)
            .checked_sub(1)
            .and_then(|i| self.sv_config.get(i).copied().flatten())
    }

    /// The collected almanac as a set: the latest subframe 5 page 25 reference time, every
    /// almanac held, page-25 health where received (else the almanac's own health word, else
    /// [`crate::almanac::HEALTH6_NOT_AVAILABLE`]) and
    /// configurations (0 where not received). None before any page 25 of subframe 5.
    pub fn almanac_set(&self) -> Option<AlmanacSet> {
        let toa = self.latest_reference?;
        let mut set = AlmanacSet::new(toa);
        for alm in self.almanacs.values() {
            set.insert(alm.clone());
        }
        for (slot, h) in set.health6.iter_mut().zip(self.health6.iter()) {
            if let Some(h) = h {
                *slot = *h;
            }
        }
        for (k, c) in self.sv_config.iter().enumerate() {
            set.sv_config[k] = c.unwrap_or(0);
        }
        Some(set)
    }
}
