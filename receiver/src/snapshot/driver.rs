//! A sequence of snapshots: each is acquired and solved on its own, seeded by the last good
//! fix.
//!
//! # Seeding
//!
//! The first snapshot starts from the given a-priori position and from its own time tag (or
//! the given time). After a fix of quality [`SnapshotQuality::Fix`] the next snapshot starts
//! from that position and from its own time tag plus the time correction just found (the
//! device clock's error changes slowly). A snapshot without such a fix (no position,
//! `unverified`, or refused by a check) leaves the seed as it was, so a bad snapshot never
//! moves the a-priori of the others.

use super::clock::SequenceClock;
use super::input::Snapshot;
use super::measure::{
    acquire_snapshot, look_at_predicted, predict_visible, search_layout, MeasureOptions,
    SnapshotAcquisition,
};
use super::solve::{predict_missed, residual_rms_m, solve_snapshot, SnapshotQuality, SolveOptions};
use super::SnapshotError;
use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine};
use gpsrx_nav::pvt::CoarseTimeSolution;
use gpsrx_nav::pvt::{PvtOptions, Weighting};
use gpsrx_nav::{GpsTime, Llh, NavData, Vector3};
use std::collections::HashMap;

/// Options of a snapshot run.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotOptions {
    /// Acquisition settings.
    pub measure: MeasureOptions,
    /// Solver settings and checks.
    pub solve: SolveOptions,
    /// Largest |front-end frequency offset| considered, Hz.
    pub fe_offset_max_hz: f64,
}

impl Default for SnapshotOptions {
    /// The settings used on the SnapperGPS and airborne captures: code-phase sigma
    /// sqrt(a^2 + b^2 / sin^2 el) at 40 dB-Hz with a = 10 m, b = 5 m, RAIM false-alarm
    /// probability 1e-3, residual RMS at most 40 m, HDOP at most 6, a-priori bounds 100 km
    /// and 60 s, front-end offset within 5 kHz.
    fn default() -> Self {
        Self {
            measure: MeasureOptions::default(),
            solve: SolveOptions {
                max_residual_rms_m: 40.0,
                max_hdop: 6.0,
                pvt: PvtOptions {
                    weighting: Weighting::ElevationCn0 {
                        a_m: 10.0,
                        b_m: 5.0,
                        cn0_ref_dbhz: 40.0,
                    },
                    ..PvtOptions::default()
                },
                pos_uncertainty_m: gpsrx_nav::pvt::coarse_time::DEFAULT_POS_UNCERTAINTY_M,
                time_uncertainty_s: gpsrx_nav::pvt::coarse_time::DEFAULT_TIME_UNCERTAINTY_S,
                height: None,
            },
            fe_offset_max_hz: 5_000.0,
        }
    }
}

/// The a-priori of a snapshot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seed {
    /// Approximate position, ECEF, m.
    pub pos_ecef_m: Vector3<f64>,
    /// Correction to add to a snapshot's own time tag, s.
    pub time_correction_s: f64,
    /// Time used when a snapshot has no tag of its own (a raw file with `--time`).
    pub time: Option<GpsTime>,
}

/// What became of one snapshot: one row of `snapshots.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct SnapshotOutcome {
    /// Position in the input, 0-based.
    pub index: usize,
    /// The input's time text.
    pub label: String,
    /// A-priori GPS time used (`None`: none known).
    pub apriori_time: Option<GpsTime>,
    /// Quality.
    pub quality: SnapshotQuality,
    /// Why there is no fix (or what was refused); empty for a fix.
    pub reason: String,
    /// Corrected GPS time of the first sample.
    pub time: Option<GpsTime>,
    /// Time correction against the snapshot's time tag (or against `--time`), s.
    pub time_correction_s: Option<f64>,
    /// Position (WGS-84).
    pub llh: Option<Llh>,
    /// Position, ECEF, m.
    pub ecef_m: Option<Vector3<f64>>,
    /// Satellites used.
    pub used_prns: Vec<u8>,
    /// HDOP.
    pub hdop: Option<f64>,
    /// PDOP.
    pub pdop: Option<f64>,
    /// Post-fit residual RMS, m.
    pub residual_rms_m: Option<f64>,
    /// Clock bias unknown of the solver, m.
    pub clock_bias_m: Option<f64>,
    /// Satellites searched / detected and accepted.
    pub searched: usize,
    /// Satellites whose code phase entered the solver.
    pub detected: usize,
    /// Peaks dropped as false or cross-correlations.
    pub rejected_prns: Vec<u8>,
    /// Satellites left out by the solver's residual test.
    pub excluded_prns: Vec<u8>,
    /// Common front-end frequency offset, Hz.
    pub fe_offset_hz: Option<f64>,
}

