//! `gpsrx bench`: how fast this machine runs the receiver.
//!
//! Every figure comes with the CPU model, the instruction sets detected and the kernel that
//! produced it. `--correlator avx2` limits the kernels to AVX2 and runs the end-to-end cases
//! with it; `--correlators-only` times the kernels alone.
//!
//! Three measurements, each of the code the receiver runs:
//! - correlator throughput, Msamples/s on one core, for every kernel this CPU runs
//!   ([`Correlator::available`]: ISA x arithmetic), input format (ci8, ci16, cf32; cu8, ri8 and
//!   ri16 as the receiver holds them: converted to ci16 when read) and tap count
//!   (1, 3, 5): 1 ms blocks at 4 MHz (4000 samples), code and carrier generated inside the
//!   kernel, as tracking calls it; the best of many 5 ms stretches (the least disturbed by
//!   other processes); with the kernel `auto` (the default) takes per format;
//! - the wall time of a 32-PRN cold search (1 ms coherent x 10 non-coherent, +-5 kHz) at
//!   4 MHz with [`AcquisitionEngine`] on every core, on simulated samples: the median of a
//!   few runs;
//! - the end-to-end real-time factor: the built-in 4 MHz ci8 12-satellite scenario
//!   (`samples/scenarios/static-seoul-4msps.toml`) simulated into a temporary directory, then
//!   [`Receiver::run`] (what `gpsrx run` does) timed from file to fixes, with the peak resident
//!   memory of that run (`VmHWM` after resetting it through `/proc/self/clear_refs`);
//! - the same for a weak-signal case (`samples/scenarios/weak-mix-2p6msps.toml`: 8 satellites
//!   from 45 down to 28 dB-Hz at 2.6 MHz, 1.5 times the duration), where the background search
//!   for the weak satellites runs beside the tracking.

use crate::commands::simulate::simulate;
use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine};
use gpsrx_dsp::ca_code::CaCode;
use gpsrx_dsp::constants::{CA_CHIP_RATE_HZ, F_L1_HZ};
use gpsrx_dsp::correlator::{
    correlate, Arithmetic, Correlator, Isa, PackedCode, ReplicaState, SampleSlice,
};
use gpsrx_dsp::Prn;
use gpsrx_receiver::output::FileSink;
use gpsrx_receiver::{Assistance, Receiver};
use gpsrx_samples::format::SampleFormat;
use gpsrx_samples::mixer::Mixer;
use gpsrx_samples::sim::scenario::ReceiverConfig;
use gpsrx_samples::sim::Scenario;
use gpsrx_samples::{held_gain, open_source, quantize_to_ci16, SourceConfig};
use gpsrx_tracking::{CorrelatorChoice, CorrelatorIsa};
use num_complex::Complex32;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::hint::black_box;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

pub use crate::cli::BenchArgs;

/// The end-to-end scenario: 60 s, 4 MHz ci8, 12 satellites over Seoul.
const SEOUL_SCENARIO_TOML: &str =
    include_str!("../../../samples/scenarios/static-seoul-4msps.toml");

/// The weak-signal end-to-end scenario: 90 s, 2.6 MHz ci8, 8 satellites at 45-28 dB-Hz.
const WEAK_SCENARIO_TOML: &str = include_str!("../../../samples/scenarios/weak-mix-2p6msps.toml");

/// Sampling rate of the correlator and acquisition measurements, Hz.
const BENCH_FS_HZ: f64 = 4.0e6;

/// Samples per correlator call: one code period at 4 MHz.
const BLOCK_SAMPLES: usize = 4000;

/// Tap sets measured: prompt; early/prompt/late; very early to very late.
const TAP_SETS: [&[f64]; 3] = [&[0.0], &[-0.5, 0.0, 0.5], &[-1.0, -0.5, 0.0, 0.5, 1.0]];

/// One correlator measurement.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CorrelatorRow {
    /// `scalar`, `avx2+fma` or `avx512`.
    pub isa: String,
    /// `f32` or `i16`.
    pub arithmetic: String,
    /// The kernel's name, e.g. `avx512/i16`.
    pub kernel: String,
    /// The kernel that ran on this format, e.g. `avx2+fma/i16 (16 lanes)` (an i16
    /// correlator runs the f32 kernel on cf32).
    pub runs: String,
    /// Input format: `ci8`, `ci16`, `cf32`, or `cu8`, `ri8`, `ri16` (held as ci16).
    pub format: String,
    /// Correlator taps accumulated in one pass.
    pub taps: usize,
    /// Input samples per second on one core, millions.
    pub msps_per_core: f64,
}

