//! `gpsrx run`: a recording (or standard input) in, position fixes and standard files out.
//!
//! A thin layer over [`gpsrx_receiver::Receiver`]: the command line and configuration file
//! become a [`gpsrx_receiver::ReceiverConfig`], the recording a sample source read once, and
//! the outputs a [`FileSink`] in `--out DIR` (`pvt.csv`, `pvt.nmea`, `observables.rnx`,
//! `ephemeris.rnx`, `track.geojson`, `track.kml`, `channels.csv`, and unless `--no-plots` the
//! PNG plots `track.png`, `skyplot.png`, `cn0.png`, `dop.png`); with `--dr`/`--accel` the
//! fixes are then fused with the DR logs (`dr_inputs`, and `dr.png`).

use crate::commands::source::{interrupted, open_interruptible};
use crate::exit::Completion;
use gpsrx_ins_aiding::DrParams;
use gpsrx_receiver::fusion::gnss::GnssFix;
use gpsrx_receiver::output::{FileSink, Fix, FixQuality};
use gpsrx_receiver::pipeline::{AssistanceFiles, FixReport, Progress, Sink, SinkError, Tee};
use gpsrx_receiver::{Assistance, Receiver, RunSummary};
use gpsrx_samples::sigmf::RecordingStart;
use gpsrx_samples::{SampleSource, SourceConfig};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};

mod dr_inputs;
pub mod profile_table;
pub mod progress_line;

pub use crate::cli::{DrFilterChoice, IonoModel, RunArgs, TropoModel};
use dr_inputs::{write_fused_outputs, DrInputs};

/// What `gpsrx run` produced: the receiver's summary and, with `--dr`/`--accel`, the fusion's.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct RunReport {
    /// The receiver's summary (tracked and dropped satellites, fixes).
    #[serde(flatten)]
    pub receiver: RunSummary,
    /// With `--dr`/`--accel`: rows of `fused.csv` by source (gnss, fused, dr).
    pub fused_rows: Option<[usize; 3]>,
    /// With `--dr`: the calibrated sensor parameters at the end.
    pub dr_params: Option<DrParams>,
}

/// The command's own sink beside the files: the progress bar and the fixes for DR fusion.
struct CommandSink {
    bar: ProgressBar,
    /// The progress as log lines, when standard error is not a terminal.
    line: Option<progress_line::ProgressLine>,
    gnss_fixes: Option<Vec<GnssFix>>,
}

impl Sink for CommandSink {
    fn fix(&mut self, report: &FixReport) -> Result<(), SinkError> {
        // Only valid fixes update the DR filters (a flagged solution steers nothing).
        if let (Some(f), true) = (&mut self.gnss_fixes, report.fix.quality != FixQuality::None) {
            f.push(GnssFix::from_solution(report.t_stream_s, &report.solution));
        }
        Ok(())
    }

    fn progress(&mut self, p: &Progress) -> Result<(), SinkError> {
        if let Some(line) = &mut self.line {
            line.update(p);
        }
        self.bar.set_position(p.sample_index);
        self.bar.set_message(format!(
            "{} satellites, {} frame-synced, {} with ephemeris",
            p.satellites, p.frame_synced, p.with_ephemeris
        ));
        Ok(())
    }
}

/// The assistance inputs named on the command line (a navigation file without a single GPS
/// ephemeris is an error: [`Assistance::read`]).
fn assistance(args: &RunArgs) -> anyhow::Result<Assistance> {
    Ok(Assistance::read(&AssistanceFiles {
        nav: args.nav.as_deref(),
        ins: args.ins.as_deref(),
        ins_max_gap_s: args.ins_max_gap,
        ins_band_limit_rad_s: args.ins_band_limit,
        no_aiding: args.no_aiding,
        landmarks: args.landmarks.as_deref(),
    })?)
}

