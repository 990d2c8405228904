//! The settings of `gpsrx run`: the `[run]` and `[dr]` tables of a configuration file, and
//! their resolution with the command line (command line over file over defaults).

use super::args::{IonoModel, RunArgs, TropoModel};

/// The `[dr]` table of a configuration file: the nominal DR sensor parameters (seed 000) and
/// the fusion settings of `gpsrx run --dr`.
#[derive(Debug, Clone, Default, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct DrRunConfig {
    /// Gyro scale factor Sf_G, deg/s/V.
    pub sf_g_dps_per_v: Option<f64>,
    /// Gyro zero-rate voltage V_nom, V.
    pub v_nom_v: Option<f64>,
    /// Odometer scale factor Sf_N, m/pulse.
    pub sf_n_m_per_pulse: Option<f64>,
    /// `proposed` or `conventional`.
    pub filter: Option<String>,
    /// Least interval between GNSS updates of the filters, s.
    pub update_interval_s: Option<f64>,
}

/// The `[run]` table of a configuration file; command-line options override it.
#[derive(Debug, Clone, Default, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Observable and fix rate, Hz.
    pub rate_hz: Option<f64>,
    /// Elevation mask, degrees.
    pub elevation_mask_deg: Option<f64>,
    /// `klobuchar` or `none`.
    pub iono: Option<String>,
    /// `saastamoinen` or `none`.
    pub tropo: Option<String>,
    /// RAIM false-alarm probability.
    pub raim_pfa: Option<f64>,
    /// Acquisition Doppler half-width, Hz.
    pub doppler_max_hz: Option<f64>,
    /// Acquisition Doppler search centre, Hz.
    pub doppler_center_hz: Option<f64>,
    /// Acquisition coherent integration, ms.
    pub acq_coherent_ms: Option<u32>,
    /// Acquisition non-coherent blocks.
    pub acq_noncoherent: Option<u32>,
    /// Use unhealthy satellites.
    pub allow_unhealthy: Option<bool>,
}

/// Run settings after defaults, the config file and the command line.
#[derive(Debug, Clone, Copy)]
pub(super) struct Settings {
    pub(super) rate: f64,
    pub(super) elevation_mask: f64,
    pub(super) iono: IonoModel,
    pub(super) tropo: TropoModel,
    pub(super) raim_pfa: f64,
    pub(super) doppler_max: f64,
    pub(super) doppler_center: f64,
    pub(super) acq_coherent_ms: u32,
    pub(super) acq_noncoherent: u32,
    pub(super) allow_unhealthy: bool,
}

impl Settings {
    pub(super) fn resolve(args: &RunArgs) -> anyhow::Result<Settings> {
        let file = args.loops.run_config()?.unwrap_or_default();
        let iono = match (args.iono, file.iono.as_deref()) {
            (Some(i), _) => i,
            (None, None | Some("klobuchar")) => IonoModel::Klobuchar,
            (None, Some("none")) => IonoModel::None,
            (None, Some(other)) => {
                anyhow::bail!("[run] iono = \"{other}\": use \"klobuchar\" or \"none\"")
            }
        };
        let tropo = match (args.tropo, file.tropo.as_deref()) {
            (Some(t), _) => t,
            (None, None | Some("saastamoinen")) => TropoModel::Saastamoinen,
            (None, Some("none")) => TropoModel::None,
            (None, Some(other)) => {
                anyhow::bail!("[run] tropo = \"{other}\": use \"saastamoinen\" or \"none\"")
            }
        };
        let s = Settings {
            rate: args.rate.or(file.rate_hz).unwrap_or(10.0),
            elevation_mask: args
                .elevation_mask
                .or(file.elevation_mask_deg)
                .unwrap_or(5.0),
            iono,
            tropo,
            raim_pfa: args.raim_pfa.or(file.raim_pfa).unwrap_or(1e-3),
            doppler_max: args.doppler_max.or(file.doppler_max_hz).unwrap_or(5000.0),
            doppler_center: args
                .doppler_center
                .or(file.doppler_center_hz)
                .unwrap_or(0.0),
            acq_coherent_ms: args.acq_coherent_ms.or(file.acq_coherent_ms).unwrap_or(1),
            acq_noncoherent: args.acq_noncoherent.or(file.acq_noncoherent).unwrap_or(10),
            allow_unhealthy: args.allow_unhealthy || file.allow_unhealthy.unwrap_or(false),
        };
        if !(1.0..=50.0).contains(&s.rate) {
            anyhow::bail!("rate {} Hz: use 1 to 50 Hz", s.rate);
        }
        if !(-10.0..=90.0).contains(&s.elevation_mask) {
            anyhow::bail!("elevation mask {} deg: use -10 to 90", s.elevation_mask);
        }
        if !(s.raim_pfa > 0.0 && s.raim_pfa < 1.0) {
            anyhow::bail!(
                "RAIM false-alarm probability {}: use a value in (0, 1)",
                s.raim_pfa
            );
        }
        if !(s.doppler_max > 0.0 && s.doppler_max <= 100e3) {
            anyhow::bail!(
                "Doppler search half-width {} Hz: use (0, 100000]",
                s.doppler_max
            );
        }
        if !(s.doppler_center.is_finite() && s.doppler_center.abs() <= 100e3) {
            anyhow::bail!(
                "Doppler search centre {} Hz: use a value within +-100000",
                s.doppler_center
            );
        }
        if !(1..=10).contains(&s.acq_coherent_ms) {
            anyhow::bail!(
                "acquisition coherent integration {} ms: use 1 to 10 ms",
                s.acq_coherent_ms
            );
        }
        if !(1..=1000).contains(&s.acq_noncoherent) {
            anyhow::bail!(
                "acquisition non-coherent blocks {}: use 1 to 1000",
                s.acq_noncoherent
            );
        }
        Ok(s)
    }
}
