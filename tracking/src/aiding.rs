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

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_dsp::constants::F_L1_HZ;

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
        };
        assert!((aid.mean_over_hz(0.02) - 100.5).abs() < 1e-12);
        assert_eq!(carrier_nco_hz(f64::NAN, 3.0), 3.0);
    }
}