/// When the recording's first processed sample was taken, from its SigMF `core:datetime`
/// (moved by the skip); a date that cannot be read is a warning, not an error.
pub(crate) fn recording_start(cfg: &SourceConfig) -> Option<RecordingStart> {
    match gpsrx_samples::sigmf::recording_start(&cfg.path) {
        Ok(start) => start.map(|mut s| {
            s.time = s.time.add_seconds(cfg.skip_s);
            s
        }),
        Err(e) => {
            tracing::warn!("{e}: the recording's date is ignored");
            None
        }
    }
}

/// Logs what the source had to fix up while reading (NaN values read as 0, trailing bytes
/// dropped, a duration cut at the end of the file).
pub(crate) fn warn_source(src: &dyn SampleSource) {
    for w in src.warnings() {
        tracing::warn!("{w}");
    }
}

/// Runs the receiver on the recording of `args`; returns the report and the fixes.
pub fn run_file(args: &RunArgs, show_progress: bool) -> anyhow::Result<(RunReport, Vec<Fix>)> {
    let config = args.receiver_config()?;
    let src_cfg = args.source.to_config()?;
    let mut src = open_interruptible(&src_cfg)?;
    let dr_inputs = DrInputs::load(args, &config)?;
    let mut assistance = assistance(args)?;
    assistance.recording_start = recording_start(&src_cfg);
    let mut receiver = Receiver::new(&config, src.fs_hz(), assistance)?;
    let bar = if show_progress {
        src.total_samples()
            .map(ProgressBar::new)
            .unwrap_or_else(ProgressBar::no_length)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {percent:>3}% {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let files = FileSink::create(&args.out, config.run.rate_hz)?.with_plots(config.run.plots);
    let line = (show_progress && !std::io::stderr().is_terminal())
        .then(|| progress_line::ProgressLine::new(src.fs_hz(), src.total_samples()));
    let extra = CommandSink {
        bar: bar.clone(),
        line,
        gnss_fixes: dr_inputs.as_ref().map(|_| Vec::new()),
    };
    let mut sink = Tee(files, extra);
    let run = receiver.run(src.as_mut(), &mut sink);
    bar.finish_and_clear();
    warn_source(src.as_ref());
    let summary = match run {
        // E.g. Ctrl-C on a stream that sent too little for the cold start.
        Err(e) if interrupted() => {
            return Err(anyhow::Error::new(e).context("interrupted (Ctrl-C)"))
        }
        r => r?,
    };
    let Tee(files, extra) = sink;
    let mut report = RunReport {
        receiver: summary,
        ..RunReport::default()
    };
    if let (Some(inputs), Some(gnss)) = (&dr_inputs, &extra.gnss_fixes) {
        let (rows, params) = write_fused_outputs(inputs, gnss, &args.out, config.run.plots)?;
        report.fused_rows = Some(rows);
        report.dr_params = params;
    }
    Ok((report, files.into_fixes()))
}

/// Runs `gpsrx run`: [`Completion::NoValidFix`] (exit status 2) when the recording was
/// processed to the end without a valid fix (the summary says why).
pub fn run(args: &RunArgs) -> anyhow::Result<Completion> {
    let (report, _) = run_file(args, true)?;
    let mut out = crate::exit::stdout();
    if args.json {
        let mut value = serde_json::to_value(&report)?;
        if let Some(map) = value.as_object_mut() {
            map.insert("outputs".into(), args.out.display().to_string().into());
        }
        writeln!(out, "{}", serde_json::to_string_pretty(&value)?)?;
    } else {
        print_report(&mut out, &report, args)?;
        if args.profile {
            let s = &report.receiver;
            profile_table::write_profile(
                &mut out,
                &s.profile,
                s.duration_s,
                s.wall_s,
                profile_table::process_usage(),
            )?;
        }
    }
    out.flush()?;
    Ok(if report.receiver.fixes == 0 {
        Completion::NoValidFix
    } else {
        Completion::Done
    })
}

/// The summary, for people.
fn print_report(out: &mut dyn Write, report: &RunReport, args: &RunArgs) -> std::io::Result<()> {
    let s = &report.receiver;
    writeln!(
        out,
        "processed {:.1} s in {:.1} s ({:.1}x real time)",
        s.duration_s,
        s.wall_s,
        s.duration_s / s.wall_s.max(1e-9)
    )?;
    writeln!(out, "satellites tracked: {:?}", s.tracked_prns)?;
    if !report.receiver.dropped_prns.is_empty() {
        writeln!(
            out,
            "searched and dropped (never locked): {:?}",
            report.receiver.dropped_prns
        )?;
    }
    match (s.first_fix_s, s.mean_llh) {
        (Some(t), Some((lat, lon, h))) => {
            writeln!(out, "first fix {t:.2} s after the start; {} fixes", s.fixes)?;
            if s.invalid_fixes > 0 {
                writeln!(out, "{} more solutions failed the RAIM test and are flagged invalid (quality none in pvt.csv, GGA quality 0, not in the tracks)", s.invalid_fixes)?;
            }
            writeln!(out, "mean position {lat:.7} deg, {lon:.7} deg, {h:.2} m; mean PDOP {:.2}", s.mean_pdop.unwrap_or(f64::NAN))?;
        }
        _ if s.tracked_prns.is_empty() => writeln!(out,
            "no fix: no satellite was tracked. Check the format, rate, IF and Q sign (gpsrx info FILE), widen the search (--doppler-max, --doppler-center for a front-end LO offset) or integrate longer (--acq-coherent-ms 10 --acq-noncoherent 20)"
        )?,
        _ if s.invalid_fixes > 0 => writeln!(out,
            "no valid fix: all {} solutions failed the RAIM test (a faulty measurement it could not exclude: see the log and the raim column of pvt.csv)",
            s.invalid_fixes
        )?,
        _ if args.nav.is_some() => writeln!(out,
            "no fix: fewer than 4 satellites were tracked with their time of week known long enough for a position (frame sync takes 6-12 s; see the log for lost channels)"
        )?,
        _ => writeln!(out,
            "no fix: the recording ended before 4 satellites had their ephemeris (subframes 1-3 take 18-30 s; give --nav FILE to start sooner)"
        )?,
    }
    if let Some(a) = &s.ins_aiding {
        let times = |n: usize| {
            if n == 1 {
                "once".to_string()
            } else {
                format!("{n} times")
            }
        };
        write!(
            out,
            "INS aiding: {:.1} s of {:.1} s aided ({:.0} %)",
            a.aided_s,
            s.duration_s,
            100.0 * a.aided_fraction
        )?;
        if a.rejections > 0 {
            writeln!(out, "; the INS was rejected {} for disagreeing with the tracked Doppler (see the warnings), the loops ran unaided meanwhile", times(a.rejections))?;
        } else if a.admissions == 0 {
            writeln!(out, "; the feed-forward was never verified against the tracked Doppler (3 satellites in phase lock and the INS, GPS time and ephemerides needed), the loops ran unaided")?;
        } else {
            writeln!(out)?;
        }
    }
    if let Some(v) = &s.vector {
        writeln!(
            out,
            "vector tracking: the navigation filter drove the channels for {:.1} s of {:.1} s (taken {} times, given back {} times); {} measurements admitted, {} excluded by its innovation test",
            v.vector_s, s.duration_s, v.engagements, v.disengagements, v.admitted_rows, v.rejected_rows
        )?;
    }
    if let Some([g, f, d]) = report.fused_rows {
        writeln!(
            out,
            "fused.csv: {f} fused rows, {d} dead-reckoning only, {g} GNSS only"
        )?;
    }
    if let Some(p) = &report.dr_params {
        writeln!(
            out,
            "DR calibration: Sf_G {:.3} deg/s/V, V_nom {:.4} V, Sf_N {:.5} m/pulse (dr_params.toml)",
            p.sf_g_dps_per_v, p.v_nom_v, p.sf_n_m_per_pulse
        )?;
    }
    writeln!(out, "outputs in {}", args.out.display())
}
