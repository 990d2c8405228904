//! Assisted acquisition: which satellites are above the horizon and at what Doppler, from
//! broadcast ephemerides, an approximate position and the time.

use anyhow::{bail, Context};
use gpsrx_core::PosVel;
use gpsrx_dsp::Prn;
use gpsrx_nav::{GpsTime, HealthPolicy, Llh, NavData, Vector3};
use gpsrx_receiver::pipeline::channels::predict_satellite;

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
/// at least `mask_deg` above the horizon of a static receiver at `rx`
/// ([`gpsrx_receiver::pipeline::channels::predict_satellite`]). The receiver's own clock drift is
/// unknown here and adds `-drift * f_L1` to every satellite (1e-6 s/s = -1575 Hz): cover it
/// with the search window.
pub fn predict(nav: &NavData, rx: &Llh, t: GpsTime, mask_deg: f64) -> Vec<Prediction> {
    let rx = PosVel {
        pos_m: rx.to_ecef(),
        vel_mps: Vector3::zeros(),
    };
    Prn::all()
        .filter_map(|prn| {
            let eph = nav.select_with(prn.get(), t, HealthPolicy::PreferHealthy)?;
            let p = predict_satellite(eph, &rx, t, 0.0)?;
            (p.elevation_deg >= mask_deg).then_some(Prediction {
                prn,
                doppler_hz: p.doppler_hz,
                elevation_deg: p.elevation_deg,
                azimuth_deg: p.azimuth_deg,
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
