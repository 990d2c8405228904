//! The GPS L1 C/A signal simulator: scenario -> IF samples + truth files.
//!
//! The project's own test bench. Every sample of every satellite's signal comes from the
//! propagation model in [`geometry`] (light time, Earth rotation, satellite clock, ionosphere,
//! troposphere, receiver clock), evaluated once per code period and interpolated linearly in
//! between ([`signal`]); navigation data bits are real LNAV subframes built from the broadcast
//! ephemeris ([`gpsrx_nav::lnav::LnavEncoder`]); the noise is white Gaussian, seeded per block so
//! the same seed gives the same bytes on any number of threads.

pub mod clock;
pub mod geometry;
pub mod scenario;
pub mod signal;
pub mod trajectory;
pub mod truth;

use crate::error::SampleError;
use crate::format::SampleFormat;
use crate::sigmf::{write_sigmf_meta, SigmfMeta};
use crate::writer::create_writer;
use clock::ReceiverClock;
use geometry::{Environment, Observation, SlowTerms};
use gpsrx_dsp::constants::F_L1_HZ;
use gpsrx_dsp::nco::SinCosTable;
use gpsrx_dsp::{CaCode, Prn};
use gpsrx_nav::almanac::{toa_near, AlmanacSet};
use gpsrx_nav::ephemeris::{Ephemeris, HealthPolicy};
use gpsrx_nav::lnav::LnavEncoder;
use gpsrx_nav::rinex_nav::parse_rinex_nav;
use gpsrx_nav::time::GpsTime;
use num_complex::Complex32;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
pub use scenario::Scenario;
use std::path::{Path, PathBuf};
use std::time::Instant;
use trajectory::Trajectory;

/// Simulator errors.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scenario is invalid.
    #[error("scenario: {0}")]
    Scenario(String),
    /// A file could not be read or written.
    #[error("{}: {message}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// Navigation data problem.
    #[error("navigation data: {0}")]
    Nav(String),
    /// Writing samples failed.
    #[error(transparent)]
    Samples(#[from] SampleError),
}

/// One simulated satellite.
#[derive(Debug, Clone)]
pub struct SimSatellite {
    /// PRN.
    pub prn: Prn,
    /// The ephemeris used for both the orbit and the navigation message, quantised to the
    /// IS-GPS-200 LSBs so that what is transmitted is exactly what moves the satellite.
    pub ephemeris: Ephemeris,
    /// C/A code three times over.
    code3: Vec<i8>,
    /// Data bits (+1/-1) from the reference subframe boundary on.
    pub bits: Vec<i8>,
    /// Fixed C/N0, dB-Hz, or None for the elevation model.
    cn0_fixed_dbhz: Option<f64>,
    /// Outage windows (s since start) that block this satellite.
    blocked: Vec<(f64, f64)>,
    /// C/N0 ramps that apply to this satellite.
    fades: Vec<scenario::Fade>,
    /// Elevation at the start, degrees.
    pub start_elevation_deg: f64,
}

/// A prepared simulation.
#[derive(Debug)]
pub struct Simulator {
    /// The scenario.
    pub scenario: Scenario,
    /// The shared propagation environment.
    pub env: Environment,
    /// Simulated satellites.
    pub satellites: Vec<SimSatellite>,
    format: SampleFormat,
    fs_hz: f64,
    if_hz: f64,
    noise_sigma: f64,
    total_samples: u64,
    node_samples: usize,
    table: SinCosTable,
    nav_source: String,
}

/// What a run produced.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SimReport {
    /// The recording.
    pub data_path: PathBuf,
    /// Its SigMF metadata.
    pub meta_path: PathBuf,
    /// Receiver truth.
    pub truth_path: PathBuf,
    /// Per-satellite truth.
    pub truth_sv_path: PathBuf,
    /// Format name.
    pub format: String,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Samples written.
    pub samples: u64,
    /// Bytes written.
    pub bytes: u64,
    /// Samples that saturated the output format.
    pub clipped: u64,
    /// Recording length, s.
    pub duration_s: f64,
    /// Wall-clock time of the run, s.
    pub wall_s: f64,
    /// Recording length divided by wall time.
    pub realtime_factor: f64,
    /// (PRN, elevation at start in degrees, C/N0 at start in dB-Hz).
    pub satellites: Vec<(u8, f64, f64)>,
}

