//! [`FileSink`]: the receiver's standard output files in a directory.
//!
//! `pvt.csv` and `pvt.nmea` (flushed at every fix, so a live stream can be followed),
//! `channels.csv`, `observables.rnx` (RINEX 3; held back until the first fix gives the
//! header's approximate position, or 300 s of observables with the week known, or the end;
//! never written while the GPS week is unknown, see [`crate::pipeline::WeekReference`]),
//! `ephemeris.rnx` (the decoded ephemerides, at the end), `almanac.yuma` (the decoded almanac,
//! when one was), `track.geojson`, `track.kml` and `track.gpx` (the
//! fixes, at the end); with [`FileSink::with_plots`], the PNG plots of
//! [`crate::output::plots`] (`track.png`, `skyplot.png`, `cn0.png`, `dop.png`, at the end; a
//! plot that cannot be drawn is a warning).

use crate::output::plots::{write_run_plots, RunPlotData};
use crate::output::{
    create_file, rinex_nav::write_rinex_nav_file, write_geojson, write_kml, ChannelCsvWriter,
    ChannelRow, Fix, NavHeader, NavRecord, NmeaOptions, NmeaWriter, ObsEpoch, ObsHeader,
    OutputError, PvtCsvWriter, RinexObsWriter,
};
use crate::pipeline::sink::{
    FixReport, NavigationEnd, ObservablesReport, ReceiverEvent, Sink, SinkError,
};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Seconds of observables held back waiting for the first fix (whose position goes into the
/// RINEX header) before they are written without one.
const OBS_BACKLOG_MAX_S: f64 = 300.0;

/// Writes the standard files into a directory.
#[derive(Debug)]
pub struct FileSink {
    dir: PathBuf,
    rate_hz: f64,
    pvt_csv: PvtCsvWriter<BufWriter<File>>,
    nmea: NmeaWriter<BufWriter<File>>,
    channels_csv: ChannelCsvWriter<BufWriter<File>>,
    obs_writer: Option<RinexObsWriter<BufWriter<File>>>,
    obs_backlog: Vec<ObsEpoch>,
    /// Whether the week of the latest observables was known.
    obs_week_known: bool,
    /// Epochs dropped from the backlog while the week was unknown (memory bound).
    obs_dropped: usize,
    /// Observable epochs left out because their time was not after the last one written.
    obs_not_after: usize,
    /// `COMMENT` lines for observables.rnx that came before it was opened (its header's).
    obs_comments: Vec<String>,
    fixes: Vec<Fix>,
    /// What the plots need, when they are drawn.
    plots: Option<RunPlotData>,
}

impl FileSink {
    /// Creates `dir` if needed and the streaming files in it; `rate_hz` is the observable rate
    /// (the RINEX interval).
    pub fn create(dir: &Path, rate_hz: f64) -> Result<Self, OutputError> {
        std::fs::create_dir_all(dir).map_err(OutputError::io(&dir.display().to_string()))?;
        // observables.rnx is written later, or not at all (week unknown): a previous run's
        // must not pass for this run's.
        let obs = dir.join("observables.rnx");
        match std::fs::remove_file(&obs) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(OutputError::io(&obs.display().to_string())(e))
            }
            _ => {}
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            rate_hz,
            pvt_csv: PvtCsvWriter::create(&dir.join("pvt.csv"))?,
            nmea: NmeaWriter::create(&dir.join("pvt.nmea"), NmeaOptions::default())?,
            channels_csv: ChannelCsvWriter::create(&dir.join("channels.csv"))?,
            obs_writer: None,
            obs_backlog: Vec::new(),
            obs_week_known: false,
            obs_dropped: 0,
            obs_not_after: 0,
            obs_comments: Vec::new(),
            fixes: Vec::new(),
            plots: None,
        })
    }

    /// Draws the PNG plots at the end too when `enabled` (off by default: [`FileSink::create`]
    /// makes the text files only; `gpsrx run` follows [`crate::config::RunSettings::plots`]).
    pub fn with_plots(mut self, enabled: bool) -> Self {
        self.plots = enabled.then(RunPlotData::default);
        self
    }

    /// The fixes written.
    pub fn fixes(&self) -> &[Fix] {
        &self.fixes
    }

    /// The fixes written, consumed.
    pub fn into_fixes(self) -> Vec<Fix> {
        self.fixes
    }

    /// Creates `observables.rnx` (header position `approx_position_m`, if known) and writes
    /// the epochs held back for it, in increasing time. They all get `week`: epochs before the
    /// first subframe 1 carried the reference week, which can be 1024 weeks (or more) off.
    fn open_observables(
        &mut self,
        approx_position_m: Option<[f64; 3]>,
        week: u32,
    ) -> Result<(), OutputError> {
        // GPS - UTC at the start of the week (the IERS table; 18 s since 2017).
        let (year, month, ..) = gpsrx_nav::GpsTime::new(week, 0.0).to_calendar();
        let header = ObsHeader {
            approx_position_m: approx_position_m.unwrap_or_default(),
            interval_s: Some(1.0 / self.rate_hz),
            leap_seconds: Some(gpsrx_nav::utc::leap_seconds_on(year, month)),
            comments: std::mem::take(&mut self.obs_comments),
            ..ObsHeader::default()
        };
        if self.obs_dropped > 0 {
            tracing::warn!(
                "observables.rnx starts {:.1} s late: the observables of the first {} epochs came while the GPS week was unknown and were dropped (at most {OBS_BACKLOG_MAX_S} s are held back)",
                self.obs_dropped as f64 / self.rate_hz,
                self.obs_dropped
            );
        }
        let mut w = RinexObsWriter::create(&self.dir.join("observables.rnx"), header)?;
        let mut last_tow_s = f64::NEG_INFINITY;
        for mut o in self.obs_backlog.drain(..) {
            o.time.week = week;
            if o.time.tow_s > last_tow_s {
                last_tow_s = o.time.tow_s;
                w.write_epoch(&o)?;
            }
        }
        self.obs_writer = Some(w);
        Ok(())
    }
}

