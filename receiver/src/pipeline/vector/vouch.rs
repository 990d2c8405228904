//! Channels vouched for by the prediction before the filter has a measurement of them
//! (`super::feed`, "Before a satellite's first measurement").
//!
//! While the filter drives the channels, every report of a channel that is neither lost nor
//! coasting is compared (at most every [`VOUCH_EVERY_S`] per satellite) with the predicted
//! code phase at its first sample ([`code_phase_chips`] of
//! [`Snapshot::sv_tow_s`]): within [`VOUCH_CHIPS`]
//! (modulo the 1023-chip period) the channel tracks its satellite's signal, and counts as
//! checked for [`super::feed::CHECKED_S`] ([`Snapshot::checked`]): its loss threshold is
//! `[tracking] vector_cn0_lost_dbhz`, so a satellite at 22-25 dB-Hz stays tracked until its
//! bits and frame are synchronised and its observables reach the filter's innovation test.
//! A satellite whose pseudorange or Doppler the filter excluded within `CHECKED_S` is not
//! vouched for (the innovation test outranks the code check). A channel vouched for also
//! gets its data-bit edges from the prediction (the 20 ms boundaries of the SV time,
//! `crate::pipeline::timing::predicted`), which a channel still searching for them takes
//! (`Channel::assume_bit_edge`): a weak pull-in is bit-aligned at once instead of after
//! 2-10 s of histogram.
//!
//! The tolerance, half a chip (147 m), is the DLL's own pull-in range; what the prediction
//! leaves out or gets wrong stays well inside it: the ionosphere and troposphere (2-50 m,
//! their mean in the filter's clock bias), the filter's position (metres), and the code
//! noise at 19 dB-Hz (under 0.1 chip). A cross-correlation peak or a false acquisition lies
//! anywhere in the period: one chance in 1023 to fall within it.

use super::feed::{code_phase_chips, Snapshot, CHECKED_S};
use crate::pipeline::timing::modulo::nearest_remainder;
use crate::pipeline::timing::predicted;
use gpsrx_core::constants::CA_CODE_LENGTH;
use gpsrx_tracking::{ChannelEpoch, ChannelState};
use std::collections::BTreeMap;

/// Largest distance of a channel's code phase from the prediction that vouches for it, chips.
pub const VOUCH_CHIPS: f64 = 0.5;
/// A satellite's channel is compared with the prediction at most this often, s.
pub const VOUCH_EVERY_S: f64 = 0.1;

/// The channels the prediction vouches for (module docs).
#[derive(Debug, Clone, Default)]
pub struct Vouchers {
    /// Stream time each satellite's channel last agreed with the prediction, s.
    vouched_s: BTreeMap<u8, f64>,
    /// Stream time the filter last excluded a measurement of each satellite, s.
    excluded_s: BTreeMap<u8, f64>,
    /// Stream time each satellite's channel was last compared, s.
    tried_s: BTreeMap<u8, f64>,
}

impl Vouchers {
    /// Compares report `e` with the prediction `snap` (module docs); when it vouches for the
    /// channel, returns the data-bit edges the prediction puts on it
    /// (`crate::pipeline::timing::predicted::bit_edge_phase`).
    pub fn observe(&mut self, snap: &Snapshot, e: &ChannelEpoch) -> Option<usize> {
        if e.state == ChannelState::Lost || e.coasting {
            return None;
        }
        let t = e.t_rx_s;
        let recent = |m: &BTreeMap<u8, f64>, window: f64| {
            m.get(&e.prn)
                .is_some_and(|s| (0.0..window).contains(&(t - s)))
        };
        if recent(&self.tried_s, VOUCH_EVERY_S) {
            return None;
        }
        self.tried_s.insert(e.prn, t);
        if recent(&self.excluded_s, CHECKED_S) {
            return None;
        }
        let sv_tow_s = snap.sv_tow_s(e.prn, t)?;
        if code_distance_chips(code_phase_chips(sv_tow_s), e.code_phase_chips) > VOUCH_CHIPS {
            return None;
        }
        self.vouched_s.insert(e.prn, t);
        predicted::bit_edge_phase(e, sv_tow_s)
    }

    /// The filter excluded a measurement of `prn` at stream time `t_s`: no vouching for it
    /// for [`CHECKED_S`], and the vouching it had is withdrawn.
    pub fn note_excluded(&mut self, prn: u8, t_s: f64) {
        self.excluded_s.insert(prn, t_s);
        self.vouched_s.remove(&prn);
    }

    /// Forgets everything (the filter starts again).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Stream time each satellite's channel was last vouched for, s.
    pub fn vouched_s(&self) -> &BTreeMap<u8, f64> {
        &self.vouched_s
    }
}

/// Distance of two code phases modulo the C/A period, chips in `[0, 511.5]`.
pub fn code_distance_chips(a: f64, b: f64) -> f64 {
    nearest_remainder(a - b, CA_CODE_LENGTH as f64).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn code_distance_wraps_around_the_period() {
        assert!((code_distance_chips(0.2, 1022.9) - 0.3).abs() < 1e-9);
        assert!((code_distance_chips(1022.9, 0.2) - 0.3).abs() < 1e-9);
        assert!((code_distance_chips(100.0, 611.5) - 511.5).abs() < 1e-9);
        assert_eq!(code_distance_chips(5.0, 5.0), 0.0);
    }
}

#[cfg(test)]
mod prediction_tests {
    use super::*;
    use crate::pipeline::vector::feed::test_snapshot;
    use num_complex::Complex64;

    /// A report of G16 at stream time `t_s` whose code stands `off_chips` from the prediction.
    fn report_at(snap: &Snapshot, t_s: f64, off_chips: f64) -> ChannelEpoch {
        let mut e = crate::pipeline::test_support::report(
            16,
            (t_s * 1e3) as u64,
            Complex64::new(1.0, 0.0),
            0.0,
            0.0,
            24.0,
        );
        e.t_rx_s = t_s;
        let sv = snap.sv_tow_s(16, t_s).unwrap_or(f64::NAN);
        e.code_phase_chips = (code_phase_chips(sv) + off_chips).rem_euclid(1023.0);
        e
    }

    #[test]
    fn a_channel_on_the_predicted_code_is_vouched_for_and_one_off_it_is_not() {
        let snap = test_snapshot();
        let mut v = Vouchers::default();
        assert!(v.observe(&snap, &report_at(&snap, 10.0, 3.0)).is_none());
        assert!(v.vouched_s().is_empty());
        // Compared again only after VOUCH_EVERY_S.
        assert!(v.observe(&snap, &report_at(&snap, 10.05, 0.1)).is_none());
        let edge = v.observe(&snap, &report_at(&snap, 10.2, 0.1));
        assert!(edge.is_some_and(|p| p < 20), "{edge:?}");
        assert_eq!(v.vouched_s().get(&16), Some(&10.2));
        // An exclusion by the innovation test withdraws it and holds it off for CHECKED_S.
        v.note_excluded(16, 10.25);
        assert!(v.vouched_s().is_empty());
        assert!(v.observe(&snap, &report_at(&snap, 10.4, 0.0)).is_none());
        assert!(v.observe(&snap, &report_at(&snap, 11.3, 0.0)).is_some());
    }
}