/// The kernel `auto` (the default correlator, `--correlator` ceiling applied) runs on one
/// input format at the benchmark's rate.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AutoChoice {
    /// Input format, as in [`CorrelatorRow::format`].
    pub format: String,
    /// The kernel (a `kernel` of the correlator rows), e.g. `avx512/i16`.
    pub kernel: String,
    /// What runs, e.g. `avx512/i16 (32 lanes)` (the `runs` of that row).
    pub runs: String,
}

/// The acquisition measurement.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AcquisitionBench {
    /// PRNs searched.
    pub prns: usize,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Coherent integration, ms.
    pub coherent_ms: u32,
    /// Non-coherent sums.
    pub noncoherent: u32,
    /// Doppler half-width, Hz.
    pub doppler_max_hz: f64,
    /// Timed runs.
    pub runs: usize,
    /// Wall time of every run, ms.
    pub runs_ms: Vec<f64>,
    /// Satellites detected (the simulated recording has 12).
    pub detected: usize,
    /// Rayon threads the search ran on.
    pub threads: usize,
}

/// The end-to-end measurement.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EndToEnd {
    /// Recording length, s.
    pub duration_s: f64,
    /// Sampling rate, Hz.
    pub fs_hz: f64,
    /// Sample format of the file.
    pub format: String,
    /// Satellites in the simulation.
    pub satellites_simulated: usize,
    /// Satellites the receiver tracked.
    pub satellites_tracked: usize,
    /// Wall time from opening the file to the last output written, s.
    pub wall_s: f64,
    /// Recording seconds per wall second.
    pub realtime_factor: f64,
    /// Position fixes.
    pub fixes: usize,
    /// Horizontal distance of the mean fix from the simulated antenna, m (None: no fix).
    pub mean_horizontal_error_m: Option<f64>,
    /// Peak resident memory during the run, MB (None where /proc is missing).
    pub peak_rss_mb: Option<f64>,
    /// Whether the peak could be reset before the run (else it includes the simulation).
    pub peak_rss_reset: bool,
    /// Wall time of the simulation (not part of the run), s.
    pub simulate_s: f64,
    /// The tracking channels' correlator and the kernel it runs per block format.
    pub correlator: String,
}

/// The instruction sets this CPU reports (what the kernels can use).
#[derive(Debug, Clone, serde::Serialize)]
pub struct CpuFeatures {
    /// AVX2.
    pub avx2: bool,
    /// FMA.
    pub fma: bool,
    /// AVX-512 F.
    pub avx512f: bool,
    /// AVX-512 BW.
    pub avx512bw: bool,
}

impl CpuFeatures {
    fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            Self {
                avx2: is_x86_feature_detected!("avx2"),
                fma: is_x86_feature_detected!("fma"),
                avx512f: is_x86_feature_detected!("avx512f"),
                avx512bw: is_x86_feature_detected!("avx512bw"),
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Self {
                avx2: false,
                fma: false,
                avx512f: false,
                avx512bw: false,
            }
        }
    }

    /// E.g. `AVX2 FMA AVX-512F AVX-512BW`, or `none of AVX2, FMA, AVX-512`.
    fn describe(&self) -> String {
        let names: Vec<&str> = [
            (self.avx2, "AVX2"),
            (self.fma, "FMA"),
            (self.avx512f, "AVX-512F"),
            (self.avx512bw, "AVX-512BW"),
        ]
        .into_iter()
        .filter_map(|(on, n)| on.then_some(n))
        .collect();
        if names.is_empty() {
            "none of AVX2, FMA, AVX-512".into()
        } else {
            names.join(" ")
        }
    }
}