/// Nodes (code periods) per parallel work unit.
const NODES_PER_CHUNK: usize = 100;

impl Simulator {
    /// Prepares a scenario: reads the navigation data, selects satellites, builds their
    /// navigation messages.
    pub fn new(scenario: &Scenario, base_dir: &Path) -> Result<Self, SimError> {
        scenario.validate()?;
        let start = scenario.start_time()?;
        let (nav_text, nav_source) = scenario.nav_text(base_dir)?;
        let nav =
            parse_rinex_nav(&nav_text).map_err(|e| SimError::Nav(format!("{nav_source}: {e}")))?;
        let format = scenario.format()?;
        let fs_hz = scenario.output.fs_hz;
        let span = scenario.duration_s + 2.0;
        let trajectory =
            Trajectory::from_config(&scenario.receiver, base_dir, scenario.duration_s)?;
        let clock = ReceiverClock::with_random_walk_fm(
            scenario.clock.bias_s,
            scenario.clock.drift_s_s,
            scenario.clock.allan_deviation_1s,
            scenario.clock.random_walk_fm_h_m2,
            span,
            scenario.seed,
        );
        // Code chips and data bits are counted from a subframe boundary at least 12 s before the
        // start, so every signal in the recording (travel time < 0.1 s) comes after it.
        let early = start.add_seconds(-12.0);
        let sv_ref = GpsTime::new(early.week, (early.tow_s / 6.0).floor() * 6.0);
        let env = Environment {
            start,
            trajectory,
            clock,
            iono: if scenario.atmosphere.ionosphere {
                nav.iono
            } else {
                None
            },
            tropo: scenario.atmosphere.troposphere,
            sv_ref_s: sv_ref.diff_s(start),
        };
        // The almanac every satellite transmits (when asked for): all PRNs with an ephemeris
        // near the start, visible or not, referred to the 4096-s t_oa nearest the start.
        let almanac = scenario.satellites.almanac.then(|| {
            let ephs: Vec<Ephemeris> = Prn::all()
                .filter_map(|p| nav.select_with(p.get(), start, HealthPolicy::Ignore))
                .map(Ephemeris::quantized_to_icd)
                .collect();
            AlmanacSet::from_ephemerides(&ephs, toa_near(start))
        });
        let explicit = scenario.satellites.prns.clone();
        let mut satellites = Vec::new();
        for prn in Prn::all() {
            if let Some(list) = &explicit {
                if !list.contains(&prn.get()) {
                    continue;
                }
            }
            // The nearest valid ephemeris, healthy or not: an unhealthy satellite still transmits,
            // with its health bits set, and receivers must cope with that.
            let Some(eph) = nav.select_with(prn.get(), start, HealthPolicy::Ignore) else {
                if explicit.is_some() {
                    return Err(SimError::Scenario(format!(
                        "{prn} has no ephemeris within 4 h of {start:?} in {nav_source}"
                    )));
                }
                continue;
            };
            let eph = eph.quantized_to_icd();
            let slow = env.slow_terms(&eph, 0.0);
            let el_deg = slow.el_rad.to_degrees();
            let mask = if explicit.is_some() {
                0.0
            } else {
                scenario.satellites.elevation_mask_deg
            };
            if el_deg < mask {
                if explicit.is_some() {
                    return Err(SimError::Scenario(format!(
                        "{prn} is below the horizon ({el_deg:.1} deg) at the start: remove it from [satellites] prns"
                    )));
                }
                continue;
            }
            let bits = if scenario.satellites.nav_data {
                navigation_bits(
                    &eph,
                    &nav,
                    almanac.as_ref(),
                    sv_ref,
                    -env.sv_ref_s + scenario.duration_s + 6.0,
                )?
            } else {
                Vec::new()
            };
            let cn0_fixed_dbhz = scenario
                .satellites
                .cn0
                .iter()
                .find(|c| c.prn == prn.get())
                .map(|c| c.dbhz)
                .or(scenario.satellites.cn0_all_dbhz);
            let blocked = scenario
                .outages
                .iter()
                .filter(|o| o.prns.is_empty() || o.prns.contains(&prn.get()))
                .map(|o| (o.start_s, o.end_s))
                .collect();
            let fades = scenario
                .fades
                .iter()
                .filter(|f| f.prns.is_empty() || f.prns.contains(&prn.get()))
                .cloned()
                .collect();
            satellites.push(SimSatellite {
                prn,
                ephemeris: eph,
                code3: signal::triple_code(CaCode::new(prn).chips()),
                bits,
                cn0_fixed_dbhz,
                blocked,
                fades,
                start_elevation_deg: el_deg,
            });
        }
        if satellites.is_empty() {
            return Err(SimError::Scenario(format!(
                "no satellite with a valid ephemeris above the mask at {start:?}: is the start time within the nav file {nav_source}?"
            )));
        }
        let total_samples = (scenario.duration_s * fs_hz).round() as u64;
        Ok(Self {
            scenario: scenario.clone(),
            env,
            satellites,
            noise_sigma: scenario.noise_sigma()?,
            format,
            fs_hz,
            if_hz: scenario.output.if_hz,
            total_samples,
            node_samples: ((fs_hz * 1e-3).round() as usize).max(1),
            table: SinCosTable::new(12),
            nav_source,
        })
    }

