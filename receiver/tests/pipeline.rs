//! The receiver pipeline in memory: samples from the simulator pushed block by block in any
//! chunking, or read through a source, give the same fixes, and they land on the truth.

use gpsrx_nav::rinex_nav::parse_rinex_nav;
use gpsrx_receiver::pipeline::{MemorySink, ReceiverEvent, Sink};
use gpsrx_receiver::{Assistance, Receiver, ReceiverConfig};
use gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT;
use gpsrx_samples::sim::{Scenario, Simulator};
use gpsrx_samples::{IntegerFormat, IntegerSamplesMut, SampleError, SampleFormat, SampleSource};
use num_complex::Complex32;
use std::path::Path;

/// A static receiver near Daejeon, 2.048 MHz, the built-in broadcast ephemerides.
pub(crate) fn simulator(duration_s: f64) -> Simulator {
    simulator_with(duration_s, "")
}

/// [`simulator`] with more of the scenario (`extra`: TOML tables such as `[[outages]]`).
pub(crate) fn simulator_with(duration_s: f64, extra: &str) -> Simulator {
    let text = format!(
        r#"
duration_s = {duration_s}
seed = 7
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538198.0
[output]
format = "cf32_le"
fs_hz = 2.048e6
[receiver]
kind = "static"
llh_deg = [36.3721, 127.3604, 80.0]
[clock]
bias_s = 3.0e-4
drift_s_s = 4.0e-8
{extra}
"#
    );
    let sc = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
    Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// The simulator's samples as a source, read in reads of any size.
pub(crate) struct SimSource<'a> {
    sim: &'a Simulator,
    chunk: u64,
    buf: Vec<Complex32>,
    used: usize,
    next: u64,
    format: SampleFormat,
}

impl<'a> SimSource<'a> {
    pub(crate) fn new(sim: &'a Simulator) -> Self {
        Self {
            sim,
            chunk: 0,
            buf: Vec::new(),
            used: 0,
            next: 0,
            format: SampleFormat::Cf32Le,
        }
    }
}

impl SampleSource for SimSource<'_> {
    fn fs_hz(&self) -> f64 {
        2.048e6
    }
    fn format(&self) -> &SampleFormat {
        &self.format
    }
    fn total_samples(&self) -> Option<u64> {
        Some(self.sim.total_samples())
    }
    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let first = self.next;
        let mut n = 0;
        while n < out.len() {
            if self.used == self.buf.len() {
                if self.chunk >= self.sim.chunk_count() {
                    break;
                }
                self.sim.generate_chunk(self.chunk, &mut self.buf);
                self.chunk += 1;
                self.used = 0;
            }
            let k = (out.len() - n).min(self.buf.len() - self.used);
            out[n..n + k].copy_from_slice(&self.buf[self.used..self.used + k]);
            self.used += k;
            n += k;
        }
        self.next += n as u64;
        Ok((first, n))
    }
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}

/// A receiver with the built-in broadcast ephemerides as `--nav`, week 2190, no troposphere
/// model (the simulator has none).
pub(crate) fn receiver(fs_hz: f64) -> Receiver {
    receiver_with(fs_hz, |_| ())
}

