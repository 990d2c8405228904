//! `gpsrx acquire`: search a recording for GPS L1 C/A satellites (cold, or assisted by an
//! ephemeris, an approximate position and the time), and print what was found.

pub mod assist;

use anyhow::Context;
use assist::Prediction;
use gpsrx_dsp::acquisition::{AcqConfig, AcqResult, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_samples::{open_source, SampleSource};
use num_complex::Complex32;
use std::io::Write;

pub use crate::cli::AcquireArgs;

/// One line of the report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AcquireRow {
    /// PRN number.
    #[serde(serialize_with = "ser_prn")]
    pub prn: Prn,
    /// Whether the threshold was passed.
    pub detected: bool,
    /// Sample index (after --skip) where a C/A code period starts.
    pub code_phase_samples: f64,
    /// The same in chips.
    pub code_phase_chips: f64,
    /// Carrier Doppler, Hz.
    pub doppler_hz: f64,
    /// C/N0 estimate, dB-Hz (detections).
    pub cn0_dbhz: Option<f64>,
    /// Peak / noise floor.
    pub metric: f64,
    /// Detection threshold on `metric`.
    pub threshold: f64,
    /// Peak / second peak (more than one chip away).
    pub peak_ratio: f64,
    /// Predicted Doppler (assisted search), Hz.
    pub predicted_doppler_hz: Option<f64>,
    /// Predicted elevation (assisted search), degrees.
    pub elevation_deg: Option<f64>,
    /// The stronger PRN this peak is taken to be a cross-correlation of (not a detection).
    pub cross_correlation_of: Option<u8>,
    /// Health of the ephemeris used for the prediction (assisted search).
    pub healthy: Option<bool>,
}

/// What `gpsrx acquire` found, with the settings it used.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AcquireReport {
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Index in the file of the first sample searched (code phases count from it).
    pub first_sample: u64,
    /// Coherent integration, ms.
    pub coherent_ms: u32,
    /// Non-coherent blocks actually used.
    pub noncoherent: u32,
    /// Doppler bin width, Hz.
    pub doppler_step_hz: f64,
    /// Doppler range searched, Hz.
    pub doppler_range_hz: (f64, f64),
    /// Search time, s.
    pub search_s: f64,
    /// Every searched PRN, strongest first.
    pub rows: Vec<AcquireRow>,
    /// Things the user should know (shortened search, reader warnings).
    pub warnings: Vec<String>,
}

pub(crate) fn ser_prn<S: serde::Serializer>(p: &Prn, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u8(p.get())
}

/// Runs `gpsrx acquire`.
pub fn run(args: &AcquireArgs) -> anyhow::Result<()> {
    let report = acquire(args)?;
    for w in &report.warnings {
        tracing::warn!("{w}");
    }
    if args.json {
        let rows: Vec<&AcquireRow> = report
            .rows
            .iter()
            .filter(|r| args.all || r.detected)
            .collect();
        let text = serde_json::to_string_pretty(&rows)?;
        let mut out = crate::exit::stdout();
        writeln!(out, "{text}")?;
        out.flush()?;
    } else {
        let mut out = crate::exit::stdout();
        write!(out, "{}", render_table(&report, args.all))?;
        out.flush()?;
    }
    Ok(())
}

/// Reads the recording, runs the search and returns the report (what [`run`] prints).
pub fn acquire(args: &AcquireArgs) -> anyhow::Result<AcquireReport> {
    let cfg = args.source.to_config()?;
    let mut source =
        open_source(&cfg).with_context(|| format!("cannot read {}", cfg.path.display()))?;
    let fs_hz = source.fs_hz();
    let (mut config, targets, predictions) = search_plan(args)?;
    let mut engine = AcquisitionEngine::new(fs_hz, config.clone())?;
    let (first_sample, samples) = read_samples(source.as_mut(), engine.samples_wanted())?;
    let mut warnings = source.warnings();
    if samples.len() < engine.samples_needed() && config.noncoherent > 1 {
        let asked = config.noncoherent;
        // Whole blocks that fit, then down one at a time for the bit-edge pass's extra T/2.
        let block = f64::from(config.coherent_ms) * fs_hz * 1e-3;
        let fit = (samples.len() as f64 / block)
            .floor()
            .clamp(1.0, f64::from(asked)) as u32;
        config.noncoherent = fit;
        engine = AcquisitionEngine::new(fs_hz, config.clone())?;
        while samples.len() < engine.samples_needed() && config.noncoherent > 1 {
            config.noncoherent -= 1;
            engine = AcquisitionEngine::new(fs_hz, config.clone())?;
        }
        warnings.push(format!(
            "the recording holds {:.1} ms: non-coherent blocks reduced from {asked} to {}",
            samples.len() as f64 / fs_hz * 1e3,
            config.noncoherent
        ));
    }
    let t0 = std::time::Instant::now();
    let results = engine.search(&samples, &targets)?;
    let search_s = t0.elapsed().as_secs_f64();
    let mut rows: Vec<AcquireRow> = results
        .iter()
        .map(|r| row(r, predictions.as_deref()))
        .collect();
    rows.sort_by(|a, b| {
        b.detected
            .cmp(&a.detected)
            .then(b.metric.total_cmp(&a.metric))
    });
    Ok(AcquireReport {
        fs_hz,
        first_sample,
        coherent_ms: config.coherent_ms,
        noncoherent: config.noncoherent,
        doppler_step_hz: engine.doppler_step_hz(),
        doppler_range_hz: engine.doppler_range_hz(),
        search_s,
        rows,
        warnings,
    })
}

