//! `gpsrx run`: a recording in, position fixes and standard files out.
//!
//! acquisition -> tracking channels (with re-acquisition) -> navigation message per satellite
//! -> observables at common receiver epochs -> WLS PVT with RAIM -> outputs in `--out DIR`:
//! `pvt.csv`, `pvt.nmea`, `observables.rnx`, `ephemeris.rnx`, `track.geojson`, `track.kml`,
//! `channels.csv`.
//!
//! `args` is the command line, `settings` its merge with the configuration file,
//! `cold_start` the first acquisition, `dr_inputs` the `--dr`/`--accel` fusion; this module
//! runs the pipeline and writes the outputs.

use gpsrx_receiver::fusion::gnss::GnssFix;
use gpsrx_receiver::output::{
    self, create_file, ChannelCsvWriter, ChannelRow, Fix, FixQuality, NavHeader, NavRecord,
    NmeaOptions, NmeaWriter, ObsEpoch, ObsHeader, PvtCsvWriter, RinexObsWriter, SatObs, SatView,
};
use gpsrx_receiver::pipeline::aiding::InsFeedForward;
use gpsrx_receiver::pipeline::navdata::{current_gps_week, NavDecoder, NavEvent};
use gpsrx_receiver::pipeline::observables::{ObservableBuilder, ObservableEpoch};
use gpsrx_receiver::pipeline::tracker::{track_with_reacquisition, AidSource, Reacquisition};
use anyhow::Context;
use gpsrx_ins_aiding::{read_ins_csv, DrParams};
use gpsrx_nav::atmosphere::KlobucharParams;
use gpsrx_nav::ephemeris::Ephemeris;
use gpsrx_nav::frames::azimuth_elevation;
use gpsrx_nav::pvt::{solve, PvtOptions, PvtSolution, RaimStatus, SatMeasurement};
use gpsrx_nav::rinex_nav::{read_rinex_nav, NavData};
use gpsrx_samples::open_source;
use gpsrx_tracking::ChannelState;
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::BTreeMap;

mod args;
mod cold_start;
mod dr_inputs;
mod settings;

pub use args::{DrFilterChoice, IonoModel, RunArgs, TropoModel};
use cold_start::cold_start;
use dr_inputs::{write_fused_outputs, DrInputs};
use settings::Settings;
pub use settings::{DrRunConfig, RunConfig};

/// What a run produced.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct RunSummary {
    /// Seconds of recording processed.
    pub duration_s: f64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Satellites tracked at some point.
    pub tracked_prns: Vec<u8>,
    /// Receive time (s from the file start) of the first fix.
    pub first_fix_s: Option<f64>,
    /// Number of fixes.
    pub fixes: usize,
    /// Mean position of the fixes, LLH degrees/m.
    pub mean_llh: Option<(f64, f64, f64)>,
    /// Mean PDOP.
    pub mean_pdop: Option<f64>,
    /// With `--dr`/`--accel`: rows of `fused.csv` by source (gnss, fused, dr).
    pub fused_rows: Option<[usize; 3]>,
    /// With `--dr`: the calibrated sensor parameters at the end.
    pub dr_params: Option<DrParams>,
}

/// Seconds of observables held back waiting for the first fix (whose position goes into the
/// RINEX header) before they are written without one.
const OBS_BACKLOG_MAX_S: f64 = 300.0;