/// [`receiver`] with its configuration changed by `edit` first.
pub(crate) fn receiver_with(fs_hz: f64, edit: impl FnOnce(&mut ReceiverConfig)) -> Receiver {
    let mut config = ReceiverConfig::default();
    // Without a troposphere model (the simulator applies one: it leaves 6-8 m vertically in
    // the fixes, within the bounds of the tests that take this default).
    config.run.tropo = gpsrx_receiver::config::TropoModel::None;
    config.run.week = Some(2190);
    edit(&mut config);
    let nav = parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}"));
    let assistance = Assistance {
        nav: Some(nav),
        ..Assistance::default()
    };
    Receiver::new(&config, fs_hz, assistance).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn pushed_blocks_of_any_size_give_the_fixes_of_a_source_run() {
    let sim = simulator(14.0);
    let fs = 2.048e6;
    // Run from a source.
    let mut by_run = MemorySink::new();
    let summary = receiver(fs)
        .run(&mut SimSource::new(&sim), &mut by_run)
        .unwrap_or_else(|e| panic!("{e}"));
    // Pushed in odd block sizes (a prime, and 1 ms + 1 sample).
    let mut pushed = [MemorySink::new(), MemorySink::new()];
    let mut rx = [receiver(fs), receiver(fs)];
    let sizes = [7919usize, 2049];
    let mut src = SimSource::new(&sim);
    let mut block = vec![Complex32::new(0.0, 0.0); 50_000];
    let mut pending: [Vec<Complex32>; 2] = [Vec::new(), Vec::new()];
    loop {
        let (_, n) = src.read(&mut block).unwrap_or_else(|e| panic!("{e}"));
        for k in 0..2 {
            pending[k].extend_from_slice(&block[..n]);
            let whole = pending[k].len() / sizes[k] * sizes[k];
            let take = if n == 0 { pending[k].len() } else { whole };
            for part in pending[k][..take].chunks(sizes[k]) {
                rx[k]
                    .push(part, &mut pushed[k])
                    .unwrap_or_else(|e| panic!("{e}"));
            }
            pending[k].drain(..take);
        }
        if n == 0 {
            break;
        }
    }
    for k in 0..2 {
        let s = rx[k]
            .finish(&mut pushed[k])
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.fixes, summary.fixes, "block size {}", sizes[k]);
        assert_eq!(s.tracked_prns, summary.tracked_prns);
        for (a, b) in pushed[k].fixes.iter().zip(&by_run.fixes) {
            assert_eq!(a.fix.ecef_m, b.fix.ecef_m, "block size {}", sizes[k]);
            assert_eq!(a.fix.time, b.fix.time);
        }
        assert_eq!(pushed[k].observables.len(), by_run.observables.len());
        assert_eq!(pushed[k].events, by_run.events);
    }
    // The fixes land on the truth (static antenna): within 3 m horizontally and 8.5 m
    // vertically, every one of them (this simulation's vertical error is a steady 6-8 m; the
    // fixes start at 3.3 s now, 1.2 s into the first subframe, the TLM and HOW confirmed
    // across satellites, with the ephemerides of the navigation file).
    assert!(summary.fixes > 10, "{} fixes", summary.fixes);
    let first = summary.first_fix_s.unwrap_or(f64::INFINITY);
    assert!(first < 6.0, "first fix at {first:.1} s");
    for (f, (h, v)) in by_run.fixes.iter().zip(fix_errors(&sim, &by_run)) {
        let (h_max, v_max) = fix_bounds();
        assert!(
            h < h_max && v < v_max,
            "fix at {:.1} s off by {h:.2} m horizontally, {v:.2} m vertically",
            f.t_stream_s
        );
    }
    // Every simulated satellite above the mask was acquired, and each was announced once.
    let acquired: Vec<u8> = by_run
        .events
        .iter()
        .filter_map(|e| match e {
            ReceiverEvent::Acquired { prn, .. } => Some(*prn),
            _ => None,
        })
        .collect();
    assert_eq!(
        acquired.len(),
        summary.tracked_prns.len() + summary.dropped_prns.len()
    );
    assert!(
        summary.tracked_prns.len() >= 6,
        "{:?}",
        summary.tracked_prns
    );
    assert!(by_run.end.is_some(), "the sink was not finished");
}

#[test]
fn a_source_at_another_rate_is_refused() {
    let sim = simulator(1.0);
    let mut rx = receiver(4.0e6);
    let err = rx
        .run(&mut SimSource::new(&sim), &mut MemorySink::new())
        .err()
        .unwrap_or_else(|| panic!("a 2.048 MHz source accepted by a 4 MHz receiver"));
    assert!(err.to_string().contains("2048000 Hz"), "{err}");
}

#[test]
fn a_stream_shorter_than_one_search_is_an_error_naming_it() {
    let mut rx = receiver(2.048e6);
    let mut sink = MemorySink::new();
    rx.push(&[Complex32::new(1.0, 0.0); 1000], &mut sink)
        .unwrap_or_else(|e| panic!("{e}"));
    let err = rx
        .finish(&mut sink)
        .err()
        .unwrap_or_else(|| panic!("1000 samples accepted"));
    assert!(err.to_string().contains("too short"), "{err}");
}

#[test]
fn non_finite_samples_read_as_zero_and_samples_after_the_end_are_refused() {
    let mut rx = receiver(2.048e6);
    let mut sink = MemorySink::new();
    let nan = Complex32::new(f32::NAN, f32::INFINITY);
    // Half a second of NaN and infinity: no panic, no satellite, no fix.
    for _ in 0..50 {
        rx.push(&[nan; 20_480], &mut sink)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    let summary = rx.finish(&mut sink).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        summary.tracked_prns.is_empty(),
        "{:?}",
        summary.tracked_prns
    );
    assert_eq!(summary.fixes, 0);
    let err = rx
        .push(&[Complex32::new(1.0, 0.0); 10], &mut sink)
        .err()
        .unwrap_or_else(|| panic!("samples accepted after finish"));
    assert!(err.to_string().contains("ended"), "{err}");
}

#[test]
fn an_invalid_configuration_names_the_setting() {
    let mut config = ReceiverConfig::default();
    config.run.rate_hz = 100.0;
    let err = Receiver::new(&config, 2.048e6, Assistance::default())
        .err()
        .unwrap_or_else(|| panic!("rate 100 Hz accepted"));
    assert!(
        err.to_string().contains("rate 100 Hz: use 1 to 50 Hz"),
        "{err}"
    );
    let err = ReceiverConfig::from_toml("[run]\nrate = 5\n", "test.toml")
        .err()
        .unwrap_or_else(|| panic!("unknown key accepted"));
    assert!(err.to_string().contains("rate"), "{err}");
}