impl SnapshotOutcome {
    fn none(s: &Snapshot, apriori_time: Option<GpsTime>, reason: String) -> Self {
        SnapshotOutcome {
            label: s.label.clone(),
            apriori_time,
            reason,
            ..Self::empty(s.index)
        }
    }

    /// A row of quality `none` with nothing known, for the snapshot at `index`.
    pub(crate) fn empty(index: usize) -> Self {
        SnapshotOutcome {
            index,
            label: String::new(),
            apriori_time: None,
            quality: SnapshotQuality::None,
            reason: String::new(),
            time: None,
            time_correction_s: None,
            llh: None,
            ecef_m: None,
            used_prns: Vec::new(),
            hdop: None,
            pdop: None,
            residual_rms_m: None,
            clock_bias_m: None,
            searched: 0,
            detected: 0,
            rejected_prns: Vec::new(),
            excluded_prns: Vec::new(),
            fe_offset_hz: None,
        }
    }

    /// Whether the row has a position (`fix` or `unverified`).
    pub fn has_position(&self) -> bool {
        self.llh.is_some()
    }
}

/// Acquires and solves snapshots with one navigation file and one set of options; keeps the
/// acquisition engines (FFT plans, replica spectra) between snapshots of the same layout.
#[derive(Debug)]
pub struct SnapshotProcessor<'a> {
    nav: &'a NavData,
    opts: SnapshotOptions,
    engines: HashMap<(u64, u32, u32), AcquisitionEngine>,
}

impl<'a> SnapshotProcessor<'a> {
    /// A processor with the ephemerides of `nav`. The ionosphere of `nav` is used when the
    /// options have none. Without a single GPS ephemeris in `nav` no satellite can be
    /// predicted: [`SnapshotError::NoEphemerides`].
    pub fn new(nav: &'a NavData, mut opts: SnapshotOptions) -> Result<Self, SnapshotError> {
        if nav.ephemerides.is_empty() {
            return Err(SnapshotError::NoEphemerides);
        }
        if opts.solve.pvt.iono.is_none() {
            opts.solve.pvt.iono = nav.iono;
        }
        Ok(Self {
            nav,
            opts,
            engines: HashMap::new(),
        })
    }

    /// Processes `snapshots` in order from `seed` (module docs: seeding), then, when the
    /// snapshots carry time tags and enough of them gave fixes, solves each again with the
    /// sequence's clock ([`super::clock`]); `progress` is called after each snapshot of the
    /// first pass.
    pub fn run(
        &mut self,
        snapshots: &[Snapshot],
        mut seed: Seed,
        mut progress: impl FnMut(&SnapshotOutcome),
    ) -> Vec<SnapshotOutcome> {
        let mut out = Vec::with_capacity(snapshots.len());
        let mut kept = Vec::with_capacity(snapshots.len());
        let mut clock = SequenceClock::default();
        let t0 = snapshots.iter().find_map(|s| s.approx_time);
        for s in snapshots {
            let (o, acq) = self.process(s, &seed);
            if o.quality == SnapshotQuality::Fix {
                if let (Some(x), Some(dt)) = (o.ecef_m, o.time_correction_s) {
                    seed.pos_ecef_m = x;
                    if let (Some(tag), Some(t0)) = (s.approx_time, t0) {
                        seed.time_correction_s = dt;
                        clock.push(tag.diff_s(t0), dt);
                    }
                }
            }
            progress(&o);
            kept.push(acq.map(|a| (a, o.ecef_m.unwrap_or(seed.pos_ecef_m))));
            out.push(o);
        }
        let Some(t0) = t0 else {
            return out;
        };
        for ((s, o), k) in snapshots.iter().zip(out.iter_mut()).zip(&kept) {
            let (Some(tag), Some((acq, pos))) = (s.approx_time, k) else {
                continue;
            };
            let Some((corr, sigma)) = clock.at(tag.diff_s(t0)) else {
                continue;
            };
            let again = self.solve_augmented(s, acq, tag.add_seconds(corr), pos, corr, Some(sigma));
            if again.quality == SnapshotQuality::Fix || o.quality != SnapshotQuality::Fix {
                *o = again;
            } else {
                o.reason = format!(
                    "solved alone: with the sequence's clock ({corr:+.3} s) {}",
                    again.reason
                );
            }
        }
        out
    }