/// Runs the receiver on a file.
pub fn run_file(args: &RunArgs, show_progress: bool) -> anyhow::Result<(RunSummary, Vec<Fix>)> {
    let t_wall = std::time::Instant::now();
    let set = Settings::resolve(args)?;
    let cfg = args.loops.channel_config()?;
    let src_cfg = args.source.to_config()?;
    let mut src =
        open_source(&src_cfg).with_context(|| format!("cannot read {}", src_cfg.path.display()))?;
    let fs = src.fs_hz();
    let total = src.total_samples();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let nav_assist: Option<NavData> = match &args.nav {
        Some(p) => Some(
            read_rinex_nav(p)
                .with_context(|| format!("cannot read the navigation file {}", p.display()))?,
        ),
        None => None,
    };
    // The week that resolves the broadcast 10-bit week: --week, else the navigation file's,
    // else today's.
    let landmark_obs = match &args.landmarks {
        Some(p) => gpsrx_receiver::landmarks::read_landmarks(p)?,
        None => Vec::new(),
    };
    let reference_week = args
        .week
        .or_else(|| {
            nav_assist
                .as_ref()
                .and_then(|n| n.ephemerides.first())
                .map(|e| e.toe.week)
        })
        .unwrap_or_else(current_gps_week);
    let dr_inputs = DrInputs::load(args, set.rate)?;
    let mut gnss_fixes: Vec<GnssFix> = Vec::new();
    let feedforward = match &args.ins {
        Some(path) => {
            if let Some(a) = args.ins_band_limit {
                if !(a.is_finite() && a > 0.0) {
                    anyhow::bail!("--ins-band-limit {a}: give a corner frequency > 0 rad/s");
                }
            }
            let track = read_ins_csv(path, args.ins_max_gap)?;
            let (a, b) = track.span_s();
            tracing::info!(
                "INS {}: {} rows from {a:.2} to {b:.2} s{}",
                path.display(),
                track.samples().len(),
                if args.no_aiding {
                    " (aiding off: --no-aiding)"
                } else {
                    ""
                }
            );
            (!args.no_aiding).then(|| {
                InsFeedForward::new(
                    track,
                    nav_assist.clone(),
                    reference_week,
                    args.ins_band_limit,
                )
                .allow_unhealthy(set.allow_unhealthy)
            })
        }
        None => None,
    };
    let feedforward = feedforward.as_ref();
    let aid_fn = |prn: u8, t_s: f64| feedforward.and_then(|f| f.aid(prn, t_s));
    let aid_source: Option<AidSource<'_>> = feedforward.map(|_| &aid_fn as AidSource<'_>);

    // Cold acquisition on the first samples (with the weak-signal search if needed).
    let (engine, channels) = cold_start(fs, &set, &src_cfg, &cfg)?;
    let reacq = Reacquisition {
        engine: &engine,
        interval_s: 1.0,
        channel_config: cfg,
        prns: Vec::new(),
    };

    let bar = if show_progress {
        total
            .map(ProgressBar::new)
            .unwrap_or_else(ProgressBar::no_length)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {percent:>3}% {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );

    let mut decoders: BTreeMap<u8, NavDecoder> = BTreeMap::new();
    let mut builder = ObservableBuilder::new(fs, set.rate).with_min_cn0_dbhz(cfg.cn0_lost_dbhz);
    let opts = PvtOptions {
        tropo: set.tropo == TropoModel::Saastamoinen,
        elevation_mask_deg: set.elevation_mask,
        raim_pfa: set.raim_pfa,
        ..PvtOptions::default()
    };
    let out = |name: &str| args.out.join(name);
    let mut pvt_csv = PvtCsvWriter::create(&out("pvt.csv"))?;
    let mut nmea = NmeaWriter::create(&out("pvt.nmea"), NmeaOptions::default())?;
    let mut channels_csv = ChannelCsvWriter::create(&out("channels.csv"))?;
    let mut obs_writer: Option<RinexObsWriter<std::io::BufWriter<std::fs::File>>> = None;
    let mut obs_backlog: Vec<ObsEpoch> = Vec::new();
    let mut fixes: Vec<Fix> = Vec::new();
    let mut prior: Option<PvtSolution> = None;
    let mut summary = RunSummary::default();
    let mut err: Option<anyhow::Error> = None;
    let mut last_row_t: BTreeMap<usize, f64> = BTreeMap::new();
    let mut iono_fallback_said = false;

    let mut handle_epoch = |epoch: ObservableEpoch,
                            decoders: &BTreeMap<u8, NavDecoder>,
                            builder: &mut ObservableBuilder|
     -> anyhow::Result<()> {
        let iono = if set.iono == IonoModel::Klobuchar {
            let known = decoders
                .values()
                .find_map(|d| d.iono)
                .or_else(|| nav_assist.as_ref().and_then(|n| n.iono));
            if known.is_none() && !iono_fallback_said {
                tracing::info!(
                    "ionosphere: typical Klobuchar coefficients until subframe 4 page 18 is decoded (or give --nav)"
                );
                iono_fallback_said = true;
            }
            Some(known.unwrap_or(KlobucharParams::FALLBACK))
        } else {
            None
        };
        let ephs: Vec<(u8, Ephemeris)> = epoch
            .sats
            .iter()
            .filter_map(|s| {
                let decoded = decoders.get(&s.prn).and_then(|d| d.ephemeris.clone());
                decoded
                    .or_else(|| {
                        nav_assist
                            .as_ref()
                            .and_then(|n| n.select(s.prn, epoch.rx_time).cloned())
                    })
                    .map(|e| (s.prn, e))
            })
            .collect();
        let meas: Vec<SatMeasurement<'_>> = epoch
            .sats
            .iter()
            .filter_map(|s| {
                let (_, eph) = ephs.iter().find(|(p, _)| *p == s.prn)?;
                (eph.sv_health == 0 || set.allow_unhealthy).then_some(SatMeasurement {
                    prn: s.prn,
                    pseudorange_m: s.smoothed_pseudorange_m,
                    doppler_hz: Some(s.doppler_hz),
                    cn0_dbhz: s.cn0_dbhz,
                    tx_time: None,
                    ephemeris: eph,
                })
            })
            .collect();
        let opts = PvtOptions { iono, ..opts };
        // Landmark observations of this epoch (receiver time within half an interval; the clock
        // bias is kept below 0.5 ms, far less than that).
        let landmarks: Vec<gpsrx_nav::pvt::Landmark> = landmark_obs
            .iter()
            .filter(|l| (l.tow_s - epoch.rx_time.tow_s).abs() <= 0.5 / set.rate)
            .map(|l| l.landmark)
            .collect();
        let solution = if meas.len() + landmarks.len() >= 4 && !meas.is_empty() {
            match solve(epoch.rx_time, &meas, &landmarks, &opts, prior.as_ref()) {
                Ok(s) => Some(s),
                Err(e) => {
                    tracing::debug!("no fix at {:.3}: {e}", epoch.rx_time.tow_s);
                    None
                }
            }
        } else {
            tracing::trace!(
                "{} satellites with ephemeris at {:.3}",
                meas.len(),
                epoch.rx_time.tow_s
            );
            None
        };
        // Observables to RINEX (held until the first fix gives the header's position).
        let obs = ObsEpoch {
            time: epoch.rx_time,
            clock_offset_s: None,
            sats: epoch
                .sats
                .iter()
                .map(|s| SatObs {
                    prn: s.prn,
                    pseudorange_m: Some(s.pseudorange_m),
                    carrier_cycles: Some(s.carrier_cycles),
                    doppler_hz: Some(s.doppler_hz),
                    cn0_dbhz: s.cn0_dbhz.is_finite().then_some(s.cn0_dbhz),
                    loss_of_lock: s.loss_of_lock || epoch.clock_step_ms != 0,
                    half_cycle_ambiguous: s.half_cycle_ambiguous,
                })
                .collect(),
        };
        match (&mut obs_writer, &solution) {
            (Some(w), _) => w.write_epoch(&obs)?,
            (None, Some(sol)) => {
                let position = [sol.pos_ecef_m.x, sol.pos_ecef_m.y, sol.pos_ecef_m.z];
                let mut w = open_observables(
                    &out("observables.rnx"),
                    Some(position),
                    set.rate,
                    &mut obs_backlog,
                    epoch.rx_time.week,
                )?;
                w.write_epoch(&obs)?;
                obs_writer = Some(w);
            }
            (None, None) => {
                obs_backlog.push(obs);
                // Bounded memory: without a fix for this long (but with the week decoded, so
                // the labels will not change), the observables go out with an unknown position.
                let week_known = decoders.values().any(|d| d.decoded_week().is_some());
                if week_known && obs_backlog.len() as f64 > OBS_BACKLOG_MAX_S * set.rate {
                    let w = open_observables(
                        &out("observables.rnx"),
                        None,
                        set.rate,
                        &mut obs_backlog,
                        epoch.rx_time.week,
                    )?;
                    tracing::warn!(
                        "no fix after {OBS_BACKLOG_MAX_S} s of observables: observables.rnx has no approximate position"
                    );
                    obs_writer = Some(w);
                }
            }
        }
        let Some(sol) = solution else {
            return Ok(());
        };
        // Keep the receiver clock within +-0.5 ms of GPS time by whole-millisecond steps.
        let bias_ms = sol.clock_bias_m / 299_792_458.0 * 1e3;
        if bias_ms.abs() > 0.5 {
            builder.step_clock_ms(-bias_ms.round() as i64);
            tracing::debug!("receiver clock stepped by {} ms", -bias_ms.round() as i64);
        }
        let t_file = epoch.sample / fs;
        if summary.first_fix_s.is_none() {
            summary.first_fix_s = Some(t_file);
            tracing::info!(
                "first fix at {:.2} s: {:.7} {:.7} {:.1} m, {} satellites, PDOP {:.1}",
                t_file,
                sol.llh.lat_rad.to_degrees(),
                sol.llh.lon_rad.to_degrees(),
                sol.llh.h_m,
                sol.n_sv,
                sol.dop.pdop
            );
        }
        let sats_in_view = ephs
            .iter()
            .map(|(prn, eph)| {
                let sv = eph.sv_state(sol.time);
                let (az, el) = azimuth_elevation(&sol.pos_ecef_m, &sv.pos_m);
                let cn0 = epoch
                    .sats
                    .iter()
                    .find(|s| s.prn == *prn)
                    .map(|s| s.cn0_dbhz)
                    .filter(|c| c.is_finite());
                SatView {
                    prn: *prn,
                    el_deg: el.to_degrees(),
                    az_deg: az.to_degrees().rem_euclid(360.0),
                    cn0_dbhz: cn0,
                }
            })
            .collect();
        let fix = Fix {
            time: sol.time,
            ecef_m: [sol.pos_ecef_m.x, sol.pos_ecef_m.y, sol.pos_ecef_m.z],
            llh: sol.llh,
            vel_ecef_mps: sol.vel_ecef_mps.map(|v| [v.x, v.y, v.z]),
            clock_bias_m: sol.clock_bias_m,
            clock_drift_mps: sol.clock_drift_mps,
            n_sv: sol.n_sv,
            used_prns: sol.used_prns.clone(),
            pdop: sol.dop.pdop,
            hdop: sol.dop.hdop,
            vdop: sol.dop.vdop,
            raim: raim_text(&sol.raim),
            quality: FixQuality::Gnss,
            sats_in_view,
        };
        if let Some(ff) = feedforward {
            ff.set_fix(t_file, sol.pos_ecef_m, sol.clock_drift_mps);
        }
        if dr_inputs.is_some() {
            gnss_fixes.push(GnssFix::from_solution(t_file, &sol));
        }
        pvt_csv.write_fix(&fix)?;
        nmea.write_fix(&fix)?;
        fixes.push(fix);
        prior = Some(sol);
        Ok(())
    };

    let mut processed = 0u64;
    track_with_reacquisition(src.as_mut(), channels, aid_source, Some(&reacq), |i, e| {
        if err.is_some() {
            return;
        }
        let dec = decoders
            .entry(e.prn)
            .or_insert_with(|| NavDecoder::new(e.prn, reference_week));
        if let (Some(b), Some(ms)) = (e.bit, e.bit_start_ms) {
            for ev in dec.push_bit(b.value, ms) {
                match ev {
                    NavEvent::FrameSync { tow_s } => {
                        tracing::info!("G{:02}: frame sync, TOW {tow_s} s", e.prn)
                    }
                    NavEvent::Ephemeris(eph) => {
                        tracing::info!("G{:02}: ephemeris decoded (IODE {})", e.prn, eph.iode);
                        if let Some(ff) = feedforward {
                            ff.set_ephemeris(&eph);
                        }
                    }
                    _ => {}
                }
            }
        }
        if e.state == ChannelState::Lost {
            dec.reset_sync();
        }
        if last_row_t
            .get(&i)
            .is_none_or(|&t| e.t_rx_s - t >= 1.0 / set.rate - 1e-9)
        {
            last_row_t.insert(i, e.t_rx_s);
            let row = ChannelRow {
                time: builder
                    .rx_time_origin()
                    .map(|t0| t0.add_seconds(e.t_rx_s))
                    .unwrap_or(gpsrx_nav::time::GpsTime {
                        week: 0,
                        tow_s: e.t_rx_s,
                    }),
                channel: i as u32,
                prn: e.prn,
                state: format!("{:?}", e.state).to_lowercase(),
                cn0_dbhz: e.cn0_dbhz.is_finite().then_some(e.cn0_dbhz),
                doppler_hz: Some(e.doppler_hz),
                code_phase_chips: Some(e.code_phase_chips),
                pll_lock_indicator: Some(e.pll_lock_metric),
                code_lock: e.code_lock,
                carrier_lock: e.pll_lock,
                bit_sync: e.bit_edge || dec.synced(),
                frame_sync: dec.synced(),
            };
            if let Err(x) = channels_csv.write_row(&row) {
                err = Some(x.into());
            }
        }
        let ready = match decoders.get(&e.prn) {
            Some(d) => builder.push(e, d),
            None => Vec::new(),
        };
        if let (Some(ff), Some(t0)) = (feedforward, builder.rx_time_origin()) {
            ff.set_time_origin(t0);
        }
        for epoch in ready {
            if let Err(x) = handle_epoch(epoch, &decoders, &mut builder) {
                err = Some(x);
            }
        }
        let s = e.sample_index;
        if s > processed + (fs * 0.2) as u64 {
            processed = s;
            bar.set_position(s);
            let synced = decoders.values().filter(|d| d.synced()).count();
            let with_eph = decoders.values().filter(|d| d.ephemeris.is_some()).count();
            bar.set_message(format!(
                "{} satellites, {synced} frame-synced, {with_eph} with ephemeris",
                decoders.len()
            ));
        }
    })?;
    bar.finish_and_clear();
    if let Some(e) = err {
        return Err(e);
    }
    pvt_csv.finish()?;
    nmea.finish()?;
    channels_csv.finish()?;
    match obs_writer {
        Some(w) => {
            w.finish()?;
        }
        None if !obs_backlog.is_empty() => {
            // No fix: the observables still go out, with an unknown approximate position, all
            // labelled with the best week known (the last epoch's: decoded, or the reference).
            let week = obs_backlog.last().map_or(0, |o| o.time.week);
            open_observables(
                &out("observables.rnx"),
                None,
                set.rate,
                &mut obs_backlog,
                week,
            )?
            .finish()?;
        }
        None => {}
    }
    // Decoded ephemerides.
    let records: Vec<NavRecord> = decoders
        .values()
        .filter_map(|d| d.ephemeris.clone())
        .map(NavRecord::from)
        .collect();
    let header = NavHeader {
        iono: decoders.values().find_map(|d| d.iono),
        utc: decoders.values().find_map(|d| d.utc),
        ..NavHeader::default()
    };
    output::rinex_nav::write_rinex_nav_file(&out("ephemeris.rnx"), &header, &records)?;
    let mut f = create_file(&out("track.geojson"))?;
    output::write_geojson(&mut f, "track.geojson", &fixes)?;
    let mut f = create_file(&out("track.kml"))?;
    output::write_kml(&mut f, "track.kml", "gpsrx track", &fixes)?;

    if let Some(inputs) = &dr_inputs {
        let (rows, params) = write_fused_outputs(inputs, &gnss_fixes, &out)?;
        summary.fused_rows = Some(rows);
        summary.dr_params = params;
    }

    summary.duration_s = total
        .map(|t| t as f64 / fs)
        .unwrap_or(processed as f64 / fs);
    summary.wall_s = t_wall.elapsed().as_secs_f64();
    summary.tracked_prns = decoders.keys().copied().collect();
    summary.fixes = fixes.len();
    if !fixes.is_empty() {
        let n = fixes.len() as f64;
        let lat = fixes
            .iter()
            .map(|f| f.llh.lat_rad.to_degrees())
            .sum::<f64>()
            / n;
        let lon = fixes
            .iter()
            .map(|f| f.llh.lon_rad.to_degrees())
            .sum::<f64>()
            / n;
        let h = fixes.iter().map(|f| f.llh.h_m).sum::<f64>() / n;
        summary.mean_llh = Some((lat, lon, h));
        summary.mean_pdop = Some(fixes.iter().map(|f| f.pdop).sum::<f64>() / n);
    }
    Ok((summary, fixes))
}

