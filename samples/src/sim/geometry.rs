//! The signal's propagation model: what each satellite's signal looks like at the antenna at a
//! given receiver time.
//!
//! For a sample taken at receiver time `t_rcv` (true time `t = t_rcv - b`):
//! - transmit time `t_tx` solves `t - t_tx = |R3(OmegaE tau) r_sv(t_tx) - r_rx(t)| / c` (light time
//!   with the Earth's rotation during flight, IS-GPS-200 20.3.3.4.3.3.2), iterated;
//! - the code leaves the satellite at SV time `t_sv = t_tx - (I + T)/c + dt_sv(t_tx)` (ionospheric
//!   group delay `I`, tropospheric delay `T`, satellite clock `dt_sv` with the relativistic term and
//!   TGD, so a receiver applying the broadcast correction recovers `t_tx`); hence the code
//!   pseudorange `P = c (t_rcv - t_sv) = rho + I + T + c (b - dt_sv)`;
//! - the carrier phase is advanced by the ionosphere: `Phi = rho - I + T + c (b - dt_sv)`, and the
//!   complex baseband phase is `phi = f_IF t_rcv - Phi / lambda` cycles, so the Doppler
//!   `-dPhi/dt / lambda` is positive for an approaching satellite.

use crate::sim::clock::ReceiverClock;
use crate::sim::trajectory::{RxState, Trajectory};
use gpsrx_dsp::constants::{CA_CHIP_RATE_HZ, LAMBDA_L1_M, SPEED_OF_LIGHT_MPS};
use gpsrx_nav::atmosphere::{klobuchar_delay_s, saastamoinen_delay_m, KlobucharParams};
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::frames::{azimuth_elevation, light_time, Llh, Vector3};
use gpsrx_nav::time::GpsTime;

/// What is common to all satellites: time origin, receiver motion and clock, atmosphere.
#[derive(Debug)]
pub struct Environment {
    /// GPS time (receiver clock) of the first sample.
    pub start: GpsTime,
    /// Receiver trajectory, in true seconds since `start`.
    pub trajectory: Trajectory,
    /// Receiver clock.
    pub clock: ReceiverClock,
    /// Ionosphere model parameters, if the ionosphere is simulated.
    pub iono: Option<KlobucharParams>,
    /// Whether the troposphere is simulated.
    pub tropo: bool,
    /// SV time (s since `start`) of the subframe boundary from which code chips and data bits are
    /// counted.
    pub sv_ref_s: f64,
}

/// Terms that change slowly (seconds to minutes) and are evaluated every chunk, not every node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlowTerms {
    /// Ionospheric group delay on L1, m (0 when off).
    pub iono_m: f64,
    /// Tropospheric delay, m (0 when off).
    pub tropo_m: f64,
    /// Elevation, rad.
    pub el_rad: f64,
    /// Azimuth, rad.
    pub az_rad: f64,
}

impl SlowTerms {
    /// Linear interpolation between two evaluations.
    pub fn lerp(&self, other: &SlowTerms, u: f64) -> SlowTerms {
        let l = |a: f64, b: f64| a + (b - a) * u;
        SlowTerms {
            iono_m: l(self.iono_m, other.iono_m),
            tropo_m: l(self.tropo_m, other.tropo_m),
            el_rad: l(self.el_rad, other.el_rad),
            az_rad: l(self.az_rad, other.az_rad),
        }
    }
}

/// A satellite's signal at one receiver instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// True time, s since start.
    pub t_true_s: f64,
    /// Receiver state at the true time.
    pub rx: RxState,
    /// Satellite position at transmit time, rotated into the ECEF frame at reception, m.
    pub sv_pos_m: Vector3<f64>,
    /// Geometric range, m.
    pub range_m: f64,
    /// Geometric signal travel time, s.
    pub tau_s: f64,
    /// Satellite clock correction dt_sv (with relativistic term and TGD), s.
    pub sv_clock_s: f64,
    /// Receiver clock bias, s.
    pub rx_clock_s: f64,
    /// Code pseudorange, m.
    pub pseudorange_m: f64,
    /// Carrier-phase range (ionosphere advanced), m.
    pub phase_range_m: f64,
    /// Code phase counted from the reference subframe boundary, chips.
    pub chips: f64,
    /// Carrier phase without the IF term, `-Phi / lambda`, cycles.
    pub carrier_cycles: f64,
}

impl Environment {
    /// Slow terms for `eph`'s satellite at receiver time `t_rcv_s` (seconds since start).
    pub fn slow_terms(&self, eph: &Ephemeris, t_rcv_s: f64) -> SlowTerms {
        let t = self.clock.true_time(t_rcv_s);
        let rx = self.trajectory.state(t);
        // One light-time pass from 75 ms: the satellite to ~0.1 km, ample for the elevation.
        let start = self.start;
        let sv_pos = light_time(
            |tau| eph.sv_state(start.add_seconds(t - tau)),
            &rx.pos_m,
            0.075,
            1,
        )
        .sv
        .pos_m;
        let (az, el) = azimuth_elevation(&rx.pos_m, &sv_pos);
        let llh = Llh::from_ecef(&rx.pos_m);
        let iono_m = match &self.iono {
            Some(p) if el > 0.0 => {
                klobuchar_delay_s(p, self.start.add_seconds(t).tow_s, &llh, az, el)
                    * SPEED_OF_LIGHT_MPS
            }
            _ => 0.0,
        };
        let tropo_m = if self.tropo && el > 0.0 {
            saastamoinen_delay_m(&llh, el)
        } else {
            0.0
        };
        SlowTerms {
            iono_m,
            tropo_m,
            el_rad: el,
            az_rad: az,
        }
    }

    /// The signal of `eph`'s satellite at receiver time `t_rcv_s`, starting the light-time
    /// iteration from `tau_guess_s` and iterating `iterations` times (2 from a guess within a
    /// millisecond of travel-time change is exact to well below a micrometre).
    pub fn observe(
        &self,
        eph: &Ephemeris,
        t_rcv_s: f64,
        slow: &SlowTerms,
        tau_guess_s: f64,
        iterations: usize,
    ) -> Observation {
        let b = self.clock.bias_s(self.clock.true_time(t_rcv_s));
        let t = t_rcv_s - b;
        let rx = self.trajectory.state(t);
        let start = self.start;
        let seen = light_time(
            |tau| eph.sv_state(start.add_seconds(t - tau)),
            &rx.pos_m,
            tau_guess_s,
            iterations,
        );
        let (sv_pos, range, tau) = (seen.sv.pos_m, seen.range_m, seen.flight_time_s);
        let sv_clock = seen.sv.clock_bias_s;
        let clock_term = SPEED_OF_LIGHT_MPS * (b - sv_clock);
        let pseudorange_m = range + slow.iono_m + slow.tropo_m + clock_term;
        let phase_range_m = range - slow.iono_m + slow.tropo_m + clock_term;
        let chips =
            (t_rcv_s - pseudorange_m / SPEED_OF_LIGHT_MPS - self.sv_ref_s) * CA_CHIP_RATE_HZ;
        Observation {
            t_true_s: t,
            rx,
            sv_pos_m: sv_pos,
            range_m: range,
            tau_s: tau,
            sv_clock_s: sv_clock,
            rx_clock_s: b,
            pseudorange_m,
            phase_range_m,
            chips,
            carrier_cycles: -phase_range_m / LAMBDA_L1_M,
        }
    }
}