#[test]
fn the_channel_manager_alone_finds_the_simulated_satellites_at_their_doppler() {
    use gpsrx_dsp::acquisition::AcqConfig;
    use gpsrx_receiver::pipeline::channels::{ChannelManager, SearchSettings};
    let sim = simulator(0.5);
    let fs = 2.048e6;
    let settings = SearchSettings {
        acq: AcqConfig::default(),
        weak_fallback: true,
        background: Some(gpsrx_receiver::pipeline::channels::SearchBudget::default()),
        prns: Vec::new(),
        cold_targets: None,
    };
    let mut manager = ChannelManager::new(fs, gpsrx_tracking::ChannelConfig::default(), settings)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut samples = vec![Complex32::new(0.0, 0.0); manager.cold_start_samples()];
    let (first, n) = SimSource::new(&sim)
        .read(&mut samples)
        .unwrap_or_else(|e| panic!("{e}"));
    let found = manager
        .cold_start(&samples[..n], first)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(found.len() >= 6, "{} found", found.len());
    assert_eq!(manager.channels().len(), found.len());
    for d in &found {
        // Truth Doppler: the rate of the simulated carrier phase at the middle of the search.
        let sat = sim
            .satellites
            .iter()
            .find(|s| s.prn == d.prn)
            .unwrap_or_else(|| panic!("{}: not simulated (a false acquisition)", d.prn));
        let t = n as f64 / fs / 2.0;
        let (a, _) = sim.observe(sat, t - 0.5e-3);
        let (b, _) = sim.observe(sat, t + 0.5e-3);
        let truth_hz = (b.carrier_cycles - a.carrier_cycles) / 1e-3;
        assert!(
            (d.doppler_hz - truth_hz).abs() < 100.0,
            "{}: Doppler {:.0} Hz, truth {truth_hz:.0} Hz",
            d.prn,
            d.doppler_hz
        );
    }
}

#[test]
fn the_navigation_processor_alone_and_the_file_sink_alone_reproduce_a_run() {
    use gpsrx_receiver::output::FileSink;
    use gpsrx_receiver::pipeline::navigation::NavigationProcessor;
    use gpsrx_receiver::pipeline::Tee;
    let sim = simulator(13.0);
    let fs = 2.048e6;
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    // A run writing files and keeping every channel report.
    let mut sink = Tee(
        FileSink::create(&dir.path().join("run"), 10.0).unwrap_or_else(|e| panic!("{e}")),
        MemorySink::new().with_channel_epochs(),
    );
    let summary = receiver(fs)
        .run(&mut SimSource::new(&sim), &mut sink)
        .unwrap_or_else(|e| panic!("{e}"));
    let Tee(_, memory) = sink;
    assert!(summary.fixes > 5, "{} fixes", summary.fixes);
    // The navigation processor on the recorded reports alone (no samples, no tracking) into a
    // second file sink: the same fixes and the same files.
    let mut config = ReceiverConfig::default();
    config.run.tropo = gpsrx_receiver::config::TropoModel::None;
    let nav = parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}"));
    let mut alone = NavigationProcessor::new(
        fs,
        config.run.clone(),
        config.tracking.cn0_lost_dbhz,
        2190,
        Some(nav),
        Vec::new(),
    );
    let mut replay = Tee(
        FileSink::create(&dir.path().join("replay"), 10.0).unwrap_or_else(|e| panic!("{e}")),
        MemorySink::new(),
    );
    for (i, e) in &memory.channel_epochs {
        alone
            .on_report(*i, e, None, None, &mut replay)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    replay
        .finish(&alone.end())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(replay.1.fixes.len(), memory.fixes.len());
    for (a, b) in replay.1.fixes.iter().zip(&memory.fixes) {
        assert_eq!(a.fix.ecef_m, b.fix.ecef_m);
    }
    for name in [
        "pvt.csv",
        "pvt.nmea",
        "channels.csv",
        "track.geojson",
        "track.kml",
    ] {
        let read = |d: &str| {
            std::fs::read(dir.path().join(d).join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
        };
        assert_eq!(read("run"), read("replay"), "{name} differs");
    }
}

#[test]
fn a_solution_with_a_fault_raim_cannot_exclude_is_never_a_valid_fix() {
    use gpsrx_nav::frames::{Llh, Vector3};
    use gpsrx_nav::pvt::{Landmark, RaimStatus};
    use gpsrx_receiver::landmarks::LandmarkObservation;
    use gpsrx_receiver::output::FixQuality;
    let sim = simulator(13.0);
    let (_, truth) = sim.receiver_truth(0.0);
    // A landmark 1 km east of the antenna whose range is 500 m too long, at every epoch: the
    // solver cannot exclude it (RAIM excludes satellites), so every solution that uses it
    // fails the test.
    let llh = Llh::from_ecef(&truth.pos_m);
    let east = Vector3::new(-llh.lon_rad.sin(), llh.lon_rad.cos(), 0.0);
    let at = truth.pos_m + 1000.0 * east;
    let landmarks: Vec<LandmarkObservation> = (0..140)
        .map(|k| LandmarkObservation {
            tow_s: 538198.0 + 0.1 * f64::from(k),
            landmark: Landmark {
                ecef_m: at,
                range_m: 1000.0 + 500.0,
                sigma_m: 1.0,
            },
        })
        .collect();
    let mut config = ReceiverConfig::default();
    config.run.tropo = gpsrx_receiver::config::TropoModel::None;
    config.run.week = Some(2190);
    let nav = parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}"));
    let assistance = Assistance {
        nav: Some(nav),
        landmarks,
        ..Assistance::default()
    };
    let mut rx = Receiver::new(&config, 2.048e6, assistance).unwrap_or_else(|e| panic!("{e}"));
    let mut sink = MemorySink::new();
    let summary = rx
        .run(&mut SimSource::new(&sim), &mut sink)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(summary.invalid_fixes > 0, "the fault was never detected");
    for f in &sink.fixes {
        let [x, y, z] = f.fix.ecef_m;
        let error_m = (Vector3::new(x, y, z) - truth.pos_m).norm();
        if f.fix.quality == FixQuality::None {
            assert_eq!(f.solution.raim, RaimStatus::FaultDetectedNotExcluded);
        } else {
            assert!(
                error_m < 10.0,
                "a fix {error_m:.1} m off handed out as valid (RAIM {:?})",
                f.solution.raim
            );
        }
    }
    assert_eq!(
        sink.fixes
            .iter()
            .filter(|f| f.fix.quality != FixQuality::None)
            .count(),
        summary.fixes
    );
}