/// Creates `observables.rnx` (header position `approx_position_m`, if known) and writes the
/// epochs held back for it, in increasing time. They all get `week`: epochs before the first
/// subframe 1 carried the reference week, which can be 1024 weeks (or more) off.
fn open_observables(
    path: &std::path::Path,
    approx_position_m: Option<[f64; 3]>,
    rate_hz: f64,
    backlog: &mut Vec<ObsEpoch>,
    week: u32,
) -> anyhow::Result<RinexObsWriter<std::io::BufWriter<std::fs::File>>> {
    let header = ObsHeader {
        approx_position_m: approx_position_m.unwrap_or_default(),
        interval_s: Some(1.0 / rate_hz),
        ..ObsHeader::default()
    };
    let mut w = RinexObsWriter::create(path, header)?;
    let mut last_tow_s = f64::NEG_INFINITY;
    for mut o in backlog.drain(..) {
        o.time.week = week;
        if o.time.tow_s > last_tow_s {
            last_tow_s = o.time.tow_s;
            w.write_epoch(&o)?;
        }
    }
    Ok(w)
}

fn raim_text(r: &RaimStatus) -> String {
    match r {
        RaimStatus::Ok => "ok".into(),
        RaimStatus::FaultExcluded { prn } => format!("excluded G{prn:02}"),
        other => format!("{other:?}").to_lowercase(),
    }
}

