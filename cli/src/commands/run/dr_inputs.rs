//! `gpsrx run --dr --accel`: the DR and accelerometer logs, read and checked before tracking,
//! and the fused outputs written after it.

use crate::cli::{DrFilterChoice, RunArgs};
use anyhow::Context;
use gpsrx_ins_aiding::{
    read_accel_csv, read_dr_csv, AccelLog, DrFilterKind, DrLog, DrParams, FixSource,
};
use gpsrx_receiver::fusion::fuse::{fuse_dr, DrFusionSettings};
use gpsrx_receiver::fusion::fused_csv::{fused_as_fixes, write_fused_csv};
use gpsrx_receiver::fusion::gnss::GnssFix;
use gpsrx_receiver::fusion::speed::{attach_speed, speed_track};
use gpsrx_receiver::output::plots::dr::draw_dr_track;
use gpsrx_receiver::output::{self, create_file, NmeaOptions, NmeaWriter};
use gpsrx_receiver::ReceiverConfig;
use std::path::Path;

/// The DR inputs of a run, read and checked before tracking starts.
pub(super) struct DrInputs {
    dr: Option<DrLog>,
    accel: Option<AccelLog>,
    settings: DrFusionSettings,
}

impl DrInputs {
    pub(super) fn load(
        args: &RunArgs,
        config: &ReceiverConfig,
    ) -> anyhow::Result<Option<DrInputs>> {
        let rate_hz = config.run.rate_hz;
        if args.dr.is_none() && args.accel.is_none() {
            return Ok(None);
        }
        let file = &config.dr;
        let nominal = DrParams::default();
        let params = DrParams {
            sf_g_dps_per_v: file.sf_g_dps_per_v.unwrap_or(nominal.sf_g_dps_per_v),
            v_nom_v: file.v_nom_v.unwrap_or(nominal.v_nom_v),
            sf_n_m_per_pulse: file.sf_n_m_per_pulse.unwrap_or(nominal.sf_n_m_per_pulse),
        };
        params.validate().context("config [dr]")?;
        let kind = match (args.dr_filter, file.filter.as_deref()) {
            (Some(DrFilterChoice::Proposed), _) | (None, None | Some("proposed")) => {
                DrFilterKind::Proposed8
            }
            (Some(DrFilterChoice::Conventional), _) | (None, Some("conventional")) => {
                DrFilterKind::Conventional4
            }
            (None, Some(other)) => {
                anyhow::bail!("[dr] filter = \"{other}\": use \"proposed\" or \"conventional\"")
            }
        };
        let mut settings = DrFusionSettings::new(kind, params, 1.0 / rate_hz);
        settings.calibration = args.dr_params.as_deref().map(DrParams::load).transpose()?;
        if let Some(u) = file.update_interval_s {
            if !(u.is_finite() && u > 0.0 && u <= 60.0) {
                anyhow::bail!("[dr] update_interval_s = {u}: use (0, 60] s");
            }
            settings.update_interval_s = u;
        }
        let dr = args.dr.as_deref().map(read_dr_csv).transpose()?;
        let accel = args.accel.as_deref().map(read_accel_csv).transpose()?;
        if let Some(d) = &dr {
            let (a, b) = d.time_span_s();
            tracing::info!("DR log: {} rows from {a:.2} to {b:.2} s", d.samples().len());
        }
        Ok(Some(DrInputs {
            dr,
            accel,
            settings,
        }))
    }
}

/// Fuses the fixes with the DR and accelerometer logs and writes `fused.csv`, `fused.nmea`,
/// `fused.geojson`, `fused.kml`, (with `--dr`) `dr_params.toml` and (with `plots`) `dr.png`;
/// returns the row counts by source (gnss, fused, dr) and the calibrated parameters.
pub(super) fn write_fused_outputs(
    inputs: &DrInputs,
    gnss: &[GnssFix],
    dir: &Path,
    plots: bool,
) -> anyhow::Result<([usize; 3], Option<DrParams>)> {
    let out = |name: &str| dir.join(name);
    let mut result = fuse_dr(gnss, inputs.dr.as_ref(), &inputs.settings)?;
    if let Some(accel) = &inputs.accel {
        let track = speed_track(gnss, accel, inputs.settings.update_interval_s)?;
        attach_speed(&mut result.fixes, &track);
    }
    write_fused_csv(&out("fused.csv"), &result.fixes)?;
    let fixes = fused_as_fixes(&result.fixes);
    let mut nmea = NmeaWriter::create(&out("fused.nmea"), NmeaOptions::default())?;
    for f in &fixes {
        nmea.write_fix(f)?;
    }
    nmea.finish()?;
    let mut f = create_file(&out("fused.geojson"))?;
    output::write_geojson(&mut f, "fused.geojson", &fixes)?;
    let mut f = create_file(&out("fused.kml"))?;
    output::write_kml(&mut f, "fused.kml", "gpsrx GNSS/DR", &fixes)?;
    if let (Some(p), Some(_)) = (&result.final_params, &inputs.dr) {
        p.save(&out("dr_params.toml"))?;
    }
    if plots && inputs.dr.is_some() && !result.fixes.is_empty() {
        if let Err(e) = draw_dr_track(&result.fixes, &out("dr.png")) {
            tracing::warn!("{e} (the fused outputs are complete)");
        }
    }
    let count = |s: FixSource| result.fixes.iter().filter(|f| f.source == s).count();
    let rows = [
        count(FixSource::Gnss),
        count(FixSource::Fused),
        count(FixSource::DrOnly),
    ];
    tracing::info!(
        "fused.csv: {} GNSS rows, {} fused, {} DR only; {} GNSS updates",
        rows[0],
        rows[1],
        rows[2],
        result.updates
    );
    Ok((rows, result.final_params.filter(|_| inputs.dr.is_some())))
}
