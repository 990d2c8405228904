//! [`RunPlotData`]: what the plots of a run need, gathered from the fixes and channel rows in
//! bounded memory ([`Decimated`] series of at most [`MAX_POINTS`] points each).

use super::decimate::Decimated;
use crate::output::{ChannelRow, Fix, FixQuality};
use std::collections::BTreeMap;

/// Most points kept per series (the decimation keeps between half and all of this).
pub const MAX_POINTS: usize = 4000;

/// One fix, as the track and DOP plots need it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixPoint {
    /// Seconds from the first sample of the stream.
    pub t_s: f64,
    /// ECEF position, m.
    pub ecef_m: [f64; 3],
    /// Satellites used.
    pub n_sv: usize,
    /// Position dilution of precision.
    pub pdop: f64,
    /// Horizontal dilution of precision.
    pub hdop: f64,
    /// Whether the fix is valid (not flagged by RAIM or the PDOP limit).
    pub valid: bool,
}

/// A satellite's direction at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyPoint {
    /// Seconds from the first sample of the stream.
    pub t_s: f64,
    /// Azimuth, degrees clockwise from north.
    pub az_deg: f64,
    /// Elevation, degrees.
    pub el_deg: f64,
}

/// The series of a run's plots.
#[derive(Debug, Clone)]
pub struct RunPlotData {
    /// Every fix (valid or flagged), decimated.
    pub fixes: Decimated<FixPoint>,
    /// Each satellite's azimuth and elevation from the fixes' satellites in view.
    pub sky: BTreeMap<u8, Decimated<SkyPoint>>,
    /// Each satellite's C/N0 against time (s, dB-Hz) from the channel rows.
    pub cn0: BTreeMap<u8, Decimated<(f64, f64)>>,
}

impl Default for RunPlotData {
    fn default() -> Self {
        Self {
            fixes: Decimated::new(MAX_POINTS / 2),
            sky: BTreeMap::new(),
            cn0: BTreeMap::new(),
        }
    }
}

impl RunPlotData {
    /// Adds a fix made `t_stream_s` after the first sample.
    pub fn add_fix(&mut self, fix: &Fix, t_stream_s: f64) {
        self.fixes.push(FixPoint {
            t_s: t_stream_s,
            ecef_m: fix.ecef_m,
            n_sv: fix.n_sv,
            pdop: fix.pdop,
            hdop: fix.hdop,
            valid: fix.quality != FixQuality::None,
        });
        for s in &fix.sats_in_view {
            if s.az_deg.is_finite() && s.el_deg.is_finite() {
                self.sky
                    .entry(s.prn)
                    .or_insert_with(|| Decimated::new(MAX_POINTS / 2))
                    .push(SkyPoint {
                        t_s: t_stream_s,
                        az_deg: s.az_deg,
                        el_deg: s.el_deg,
                    });
            }
        }
    }

    /// Adds a channel row (its C/N0, when it has one).
    pub fn add_channel(&mut self, row: &ChannelRow) {
        if let Some(cn0) = row.cn0_dbhz.filter(|v| v.is_finite()) {
            self.cn0
                .entry(row.prn)
                .or_insert_with(|| Decimated::new(MAX_POINTS / 2))
                .push((row.t_stream_s, cn0));
        }
    }
}