#[test]
fn two_seconds_of_zeros_give_no_fix() {
    // A dropout: the front end delivers zeros from 13 to 15 s. Channels must see it as an
    // outage (their C/N0 estimate falls, the fade detector never takes "no power" as a new
    // level), so no fix comes from NCOs coasting through it.
    let sim = simulator(18.0);
    let fs = 2.048e6;
    let (a, b) = ((13.0 * fs) as u64, (15.0 * fs) as u64);
    let mut src = SimSource::new(&sim);
    let mut rx = receiver(fs);
    let mut sink = MemorySink::new();
    let mut block = vec![Complex32::new(0.0, 0.0); 20_480];
    loop {
        let (first, n) = src.read(&mut block).unwrap_or_else(|e| panic!("{e}"));
        if n == 0 {
            break;
        }
        for (k, s) in block[..n].iter_mut().enumerate() {
            if (a..b).contains(&(first + k as u64)) {
                *s = Complex32::new(0.0, 0.0);
            }
        }
        rx.push(&block[..n], &mut sink)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    rx.finish(&mut sink).unwrap_or_else(|e| panic!("{e}"));
    let before = sink.fixes.iter().filter(|f| f.t_stream_s < 13.0).count();
    assert!(before > 10, "{before} fixes before the dropout");
    let during: Vec<f64> = sink
        .fixes
        .iter()
        .filter(|f| f.fix.quality != gpsrx_receiver::output::FixQuality::None)
        .map(|f| f.t_stream_s)
        .filter(|t| (13.1..=15.0).contains(t))
        .collect();
    assert!(during.is_empty(), "fixes from zeros at {during:?} s");
}

/// A receiver like [`receiver`] aided by `ins` (None: unaided).
fn aided_receiver(fs_hz: f64, ins: Option<gpsrx_ins_aiding::InsTrack>) -> Receiver {
    let mut config = ReceiverConfig::default();
    config.run.tropo = gpsrx_receiver::config::TropoModel::None;
    config.run.week = Some(2190);
    // The built-in navigation file flags a satellite unhealthy (a flag the simulator copies):
    // aid it too.
    config.run.allow_unhealthy = true;
    let nav = parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}"));
    let assistance = Assistance {
        nav: Some(nav),
        ins: ins.map(|track| gpsrx_receiver::pipeline::InsAiding {
            track,
            band_limit_rad_s: None,
        }),
        ..Assistance::default()
    };
    Receiver::new(&config, fs_hz, assistance).unwrap_or_else(|e| panic!("{e}"))
}

/// The simulator's truth as a 10 Hz INS (GPS time column included) whose velocity is off by
/// `dv_ecef` m/s (the position is the truth's).
fn ins_with_velocity_error(sim: &Simulator, dv_ecef: [f64; 3]) -> gpsrx_ins_aiding::InsTrack {
    let n = (sim.duration_s() * 10.0).floor() as usize;
    let samples = (0..=n)
        .map(|k| {
            let t_s = k as f64 / 10.0;
            let (tow, s) = sim.receiver_truth(t_s);
            gpsrx_ins_aiding::InsSample {
                t_s,
                gps_tow_s: Some(tow),
                pos_m: s.pos_m,
                vel_mps: s.vel_mps + gpsrx_nav::frames::Vector3::from(dv_ecef),
            }
        })
        .collect();
    gpsrx_ins_aiding::InsTrack::from_samples(samples).unwrap_or_else(|e| panic!("{e}"))
}