/// Everything `gpsrx bench` measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BenchReport {
    /// The CPU (`model name` of /proc/cpuinfo).
    pub cpu: String,
    /// The instruction sets detected.
    pub cpu_features: CpuFeatures,
    /// The correlator ceiling of this run (`--correlator`; `auto` without it).
    pub correlator_ceiling: String,
    /// Logical cores the rayon pool uses.
    pub threads: usize,
    /// Correlator throughput per kernel, format and tap count.
    pub correlators: Vec<CorrelatorRow>,
    /// The kernel `auto` takes per format (one of the rows of `correlators`).
    pub auto: Vec<AutoChoice>,
    /// The scalar reference `gpsrx_dsp::correlator::correlate` (cf32, 3 taps), Msamples/s.
    pub reference_msps_per_core: f64,
    /// The acquisition measurement (median), ms (None with --correlators-only).
    pub acquisition_ms: Option<f64>,
    /// The acquisition measurement in detail.
    pub acquisition: Option<AcquisitionBench>,
    /// End-to-end recording seconds per wall second (None with --no-end-to-end).
    pub realtime_factor: Option<f64>,
    /// The end-to-end run in detail.
    pub end_to_end: Option<EndToEnd>,
    /// The weak-signal end-to-end run (None with --no-end-to-end).
    pub weak_end_to_end: Option<EndToEnd>,
}

/// Runs `gpsrx bench`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    let report = bench(args)?;
    if args.json {
        let text = serde_json::to_string_pretty(&report)?;
        let mut out = crate::exit::stdout();
        writeln!(out, "{text}")?;
        out.flush()?;
    } else {
        let mut out = crate::exit::stdout();
        print_report(&mut out, &report)?;
        out.flush()?;
    }
    Ok(())
}

/// Measures everything [`BenchReport`] holds.
pub fn bench(args: &BenchArgs) -> anyhow::Result<BenchReport> {
    let duration = args.duration.unwrap_or(if args.quick { 1.0 } else { 60.0 });
    if !(duration.is_finite() && duration >= 0.5) {
        anyhow::bail!("--duration {duration}: give at least 0.5 s");
    }
    let timed_s = if args.quick { 0.01 } else { 0.15 };
    let threads = rayon::current_num_threads();
    let log = |msg: &str| {
        if !args.json {
            eprintln!("{msg}");
        }
    };

    let choice = args.correlator.unwrap_or(CorrelatorChoice {
        isa: CorrelatorIsa::Auto,
        arithmetic: None,
    });
    log("timing the correlator kernels (one core)...");
    let correlators = bench_correlators(timed_s, choice.isa.max_isa());
    let reference_msps_per_core = bench_reference(timed_s);
    let mut report = BenchReport {
        cpu: cpu_name(),
        cpu_features: CpuFeatures::detect(),
        correlator_ceiling: args.correlator.map_or("auto".into(), |_| {
            format!("{:?}", choice.isa).to_lowercase()
        }),
        threads,
        correlators,
        auto: auto_choices(choice.isa.max_isa()),
        reference_msps_per_core,
        acquisition_ms: None,
        acquisition: None,
        realtime_factor: None,
        end_to_end: None,
        weak_end_to_end: None,
    };
    if args.correlators_only {
        return Ok(report);
    }

    let (dir, _tmp) = super::work_dir(args.keep.as_deref())?;
    let mut scenario = Scenario::from_toml(SEOUL_SCENARIO_TOML)?;
    scenario.nav = "builtin:brdc0010.22n".into();
    // Without the end-to-end run the recording only feeds the acquisition.
    scenario.duration_s = if args.no_end_to_end { 0.5 } else { duration };
    log(&format!(
        "simulating {:.1} s of {} at {:.0} MHz ({} into {})...",
        scenario.duration_s,
        scenario.output.format,
        scenario.output.fs_hz / 1e6,
        scenario.description,
        dir.display()
    ));
    let t = Instant::now();
    let sim = simulate(&scenario, Path::new(""), &dir, false)?;
    let simulate_s = t.elapsed().as_secs_f64();

    log("timing a 32-PRN cold search...");
    let acquisition = bench_acquisition(&sim.data_path, if args.quick { 3 } else { 7 })?;
    report.acquisition_ms = Some(median(&acquisition.runs_ms));
    report.acquisition = Some(acquisition);
    if args.no_end_to_end {
        return Ok(report);
    }

    log(&format!(
        "running the receiver on {} ({:.1} s)...",
        sim.data_path.display(),
        scenario.duration_s
    ));
    let mut e = timed_run(&scenario, &sim.data_path, &dir.join("run"), args.correlator)?;
    e.satellites_simulated = sim.satellites.len();
    e.simulate_s = simulate_s;
    report.realtime_factor = Some(e.realtime_factor);
    report.end_to_end = Some(e);

    let mut weak = Scenario::from_toml(WEAK_SCENARIO_TOML)?;
    weak.duration_s = 1.5 * duration;
    let weak_dir = dir.join("weak");
    log(&format!(
        "simulating and running the weak-signal case ({:.1} s, {})...",
        weak.duration_s, weak.description
    ));
    let t = Instant::now();
    let sim = simulate(&weak, Path::new(""), &weak_dir, false)?;
    let simulate_s = t.elapsed().as_secs_f64();
    let mut e = timed_run(
        &weak,
        &sim.data_path,
        &weak_dir.join("run"),
        args.correlator,
    )?;
    e.satellites_simulated = sim.satellites.len();
    e.simulate_s = simulate_s;
    report.weak_end_to_end = Some(e);
    Ok(report)
}

