//! The aiding port: how an external (INS) Doppler is fed forward into the carrier and code NCOs.
//!
//! Seed 004 Fig. 4 / Fig. 5: the INS Doppler is added at the VCO input beside the loop filter,
//! `f_NCO = f_ff + F(e)`. Because `f_ff` already follows the dynamics, the loop filter only tracks
//! the residual `f_true - f_ff`; with a perfect `f_ff` the phase error is zero for any loop order
//! and bandwidth (seed 004 eq. 7), and an aid error `delta f` enters the loop as a frequency
//! disturbance (seed 004 eq. 11). The code NCO is carrier-aided: its rate is the chip rate
//! scaled by the carrier Doppler (`f_code = f_chip (1 + f_D / f_L1)`, code Doppler = carrier
//! Doppler / 1540) plus the DLL correction, so the feed-forward reaches the code NCO too.

use gpsrx_dsp::constants::{CARRIER_CYCLES_PER_CHIP, CA_CHIP_RATE_HZ, LAMBDA_L1_M};
use gpsrx_dsp::Prn;

/// An external Doppler estimate for one integration interval.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DopplerAid {
    /// Carrier Doppler at the start of the interval, Hz (positive when the range shrinks).
    pub doppler_hz: f64,
    /// Its rate of change over the interval, Hz/s (from the INS LOS acceleration, `-a_los/lambda`);
    /// 0 when unknown.
    pub doppler_rate_hz_s: f64,
    /// The aid's source predicts the signal through an outage of it (vector tracking: the
    /// navigation filter predicts every satellite from the others, or from its motion and clock
    /// models when all are gone): while the prompt power has collapsed the channel coasts on the
    /// aid, its loops holding their memories, its lock and its C/N0 test suspended
    /// (`Channel::coasting_on_aid`). False for an INS's aid, whose channels run their own
    /// outage rules.
    pub coast: bool,
    /// The aid's source checked the channel's measurements against the others within the
    /// last second and admitted them (vector tracking's innovation test): the channel counts
    /// as lost, and gives no observables, only below
    /// `ChannelConfig::vector_cn0_lost_dbhz` instead of `cn0_lost_dbhz`.
    pub checked: bool,
    /// Where the aid comes from: when it changes, the channel keeps its NCO frequency
    /// continuous as when an aid comes or goes (two sources leave different shares to the
    /// loop: the INS feed-forward leaves it the receiver clock drift of when it came on, vector
    /// tracking's carries the whole drift; a switch between them stepped every NCO by
    /// `f_L1 d_rx`, 63 Hz at 4e-8, which read as samples lost).
    pub source: AidSource,
}

/// The source of a [`DopplerAid`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AidSource {
    /// An INS's velocity (seed 004's feed-forward).
    #[default]
    Ins,
    /// The bridge over an outage (the fixes' motion).
    Bridge,
    /// Vector tracking's navigation filter.
    Vector,
}

impl DopplerAid {
    /// The frequency to hold in the NCO over an interval of `t_coh_s` starting now: the mean of
    /// the linearly varying Doppler, `f_D + (df_D/dt) T/2`. With it a constant LOS acceleration
    /// leaves no residual at all; without the rate term it leaves a constant frequency offset
    /// `(df_D/dt) T/2` that a 2nd or higher-order loop absorbs.
    pub fn mean_over_hz(&self, t_coh_s: f64) -> f64 {
        let v = self.doppler_hz + 0.5 * self.doppler_rate_hz_s * t_coh_s;
        if v.is_finite() {
            v
        } else {
            0.0
        }
    }
}

/// Who drives the channels' NCOs (`[tracking] mode`, `gpsrx run --tracking`).
///
/// - `scalar`: every channel's own loops (PLL/FLL and DLL) track alone (or aided by an INS,
///   `--ins`);
/// - `vector`: after the first valid fix a navigation filter (position, velocity, clock bias
///   and drift) predicts every satellite's Doppler and feeds it forward through the aiding
///   port ([`AidingPort`]); the channels' own loops stay on top and track the residual
///   (a VDFLL-style feed-forward, issue 29). Back to scalar when the filter's health test fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TrackingMode {
    /// Scalar tracking loops (the default).
    #[default]
    Scalar,
    /// The navigation filter feeds every carrier NCO forward.
    Vector,
}