/// Runs `gpsrx run`.
pub fn run(args: &RunArgs) -> anyhow::Result<()> {
    let (s, _) = run_file(args, true)?;
    println!(
        "processed {:.1} s in {:.1} s ({:.1}x real time)",
        s.duration_s,
        s.wall_s,
        s.duration_s / s.wall_s.max(1e-9)
    );
    println!("satellites tracked: {:?}", s.tracked_prns);
    match (s.first_fix_s, s.mean_llh) {
        (Some(t), Some((lat, lon, h))) => {
            println!("first fix {t:.2} s after the start; {} fixes", s.fixes);
            println!("mean position {lat:.7} deg, {lon:.7} deg, {h:.2} m; mean PDOP {:.2}", s.mean_pdop.unwrap_or(f64::NAN));
        }
        _ if s.tracked_prns.is_empty() => println!(
            "no fix: no satellite was tracked. Check the format, rate, IF and Q sign (gpsrx info FILE), widen the search (--doppler-max, --doppler-center for a front-end LO offset) or integrate longer (--acq-coherent-ms 10 --acq-noncoherent 20)"
        ),
        _ => println!(
            "no fix: the recording ended before 4 satellites had their ephemeris (subframes 1-3 take 18-30 s; give --nav FILE to start sooner)"
        ),
    }
    if let Some([g, f, d]) = s.fused_rows {
        println!("fused.csv: {f} fused rows, {d} dead-reckoning only, {g} GNSS only");
    }
    if let Some(p) = s.dr_params {
        println!(
            "DR calibration: Sf_G {:.3} deg/s/V, V_nom {:.4} V, Sf_N {:.5} m/pulse (dr_params.toml)",
            p.sf_g_dps_per_v, p.v_nom_v, p.sf_n_m_per_pulse
        );
    }
    println!("outputs in {}", args.out.display());
    Ok(())
}