impl Sink for FileSink {
    fn fix(&mut self, report: &FixReport) -> Result<(), SinkError> {
        self.pvt_csv.write_fix(&report.fix)?;
        self.nmea.write_fix(&report.fix)?;
        self.pvt_csv.flush()?;
        self.nmea.flush()?;
        self.fixes.push(report.fix.clone());
        if let Some(p) = &mut self.plots {
            p.add_fix(&report.fix, report.t_stream_s);
        }
        Ok(())
    }

    fn observables(&mut self, report: &ObservablesReport) -> Result<(), SinkError> {
        let week = report.epoch.time.week;
        self.obs_week_known = report.week_known;
        if !report.week_known && self.obs_writer.is_none() {
            // No date from the system clock: held back until the week is known, the latest
            // 300 s at most.
            self.obs_backlog.push(report.epoch.clone());
            let max = (OBS_BACKLOG_MAX_S * self.rate_hz).ceil() as usize;
            if self.obs_backlog.len() > max {
                let n = self.obs_backlog.len() - max;
                self.obs_backlog.drain(..n);
                self.obs_dropped += n;
            }
            return Ok(());
        }
        match (&mut self.obs_writer, report.fix_position_m) {
            (Some(w), _) => {
                let back = w
                    .last_epoch_time()
                    .filter(|last| report.epoch.time.diff_s(*last) <= 0.0);
                if let Some(last) = back {
                    // RINEX holds increasing time only: a recording whose time went back (two
                    // captures joined in the wrong order) keeps its fixes, not these epochs.
                    if self.obs_not_after == 0 {
                        tracing::warn!(
                            "observables.rnx: the epoch at TOW {:.3} s is not after the last one written (TOW {:.3} s): the recording's time went back (captures joined out of order?); such epochs are left out of observables.rnx, the fixes go on",
                            report.epoch.time.tow_s,
                            last.tow_s
                        );
                    }
                    self.obs_not_after += 1;
                } else {
                    w.write_epoch(&report.epoch)?;
                }
            }
            (None, Some(position)) => {
                self.open_observables(Some(position), week)?;
                if let Some(w) = &mut self.obs_writer {
                    w.write_epoch(&report.epoch)?;
                }
            }
            (None, None) => {
                self.obs_backlog.push(report.epoch.clone());
                // Bounded memory: without a fix for this long (but with the week decoded, so
                // the labels will not change), the observables go out with an unknown position.
                if report.week_known
                    && self.obs_backlog.len() as f64 > OBS_BACKLOG_MAX_S * self.rate_hz
                {
                    self.open_observables(None, week)?;
                    tracing::warn!(
                        "no fix after {OBS_BACKLOG_MAX_S} s of observables: observables.rnx has no approximate position"
                    );
                }
            }
        }
        Ok(())
    }