impl std::str::FromStr for TrackingMode {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "scalar" => Ok(Self::Scalar),
            "vector" => Ok(Self::Vector),
            other => Err(format!(
                "tracking mode `{other}`: use `scalar` (each channel's own loops) or `vector` (the navigation filter drives the channels)"
            )),
        }
    }
}

impl std::fmt::Display for TrackingMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Scalar => "scalar",
            Self::Vector => "vector",
        })
    }
}

/// The aiding port of the tracking channels: where an external Doppler estimate comes from.
///
/// The receiver asks it for every channel at the start of every code period (seed 004 Fig. 4:
/// the INS Doppler is fed forward beside the loop filter); an implementation turns an INS
/// velocity, an ephemeris and a position into the line-of-sight Doppler of each satellite.
/// `None` means no aid for that satellite at that time (the loop runs unaided).
///
/// Closures `Fn(Prn, f64) -> Option<DopplerAid>` implement it, for tests and studies that know
/// the truth.
pub trait AidingPort: Sync {
    /// The aid for satellite `prn` at receive time `t_s` (seconds from the first sample of the
    /// recording).
    fn doppler_aid(&self, prn: Prn, t_s: f64) -> Option<DopplerAid>;
}

impl<F> AidingPort for F
where
    F: Fn(Prn, f64) -> Option<DopplerAid> + Sync,
{
    fn doppler_aid(&self, prn: Prn, t_s: f64) -> Option<DopplerAid> {
        self(prn, t_s)
    }
}

/// Carrier NCO frequency (Hz, relative to the nominal IF) = fed-forward Doppler + loop filter
/// output (seed 004 Fig. 4). A non-finite feed-forward is ignored (the loop runs unaided).
pub fn carrier_nco_hz(feedforward_hz: f64, loop_output_hz: f64) -> f64 {
    if feedforward_hz.is_finite() {
        feedforward_hz + loop_output_hz
    } else {
        loop_output_hz
    }
}

/// Code Doppler (chips/s) implied by a carrier Doppler: `f_D f_chip / f_L1 = f_D / 1540`
/// (`oracles.md`, "Code loop aiding").
pub fn code_doppler_chips_s(carrier_doppler_hz: f64) -> f64 {
    carrier_doppler_hz / CARRIER_CYCLES_PER_CHIP
}

/// Code NCO rate (chips/s) of a carrier-aided DLL:
/// `f_chip (1 + f_D / f_L1) + DLL output`, with `f_D` the carrier NCO's Doppler (which already
/// contains the feed-forward).
pub fn code_rate_chips_s(carrier_doppler_hz: f64, dll_output_chips_s: f64) -> f64 {
    CA_CHIP_RATE_HZ + code_doppler_chips_s(carrier_doppler_hz) + dll_output_chips_s
}

// The line-of-sight Doppler `f_D = -((v_sv - v_rx) . u) / lambda` (seed 004 eq. 6) that feeds
// this port is `gpsrx_core::los_doppler_hz`.

/// Doppler rate (Hz/s) from a LOS range acceleration (m/s^2): `-a / lambda`. 1 g is 51.5 Hz/s
/// (18,552 deg/s^2 of carrier phase).
pub fn doppler_rate_hz_s(range_accel_mps2: f64) -> f64 {
    -range_accel_mps2 / LAMBDA_L1_M
}

/// The steady phase error (cycles) an aided PLL of `order` at `bn_hz` keeps when the
/// feed-forward's error grows at a constant rate, as an INS accelerometer bias `bias_mps2` on
/// the line of sight makes it (velocity error `B t`: a Doppler ramp `B / lambda` Hz/s).
/// 2nd order: `B / (lambda w0^2)`, `w0 = Bn / 0.53` (Kaplan Table 5.6; seed 004 Table 1);
/// 3rd order: 0 (it follows a ramp); 1st order: none (the error grows without bound).
pub fn static_phase_offset_cycles(order: u8, bn_hz: f64, bias_mps2: f64) -> Option<f64> {
    match order {
        2 => {
            let w0 = crate::loop_filter::omega0(2, bn_hz);
            Some(bias_mps2 / (LAMBDA_L1_M * w0 * w0))
        }
        3 => Some(0.0),
        _ => None,
    }
}

