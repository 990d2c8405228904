//! Assisted acquisition: which satellites are above the horizon and at what Doppler, from
//! broadcast ephemerides, an approximate position and the time.

use anyhow::{bail, Context};
use gpsrx_core::{los_doppler_hz, PosVel};
use gpsrx_dsp::Prn;
use gpsrx_nav::{azimuth_elevation, GpsTime, HealthPolicy, Llh, NavData, Vector3};

/// What the ephemeris predicts for one satellite at the receiver.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Prediction {
    /// The satellite.
    #[serde(serialize_with = "super::ser_prn")]
    pub prn: Prn,
    /// Carrier Doppler for a static receiver with a perfect clock, Hz.
    pub doppler_hz: f64,
    /// Elevation, degrees.
    pub elevation_deg: f64,
    /// Azimuth, degrees clockwise from north.
    pub azimuth_deg: f64,
    /// The ephemeris's health word is zero. Unhealthy satellites usually still transmit (with
    /// their health bits set), so they are searched too.
    pub healthy: bool,
}

/// Predicted Doppler and elevation of every PRN with an ephemeris valid at `t` (healthy or not,
/// healthy ones first: [`NavData::select_with`] with [`HealthPolicy::PreferHealthy`]) that is
/// at least `mask_deg` above the horizon of a static receiver at `rx`.
///
/// The satellite state is taken at transmit time `t - tau` (light time iterated three times
/// from 75 ms) and rotated by the Earth's rotation during the flight (IS-GPS-200
/// 20.3.3.4.3.3.2; [`gpsrx_nav::Ephemeris::at_reception`]). With `u` the unit vector from the
/// receiver to the satellite, the range rate is `rho_dot = (v_sv - v_rx) . u` (v_rx = 0 in
/// ECEF), and the Doppler is positive when the range shrinks:
/// `f_D = -rho_dot / lambda_L1 + f_L1 clock_drift_sv` ([`gpsrx_core::los_doppler_hz`]; a
/// satellite clock running fast transmits above 1575.42 MHz). The receiver's own clock drift is unknown here and adds
/// `-drift * f_L1` to every satellite (1e-6 s/s = -1575 Hz): cover it with the search window.
pub fn predict(nav: &NavData, rx: &Llh, t: GpsTime, mask_deg: f64) -> Vec<Prediction> {
    let rx_ecef = rx.to_ecef();
    Prn::all()
        .filter_map(|prn| {
            let eph = nav.select_with(prn.get(), t, HealthPolicy::PreferHealthy)?;
            let seen = eph.at_reception(t, &rx_ecef, 0.075, 3);
            let sv = PosVel {
                pos_m: seen.sv.pos_m,
                vel_mps: seen.sv.vel_mps,
            };
            let rx = PosVel {
                pos_m: rx_ecef,
                vel_mps: Vector3::zeros(),
            };
            let doppler_hz = los_doppler_hz(&sv, &rx, seen.sv.clock_drift_s_s, 0.0)?;
            let (az, el) = azimuth_elevation(&rx_ecef, &seen.sv.pos_m);
            let elevation_deg = el.to_degrees();
            (elevation_deg >= mask_deg && doppler_hz.is_finite()).then_some(Prediction {
                prn,
                doppler_hz,
                elevation_deg,
                azimuth_deg: az.to_degrees(),
                healthy: eph.sv_health == 0,
            })
        })
        .collect()
}

/// Parses `LAT,LON,H` (degrees, degrees, metres above the WGS-84 ellipsoid).
pub fn parse_llh(text: &str) -> anyhow::Result<Llh> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [lat, lon, h] = parts.as_slice() else {
        bail!("--approx-llh {text:?}: give LAT,LON,H, e.g. 37.5665,126.978,40");
    };
    let num = |s: &str, what: &str| -> anyhow::Result<f64> {
        let v: f64 = s
            .parse()
            .with_context(|| format!("--approx-llh {text:?}: {what} {s:?} is not a number"))?;
        if !v.is_finite() {
            bail!("--approx-llh {text:?}: {what} must be finite");
        }
        Ok(v)
    };
    let (lat, lon, h) = (
        num(lat, "latitude")?,
        num(lon, "longitude")?,
        num(h, "height")?,
    );
    if lat.abs() > 90.0 || lon.abs() > 360.0 || h.abs() > 1e6 {
        bail!("--approx-llh {text:?}: latitude within +-90 deg, longitude within +-360 deg, |height| below 1000 km");
    }
    Ok(Llh::from_degrees(lat, lon, h))
}

/// Parses `WEEK:TOW` (full GPS week, seconds of week) of the first sample.
pub fn parse_time(text: &str) -> anyhow::Result<GpsTime> {
    let Some((w, tow)) = text.split_once(':') else {
        bail!("--time {text:?}: give WEEK:TOW, e.g. 2190:538200 (full GPS week, seconds of week)");
    };
    let week: u32 = w
        .trim()
        .parse()
        .with_context(|| format!("--time {text:?}: week {w:?} is not a whole number"))?;
    let tow: f64 = tow
        .trim()
        .parse()
        .with_context(|| format!("--time {text:?}: time of week {tow:?} is not a number"))?;
    if !(0.0..604_800.0).contains(&tow) {
        bail!("--time {text:?}: time of week must be in [0, 604800) s");
    }
    if week < 1024 {
        bail!("--time {text:?}: give the full GPS week (e.g. 2190), not the week modulo 1024");
    }
    Ok(GpsTime::new(week, tow))
}