/// Horizontal and vertical error (m) of every fix against the static truth.
/// Horizontal and vertical error bounds of a fix, m: this simulation's vertical error is a
/// steady 6-8 m from 3 s on (measured with the fixes from 3.3 s: 6.0-8.0 m).
fn fix_bounds() -> (f64, f64) {
    (3.0, 8.5)
}

fn fix_errors(sim: &Simulator, sink: &MemorySink) -> Vec<(f64, f64)> {
    let (_, truth) = sim.receiver_truth(0.0);
    sink.fixes
        .iter()
        .map(|f| {
            let r = gpsrx_nav::frames::enu_rotation(&f.fix.llh);
            let d = gpsrx_nav::frames::Vector3::new(
                f.fix.ecef_m[0] - truth.pos_m.x,
                f.fix.ecef_m[1] - truth.pos_m.y,
                f.fix.ecef_m[2] - truth.pos_m.z,
            );
            let enu = r * d;
            (enu.x.hypot(enu.y), enu.z.abs())
        })
        .collect()
}

/// Issue 13, never a silent wrong fix: an INS whose velocity is 50 m/s off on a static antenna
/// (250 Hz of feed-forward error at most, different on every satellite) is caught by the
/// integrity monitor before its aid reaches any loop, and the run gives the fixes of an unaided
/// run (same first fix, same count, on the truth). A perfect INS is admitted and aids the
/// loops for nearly all the run, never rejected.
#[test]
fn an_ins_50_mps_off_is_rejected_before_it_aids_and_the_fixes_are_the_unaided_ones() {
    let sim = simulator(14.0);
    let fs = 2.048e6;
    let run = |ins: Option<gpsrx_ins_aiding::InsTrack>| {
        let mut sink = MemorySink::new().with_channel_epochs();
        let summary = aided_receiver(fs, ins)
            .run(&mut SimSource::new(&sim), &mut sink)
            .unwrap_or_else(|e| panic!("{e}"));
        (summary, sink)
    };
    let (plain, plain_sink) = run(None);
    let (bad, bad_sink) = run(Some(ins_with_velocity_error(&sim, [50.0, 0.0, 0.0])));
    let (good, good_sink) = run(Some(ins_with_velocity_error(&sim, [0.0; 3])));
    let aiding =
        |s: &gpsrx_receiver::RunSummary| s.ins_aiding.unwrap_or_else(|| panic!("no INS summary"));
    eprintln!(
        "unaided: {} fixes, first {:?}; INS 50 m/s off: {} fixes, first {:?}, {:?}; perfect INS: {} fixes, first {:?}, {:?}",
        plain.fixes, plain.first_fix_s, bad.fixes, bad.first_fix_s, aiding(&bad), good.fixes,
        good.first_fix_s, aiding(&good)
    );
    assert!(plain.ins_aiding.is_none(), "no INS, no INS summary");

    // The wrong INS: rejected, and no loop ever got its feed-forward.
    let b = aiding(&bad);
    assert!(b.rejections >= 1, "the wrong INS was not rejected: {b:?}");
    assert_eq!(b.admissions, 0, "the wrong INS was admitted: {b:?}");
    assert_eq!(b.aided_s, 0.0, "{b:?}");
    let fed = bad_sink
        .channel_epochs
        .iter()
        .filter(|(_, e)| e.feedforward_hz.is_some())
        .count();
    assert_eq!(fed, 0, "{fed} channel epochs fed forward by the wrong INS");
    // ... and the fixes are those of the unaided run.
    let first = |s: &gpsrx_receiver::RunSummary| s.first_fix_s.unwrap_or(f64::INFINITY);
    assert!(plain.fixes > 10, "unaided: {} fixes", plain.fixes);
    assert!(
        (first(&bad) - first(&plain)).abs() <= 1.0,
        "first fix {:?} vs {:?} unaided",
        bad.first_fix_s,
        plain.first_fix_s
    );
    assert!(
        bad.fixes + 10 >= plain.fixes,
        "{} fixes vs {} unaided",
        bad.fixes,
        plain.fixes
    );
    for (f, (h, v)) in bad_sink.fixes.iter().zip(fix_errors(&sim, &bad_sink)) {
        let (h_max, v_max) = fix_bounds();
        assert!(
            h < h_max && v < v_max,
            "fix at {:.1} s off by {h:.2} m horizontally, {v:.2} m vertically",
            f.t_stream_s
        );
    }

    // The perfect INS: admitted within 2 s of the start, never rejected, aiding the rest; the
    // same fixes.
    let g = aiding(&good);
    assert_eq!(g.rejections, 0, "a perfect INS was rejected: {g:?}");
    assert!(g.aided_s > good.duration_s - 2.0, "{g:?}");
    let fed = good_sink
        .channel_epochs
        .iter()
        .filter(|(_, e)| e.t_rx_s > 3.0 && e.feedforward_hz.is_some())
        .count();
    let all = good_sink
        .channel_epochs
        .iter()
        .filter(|(_, e)| e.t_rx_s > 3.0 && e.pll_lock)
        .count();
    assert!(
        fed as f64 > 0.95 * all as f64,
        "{fed} of {all} locked epochs after 3 s fed forward"
    );
    assert!((first(&good) - first(&plain)).abs() <= 1.0);
    assert!(good.fixes + 10 >= plain.fixes);
    for (h, v) in fix_errors(&sim, &good_sink) {
        let (h_max, v_max) = fix_bounds();
        assert!(
            h < h_max && v < v_max,
            "fix off by {h:.2} m horizontally, {v:.2} m vertically"
        );
    }
    let rms = |sink: &MemorySink| {
        let e = fix_errors(&sim, sink);
        (e.iter().map(|(h, v)| h * h + v * v).sum::<f64>() / e.len().max(1) as f64).sqrt()
    };
    let (rp, rb, rg) = (rms(&plain_sink), rms(&bad_sink), rms(&good_sink));
    eprintln!(
        "3D RMS fix error: unaided {rp:.2} m, INS 50 m/s off {rb:.2} m, perfect INS {rg:.2} m"
    );
    assert!(rb < rp + 0.5, "{rb} m vs {rp} m unaided");
}