/// Seeded random samples in every input format the correlators see (the same values: cf32
/// and ci16 hold the ci8 integers, ci16 scaled by 2^4 as a 12-bit front end would deliver
/// them); cu8, ri8 and ri16 as the receiver holds them, converted to ci16 when read
/// ([`gpsrx_samples::held_gain`]): cu8 the ci8 values offset by 128 (`2 code - 255`), ri8 and
/// ri16 the I values (ri16 scaled by 2^4) as a real recording on an IF of fs/4 + 20 kHz,
/// mixed down.
struct Inputs {
    ci8: Vec<[i8; 2]>,
    ci16: Vec<[i16; 2]>,
    cf32: Vec<Complex32>,
    cu8: Vec<[i16; 2]>,
    ri8: Vec<[i16; 2]>,
    ri16: Vec<[i16; 2]>,
}

impl Inputs {
    fn new(n: usize) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let ci8: Vec<[i8; 2]> = (0..n)
            .map(|_| [rng.random_range(-40i8..=40), rng.random_range(-40i8..=40)])
            .collect();
        let ci16 = ci8
            .iter()
            .map(|[i, q]| [i16::from(*i) << 4, i16::from(*q) << 4])
            .collect();
        let cf32 = ci8
            .iter()
            .map(|[i, q]| Complex32::new(f32::from(*i), f32::from(*q)))
            .collect();
        let held = |format: SampleFormat, values: Vec<Complex32>, if_hz: f64| {
            let mut x = values;
            if if_hz != 0.0 {
                Mixer::new(if_hz, BENCH_FS_HZ).mix(0, &mut x);
            }
            let mut out = vec![[0i16; 2]; x.len()];
            quantize_to_ci16(&x, held_gain(&format).unwrap_or(1.0), &mut out);
            out
        };
        let cu8 = ci8
            .iter()
            .map(|[i, q]| Complex32::new(f32::from(*i) + 0.5, f32::from(*q) + 0.5))
            .collect();
        let real = |scale: f32| {
            ci8.iter()
                .map(|[i, _]| Complex32::new(f32::from(*i) * scale, 0.0))
                .collect::<Vec<_>>()
        };
        let if_hz = BENCH_FS_HZ / 4.0 + 20e3;
        Self {
            cu8: held(SampleFormat::Cu8 { zero: 127.5 }, cu8, 0.0),
            ri8: held(SampleFormat::Ri8, real(1.0), if_hz),
            ri16: held(SampleFormat::Ri16Le, real(16.0), if_hz),
            ci8,
            ci16,
            cf32,
        }
    }

    fn slices(&self) -> [(&'static str, SampleSlice<'_>); 6] {
        [
            ("ci8", SampleSlice::Ci8(&self.ci8)),
            ("ci16", SampleSlice::Ci16(&self.ci16)),
            ("cf32", SampleSlice::Cf32(&self.cf32)),
            ("cu8", SampleSlice::Ci16(&self.cu8)),
            ("ri8", SampleSlice::Ci16(&self.ri8)),
            ("ri16", SampleSlice::Ci16(&self.ri16)),
        ]
    }
}

/// The input formats of the correlator rows and of `auto`'s choices.
const FORMATS: [&str; 6] = ["ci8", "ci16", "cf32", "cu8", "ri8", "ri16"];

/// A tracking-like replica: 2 kHz Doppler, code rate with the matching code Doppler.
fn bench_state() -> ReplicaState {
    let doppler_hz = 2000.0;
    ReplicaState {
        code_phase_chips: 517.25,
        code_rate_chips_s: CA_CHIP_RATE_HZ * (1.0 + doppler_hz / F_L1_HZ),
        carrier_phase_cycles: 0.3,
        carrier_freq_hz: doppler_hz,
        carrier_rate_hz_s: 0.0,
    }
}