    /// Total number of samples of the recording.
    pub fn total_samples(&self) -> u64 {
        self.total_samples
    }

    /// Length of the recording in receiver (sample) time, s: `total_samples / fs`.
    pub fn duration_s(&self) -> f64 {
        self.total_samples as f64 / self.fs_hz
    }

    /// The receiver's truth at receiver-clock time `t_rcv_s` (seconds since the first sample),
    /// as `truth.csv` gives it: the true time `t` solves `t + b(t) = t_rcv` (receiver clock bias
    /// `b`), and the result is the GPS time of week of `start + t` and the trajectory's state
    /// (ECEF position, velocity, acceleration) at `t`.
    pub fn receiver_truth(&self, t_rcv_s: f64) -> (f64, trajectory::RxState) {
        let t = self.env.clock.true_time(t_rcv_s);
        (
            self.env.start.add_seconds(t).tow_s,
            self.env.trajectory.state(t),
        )
    }

    /// Samples per parallel work unit.
    pub fn chunk_samples(&self) -> usize {
        self.node_samples * NODES_PER_CHUNK
    }

    /// Number of work units.
    pub fn chunk_count(&self) -> u64 {
        self.total_samples.div_ceil(self.chunk_samples() as u64)
    }

    /// C/N0 (dB-Hz) of a satellite at elevation `el_rad` and time `t_s` (its fixed value or
    /// the elevation model, plus its `[[fades]]`).
    pub fn cn0_dbhz(&self, sat: &SimSatellite, el_rad: f64, t_s: f64) -> f64 {
        let base = sat.cn0_fixed_dbhz.unwrap_or_else(|| {
            let s = &self.scenario.satellites;
            s.cn0_zenith_dbhz - s.cn0_horizon_loss_db * (1.0 - el_rad.max(0.0).sin())
        });
        base + sat.fades.iter().map(|f| f.db_at(t_s)).sum::<f64>()
    }

    /// Whether a satellite's signal is present at `t_s` (above the horizon, not blocked).
    pub fn signal_on(&self, sat: &SimSatellite, t_s: f64, el_rad: f64) -> bool {
        el_rad > 0.0 && !sat.blocked.iter().any(|&(a, b)| t_s >= a && t_s < b)
    }

    /// Signal amplitude per sample for a C/N0, in output units: complex noise of standard
    /// deviation sigma per component has N0 = 2 sigma^2 / fs, so C/N0 = A^2 fs / (2 sigma^2) for a
    /// complex exponential of amplitude A; a real carrier A cos() carries A^2 / 2.
    pub fn amplitude(&self, cn0_dbhz: f64) -> f32 {
        let cn0 = 10f64.powf(cn0_dbhz / 10.0);
        let a = self.noise_sigma * (2.0 * cn0 / self.fs_hz).sqrt();
        (if self.format.is_complex() {
            a
        } else {
            a * std::f64::consts::SQRT_2
        }) as f32
    }

    /// The signal of satellite `sat` at receiver time `t_s` (seconds since the first sample), at
    /// full precision.
    pub fn observe(&self, sat: &SimSatellite, t_s: f64) -> (Observation, SlowTerms) {
        let slow = self.env.slow_terms(&sat.ephemeris, t_s);
        (self.env.observe(&sat.ephemeris, t_s, &slow, 0.075, 4), slow)
    }