    /// Vector tracking taking the channels or giving them back is marked in observables.rnx
    /// (an event record with `COMMENT` lines, [`RinexObsWriter::write_comments`]; in its
    /// header when it comes before the file is opened): the observables after it come from
    /// other loops, and weak ones from channels only the navigation filter's check keeps.
    fn event(&mut self, event: &ReceiverEvent) -> Result<(), SinkError> {
        let ReceiverEvent::VectorTracking { t_s, engaged } = *event else {
            return Ok(());
        };
        let lines: Vec<String> = if engaged {
            vec![
                format!("VECTOR TRACKING ON (STREAM TIME {t_s:.2} S): CARRIER NCOS"),
                "FOLLOW THE NAVIGATION FILTER'S PREDICTED DOPPLER; WEAK".into(),
                "CHANNELS IT CHECKS ARE KEPT BELOW THE SCALAR LOSS".into(),
                "THRESHOLD (S1C GIVES THEIR C/N0, HENCE THEIR NOISE)".into(),
            ]
        } else {
            vec![
                format!("VECTOR TRACKING OFF (STREAM TIME {t_s:.2} S): EACH"),
                "CHANNEL TRACKS ON ITS OWN LOOPS AGAIN".into(),
            ]
        };
        match &mut self.obs_writer {
            Some(w) => w.write_comments(&lines)?,
            None => self.obs_comments.extend(lines),
        }
        Ok(())
    }

    fn channel(&mut self, row: &ChannelRow) -> Result<(), SinkError> {
        if let Some(p) = &mut self.plots {
            p.add_channel(row);
        }
        Ok(self.channels_csv.write_row(row)?)
    }

    fn finish(&mut self, end: &NavigationEnd) -> Result<(), SinkError> {
        self.pvt_csv.flush()?;
        self.nmea.flush()?;
        self.channels_csv.flush()?;
        if self.obs_not_after > 0 {
            tracing::warn!(
                "observables.rnx: {} epochs left out because the recording's time went back",
                self.obs_not_after
            );
        }
        match self.obs_writer.take() {
            Some(w) => {
                let last = w.last_epoch_time();
                w.finish()?;
                if let Some(t) = last {
                    let path = self.dir.join("observables.rnx");
                    super::rinex_obs::insert_time_of_last_obs(&path, t)?;
                }
            }
            None if !self.obs_backlog.is_empty() && !self.obs_week_known => {
                tracing::warn!(
                    "observables.rnx not written: the GPS week was never known (no subframe 1 decoded, no SigMF core:datetime, no week or navigation data given) and RINEX epochs need a date; give the GPS week or the navigation data ({} epochs of observables left out)",
                    self.obs_backlog.len() + self.obs_dropped
                );
            }
            None if !self.obs_backlog.is_empty() => {
                // No fix: the observables still go out, with an unknown approximate position,
                // all labelled with the best week known (the last epoch's: decoded, or the
                // reference).
                let week = self.obs_backlog.last().map_or(0, |o| o.time.week);
                self.open_observables(None, week)?;
                if let Some(w) = self.obs_writer.take() {
                    let last = w.last_epoch_time();
                    w.finish()?;
                    if let Some(t) = last {
                        let path = self.dir.join("observables.rnx");
                        super::rinex_obs::insert_time_of_last_obs(&path, t)?;
                    }
                }
            }
            None => {}
        }
        let records: Vec<NavRecord> = end
            .ephemerides
            .iter()
            .map(|e| NavRecord {
                transmission_tow_s: end.transmission_tow_s.get(&e.prn).copied(),
                ephemeris: e.clone(),
            })
            .collect();
        let header = NavHeader {
            iono: end.iono,
            utc: end.utc,
            ..NavHeader::default()
        };
        write_rinex_nav_file(&self.dir.join("ephemeris.rnx"), &header, &records)?;
        if let Some(set) = end.almanac.as_ref().filter(|s| !s.almanacs.is_empty()) {
            let mut f = create_file(&self.dir.join("almanac.yuma"))?;
            super::yuma::write_yuma(&mut f, "almanac.yuma", set)?;
        }
        let mut f = create_file(&self.dir.join("track.geojson"))?;
        write_geojson(&mut f, "track.geojson", &self.fixes)?;
        let mut f = create_file(&self.dir.join("track.kml"))?;
        write_kml(&mut f, "track.kml", "gpsrx track", &self.fixes)?;
        let mut f = create_file(&self.dir.join("track.gpx"))?;
        super::write_gpx(&mut f, "track.gpx", "gpsrx track", &self.fixes)?;
        if let Some(p) = &self.plots {
            write_run_plots(&self.dir, p);
        }
        Ok(())
    }
}