/// Calls `f` (one block of `n` samples each) for about `timed_s` in all and returns the best
/// stretch in Msamples/s. Stretches last about 5 ms (at least 3 of them): on a machine shared
/// with other work the shortest time of many short stretches is the least disturbed, the way
/// `volk_gnsssdr_profile` times a kernel in one burst of a few ms.
fn throughput(n: usize, timed_s: f64, mut f: impl FnMut()) -> f64 {
    const STRETCH_S: f64 = 5e-3;
    f(); // warm-up: caches, page faults
    let stretches = ((timed_s / STRETCH_S).round() as usize).max(3);
    let stretch_s = timed_s / stretches as f64;
    let mut best = 0.0f64;
    for _ in 0..stretches {
        let t = Instant::now();
        let mut calls = 0u64;
        while t.elapsed().as_secs_f64() < stretch_s || calls == 0 {
            for _ in 0..4 {
                f();
            }
            calls += 4;
        }
        let msps = (calls * n as u64) as f64 / t.elapsed().as_secs_f64() / 1e6;
        best = best.max(msps);
    }
    best
}

/// Every available kernel up to `max_isa` x format x tap set, on the calling thread.
fn bench_correlators(timed_s: f64, max_isa: Isa) -> Vec<CorrelatorRow> {
    let inputs = Inputs::new(BLOCK_SAMPLES);
    let code = PackedCode::new(CaCode::new(prn1()).chips());
    let state = bench_state();
    let mut rows = Vec::new();
    for k in Correlator::available()
        .into_iter()
        .filter(|k| k.isa() <= max_isa)
    {
        for (format, samples) in inputs.slices() {
            for taps in TAP_SETS {
                let mut out = [Complex32::new(0.0, 0.0); 8];
                let out = &mut out[..taps.len()];
                let msps = throughput(BLOCK_SAMPLES, timed_s, || {
                    k.correlate_packed(
                        black_box(samples),
                        BENCH_FS_HZ,
                        &code,
                        black_box(&state),
                        taps,
                        out,
                    );
                    black_box(&out);
                });
                rows.push(CorrelatorRow {
                    isa: k.isa().name().into(),
                    arithmetic: k.arithmetic().name().into(),
                    kernel: k.name(),
                    runs: k.kernel_for(format, BENCH_FS_HZ),
                    format: format.into(),
                    taps: taps.len(),
                    msps_per_core: msps,
                });
            }
        }
    }
    rows
}

/// The kernel `auto` runs per format under the ceiling `max_isa`, at the benchmark's rate.
fn auto_choices(max_isa: Isa) -> Vec<AutoChoice> {
    let auto = Correlator::best_up_to(max_isa, Arithmetic::Auto);
    FORMATS
        .into_iter()
        .map(|format| {
            let k = auto.resolved_for(format, BENCH_FS_HZ);
            AutoChoice {
                format: format.into(),
                kernel: k.name(),
                runs: k.kernel_for(format, BENCH_FS_HZ),
            }
        })
        .collect()
}

/// The scalar reference correlator, cf32, 3 taps.
fn bench_reference(timed_s: f64) -> f64 {
    let inputs = Inputs::new(BLOCK_SAMPLES);
    let code = CaCode::new(prn1());
    let state = bench_state();
    let mut out = [Complex32::new(0.0, 0.0); 3];
    throughput(BLOCK_SAMPLES, timed_s, || {
        correlate(
            black_box(&inputs.cf32),
            BENCH_FS_HZ,
            code.chips(),
            black_box(&state),
            TAP_SETS[1],
            &mut out,
        );
        black_box(&out);
    })
}

/// PRN 1 (any PRN times the same).
fn prn1() -> Prn {
    Prn::new(1).unwrap_or_else(|e| panic!("PRN 1 is valid: {e}"))
}

