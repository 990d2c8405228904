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
    /// channel tracks (`tracked`), after the samples read so far (`end_sample`, at `fs_hz`).
    pub fn starts(
        &mut self,
        snap: &Snapshot,
        end_sample: u64,
        fs_hz: f64,
        mask_deg: f64,
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
            if tracked(prn) || self.tried_s.get(&prn).is_some_and(|t| now_s - t < RETRY_S) {
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