    /// Generates work unit `chunk` (samples `chunk * chunk_samples()` on) into `out`, in output
    /// units, before quantisation.
    pub fn generate_chunk(&self, chunk: u64, out: &mut Vec<Complex32>) {
        let c = self.chunk_samples();
        let first = chunk * c as u64;
        let n = (self.total_samples.saturating_sub(first)).min(c as u64) as usize;
        out.clear();
        out.resize(n, Complex32::new(0.0, 0.0));
        self.add_noise(chunk, out);
        let l = self.node_samples;
        let fs = self.fs_hz;
        let t_of = |idx: u64| idx as f64 / fs;
        let nodes = n.div_ceil(l);
        let mut obs: Vec<Observation> = Vec::with_capacity(nodes + 1);
        for sat in &self.satellites {
            let slow_a = self.env.slow_terms(&sat.ephemeris, t_of(first));
            let slow_b = self.env.slow_terms(&sat.ephemeris, t_of(first + c as u64));
            obs.clear();
            let mut tau = 0.075;
            for j in 0..=nodes {
                let slow = slow_a.lerp(&slow_b, (j * l) as f64 / c as f64);
                let o = self.env.observe(
                    &sat.ephemeris,
                    t_of(first + (j * l) as u64),
                    &slow,
                    tau,
                    if j == 0 { 4 } else { 2 },
                );
                tau = o.tau_s;
                obs.push(o);
            }
            for j in 0..nodes {
                let a = j * l;
                let b = (a + l).min(n);
                let t_node = t_of(first + a as u64);
                let slow = slow_a.lerp(&slow_b, a as f64 / c as f64);
                if !self.signal_on(sat, t_node, slow.el_rad) {
                    continue;
                }
                let amp = self.amplitude(self.cn0_dbhz(sat, slow.el_rad, t_node));
                let (o0, o1) = (&obs[j], &obs[j + 1]);
                let ramp = signal::PhaseRamp {
                    chips0: o0.chips,
                    chips_per_sample: (o1.chips - o0.chips) / l as f64,
                    cycles0: o0.carrier_cycles + self.if_hz * t_node,
                    cycles_per_sample: (o1.carrier_cycles - o0.carrier_cycles) / l as f64
                        + self.if_hz / fs,
                };
                signal::add_signal(
                    &mut out[a..b],
                    &ramp,
                    &sat.code3,
                    &sat.bits,
                    amp,
                    &self.table,
                );
            }
        }
    }

    fn add_noise(&self, chunk: u64, out: &mut [Complex32]) {
        // An independent stream per work unit: seed and chunk index mixed by SplitMix64 constants.
        let seed = self.scenario.seed ^ chunk.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let s = self.noise_sigma as f32;
        if self.format.is_complex() {
            for v in out.iter_mut() {
                let re: f32 = rng.sample(StandardNormal);
                let im: f32 = rng.sample(StandardNormal);
                *v = Complex32::new(s * re, s * im);
            }
        } else {
            for v in out.iter_mut() {
                let re: f32 = rng.sample(StandardNormal);
                *v = Complex32::new(s * re, 0.0);
            }
        }
    }