    /// One snapshot from `seed`, with its acquisition when there was one.
    pub fn process(
        &mut self,
        s: &Snapshot,
        seed: &Seed,
    ) -> (SnapshotOutcome, Option<SnapshotAcquisition>) {
        let tagged = if s.approx_time.is_some() {
            seed.time_correction_s
        } else {
            0.0
        };
        let apriori_time = s
            .approx_time
            .map(|t| t.add_seconds(seed.time_correction_s))
            .or(seed.time);
        let Some(t_a) = apriori_time else {
            let reason = "no a-priori time: the snapshot carries none and none was given".into();
            return (SnapshotOutcome::none(s, None, reason), None);
        };
        if let Some(reason) = unusable(s) {
            return (SnapshotOutcome::none(s, apriori_time, reason), None);
        }
        let acq = match self.acquire(s, t_a, &seed.pos_ecef_m) {
            Ok(a) => a,
            Err(reason) => return (SnapshotOutcome::none(s, apriori_time, reason), None),
        };
        let o = self.solve_augmented(s, &acq, t_a, &seed.pos_ecef_m, tagged, None);
        (o, Some(acq))
    }

    /// Solves an acquired snapshot at a-priori time `t_a` (the tag plus `tagged_s`) and
    /// position `pos`, with the time as an observation of sigma `time_sigma_s` if given.
    fn solve_one(
        &self,
        s: &Snapshot,
        acq: &SnapshotAcquisition,
        t_a: GpsTime,
        pos: &Vector3<f64>,
        tagged_s: f64,
        time_sigma_s: Option<f64>,
    ) -> (SnapshotOutcome, Option<CoarseTimeSolution>) {
        let mut o = SnapshotOutcome::none(s, Some(t_a), String::new());
        o.searched = acq.searched;
        o.detected = acq.sats.len();
        o.rejected_prns.clone_from(&acq.rejected_prns);
        o.fe_offset_hz = acq.offset_hz;
        if acq.offset_hz.is_none() {
            o.reason = format!(
                "{} satellites detected: too few to find the front-end frequency offset",
                acq.sats.len()
            );
            return (o, None);
        }
        let solved = solve_snapshot(
            &acq.sats,
            s.fs_hz,
            self.nav,
            t_a,
            pos,
            time_sigma_s,
            &self.opts.solve,
        );
        match solved {
            Ok((sol, quality)) => {
                o.quality = quality;
                o.time = Some(sol.time);
                // Against the snapshot's own tag.
                o.time_correction_s = Some(sol.time_correction_s + tagged_s);
                o.llh = Some(sol.llh);
                o.ecef_m = Some(sol.pos_ecef_m);
                o.used_prns = sol.satellites.iter().map(|x| x.prn).collect();
                o.hdop = Some(sol.dop.hdop);
                o.pdop = Some(sol.dop.pdop);
                o.residual_rms_m = Some(residual_rms_m(&sol));
                o.clock_bias_m = Some(sol.clock_bias_m);
                o.excluded_prns.clone_from(&sol.excluded_prns);
                if quality == SnapshotQuality::Unverified {
                    o.reason = "5 satellites: no redundancy to check the fix".into();
                }
                return (o, Some(sol));
            }
            Err(reason) => {
                o.reason = format!("{} satellites: {reason}", acq.sats.len());
            }
        }
        (o, None)
    }

