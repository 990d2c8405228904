//! The receiver's products, as the sink receives them and the writers of
//! [`crate::output`] write them: [`Fix`], [`ObsEpoch`] (with [`SatObs`]), [`ChannelRow`].
//! Small and format-neutral: the pipeline converts its own types into them.

use gpsrx_nav::{GpsTime, Llh};

/// Observations of all tracked satellites at one receiver epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct ObsEpoch {
    /// Receiver time of the epoch (GPS time scale, as read from the receiver clock).
    pub time: GpsTime,
    /// Receiver clock offset, s, if the writer should report it (RINEX epoch line field).
    pub clock_offset_s: Option<f64>,
    /// One entry per satellite.
    pub sats: Vec<SatObs>,
}

/// L1 C/A observations of one satellite at one epoch. `None` or non-finite values are written
/// as blank (not observed).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SatObs {
    /// GPS PRN, 1-32 (RINEX allows 1-99).
    pub prn: u8,
    /// Pseudorange, m.
    pub pseudorange_m: Option<f64>,
    /// Carrier phase, cycles (RINEX sign convention: grows with range).
    pub carrier_cycles: Option<f64>,
    /// Doppler, Hz (positive for an approaching satellite).
    pub doppler_hz: Option<f64>,
    /// Carrier-to-noise density, dB-Hz.
    pub cn0_dbhz: Option<f64>,
    /// Lock was lost (or a cycle slip detected) since the previous epoch of this satellite.
    pub loss_of_lock: bool,
    /// The carrier phase may be off by half a cycle (navigation bit sign not yet resolved).
    pub half_cycle_ambiguous: bool,
}

/// What kind of solution a [`Fix`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FixQuality {
    /// Autonomous GNSS fix.
    Gnss,
    /// GNSS fused with dead reckoning (a GNSS update within the last moments).
    Fused,
    /// Dead-reckoning (propagated or INS-aided) solution.
    DeadReckoning,
    /// No valid position.
    #[default]
    None,
}

impl FixQuality {
    /// Name used in CSV and GeoJSON outputs.
    pub fn name(self) -> &'static str {
        match self {
            FixQuality::Gnss => "gnss",
            FixQuality::Fused => "fused",
            FixQuality::DeadReckoning => "dead_reckoning",
            FixQuality::None => "none",
        }
    }
}

/// One satellite as seen from the fix position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatView {
    /// GPS PRN.
    pub prn: u8,
    /// Elevation, degrees.
    pub el_deg: f64,
    /// Azimuth, degrees clockwise from north.
    pub az_deg: f64,
    /// C/N0, dB-Hz, if tracked.
    pub cn0_dbhz: Option<f64>,
}

/// A position, velocity and time solution.
#[derive(Debug, Clone, PartialEq)]
pub struct Fix {
    /// GPS time of the solution (receiver time corrected by the clock bias).
    pub time: GpsTime,
    /// Whether `time.week` is known (decoded, configured, or from the recording's date):
    /// when not, the writers leave the week and the date out (the time of week and of day
    /// stand).
    pub week_known: bool,
    /// ECEF position, m.
    pub ecef_m: [f64; 3],
    /// Geodetic position (WGS-84, height above the ellipsoid).
    pub llh: Llh,
    /// ECEF velocity, m/s.
    pub vel_ecef_mps: Option<[f64; 3]>,
    /// Receiver clock bias, m.
    pub clock_bias_m: f64,
    /// Receiver clock drift, m/s.
    pub clock_drift_mps: Option<f64>,
    /// Number of satellites used.
    pub n_sv: usize,
    /// PRNs used in the solution.
    pub used_prns: Vec<u8>,
    /// Position dilution of precision.
    pub pdop: f64,
    /// Horizontal dilution of precision.
    pub hdop: f64,
    /// Vertical dilution of precision.
    pub vdop: f64,
    /// RAIM outcome as text (e.g. `ok`, `excluded G12`, `unavailable`).
    pub raim: String,
    /// Solution kind.
    pub quality: FixQuality,
    /// One-sigma position uncertainty east, north and up, m, from the solution's covariance
    /// (`s^2 N^-1` rotated to the local frame, with the variance factor's 95 % upper bound
    /// `s^2`); `None` when there is none (fused rows).
    pub sigma_enu_m: Option<[f64; 3]>,
    /// Satellites in view, for NMEA GSV.
    pub sats_in_view: Vec<SatView>,
}

/// Per-channel tracking state at one epoch, one row of `channels.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelRow {
    /// Receiver time of the epoch; `None` before the time origin is known (frame sync).
    pub time: Option<GpsTime>,
    /// Whether `time.week` is known (see [`Fix::week_known`]).
    pub week_known: bool,
    /// Seconds from the first sample of the stream (always known).
    pub t_stream_s: f64,
    /// Channel number.
    pub channel: u32,
    /// GPS PRN tracked.
    pub prn: u8,
    /// Channel state name (e.g. `acquiring`, `pull_in`, `tracking`, `lost`).
    pub state: String,
    /// C/N0 estimate, dB-Hz.
    pub cn0_dbhz: Option<f64>,
    /// Carrier Doppler, Hz.
    pub doppler_hz: Option<f64>,
    /// Code phase, chips.
    pub code_phase_chips: Option<f64>,
    /// PLL lock indicator (e.g. the cos 2 phi estimate, 1 = locked).
    pub pll_lock_indicator: Option<f64>,
    /// Code (DLL) lock declared.
    pub code_lock: bool,
    /// Carrier (PLL) lock declared.
    pub carrier_lock: bool,
    /// Navigation bit synchronisation achieved.
    pub bit_sync: bool,
    /// Subframe (preamble) synchronisation achieved.
    pub frame_sync: bool,
    /// While the channel is fed forward by an INS and its aided loop is 2nd order: the static
    /// phase offset that loop keeps under a nominal accelerometer bias
    /// (`gpsrx_tracking::aiding::nominal_aided_offset_cycles`), cycles; `None` otherwise.
    pub predicted_offset_cycles: Option<f64>,
}
