//! `gpsrx track`: acquire, then track satellites through a recording, and write every
//! integration interval of every channel to CSV for loop studies.

use crate::commands::acquire::search_plan;
use crate::commands::run::progress_line::ProgressLine;
use crate::commands::source::open_interruptible;
use anyhow::Context;
use gpsrx_receiver::pipeline::{FixReport, Progress, SearchSettings, Sink, SinkError};
use gpsrx_receiver::{Assistance, Receiver};
use gpsrx_tracking::{ChannelEpoch, ChannelState};
use std::collections::BTreeMap;
use std::io::{IsTerminal, Write};

pub use crate::cli::TrackArgs;

/// Per-channel summary of a tracking run.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct ChannelSummary {
    /// PRN.
    pub prn: u8,
    /// Final state.
    pub state: String,
    /// Last C/N0 estimate, dB-Hz.
    pub cn0_dbhz: f64,
    /// Last Doppler, Hz.
    pub doppler_hz: f64,
    /// Time of the first phase lock, s.
    pub first_lock_s: Option<f64>,
    /// Data-bit edge position: ms after the file start, modulo 20.
    pub bit_edge_ms_mod_20: Option<f64>,
    /// Bits decoded.
    pub bits: usize,
}

const CSV_HEADER: &str = "prn,state,t_rx_s,sample_index,code_phase_chips,code_rate_chips_s,carrier_phase_cycles,doppler_hz,cn0_dbhz,pll_lock,pll_lock_metric,code_lock,prompt_i,prompt_q,early_abs,late_abs,phase_error_cycles,freq_error_hz,code_error_chips,t_coh_s,bit_edge,bit,bit_t_s";

fn csv_row(e: &ChannelEpoch) -> String {
    let state = match e.state {
        ChannelState::PullIn => "pull_in",
        ChannelState::Track => "track",
        ChannelState::Recover => "recover",
        ChannelState::Lost => "lost",
    };
    let (bit, bit_t) = match e.bit {
        Some(b) => (b.value.to_string(), format!("{:.6}", b.t_s)),
        None => (String::new(), String::new()),
    };
    format!(
        "{},{state},{:.7},{},{:.5},{:.4},{:.5},{:.3},{:.2},{},{:.3},{},{:.1},{:.1},{:.1},{:.1},{:.5},{:.3},{:.5},{},{},{bit},{bit_t}",
        e.prn,
        e.t_rx_s,
        e.sample_index,
        e.code_phase_chips,
        e.code_rate_chips_s,
        e.carrier_phase_cycles,
        e.doppler_hz,
        e.cn0_dbhz,
        u8::from(e.pll_lock),
        e.pll_lock_metric,
        u8::from(e.code_lock),
        e.prompt.re,
        e.prompt.im,
        e.early.norm(),
        e.late.norm(),
        e.phase_error_cycles,
        e.freq_error_hz,
        e.code_error_chips,
        e.t_coh_s,
        u8::from(e.bit_edge),
    )
}

/// The sink of `gpsrx track`: every channel report to the CSV and into the summaries.
struct TrackSink {
    summaries: BTreeMap<u8, ChannelSummary>,
    writer: Option<std::io::BufWriter<std::fs::File>>,
    /// The progress as log lines, when standard error is not a terminal.
    line: Option<ProgressLine>,
}

impl Sink for TrackSink {
    fn fix(&mut self, _report: &FixReport) -> Result<(), SinkError> {
        Ok(())
    }

    fn progress(&mut self, p: &Progress) -> Result<(), SinkError> {
        if let Some(line) = &mut self.line {
            line.update(p);
        }
        Ok(())
    }

    fn channel_epoch(&mut self, _channel: usize, e: &ChannelEpoch) -> Result<(), SinkError> {
        let s = self
            .summaries
            .entry(e.prn)
            .or_insert_with(|| ChannelSummary {
                prn: e.prn,
                ..Default::default()
            });
        s.state = format!("{:?}", e.state);
        s.cn0_dbhz = e.cn0_dbhz;
        s.doppler_hz = e.doppler_hz;
        if e.pll_lock && s.first_lock_s.is_none() {
            s.first_lock_s = Some(e.t_rx_s);
        }
        if let Some(b) = e.bit {
            s.bits += 1;
            s.bit_edge_ms_mod_20 = Some((b.t_s * 1e3).rem_euclid(20.0));
        }
        if let Some(w) = self.writer.as_mut() {
            writeln!(w, "{}", csv_row(e))?;
        }
        Ok(())
    }
}