/// The search the options describe: the engine's settings, the targets (all PRNs, `--prn`,
/// or the predicted visible ones with their Doppler windows) and the predictions (`--nav`).
pub fn search_plan(
    args: &AcquireArgs,
) -> anyhow::Result<(AcqConfig, Vec<SearchTarget>, Option<Vec<Prediction>>)> {
    let predictions = match &args.nav {
        Some(path) => Some(predictions(args, path)?),
        None => None,
    };
    let targets = targets(args, predictions.as_deref())?;
    let mut config = AcqConfig {
        coherent_ms: args.coherent_ms,
        noncoherent: args.noncoherent,
        doppler_center_hz: args.doppler_center,
        doppler_max_hz: args.doppler_max,
        doppler_step_hz: args.doppler_step,
        pfa: args.pfa,
        bit_edge_offsets: Some(!args.no_bit_offsets),
        refine_ms: args.refine_ms,
        xcorr_margin_db: (args.xcorr_margin != 0.0).then_some(args.xcorr_margin),
        ..AcqConfig::default()
    };
    if let Some((lo, hi)) = window_span(&targets) {
        config.doppler_center_hz = 0.5 * (lo + hi);
        config.doppler_max_hz = 0.5 * (hi - lo);
    }
    Ok((config, targets, predictions))
}

fn predictions(args: &AcquireArgs, path: &std::path::Path) -> anyhow::Result<Vec<Prediction>> {
    let (Some(llh), Some(time)) = (&args.approx_llh, &args.time) else {
        anyhow::bail!("--nav needs --approx-llh LAT,LON,H and --time WEEK:TOW");
    };
    let rx = assist::parse_llh(llh)?;
    let t = assist::parse_time(time)?;
    let nav = gpsrx_nav::read_rinex_nav(path)
        .with_context(|| format!("cannot read the navigation file {}", path.display()))?;
    let p = assist::predict(&nav, &rx, t, args.elevation_mask);
    if p.is_empty() {
        anyhow::bail!(
            "{} has no ephemeris within its fit interval of {time} for a satellite above {} deg: \
             check --time (GPS week:seconds of week) and the file's date",
            path.display(),
            args.elevation_mask
        );
    }
    Ok(p)
}

/// The PRNs to search (all, or --prn, or the predicted visible ones, intersected) with their
/// Doppler windows.
fn targets(args: &AcquireArgs, pred: Option<&[Prediction]>) -> anyhow::Result<Vec<SearchTarget>> {
    let only: Vec<Prn> = args
        .prn
        .iter()
        .map(|&p| Prn::new(p).map_err(anyhow::Error::from))
        .collect::<anyhow::Result<_>>()?;
    let wanted = |p: Prn| only.is_empty() || only.contains(&p);
    if !(args.doppler_uncertainty.is_finite() && args.doppler_uncertainty >= 0.0) {
        anyhow::bail!(
            "--doppler-uncertainty {}: use a non-negative number of Hz",
            args.doppler_uncertainty
        );
    }
    let t: Vec<SearchTarget> = match pred {
        Some(pred) => pred
            .iter()
            .filter(|p| wanted(p.prn))
            .map(|p| SearchTarget::around(p.prn, p.doppler_hz, args.doppler_uncertainty))
            .collect(),
        None => Prn::all()
            .filter(|&p| wanted(p))
            .map(SearchTarget::full)
            .collect(),
    };
    if t.is_empty() {
        anyhow::bail!(
            "no PRN left to search: --prn {:?} excludes every predicted satellite",
            args.prn
        );
    }
    Ok(t)
}