    /// [`Self::solve_one`], then the satellites the search missed looked for where that
    /// solution puts them ([`look_at_predicted`]); with any found, solved again with them and
    /// that solution kept if it is a `fix`.
    fn solve_augmented(
        &self,
        s: &Snapshot,
        acq: &SnapshotAcquisition,
        t_a: GpsTime,
        pos: &Vector3<f64>,
        tagged_s: f64,
        time_sigma_s: Option<f64>,
    ) -> SnapshotOutcome {
        let (o, sol) = self.solve_one(s, acq, t_a, pos, tagged_s, time_sigma_s);
        let (Some(sol), Some(offset)) = (sol, acq.offset_hz) else {
            return o;
        };
        let have: Vec<_> = acq.sats.iter().map(|x| x.prn).collect();
        let missed = predict_missed(
            &sol,
            t_a,
            self.nav,
            &self.opts.solve.pvt,
            s.fs_hz,
            &acq.predicted,
            &have,
        );
        let extra = look_at_predicted(
            &s.samples,
            s.fs_hz,
            offset,
            &missed,
            self.opts.measure.code_band_hz,
            self.opts.measure.coherent_predicted,
        );
        if extra.is_empty() {
            return o;
        }
        let mut more = acq.clone();
        more.sats.extend(extra);
        let (again, _) = self.solve_one(s, &more, t_a, pos, tagged_s, time_sigma_s);
        if again.quality == SnapshotQuality::Fix {
            again
        } else {
            o
        }
    }

    /// The assisted acquisition of `s` at the a-priori time and position.
    fn acquire(
        &mut self,
        s: &Snapshot,
        t_a: GpsTime,
        pos: &Vector3<f64>,
    ) -> Result<SnapshotAcquisition, String> {
        let pred = predict_visible(self.nav, pos, t_a, self.opts.measure.elevation_mask_deg);
        if pred.len() < gpsrx_nav::pvt::coarse_time::MIN_SATELLITES {
            return Err(format!(
                "{} satellites with an ephemeris above the horizon at the a-priori time: \
                 check the navigation data and the a-priori time",
                pred.len()
            ));
        }
        let len_ms = (s.samples.len() as f64 / (s.fs_hz * 1e-3)).floor() as u32;
        let Some((t, nc)) = search_layout(len_ms, self.opts.measure.coherent_ms) else {
            return Err(format!("too short: {len_ms} ms of samples"));
        };
        let key = (s.fs_hz.to_bits(), t, nc);
        let cfg = AcqConfig {
            coherent_ms: t,
            noncoherent: nc,
            doppler_center_hz: 0.0,
            doppler_max_hz: self.opts.measure.doppler_max_hz,
            pfa: self.opts.measure.pfa,
            refine_ms: len_ms,
            ..AcqConfig::default()
        };
        let engine = match self.engines.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(v) => {
                v.insert(AcquisitionEngine::new(s.fs_hz, cfg.clone()).map_err(|e| e.to_string())?)
            }
        };
        acquire_snapshot(
            &s.samples,
            s.folded,
            &pred,
            engine,
            &cfg,
            self.opts.fe_offset_max_hz,
            &self.opts.measure,
        )
        .map_err(|e| e.to_string())
    }
}

/// Why a snapshot's samples cannot be searched at all, if so.
fn unusable(s: &Snapshot) -> Option<String> {
    if s.samples.is_empty() {
        return Some("too short: no samples".into());
    }
    if s.samples.len() < (s.fs_hz * 1e-3).ceil() as usize {
        return Some(format!(
            "too short: {:.2} ms of samples, need at least 1 ms",
            s.samples.len() as f64 / s.fs_hz * 1e3
        ));
    }
    let power: f64 = s.samples.iter().map(|x| f64::from(x.norm_sqr())).sum();
    if !(power > 0.0 && power.is_finite()) {
        return Some("all samples are zero".into());
    }
    None
}