/// Acquires and tracks through the recording with the receiver pipeline (the search of
/// `gpsrx acquire` for the cold start, re-acquisition every second of signal); returns a
/// summary per satellite and writes every report to `--out`.
pub fn track_file(args: &TrackArgs) -> anyhow::Result<Vec<ChannelSummary>> {
    let config = gpsrx_receiver::ReceiverConfig {
        tracking: args.loops.channel_config()?,
        ..Default::default()
    };
    let src_cfg = args.acquisition.source.to_config()?;
    let mut src = open_interruptible(&src_cfg)?;
    let (acq, targets, _) = search_plan(&args.acquisition)?;
    let prns = args
        .acquisition
        .prn
        .iter()
        .filter_map(|&p| gpsrx_dsp::Prn::new(p).ok())
        .collect();
    let search = SearchSettings {
        acq,
        weak_fallback: false,
        background: Some(gpsrx_receiver::pipeline::channels::SearchBudget::default()),
        prns,
        cold_targets: Some(targets),
    };
    let assistance = Assistance {
        recording_start: crate::commands::run::recording_start(&src_cfg),
        ..Assistance::default()
    };
    let mut receiver = Receiver::with_search(&config, src.fs_hz(), assistance, search)?;
    let writer = match &args.out {
        Some(p) => {
            let f = std::fs::File::create(p)
                .with_context(|| format!("cannot create {}", p.display()))?;
            let mut w = std::io::BufWriter::new(f);
            writeln!(w, "{CSV_HEADER}")?;
            Some(w)
        }
        None => None,
    };
    let line = (!std::io::stderr().is_terminal())
        .then(|| ProgressLine::new(src.fs_hz(), src.total_samples()));
    let mut sink = TrackSink {
        summaries: BTreeMap::new(),
        writer,
        line,
    };
    let run = receiver.run(src.as_mut(), &mut sink);
    crate::commands::run::warn_source(src.as_ref());
    run.context("tracking (or writing the tracking CSV) failed")?;
    if let Some(mut w) = sink.writer {
        w.flush().context("cannot write the tracking CSV")?;
    }
    if sink.summaries.is_empty() {
        anyhow::bail!(
            "no satellite found: check --format, --fs, --if, --invert-q, or search wider (--doppler-max) or longer (--coherent-ms 10)"
        );
    }
    Ok(sink.summaries.into_values().collect())
}

/// Runs `gpsrx track`.
pub fn run(args: &TrackArgs) -> anyhow::Result<()> {
    let summaries = track_file(args)?;
    let mut out = crate::exit::stdout();
    if args.acquisition.json {
        let text = serde_json::to_string_pretty(&summaries)?;
        writeln!(out, "{text}")?;
        out.flush()?;
        return Ok(());
    }
    writeln!(
        out,
        "PRN  state    C/N0(dB-Hz)  Doppler(Hz)  first lock(s)  bit edge(ms mod 20)  bits"
    )?;
    for s in &summaries {
        writeln!(
            out,
            "{:3}  {:7}  {:11.1}  {:11.1}  {:>13}  {:>19}  {:4}",
            s.prn,
            s.state,
            s.cn0_dbhz,
            s.doppler_hz,
            s.first_lock_s
                .map(|t| format!("{t:.3}"))
                .unwrap_or_else(|| "-".into()),
            s.bit_edge_ms_mod_20
                .map(|t| format!("{t:.2}"))
                .unwrap_or_else(|| "-".into()),
            s.bits
        )?;
    }
    if let Some(p) = &args.out {
        writeln!(out, "every integration interval written to {}", p.display())?;
    }
    out.flush()?;
    Ok(())
}
