//! RINEX 3.04 GPS observation file writer (`observables.rnx`): L1 C/A pseudorange `C1C`,
//! carrier phase `L1C`, Doppler `D1C` and C/N0 `S1C`.
//!
//! Format: RINEX 3.04 (IGS/RTCM, 2018), section 5 and Tables A1-A3. The header is written
//! when the first epoch arrives, because `TIME OF FIRST OBS` is only known then; epochs then
//! stream one by one. GPS-only files need neither `GLONASS SLOT / FRQ #` nor
//! `GLONASS COD/PHS/BIS` (Table A2: required for files containing GLONASS), but need
//! `SYS / PHASE SHIFT` (mandatory since 3.01; `G L1C 0.00000`, since our L1C phase is the
//! reference signal).

use super::{
    calendar_rounded, create_file, fit_ascii, rinex_creation_date_now, ObsEpoch, OutputError,
    SatObs,
};
use gpsrx_nav::GpsTime;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The observation types written, in order (RINEX 3.04 section 5.1, Table 4: C = code,
/// L = phase, D = Doppler, S = signal strength; band 1; attribute C = C/A).
pub const OBS_TYPES: [&str; 4] = ["C1C", "L1C", "D1C", "S1C"];

/// Header information that does not come from the observations.
#[derive(Debug, Clone, PartialEq)]
pub struct ObsHeader {
    /// Program name (`PGM / RUN BY / DATE`, A20).
    pub program: String,
    /// Who ran it (A20).
    pub run_by: String,
    /// File creation date `yyyymmdd hhmmss UTC`; `None` takes the current time.
    pub creation_date: Option<String>,
    /// `MARKER NAME` (A60).
    pub marker_name: String,
    /// `MARKER TYPE` (A20), one of the RINEX 3.04 Table 5 keywords (`NON_GEODETIC`,
    /// `GROUND_CRAFT`, ...).
    pub marker_type: String,
    /// `OBSERVER / AGENCY` observer (A20).
    pub observer: String,
    /// `OBSERVER / AGENCY` agency (A40).
    pub agency: String,
    /// `REC # / TYPE / VERS` receiver number, type and version (3 x A20).
    pub receiver: [String; 3],
    /// `ANT # / TYPE` antenna number and type (2 x A20).
    pub antenna: [String; 2],
    /// `APPROX POSITION XYZ`, ECEF m (zeros when unknown, as RINEX allows for moving receivers).
    pub approx_position_m: [f64; 3],
    /// `ANTENNA: DELTA H/E/N`, m.
    pub antenna_delta_hen_m: [f64; 3],
    /// `INTERVAL`, s, as configured (omitted when `None`).
    pub interval_s: Option<f64>,
    /// `LEAP SECONDS` (current GPS - UTC, s), omitted when `None`.
    pub leap_seconds: Option<i32>,
    /// `COMMENT` lines (each truncated to 60 characters).
    pub comments: Vec<String>,
}

impl Default for ObsHeader {
    fn default() -> ObsHeader {
        ObsHeader {
            program: format!("gpsrx {}", env!("CARGO_PKG_VERSION")),
            run_by: "gpsrx".to_string(),
            creation_date: None,
            marker_name: "GPSRX".to_string(),
            marker_type: "NON_GEODETIC".to_string(),
            observer: "unknown".to_string(),
            agency: "unknown".to_string(),
            receiver: [
                "0".to_string(),
                "GPSRX SOFTWARE RX".to_string(),
                env!("CARGO_PKG_VERSION").to_string(),
            ],
            antenna: ["0".to_string(), "unknown".to_string()],
            approx_position_m: [0.0; 3],
            antenna_delta_hen_m: [0.0; 3],
            interval_s: None,
            leap_seconds: None,
            comments: Vec::new(),
        }
    }
}

/// Streaming RINEX 3.04 observation writer. Call [`RinexObsWriter::write_epoch`] for each
/// epoch in time order, then [`RinexObsWriter::finish`].
#[derive(Debug)]
pub struct RinexObsWriter<W: Write> {
    out: W,
    file: String,
    header: ObsHeader,
    last_time: Option<GpsTime>,
    epochs: usize,
    blanked_values: usize,
}

impl RinexObsWriter<BufWriter<File>> {
    /// Creates the file at `path` (nothing is written until the first epoch).
    pub fn create(path: &Path, header: ObsHeader) -> Result<Self, OutputError> {
        Ok(RinexObsWriter::new(
            create_file(path)?,
            path.display().to_string(),
            header,
        ))
    }
}

impl<W: Write> RinexObsWriter<W> {
    /// A writer to `out`; `file` names the destination in error messages.
    pub fn new(out: W, file: impl Into<String>, header: ObsHeader) -> Self {
        RinexObsWriter {
            out,
            file: file.into(),
            header,
            last_time: None,
            epochs: 0,
            blanked_values: 0,
        }
    }

    /// Epochs written so far.
    pub fn epochs(&self) -> usize {
        self.epochs
    }

    /// Observation values written as blank because they were non-finite or did not fit the
    /// F14.3 field (|value| >= 1e9).
    pub fn blanked_values(&self) -> usize {
        self.blanked_values
    }

    /// Writes one epoch (and the header before the first). Epochs must be in strictly
    /// increasing time order; PRNs must be 1-99.
    pub fn write_epoch(&mut self, epoch: &ObsEpoch) -> Result<(), OutputError> {
        let cal = calendar_rounded(epoch.time, 7).ok_or_else(|| {
            OutputError::invalid(
                &self.file,
                format!("epoch time {:?} is not a valid GPS time", epoch.time),
            )
        })?;
        if let Some(last) = self.last_time {
            if epoch.time.diff_s(last) <= 0.0 {
                return Err(OutputError::invalid(
                    &self.file,
                    format!(
                        "epoch week {} tow {:.7} s is not after the previous epoch (week {} tow {:.7} s); RINEX needs increasing time",
                        epoch.time.week, epoch.time.tow_s, last.week, last.tow_s
                    ),
                ));
            }
        }
        if epoch.sats.len() > 999 {
            return Err(OutputError::invalid(
                &self.file,
                format!("{} satellites in one epoch (at most 999)", epoch.sats.len()),
            ));
        }
        if let Some(bad) = epoch.sats.iter().find(|s| !(1..=99).contains(&s.prn)) {
            return Err(OutputError::invalid(
                &self.file,
                format!("PRN {} out of range 1-99", bad.prn),
            ));
        }
        let clock = match epoch.clock_offset_s {
            None => String::new(),
            Some(dt) => {
                // F15.12 after 6X (columns 42-56).
                let text = format!("{dt:15.12}");
                if !dt.is_finite() || text.len() > 15 {
                    return Err(OutputError::invalid(
                        &self.file,
                        format!("receiver clock offset {dt} s does not fit RINEX F15.12"),
                    ));
                }
                format!("      {text}")
            }
        };

        let mut text = String::new();
        if self.last_time.is_none() {
            text.push_str(&self.header_text(epoch.time)?);
        }
        // A1,1X,I4,4(1X,I2.2),F11.7,2X,I1,I3,6X,F15.12 (RINEX 3.04 Table A3).
        text.push_str(&format!(
            "> {:04} {:02} {:02} {:02} {:02}{:11.7}  0{:3}{clock}\n",
            cal.year,
            cal.month,
            cal.day,
            cal.hour,
            cal.minute,
            f64::from(cal.second) + cal.frac as f64 * 1e-7,
            epoch.sats.len(),
        ));
        for sat in &epoch.sats {
            let line = self.sat_line(sat);
            text.push_str(line.trim_end());
            text.push('\n');
        }
        self.out
            .write_all(text.as_bytes())
            .map_err(OutputError::io(&self.file))?;
        self.last_time = Some(epoch.time);
        self.epochs += 1;
        Ok(())
    }

    /// Writes `comments` as `COMMENT` lines of an event record with flag 4 ("header
    /// information follows", RINEX 3.04 Table A3; its epoch left blank, as flags 2-5 allow)
    /// between the last epoch written and the next: they apply from there on. Before the first
    /// epoch they join the header's comments instead. Each line is cut to 60 characters.
    pub fn write_comments(&mut self, comments: &[String]) -> Result<(), OutputError> {
        if comments.is_empty() {
            return Ok(());
        }
        if self.last_time.is_none() {
            self.header.comments.extend(comments.iter().cloned());
            return Ok(());
        }
        if comments.len() > 999 {
            return Err(OutputError::invalid(
                &self.file,
                format!(
                    "{} comment lines in one event (at most 999)",
                    comments.len()
                ),
            ));
        }
        // `>`, the blank epoch (columns 2-31), the flag (32) and the number of records (33-35).
        let mut text = format!(">{:30}4{:3}\n", "", comments.len());
        for c in comments {
            text.push_str(&fit_ascii(c, 60));
            text.push_str("COMMENT\n");
        }
        self.out
            .write_all(text.as_bytes())
            .map_err(OutputError::io(&self.file))
    }

    /// The time of the last epoch written, if any.
    pub fn last_epoch_time(&self) -> Option<GpsTime> {
        self.last_time
    }

    /// Flushes and returns the destination. Fails with [`OutputError::Empty`] if no epoch was
    /// written, since a header without `TIME OF FIRST OBS` is not valid RINEX.
    pub fn finish(mut self) -> Result<W, OutputError> {
        if self.epochs == 0 {
            return Err(OutputError::Empty {
                file: self.file,
                what: "observation epochs",
            });
        }
        self.out.flush().map_err(OutputError::io(&self.file))?;
        Ok(self.out)
    }

    /// `Gnn` then, per observation type, F14.3 + LLI (I1) + SSI (I1).
    fn sat_line(&mut self, sat: &SatObs) -> String {
        let ssi = sat.cn0_dbhz.and_then(ssi_from_cn0);
        let lli = lli_flags(sat);
        let values = [
            sat.pseudorange_m,
            sat.carrier_cycles,
            sat.doppler_hz,
            sat.cn0_dbhz,
        ];
        let mut line = format!("G{:02}", sat.prn);
        for (k, value) in values.iter().enumerate() {
            let Some(v) = value else {
                line.push_str(&" ".repeat(16));
                continue;
            };
            let field = format!("{v:14.3}");
            if !v.is_finite() || field.len() > 14 {
                self.blanked_values += 1;
                line.push_str(&" ".repeat(16));
                continue;
            }
            line.push_str(&field);
            // LLI bits 0 and 1 apply to phase observations only (RINEX 3.04 5.7).
            line.push(match (k, lli) {
                (1, 1..=7) => char::from(b'0' + lli),
                _ => ' ',
            });
            line.push(ssi.map_or(' ', |s| char::from(b'0' + s)));
        }
        line
    }

    fn header_text(&self, first: GpsTime) -> Result<String, OutputError> {
        let h = &self.header;
        let mut out = String::new();
        let mut line = |content: String, label: &str| {
            out.push_str(&fit_ascii(&content, 60));
            out.push_str(label);
            out.push('\n');
        };
        line(
            format!("{:9.2}{:11}{:20}{:20}", 3.04, "", "OBSERVATION DATA", "G"),
            "RINEX VERSION / TYPE",
        );
        let date = h
            .creation_date
            .clone()
            .unwrap_or_else(rinex_creation_date_now);
        line(
            format!(
                "{}{}{}",
                fit_ascii(&h.program, 20),
                fit_ascii(&h.run_by, 20),
                fit_ascii(&date, 20)
            ),
            "PGM / RUN BY / DATE",
        );
        for c in &h.comments {
            line(c.clone(), "COMMENT");
        }
        line(h.marker_name.clone(), "MARKER NAME");
        line(fit_ascii(&h.marker_type, 20), "MARKER TYPE");
        line(
            format!("{}{}", fit_ascii(&h.observer, 20), fit_ascii(&h.agency, 40)),
            "OBSERVER / AGENCY",
        );
        line(
            h.receiver.iter().map(|s| fit_ascii(s, 20)).collect(),
            "REC # / TYPE / VERS",
        );
        line(
            h.antenna.iter().map(|s| fit_ascii(s, 20)).collect(),
            "ANT # / TYPE",
        );
        line(
            self.three_f14_4(h.approx_position_m, "APPROX POSITION XYZ")?,
            "APPROX POSITION XYZ",
        );
        line(
            self.three_f14_4(h.antenna_delta_hen_m, "ANTENNA: DELTA H/E/N")?,
            "ANTENNA: DELTA H/E/N",
        );
        // A1,2X,I3,13(1X,A3)
        line(
            format!("G  {:3} {}", OBS_TYPES.len(), OBS_TYPES.join(" ")),
            "SYS / # / OBS TYPES",
        );
        line("DBHZ".to_string(), "SIGNAL STRENGTH UNIT");
        if let Some(interval) = h.interval_s {
            let text = format!("{interval:10.3}");
            if !(interval.is_finite() && interval > 0.0) || text.len() > 10 {
                return Err(OutputError::invalid(
                    &self.file,
                    format!("INTERVAL {interval} s must be positive and fit F10.3"),
                ));
            }
            line(text, "INTERVAL");
        }
        let first_text = obs_time_text(first).ok_or_else(|| {
            OutputError::invalid(&self.file, format!("first epoch {first:?} is not valid"))
        })?;
        line(first_text, "TIME OF FIRST OBS");
        line("     0".to_string(), "RCV CLOCK OFFS APPL");
        if let Some(leap) = h.leap_seconds {
            line(format!("{leap:6}"), "LEAP SECONDS");
        }
        // A1,1X,A3,1X,F8.5: GPS L1C is the reference signal, no shift.
        line("G L1C  0.00000".to_string(), "SYS / PHASE SHIFT");
        line(String::new(), "END OF HEADER");
        Ok(out)
    }

    fn three_f14_4(&self, v: [f64; 3], what: &str) -> Result<String, OutputError> {
        let text = format!("{:14.4}{:14.4}{:14.4}", v[0], v[1], v[2]);
        if v.iter().any(|x| !x.is_finite()) || text.len() > 42 {
            return Err(OutputError::invalid(
                &self.file,
                format!("{what} {v:?} m must be finite and fit 3F14.4"),
            ));
        }
        Ok(text)
    }
}

/// RINEX signal strength indicator from C/N0 (RINEX 3.04 section 5.7, Table 8 note:
/// 1 = < 12 dB-Hz, 2 = 12-17, ..., 5 = 30-35 (threshold for good tracking), ...,
/// 9 = >= 54 dB-Hz), i.e. clamp(floor(C/N0 / 6), 1, 9). `None` for a non-finite C/N0.
pub fn ssi_from_cn0(cn0_dbhz: f64) -> Option<u8> {
    if !cn0_dbhz.is_finite() {
        return None;
    }
    Some((cn0_dbhz / 6.0).floor().clamp(1.0, 9.0) as u8)
}

/// Loss-of-lock indicator of the phase observation (RINEX 3.04 section 5.7): bit 0 = lost
/// lock between the previous and this observation (cycle slip possible), bit 1 = half-cycle
/// ambiguity/slip possible.
pub fn lli_flags(sat: &SatObs) -> u8 {
    u8::from(sat.loss_of_lock) | (u8::from(sat.half_cycle_ambiguous) << 1)
}

/// A header time field (5I6,F13.7,5X,A3: `TIME OF FIRST OBS` and `TIME OF LAST OBS`), `None`
/// for a time that has no calendar date.
fn obs_time_text(t: GpsTime) -> Option<String> {
    let cal = calendar_rounded(t, 7)?;
    Some(format!(
        "{:6}{:6}{:6}{:6}{:6}{:13.7}{:5}GPS",
        cal.year,
        cal.month,
        cal.day,
        cal.hour,
        cal.minute,
        f64::from(cal.second) + cal.frac as f64 * 1e-7,
        ""
    ))
}

/// Adds `TIME OF LAST OBS` (`last`) to the header of the finished file at `path`, after its
/// `TIME OF FIRST OBS` line: the header is written before the last epoch is known, so the file
/// is copied line by line into a new one beside it (bounded memory), which replaces it.
pub fn insert_time_of_last_obs(path: &Path, last: GpsTime) -> Result<(), OutputError> {
    use std::io::{BufRead, BufReader};
    let file = path.display().to_string();
    let Some(text) = obs_time_text(last) else {
        return Err(OutputError::invalid(
            &file,
            format!("last epoch {last:?} is not valid"),
        ));
    };
    let tmp = path.with_extension("rnx.tmp");
    let input = File::open(path).map_err(OutputError::io(&file))?;
    let mut out = create_file(&tmp)?;
    let mut in_header = true;
    for l in BufReader::new(input).lines() {
        let l = l.map_err(OutputError::io(&file))?;
        writeln!(out, "{l}").map_err(OutputError::io(&file))?;
        if in_header
            && l.get(60..)
                .is_some_and(|label| label.starts_with("TIME OF FIRST OBS"))
        {
            writeln!(out, "{text:<60}TIME OF LAST OBS").map_err(OutputError::io(&file))?;
        }
        in_header &= !l
            .get(60..)
            .is_some_and(|label| label.starts_with("END OF HEADER"));
    }
    out.flush().map_err(OutputError::io(&file))?;
    drop(out);
    std::fs::rename(&tmp, path).map_err(OutputError::io(&file))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> ObsHeader {
        ObsHeader {
            creation_date: Some("20220101 000000 UTC".to_string()),
            interval_s: Some(1.0),
            ..ObsHeader::default()
        }
    }

    fn epoch(tow_s: f64) -> ObsEpoch {
        ObsEpoch {
            time: GpsTime::new(2190, tow_s),
            clock_offset_s: Some(1.25e-4),
            sats: vec![
                SatObs {
                    prn: 5,
                    pseudorange_m: Some(21_000_123.456),
                    carrier_cycles: Some(110_356_789.125),
                    doppler_hz: Some(-1234.5),
                    cn0_dbhz: Some(45.2),
                    loss_of_lock: true,
                    half_cycle_ambiguous: true,
                },
                SatObs {
                    prn: 12,
                    pseudorange_m: Some(23_000_000.0),
                    carrier_cycles: None,
                    doppler_hz: Some(f64::NAN),
                    cn0_dbhz: None,
                    ..SatObs::default()
                },
            ],
        }
    }

    fn write(epochs: &[ObsEpoch]) -> Result<String, OutputError> {
        let mut w = RinexObsWriter::new(Vec::new(), "test.rnx", header());
        for e in epochs {
            w.write_epoch(e)?;
        }
        let bytes = w.finish()?;
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }

    /// A comment between epochs is an event record with flag 4 and its number of lines in
    /// RINEX 3.04's columns (those RTKLIB reads: flag at 32, count at 33-35); before the first
    /// epoch it joins the header.
    #[test]
    fn comments_between_epochs_are_a_flag_4_event() -> Result<(), OutputError> {
        let mut w = RinexObsWriter::new(Vec::new(), "test.rnx", header());
        w.write_comments(&["BEFORE THE FIRST EPOCH".to_string()])?;
        w.write_epoch(&epoch(538_200.0))?;
        let lines = ["VECTOR TRACKING ON".to_string(), "x".repeat(70)];
        w.write_comments(&lines)?;
        w.write_epoch(&epoch(538_200.5))?;
        let text = String::from_utf8_lossy(&w.finish()?).into_owned();
        let all: Vec<&str> = text.lines().collect();
        let end = all
            .iter()
            .position(|l| l.ends_with("END OF HEADER"))
            .expect("header");
        assert!(all[..end]
            .iter()
            .any(|l| l.starts_with("BEFORE THE FIRST EPOCH") && l.ends_with("COMMENT")));
        let event = all
            .iter()
            .position(|l| l.starts_with('>') && l.get(31..32) == Some("4"))
            .expect("event record");
        assert_eq!(all[event].len(), 35, "{:?}", all[event]);
        assert_eq!(all[event][1..31].trim(), "", "blank epoch");
        assert_eq!(all[event][32..35].trim(), "2");
        assert_eq!(
            all[event + 1],
            format!("{:60}COMMENT", "VECTOR TRACKING ON")
        );
        assert_eq!(all[event + 2], format!("{}COMMENT", "x".repeat(60)));
        // Between the two epochs.
        assert!(all[event - 1].starts_with("G12") && all[event + 3].starts_with("> 2022"));
        Ok(())
    }

    #[test]
    fn time_of_last_obs_goes_into_the_finished_header_only() -> Result<(), OutputError> {
        let text = write(&[epoch(538_200.0), epoch(538_200.5)])?;
        let dir = tempfile::tempdir().map_err(OutputError::io("tempdir"))?;
        let path = dir.path().join("o.rnx");
        std::fs::write(&path, &text).map_err(OutputError::io("o.rnx"))?;
        insert_time_of_last_obs(&path, GpsTime::new(2190, 538_200.5))?;
        let out = std::fs::read_to_string(&path).map_err(OutputError::io("o.rnx"))?;
        let lines: Vec<&str> = out.lines().collect();
        let first = lines.iter().position(|l| l.ends_with("TIME OF FIRST OBS"));
        let last = lines.iter().position(|l| l.ends_with("TIME OF LAST OBS"));
        assert_eq!(last, first.map(|i| i + 1), "{out}");
        // 2022-01-01 05:30:00.5 GPS time, in the columns of TIME OF FIRST OBS.
        let l = lines[last.unwrap_or(0)];
        assert_eq!(&l[..43], "  2022     1     1     5    30    0.5000000");
        assert_eq!(&l[48..51], "GPS");
        assert_eq!(l.len(), 76);
        // The body is unchanged, and the label appears once.
        assert_eq!(out.matches("TIME OF LAST OBS").count(), 1);
        assert_eq!(lines.len(), text.lines().count() + 1);
        Ok(())
    }

    #[test]
    fn header_labels_are_in_columns_61_to_80_and_complete() -> Result<(), OutputError> {
        let text = write(&[epoch(538_200.0)])?;
        let header: Vec<&str> = text
            .lines()
            .take_while(|l| !l.contains("END OF HEADER"))
            .collect();
        for l in &header {
            assert!(l.len() <= 80 && l.len() > 60, "bad header line `{l}`");
        }
        assert!(header[0].starts_with("     3.04           OBSERVATION DATA    G"));
        for label in [
            "PGM / RUN BY / DATE",
            "MARKER NAME",
            "MARKER TYPE",
            "OBSERVER / AGENCY",
            "REC # / TYPE / VERS",
            "ANT # / TYPE",
            "APPROX POSITION XYZ",
            "ANTENNA: DELTA H/E/N",
            "SYS / # / OBS TYPES",
            "SIGNAL STRENGTH UNIT",
            "INTERVAL",
            "TIME OF FIRST OBS",
            "SYS / PHASE SHIFT",
        ] {
            assert!(
                header.iter().any(|l| l[60..].trim_end() == label),
                "missing {label}"
            );
        }
        let first = header
            .iter()
            .find(|l| l.contains("TIME OF FIRST OBS"))
            .copied();
        assert_eq!(
            first.map(|l| &l[..60]),
            Some("  2022     1     1     5    30    0.0000000     GPS         ")
        );
        Ok(())
    }

    #[test]
    fn epoch_and_observation_lines_follow_the_fixed_columns() -> Result<(), OutputError> {
        let text = write(&[epoch(538_200.0), epoch(538_201.0)])?;
        let body: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.contains("END OF HEADER"))
            .skip(1)
            .collect();
        assert_eq!(
            body[0],
            "> 2022 01 01 05 30  0.0000000  0  2       0.000125000000"
        );
        assert_eq!(
            body[1],
            "G05  21000123.456 7 110356789.12537     -1234.500 7        45.200 7"
        );
        assert_eq!(body[2], "G12  23000000.000");
        assert_eq!(
            body[3],
            "> 2022 01 01 05 30  1.0000000  0  2       0.000125000000"
        );
        Ok(())
    }

    #[test]
    fn bad_inputs_are_errors_not_panics() {
        assert!(matches!(write(&[]), Err(OutputError::Empty { .. })));
        assert!(matches!(
            write(&[epoch(10.0), epoch(10.0)]),
            Err(OutputError::InvalidInput { .. })
        ));
        let mut bad = epoch(10.0);
        bad.sats[0].prn = 0;
        assert!(write(&[bad]).is_err());
        let mut bad = epoch(10.0);
        bad.clock_offset_s = Some(1e6);
        assert!(write(&[bad]).is_err());
        let mut bad = epoch(10.0);
        bad.time.tow_s = f64::NAN;
        assert!(write(&[bad]).is_err());
    }

    #[test]
    fn ssi_mapping_follows_rinex() {
        assert_eq!(ssi_from_cn0(5.0), Some(1));
        assert_eq!(ssi_from_cn0(12.0), Some(2));
        assert_eq!(ssi_from_cn0(35.9), Some(5));
        assert_eq!(ssi_from_cn0(45.0), Some(7));
        assert_eq!(ssi_from_cn0(60.0), Some(9));
        assert_eq!(ssi_from_cn0(f64::NAN), None);
    }
}