/// The simulator's samples quantised to ci8 (about 20 LSB rms) or ci16 (about 500 LSB rms),
/// offered either as stored (`read_integer`: the window holds them and the correlators read
/// them in place) or only through `read` as complex f32.
struct IntSource<'a> {
    inner: SimSource<'a>,
    format: IntegerFormat,
    offer_integers: bool,
    scale: f32,
    buf: Vec<Complex32>,
}

impl<'a> IntSource<'a> {
    fn new(sim: &'a Simulator, format: IntegerFormat, offer_integers: bool) -> Self {
        let mut first = Vec::new();
        sim.generate_chunk(0, &mut first);
        let power = first.iter().map(|c| c.norm_sqr()).sum::<f32>() / first.len() as f32;
        let rms = match format {
            IntegerFormat::Ci8 => 20.0,
            IntegerFormat::Ci16 => 500.0,
        };
        Self {
            inner: SimSource::new(sim),
            format,
            offer_integers,
            scale: rms / power.sqrt(),
            buf: Vec::new(),
        }
    }

    fn quantise(&self, x: f32) -> i16 {
        let max = match self.format {
            IntegerFormat::Ci8 => 127.0,
            IntegerFormat::Ci16 => 32767.0,
        };
        (x * self.scale).round().clamp(-max, max) as i16
    }
}

impl SampleSource for IntSource<'_> {
    fn fs_hz(&self) -> f64 {
        self.inner.fs_hz()
    }
    fn format(&self) -> &SampleFormat {
        match self.format {
            IntegerFormat::Ci8 => &SampleFormat::Ci8,
            IntegerFormat::Ci16 => &SampleFormat::Ci16Le,
        }
    }
    fn total_samples(&self) -> Option<u64> {
        self.inner.total_samples()
    }
    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        let (first, n) = self.inner.read(out)?;
        for o in &mut out[..n] {
            *o = Complex32::new(
                f32::from(self.quantise(o.re)),
                f32::from(self.quantise(o.im)),
            );
        }
        Ok((first, n))
    }
    fn integer_format(&self) -> Option<IntegerFormat> {
        self.offer_integers.then_some(self.format)
    }
    fn read_integer(&mut self, out: IntegerSamplesMut<'_>) -> Result<(u64, usize), SampleError> {
        if out.format() != self.format {
            return Err(SampleError::NoIntegerRead {
                asked: out.format(),
            });
        }
        let mut buf = std::mem::take(&mut self.buf);
        buf.resize(
            match &out {
                IntegerSamplesMut::Ci8(o) => o.len(),
                IntegerSamplesMut::Ci16(o) => o.len(),
            },
            Complex32::new(0.0, 0.0),
        );
        let (first, n) = self.inner.read(&mut buf)?;
        let q = |c: &Complex32| [self.quantise(c.re), self.quantise(c.im)];
        match out {
            IntegerSamplesMut::Ci8(out) => {
                for (o, c) in out.iter_mut().zip(&buf[..n]) {
                    // Within -127..=127 for ci8 (quantise clamps).
                    *o = q(c).map(|v| v as i8);
                }
            }
            IntegerSamplesMut::Ci16(out) => {
                for (o, c) in out.iter_mut().zip(&buf[..n]) {
                    *o = q(c);
                }
            }
        }
        self.buf = buf;
        Ok((first, n))
    }
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}