/// Times `runs` 32-PRN cold searches of the first samples of `file`.
fn bench_acquisition(file: &Path, runs: usize) -> anyhow::Result<AcquisitionBench> {
    let mut src = open_source(&SourceConfig::new(file.to_path_buf()))?;
    let fs = src.fs_hz();
    let cfg = AcqConfig::default();
    let engine = AcquisitionEngine::new(fs, cfg.clone())?;
    let mut samples = vec![Complex32::new(0.0, 0.0); engine.samples_wanted()];
    let mut filled = 0;
    while filled < samples.len() {
        let (_, got) = src.read(&mut samples[filled..])?;
        if got == 0 {
            break;
        }
        filled += got;
    }
    if filled < engine.samples_needed() {
        anyhow::bail!(
            "{}: {filled} samples, the search needs {}",
            file.display(),
            engine.samples_needed()
        );
    }
    let samples = &samples[..filled];
    let mut detected = 0;
    let mut runs_ms = Vec::with_capacity(runs);
    // One untimed run makes the engine's scratch buffers.
    engine.search_all(samples)?;
    for _ in 0..runs {
        let t = Instant::now();
        let r = engine.search_all(black_box(samples))?;
        runs_ms.push(t.elapsed().as_secs_f64() * 1e3);
        detected = r.iter().filter(|d| d.detected).count();
    }
    Ok(AcquisitionBench {
        prns: 32,
        fs_hz: fs,
        coherent_ms: cfg.coherent_ms,
        noncoherent: cfg.noncoherent,
        doppler_max_hz: cfg.doppler_max_hz,
        runs,
        runs_ms,
        detected,
        threads: rayon::current_num_threads(),
    })
}

/// [`bench_end_to_end`] on the recording `file` of `scenario` (its week and, when static,
/// its antenna position as the truth).
fn timed_run(
    scenario: &Scenario,
    file: &Path,
    out: &Path,
    correlator: Option<CorrelatorChoice>,
) -> anyhow::Result<EndToEnd> {
    let week = scenario.start_time()?.week;
    let llh = match scenario.receiver {
        ReceiverConfig::Static { llh_deg, .. } => llh_deg,
        _ => None,
    };
    let mut config = gpsrx_receiver::ReceiverConfig::default();
    config.run.week = Some(week);
    if let Some(c) = correlator {
        config.tracking.correlator = c.isa;
        if let Some(a) = c.arithmetic {
            config.tracking.correlator_arithmetic = a;
        }
    }
    bench_end_to_end(file, out, &config, llh)
}

/// Times the receiver ([`Receiver::run`], what `gpsrx run` does) on `file`.
fn bench_end_to_end(
    file: &Path,
    out: &Path,
    config: &gpsrx_receiver::ReceiverConfig,
    truth_llh_deg: Option<[f64; 3]>,
) -> anyhow::Result<EndToEnd> {
    let src_cfg = SourceConfig::new(file.to_path_buf());
    let peak_rss_reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let mut source = open_source(&src_cfg)?;
    let mut receiver = Receiver::new(config, source.fs_hz(), Assistance::default())?;
    let mut sink = FileSink::create(out, config.run.rate_hz)?;
    let summary = receiver.run(source.as_mut(), &mut sink)?;
    let fixes = sink.into_fixes();
    let peak_rss_mb = peak_rss_kb().map(|kb| kb as f64 / 1024.0);
    let src = open_source(&SourceConfig::new(file.to_path_buf()))?;
    let mean_horizontal_error_m = match (summary.mean_llh, truth_llh_deg) {
        (Some((lat, lon, _)), Some(t)) => {
            // Small-angle local distance on a sphere of the Earth's mean radius: metres of
            // error are far below the size where that approximation matters.
            let r = 6_371_000.0;
            let dn = (lat - t[0]).to_radians() * r;
            let de = (lon - t[1]).to_radians() * r * t[0].to_radians().cos();
            Some(dn.hypot(de))
        }
        _ => None,
    };
    Ok(EndToEnd {
        duration_s: summary.duration_s,
        fs_hz: src.fs_hz(),
        format: src.format().to_string(),
        satellites_simulated: 0,
        satellites_tracked: summary.tracked_prns.len(),
        wall_s: summary.wall_s,
        realtime_factor: summary.duration_s / summary.wall_s.max(1e-9),
        fixes: fixes.len(),
        mean_horizontal_error_m,
        peak_rss_mb,
        peak_rss_reset,
        simulate_s: 0.0,
        correlator: {
            let c = config
                .tracking
                .correlator
                .correlator(config.tracking.correlator_arithmetic);
            let k = |f: &str| c.kernel_for(f, src.fs_hz());
            format!(
                "{} (on ci8 blocks {}, ci16 {}, cf32 {})",
                c.name(),
                k("ci8"),
                k("ci16"),
                k("cf32")
            )
        },
    })
}

/// `VmHWM` of /proc/self/status, kB.
fn peak_rss_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

