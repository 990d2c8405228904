//! Satellites taken in from the filter's prediction without a search (issue 29: "satellites
//! that rise or come back are taken in from the filter's prediction").
//!
//! While the filter drives the channels it knows every satellite's code phase and Doppler
//! ([`Snapshot::sv_tow_s`], [`Snapshot::doppler_hz`]). Once a second, each satellite with an
//! ephemeris, above the elevation mask (at least [`MIN_ELEVATION_DEG`]) and tracked by no
//! channel gets a channel started where the prediction puts its signal
//! (`Channel::predicted`): the code period that starts after the end of the samples read,
//! at the sample where the predicted SV time is a whole millisecond. The search, which at
//! 24 dB-Hz needs seconds of non-coherent integration and may not find the satellite at all
//! (measured: 17 s for one, none in 20 s for another), is not needed. A satellite whose
//! signal is not there (blocked, or weaker than the pull-in holds) is released by the
//! weak pull-in's C/N0 test in about a second, and tried again [`RETRY_S`] later.
//!
//! The start's error is the prediction's (the ionosphere and troposphere it leaves out,
//! 2-50 m, and the filter's position: under 0.2 chip) plus half a sample, within the
//! 1-chip early-late discriminator's pull-in range; its Doppler is good to the filter's
//! velocity and drift (a fraction of a hertz), far inside the frequency stage's +-25 Hz.

use super::feed::{code_phase_chips, Snapshot};
use gpsrx_core::constants::{CA_CHIP_RATE_HZ, CA_CODE_LENGTH, F_L1_HZ};
use gpsrx_core::frames::azimuth_elevation;
use gpsrx_core::Prn;
use gpsrx_tracking::ChannelStart;
use std::collections::BTreeMap;

/// Lowest elevation at which a satellite is taken in, deg (whatever the elevation mask).
pub const MIN_ELEVATION_DEG: f64 = 5.0;
/// A satellite taken in and lost is taken in again after this long, s.
pub const RETRY_S: f64 = 10.0;
/// The satellites are looked over at most this often, s.
const EVERY_S: f64 = 1.0;

/// Which satellites were taken in when (module docs).
#[derive(Debug, Clone, Default)]
pub struct TakeIn {
    /// Stream time each satellite was last taken in, s.
    tried_s: BTreeMap<u8, f64>,
    /// Stream time of the last look, s.
    looked_s: Option<f64>,
}

impl TakeIn {
    /// The channels to start for the satellites `snap` predicts above `mask_deg` and no
    /// channel tracks (`tracked`), among `prns` (`[run] prns`; empty: all), after the samples
    /// read so far (`end_sample`, at `fs_hz`).
    pub fn starts(
        &mut self,
        snap: &Snapshot,
        end_sample: u64,
        fs_hz: f64,
        (mask_deg, prns): (f64, &[u8]),
        tracked: &dyn Fn(u8) -> bool,
    ) -> Vec<ChannelStart> {
        let now_s = end_sample as f64 / fs_hz;
        if self.looked_s.is_some_and(|t| now_s - t < EVERY_S) {
            return Vec::new();
        }
        self.looked_s = Some(now_s);
        let min_el = mask_deg.max(MIN_ELEVATION_DEG).to_radians();
        let mut out = Vec::new();
        for (&prn, eph) in snap.ephemerides.iter() {
            let wanted = prns.is_empty() || prns.contains(&prn);
            if !wanted
                || tracked(prn)
                || self.tried_s.get(&prn).is_some_and(|t| now_s - t < RETRY_S)
            {
                continue;
            }
            let Ok(p) = Prn::new(prn) else { continue };
            let pos = snap.position_at(now_s);
            let seen = eph.at_reception(snap.gps_time, &pos, 0.075, 2);
            let (_, el) = azimuth_elevation(&pos, &seen.sv.pos_m);
            if el < min_el {
                continue;
            }
            let (Some(sv_tow_s), Some(doppler_hz)) =
                (snap.sv_tow_s(prn, now_s), snap.doppler_hz(prn, now_s))
            else {
                continue;
            };
            // The next code period: (1023 - c) chips later at the code rate the Doppler gives.
            let rate = CA_CHIP_RATE_HZ * (1.0 + doppler_hz / F_L1_HZ);
            let to_next_s = (CA_CODE_LENGTH as f64 - code_phase_chips(sv_tow_s)) / rate;
            let code_start_sample = end_sample + (to_next_s * fs_hz).round() as u64;
            self.tried_s.insert(prn, now_s);
            out.push(ChannelStart {
                prn: p,
                code_start_sample,
                doppler_hz,
                cn0_dbhz: f64::NAN,
            });
        }
        out
    }

    /// Forgets the satellites tried (the filter starts again).
    pub fn clear(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::vector::feed::test_snapshot;

    const FS_HZ: f64 = 2.6e6;

    #[test]
    fn satellites_above_the_horizon_start_where_their_code_period_starts() {
        let snap = test_snapshot();
        let end = (10.2 * FS_HZ) as u64;
        let mut take = TakeIn::default();
        let tracked = |prn: u8| prn == 31;
        let starts = take.starts(&snap, end, FS_HZ, (5.0, &[]), &tracked);
        let prns: Vec<u8> = starts.iter().map(|s| s.prn.get()).collect();
        // The GPS-SDR-SIM recording of this place and time sees 3, 16, 22, 25, 26, 29, 31
        // and 32 (../shared/data/README.md); 31 is tracked already.
        for p in [3, 16, 22, 25, 26, 29, 32] {
            assert!(prns.contains(&p), "G{p:02} not taken in: {prns:?}");
        }
        assert!(!prns.contains(&31), "{prns:?}");
        for s in &starts {
            // The predicted code phase at the start sample is a whole period (within half a
            // sample, 0.2 chip at 2.6 MHz), within 1 ms after the end of the samples read.
            assert!(s.code_start_sample >= end && s.code_start_sample < end + 2600);
            let t = s.code_start_sample as f64 / FS_HZ;
            let sv = snap.sv_tow_s(s.prn.get(), t).unwrap_or(f64::NAN);
            let off =
                crate::pipeline::vector::vouch::code_distance_chips(code_phase_chips(sv), 0.0);
            assert!(off <= 0.25, "{}: {off:.3} chip off a period start", s.prn);
            assert!(s.cn0_dbhz.is_nan() && s.doppler_hz.abs() < 5000.0, "{s:?}");
            let (_, el) = azimuth_elevation(&snap.position_at(t), &{
                let eph = &snap.ephemerides[&s.prn.get()];
                eph.at_reception(snap.gps_time, &snap.position_at(t), 0.075, 2)
                    .sv
                    .pos_m
            });
            assert!(
                el.to_degrees() >= MIN_ELEVATION_DEG,
                "{}: {:.1} deg",
                s.prn,
                el.to_degrees()
            );
        }
        // Not again within the second, nor for RETRY_S; only the listed PRNs with `prns`.
        assert!(take
            .starts(&snap, end + 1000, FS_HZ, (5.0, &[]), &tracked)
            .is_empty());
        let mut fresh = TakeIn::default();
        let only = fresh.starts(&snap, end, FS_HZ, (5.0, &[16, 31]), &tracked);
        assert_eq!(
            only.iter().map(|s| s.prn.get()).collect::<Vec<_>>(),
            vec![16]
        );
    }
}