/// A run of the 8 s recording as integer samples of `format` at 2.048 MHz: offered to the
/// receiver as stored (`offer_integers`) or converted to f32 first, with the correlator
/// `arithmetic`.
fn run_held(
    sim: &Simulator,
    format: IntegerFormat,
    offer_integers: bool,
    arithmetic: gpsrx_tracking::CorrelatorArithmetic,
) -> (gpsrx_receiver::RunSummary, MemorySink) {
    let mut sink = MemorySink::new();
    let summary = receiver_with(2.048e6, |c| c.tracking.correlator_arithmetic = arithmetic)
        .run(&mut IntSource::new(sim, format, offer_integers), &mut sink)
        .unwrap_or_else(|e| panic!("{e}"));
    (summary, sink)
}

/// Two runs of the same samples give the same events and fixes, the fixes within `tol_m`.
fn assert_same_fixes(
    (a, sa): (&gpsrx_receiver::RunSummary, &MemorySink),
    (b, sb): (&gpsrx_receiver::RunSummary, &MemorySink),
    tol_m: f64,
) {
    assert_eq!(a.fixes, b.fixes);
    assert_eq!(a.tracked_prns, b.tracked_prns);
    assert_eq!(sa.events, sb.events);
    for (x, y) in sa.fixes.iter().zip(&sb.fixes) {
        assert_eq!(x.t_stream_s, y.t_stream_s);
        assert!((x.fix.time.tow_s - y.fix.time.tow_s).abs() < 1e-9);
        let d: f64 = (0..3)
            .map(|i| (x.fix.ecef_m[i] - y.fix.ecef_m[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(d < tol_m, "fixes {d} m apart at {:.1} s", x.t_stream_s);
    }
}

#[test]
fn ci8_samples_held_as_stored_give_the_fixes_of_the_same_samples_in_f32() {
    use gpsrx_tracking::CorrelatorArithmetic;
    let sim = simulator(8.0);
    let run = |offer, arithmetic| run_held(&sim, IntegerFormat::Ci8, offer, arithmetic);
    let (a, as_f32) = run(false, CorrelatorArithmetic::F32);
    // The same f32 kernel on the ci8 held as stored: the same sums in another lane order.
    let (b, as_stored) = run(true, CorrelatorArithmetic::F32);
    // The default: the int16 kernel on ci8 (products rounded to 2^-7 sample, carrier within
    // 4.1e-4): the same fixes to a few centimetres, far below their metre-level noise.
    let (c, as_i16) = run(true, CorrelatorArithmetic::Auto);
    assert!(a.fixes > 5, "{} fixes", a.fixes);
    assert_same_fixes((&a, &as_f32), (&b, &as_stored), 1e-3);
    assert_same_fixes((&a, &as_f32), (&c, &as_i16), 0.25);
    for (f, (h, v)) in as_i16.fixes.iter().zip(fix_errors(&sim, &as_i16)) {
        let (h_max, v_max) = fix_bounds();
        assert!(
            h < h_max && v < v_max,
            "fix at {:.1} s off by {h:.2} / {v:.2} m",
            f.t_stream_s
        );
    }
}

#[test]
fn ci16_samples_held_as_stored_give_the_fixes_of_the_same_samples_in_f32() {
    // The default (auto) runs the int16-lane kernel on ci16 blocks (products rounded to
    // 2^-sh sample with sh the block's headroom, carrier within 4.1e-4): the same events, the
    // same fixes to a few centimetres, as the f32 kernel on the same samples read as f32.
    use gpsrx_tracking::CorrelatorArithmetic;
    let sim = simulator(8.0);
    let run = |offer, arithmetic| run_held(&sim, IntegerFormat::Ci16, offer, arithmetic);
    let (a, as_f32) = run(false, CorrelatorArithmetic::F32);
    let (b, as_i16) = run(true, CorrelatorArithmetic::Auto);
    assert!(a.fixes > 5, "{} fixes", a.fixes);
    assert_same_fixes((&a, &as_f32), (&b, &as_i16), 0.25);
}

/// A source that hands every sample over as f32 (`read`), never as integers: the f32 path of
/// whatever it wraps.
struct F32Only(Box<dyn SampleSource>);

impl SampleSource for F32Only {
    fn fs_hz(&self) -> f64 {
        self.0.fs_hz()
    }
    fn format(&self) -> &SampleFormat {
        self.0.format()
    }
    fn total_samples(&self) -> Option<u64> {
        self.0.total_samples()
    }
    fn read(&mut self, out: &mut [Complex32]) -> Result<(u64, usize), SampleError> {
        self.0.read(out)
    }
    fn warnings(&self) -> Vec<String> {
        self.0.warnings()
    }
}

/// A cu8 recording (RTL-SDR offset binary, zero 127.5) is held as ci16, `2 code - 255`, and
/// correlated by the int16 kernel: the same events and the same fixes to a few centimetres as
/// the f32 path on the same file (read as `code - 127.5`, f32 kernel), on the truth.
#[test]
fn cu8_recordings_held_as_ci16_give_the_fixes_of_the_f32_path() {
    use gpsrx_samples::{open_source, SourceConfig};
    use gpsrx_tracking::CorrelatorArithmetic;
    let sim = simulator(8.0);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("sim.cu8");
    let format = SampleFormat::Cu8 { zero: 127.5 };
    let mut src = SimSource::new(&sim);
    let mut first = Vec::new();
    sim.generate_chunk(0, &mut first);
    let rms = (first.iter().map(|c| c.norm_sqr()).sum::<f32>() / first.len() as f32).sqrt();
    let mut w = gpsrx_samples::writer::create_writer(&path, &format).expect("writer");
    let mut buf = vec![Complex32::new(0.0, 0.0); 1 << 16];
    loop {
        let (_, n) = src.read(&mut buf).expect("simulate");
        if n == 0 {
            break;
        }
        let scaled: Vec<Complex32> = buf[..n].iter().map(|c| c * (20.0 / rms)).collect();
        w.write(&scaled).expect("write");
    }
    w.finish().expect("finish");
    let cfg = SourceConfig::new(&path)
        .with_format(format)
        .with_fs_hz(2.048e6);
    let run = |source: &mut dyn SampleSource, arithmetic| {
        let mut sink = MemorySink::new();
        let summary = receiver_with(2.048e6, |c| c.tracking.correlator_arithmetic = arithmetic)
            .run(source, &mut sink)
            .unwrap_or_else(|e| panic!("{e}"));
        (summary, sink)
    };
    let mut held = open_source(&cfg).expect("open");
    assert_eq!(held.integer_format(), Some(IntegerFormat::Ci16));
    assert_eq!(held.integer_gain(), 2.0);
    let (a, as_f32) = run(
        &mut F32Only(open_source(&cfg).expect("open")),
        CorrelatorArithmetic::F32,
    );
    let (b, as_i16) = run(held.as_mut(), CorrelatorArithmetic::Auto);
    assert!(a.fixes > 5, "{} fixes", a.fixes);
    assert_same_fixes((&a, &as_f32), (&b, &as_i16), 0.25);
    for (f, (h, v)) in as_i16.fixes.iter().zip(fix_errors(&sim, &as_i16)) {
        let (h_max, v_max) = fix_bounds();
        assert!(
            h < h_max && v < v_max,
            "fix at {:.1} s off by {h:.2} / {v:.2} m",
            f.t_stream_s
        );
    }
}

/// `Receiver::run` works a round of the channels while the navigation processor takes the
/// reports of the round before, and works it again when the end of block asks for something
/// (here the collapse of 2 s of zeros, the channels lost and the searches after it): the
/// fixes, observables and events are those of the same run whose rounds wait for the
/// navigation.
#[test]
fn a_run_whose_rounds_overlap_the_navigation_gives_what_waiting_rounds_give_through_an_outage() {
    // Outages starting at several phases of the 40 ms rounds and 0.1 s search ticks: the
    // channels are lost, and searched again, in different rounds.
    for start_s in [8.0, 8.025, 8.05, 8.075] {
        overlapped_run_matches_waiting_run(start_s);
    }
}

/// [`a_run_whose_rounds_overlap_the_navigation_gives_what_waiting_rounds_give_through_an_outage`]
/// with every signal blocked for 2 s from `start_s`.
fn overlapped_run_matches_waiting_run(start_s: f64) {
    let fs = 2.048e6;
    let outage = format!(
        "[[outages]]\nstart_s = {start_s}\nend_s = {}\n",
        start_s + 2.0
    );
    let sim = simulator_with(14.0, &outage);
    let run = |overlap: bool| {
        let mut rx = receiver(fs);
        rx.set_overlap(overlap);
        let mut sink = MemorySink::new();
        let summary = rx
            .run(&mut SimSource::new(&sim), &mut sink)
            .unwrap_or_else(|e| panic!("{e}"));
        (summary, sink)
    };
    let (summary, by_run) = run(true);
    let p = summary.profile;
    assert!(p.overlapped_rounds > 200, "{p:?}");
    assert!(p.redone_rounds >= 1, "no round worked again: {p:?}");
    let (s, waiting) = run(false);
    assert_eq!(s.profile.overlapped_rounds, 0);
    let fixes = |s: &gpsrx_receiver::RunSummary| (s.fixes, s.invalid_fixes);
    assert_eq!(fixes(&s), fixes(&summary), "outage from {start_s} s");
    assert!(summary.fixes > 10, "{} fixes", summary.fixes);
    for (a, b) in waiting.fixes.iter().zip(&by_run.fixes) {
        let at = |f: &gpsrx_receiver::pipeline::FixReport| (f.fix.ecef_m, f.fix.time);
        assert_eq!(at(a), at(b), "outage from {start_s} s");
    }
    assert_eq!(waiting.observables.len(), by_run.observables.len());
    assert_eq!(waiting.events, by_run.events, "outage from {start_s} s");
    // The outage was seen: channels lost and found again after it.
    let acquired_after = by_run
        .events
        .iter()
        .filter(|e| matches!(e, ReceiverEvent::Acquired { t_s, .. } if *t_s > start_s))
        .count();
    assert!(acquired_after > 0, "{:?}", by_run.events);
}