    /// Runs the simulation into `out_dir`: the recording `<name>.<ext>`, its `.sigmf-meta`,
    /// `truth.csv` and `truth_sv.csv`. `progress` is called with the fraction done.
    pub fn run(
        &self,
        out_dir: &Path,
        progress: &(dyn Fn(f64) + Sync),
    ) -> Result<SimReport, SimError> {
        let t0 = Instant::now();
        std::fs::create_dir_all(out_dir).map_err(|e| SimError::Io {
            path: out_dir.to_path_buf(),
            message: e.to_string(),
        })?;
        let data_path = out_dir.join(format!(
            "{}.{}",
            self.scenario.output.name,
            self.format.name()
        ));
        let mut writer = create_writer(&data_path, &self.format)?;
        let chunks = self.chunk_count();
        let batch = (rayon::current_num_threads() * 2) as u64;
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<Vec<Complex32>>>(1);
        let stats = std::thread::scope(|scope| -> Result<_, SimError> {
            let writer_thread = scope.spawn(move || -> Result<_, SimError> {
                for bufs in rx {
                    for b in &bufs {
                        writer.write(b)?;
                    }
                }
                Ok(writer.finish()?)
            });
            let mut next = 0u64;
            while next < chunks {
                let end = (next + batch).min(chunks);
                let bufs: Vec<Vec<Complex32>> = (next..end)
                    .into_par_iter()
                    .map(|ci| {
                        let mut v = Vec::new();
                        self.generate_chunk(ci, &mut v);
                        v
                    })
                    .collect();
                if tx.send(bufs).is_err() {
                    break; // the writer failed; its error is reported below
                }
                next = end;
                progress(next as f64 / chunks as f64);
            }
            drop(tx);
            writer_thread.join().map_err(|_| SimError::Io {
                path: data_path.clone(),
                message: "writer thread panicked".into(),
            })?
        })?;
        tracing::debug!(
            "samples generated and written in {:.2} s",
            t0.elapsed().as_secs_f64()
        );
        let meta = self.sigmf_meta();
        let meta_path = write_sigmf_meta(&data_path, &meta)?;
        let truth_path = out_dir.join("truth.csv");
        let truth_sv_path = out_dir.join("truth_sv.csv");
        truth::write_receiver_truth(self, &truth_path)?;
        truth::write_satellite_truth(self, &truth_sv_path)?;
        let wall_s = t0.elapsed().as_secs_f64();
        tracing::debug!("truth written, total {wall_s:.2} s");
        let duration_s = self.total_samples as f64 / self.fs_hz;
        let satellites = self
            .satellites
            .iter()
            .map(|s| {
                let (_, slow) = self.observe(s, 0.0);
                (
                    s.prn.get(),
                    slow.el_rad.to_degrees(),
                    self.cn0_dbhz(s, slow.el_rad, 0.0),
                )
            })
            .collect();
        Ok(SimReport {
            data_path,
            meta_path,
            truth_path,
            truth_sv_path,
            format: self.format.name(),
            fs_hz: self.fs_hz,
            samples: stats.samples_written,
            bytes: stats.bytes_written,
            clipped: stats.clipped,
            duration_s,
            wall_s,
            realtime_factor: duration_s / wall_s.max(1e-9),
            satellites,
        })
    }

    /// SigMF metadata describing the recording.
    pub fn sigmf_meta(&self) -> SigmfMeta {
        let mut extra = serde_json::Map::new();
        let start = self.env.start;
        extra.insert("gpsrx:start_gps_week".into(), start.week.into());
        extra.insert("gpsrx:start_tow_s".into(), start.tow_s.into());
        extra.insert("gpsrx:noise_sigma".into(), self.noise_sigma.into());
        extra.insert("gpsrx:nav".into(), self.nav_source.clone().into());
        SigmfMeta {
            datatype: self.format.name(),
            sample_rate_hz: self.fs_hz,
            frequency_hz: Some(F_L1_HZ - self.if_hz),
            if_hz: self.if_hz,
            invert_q: false,
            packed_map: match &self.format {
                SampleFormat::Packed2 { map, .. } => Some(*map),
                _ => None,
            },
            description: format!("gpsrx simulate: {}", self.scenario.description),
            // The scenario's start (GPS time of the first sample) in UTC, so a receiver dates
            // the recording as the simulation did.
            datetime: Some(crate::sigmf::format_datetime_utc(start)),
            capture_sample_start: 0,
            extra,
        }
    }
}

/// Builds the transmitted LNAV bit stream (+1/-1, logic 0 -> +1) of one satellite from `sv_ref`
/// on, covering at least `span_s` seconds, with `almanac` in subframes 4 and 5 when given.
fn navigation_bits(
    eph: &Ephemeris,
    nav: &gpsrx_nav::rinex_nav::NavData,
    almanac: Option<&AlmanacSet>,
    sv_ref: GpsTime,
    span_s: f64,
) -> Result<Vec<i8>, SimError> {
    let mut enc = LnavEncoder::new(eph, nav.iono.as_ref(), nav.utc.as_ref())
        .map_err(|e| SimError::Nav(format!("PRN {}: {e}", eph.prn)))?;
    if let Some(set) = almanac {
        enc = enc
            .with_almanac(set)
            .map_err(|e| SimError::Nav(format!("almanac sent by PRN {}: {e}", eph.prn)))?;
    }
    let subframes = (span_s / 6.0).ceil() as usize + 1;
    let mut bits = Vec::with_capacity(subframes * 300);
    for j in 0..subframes {
        let t = sv_ref.add_seconds(6.0 * j as f64);
        let tow = t.tow_s.round() as u32;
        for b in enc.subframe_bits(tow, t.week) {
            bits.push(1 - 2 * b as i8);
        }
    }
    Ok(bits)
}