/// The INS accelerometer bias the receiver assumes when it predicts the static phase offset of
/// its aided loops, m/s^2: 1 mg per axis, all of it on the line of sight (`sqrt(3)` mg), a
/// tactical-grade IMU's worst case.
pub const NOMINAL_INS_BIAS_LOS_MPS2: f64 = 1.732_050_807_568_877_2 * 9.806_65e-3;

/// The static phase offset (cycles) the aided loops of `cfg` (`aided_track`, else `track`)
/// keep under [`NOMINAL_INS_BIAS_LOS_MPS2`]: [`static_phase_offset_cycles`] of a 2nd-order
/// loop; `None` for other orders (3rd order keeps none, 1st order drifts without bound).
pub fn nominal_aided_offset_cycles(cfg: &crate::ChannelConfig) -> Option<f64> {
    let loops = cfg.aided_track.unwrap_or(cfg.track);
    (loops.pll_order == 2)
        .then(|| static_phase_offset_cycles(2, loops.pll_bw_hz, NOMINAL_INS_BIAS_LOS_MPS2))
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_dsp::constants::F_L1_HZ;

    #[test]
    fn a_1_mg_bias_leaves_a_2nd_order_0p4_hz_loop_a_tenth_of_a_cycle() {
        // w0 = 0.4 / 0.53 = 0.755 rad/s: 9.81e-3 / (0.1903 x 0.570) = 0.0905 cycle; the issue's
        // 0.1-0.16 cycle for 1 mg on each of 3 axes (up to sqrt 3 on a line of sight).
        let c = static_phase_offset_cycles(2, 0.4, 9.80665e-3).unwrap_or(f64::NAN);
        assert!((c - 0.0905).abs() < 5e-4, "{c}");
        assert_eq!(static_phase_offset_cycles(3, 0.4, 9.80665e-3), Some(0.0));
        assert_eq!(static_phase_offset_cycles(1, 0.4, 9.80665e-3), None);
    }

    #[test]
    fn the_nominal_offset_is_given_for_2nd_order_aided_loops_only() {
        let mut cfg = crate::ChannelConfig::default();
        // Default tracking loops: 3rd order, no offset.
        assert_eq!(nominal_aided_offset_cycles(&cfg), None);
        let mut aided = cfg.track;
        aided.pll_order = 2;
        aided.pll_bw_hz = 0.4;
        cfg.aided_track = Some(aided);
        // sqrt(3) x 0.0905 cycle (the 1 mg case above).
        let c = nominal_aided_offset_cycles(&cfg).unwrap_or(f64::NAN);
        assert!((c - 3f64.sqrt() * 0.0905).abs() < 1e-3, "{c}");
        aided.pll_order = 1;
        cfg.aided_track = Some(aided);
        assert_eq!(nominal_aided_offset_cycles(&cfg), None);
        // Without aided loops the tracking loops are the aided ones.
        cfg.aided_track = None;
        cfg.track.pll_order = 2;
        cfg.track.pll_bw_hz = 3.0;
        assert!(nominal_aided_offset_cycles(&cfg).is_some_and(|c| c > 0.0 && c < 0.01));
    }

    #[test]
    fn code_aiding_is_doppler_over_1540() {
        assert!((code_doppler_chips_s(1540.0) - 1.0).abs() < 1e-12);
        let r = code_rate_chips_s(-4000.0, 0.25);
        let want = CA_CHIP_RATE_HZ * (1.0 - 4000.0 / F_L1_HZ) + 0.25;
        assert!((r - want).abs() < 1e-9);
    }

    #[test]
    fn doppler_sign_and_units() {
        // 1 g towards the satellite: range acceleration -g, Doppler rate +51.5 Hz/s,
        // i.e. 18,552 deg/s^2.
        let r = doppler_rate_hz_s(-9.80665);
        assert!((r * 360.0 - 18_552.0).abs() < 1.0, "{}", r * 360.0);
        let aid = DopplerAid {
            doppler_hz: 100.0,
            doppler_rate_hz_s: 50.0,
            coast: false,
            checked: false,
            source: crate::AidSource::Ins,
        };
        assert!((aid.mean_over_hz(0.02) - 100.5).abs() < 1e-12);
        assert_eq!(carrier_nco_hz(f64::NAN, 3.0), 3.0);
    }
}