/// The Doppler span of all windows (assisted search), so one engine covers them.
fn window_span(targets: &[SearchTarget]) -> Option<(f64, f64)> {
    targets
        .iter()
        .filter_map(|t| t.doppler_window_hz)
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
}

/// Reads up to `wanted` samples from the start of the source.
fn read_samples(
    source: &mut dyn SampleSource,
    wanted: usize,
) -> anyhow::Result<(u64, Vec<Complex32>)> {
    let mut samples = vec![Complex32::new(0.0, 0.0); wanted];
    let mut filled = 0;
    let mut first = None;
    while filled < wanted {
        let (index, n) = source.read(&mut samples[filled..])?;
        if n == 0 {
            break;
        }
        first.get_or_insert(index);
        filled += n;
    }
    samples.truncate(filled);
    Ok((first.unwrap_or(0), samples))
}

fn row(r: &AcqResult, pred: Option<&[Prediction]>) -> AcquireRow {
    let p = pred.and_then(|ps| ps.iter().find(|p| p.prn == r.prn));
    AcquireRow {
        prn: r.prn,
        detected: r.detected,
        code_phase_samples: r.code_phase_samples,
        code_phase_chips: r.code_phase_chips,
        doppler_hz: r.doppler_hz,
        cn0_dbhz: r.cn0_dbhz,
        metric: r.metric,
        threshold: r.threshold,
        peak_ratio: r.peak_ratio,
        predicted_doppler_hz: p.map(|p| p.doppler_hz),
        elevation_deg: p.map(|p| p.elevation_deg),
        cross_correlation_of: r.cross_correlation_of.map(Prn::get),
        healthy: p.map(|p| p.healthy),
    }
}

/// The report as a table: a settings line, a count, and one line per PRN (detected only unless
/// `all`).
pub fn render_table(report: &AcquireReport, all: bool) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let (lo, hi) = report.doppler_range_hz;
    let _ = writeln!(
        out,
        "fs {:.6} MHz, {} ms coherent x {} non-coherent, Doppler {lo:.0}..{hi:.0} Hz in {:.1} Hz \
         bins, code phase from sample {}; searched in {:.0} ms",
        report.fs_hz * 1e-6,
        report.coherent_ms,
        report.noncoherent,
        report.doppler_step_hz,
        report.first_sample,
        report.search_s * 1e3
    );
    let detected = report.rows.iter().filter(|r| r.detected).count();
    let _ = writeln!(out, "{detected} of {} PRNs detected", report.rows.len());
    let rows: Vec<&AcquireRow> = report.rows.iter().filter(|r| all || r.detected).collect();
    if rows.is_empty() {
        return out;
    }
    let assisted = rows.iter().any(|r| r.predicted_doppler_hz.is_some());
    let _ = write!(
        out,
        "PRN  code phase (samples)  (chips)  Doppler (Hz)  C/N0 (dB-Hz)  metric  threshold  peak ratio"
    );
    let _ = writeln!(
        out,
        "{}",
        if assisted {
            "  predicted (Hz)  elev (deg)"
        } else {
            ""
        }
    );
    for r in rows {
        let cn0 = r.cn0_dbhz.map_or("-".to_string(), |c| format!("{c:.1}"));
        let _ = write!(
            out,
            "{:>3}  {:>20.1}  {:>7.2}  {:>12.0}  {:>12}  {:>6.1}  {:>9.1}  {:>10.1}",
            r.prn.get(),
            r.code_phase_samples,
            r.code_phase_chips,
            r.doppler_hz,
            cn0,
            r.metric,
            r.threshold,
            r.peak_ratio
        );
        if let (Some(d), Some(e)) = (r.predicted_doppler_hz, r.elevation_deg) {
            let _ = write!(out, "  {d:>14.0}  {e:>10.1}");
            if r.healthy == Some(false) {
                out.push_str("  unhealthy");
            }
        }
        match (r.detected, r.cross_correlation_of) {
            (true, _) => out.push('\n'),
            (false, Some(p)) => {
                let _ = writeln!(out, "  (cross-correlation of PRN {p})");
            }
            (false, None) => out.push_str("  (not detected)\n"),
        }
    }
    out
}