fn print_report(out: &mut dyn Write, r: &BenchReport) -> std::io::Result<()> {
    writeln!(out, "gpsrx bench on {} ({} threads)", r.cpu, r.threads)?;
    writeln!(
        out,
        "instruction sets: {}; correlator ceiling: {}",
        r.cpu_features.describe(),
        r.correlator_ceiling
    )?;
    writeln!(out)?;
    print_correlators(out, r)?;
    if let (Some(a), Some(ms)) = (&r.acquisition, r.acquisition_ms) {
        writeln!(out)?;
        writeln!(out, "acquisition: {}-PRN cold search, {} ms x {} non-coherent, +-{:.0} Hz, {:.0} MHz, {} threads: {:.0} ms (median of {}; {} satellites found)",
            a.prns,
            a.coherent_ms,
            a.noncoherent,
            a.doppler_max_hz,
            a.fs_hz / 1e6,
            a.threads,
            ms,
            a.runs,
            a.detected
        )?;
    }
    for (name, e) in [
        ("end to end", &r.end_to_end),
        ("weak signals", &r.weak_end_to_end),
    ] {
        if let Some(e) = e {
            print_end_to_end(out, name, e)?;
        }
    }
    Ok(())
}

/// The correlator table: one line per kernel and format, the kernel that ran at the end.
fn print_correlators(out: &mut dyn Write, r: &BenchReport) -> std::io::Result<()> {
    writeln!(out, "correlator throughput, Msamples/s on one core (4000-sample blocks at 4 MHz, code and carrier generated inside;")?;
    writeln!(
        out,
        "cu8, ri8 and ri16 as the receiver holds them: converted to ci16 when read):"
    )?;
    writeln!(
        out,
        "  {:<14} {:<6} {:>9} {:>9} {:>9}   ran",
        "kernel", "input", "1 tap", "3 taps", "5 taps"
    )?;
    let mut keys: Vec<(String, String, String)> = Vec::new();
    for c in &r.correlators {
        let k = (c.kernel.clone(), c.format.clone(), c.runs.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    for (kernel, format, runs) in &keys {
        let cell = |taps: usize| {
            r.correlators
                .iter()
                .find(|c| &c.kernel == kernel && &c.format == format && c.taps == taps)
                .map_or("-".to_string(), |c| format!("{:.0}", c.msps_per_core))
        };
        let is_auto = r
            .auto
            .iter()
            .any(|a| &a.kernel == kernel && &a.format == format);
        writeln!(
            out,
            "  {:<14} {:<6} {:>9} {:>9} {:>9}   {}{}",
            kernel,
            format,
            cell(1),
            cell(3),
            cell(5),
            runs,
            if is_auto { "   <- auto" } else { "" }
        )?;
    }
    let auto: Vec<String> = r
        .auto
        .iter()
        .map(|a| format!("{} {}", a.format, a.runs))
        .collect();
    writeln!(
        out,
        "  auto (the default; ceiling {}) takes: {}",
        r.correlator_ceiling,
        auto.join(", ")
    )?;
    writeln!(
        out,
        "  (scalar reference correlate(), cf32, 3 taps: {:.0})",
        r.reference_msps_per_core
    )
}

/// One end-to-end run's lines of the report.
fn print_end_to_end(out: &mut dyn Write, name: &str, e: &EndToEnd) -> std::io::Result<()> {
    writeln!(out)?;
    writeln!(
        out,
        "{name}: {:.1} s of {} at {:.1} MHz, {} satellites simulated ({:.1} s to simulate)",
        e.duration_s,
        e.format,
        e.fs_hz / 1e6,
        e.satellites_simulated,
        e.simulate_s
    )?;
    writeln!(
        out,
        "  file to fixes in {:.2} s: {:.1}x real time; {} satellites tracked, {} fixes{}",
        e.wall_s,
        e.realtime_factor,
        e.satellites_tracked,
        e.fixes,
        e.mean_horizontal_error_m.map_or(String::new(), |h| format!(
            ", mean fix {h:.2} m from the antenna (horizontal)"
        ))
    )?;
    writeln!(out, "  tracking correlator: {}", e.correlator)?;
    match e.peak_rss_mb {
        Some(m) => writeln!(
            out,
            "  peak resident memory {m:.1} MB{}",
            if e.peak_rss_reset {
                ""
            } else {
                " (could not reset the peak: includes the simulation)"
            }
        ),
        None => writeln!(
            out,
            "  peak resident memory: unknown (no /proc/self/status)"
        ),
    }
}
