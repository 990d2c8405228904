//! Long gaps in the sample stream (seconds to a minute cut out): the receiver time must be
//! re-established from the signal, with the ephemerides known (coarse time) or from the next
//! time of week, and no wrong fix may be flagged valid meanwhile. Scored against the
//! simulator's truth position.

use gpsrx_core::frames::Llh;
use gpsrx_nav::rinex_nav::parse_rinex_nav;
use gpsrx_receiver::output::FixQuality;
use gpsrx_receiver::pipeline::{MemorySink, ReceiverEvent};
use gpsrx_receiver::{Assistance, Receiver, ReceiverConfig};
use gpsrx_samples::sim::scenario::BUILTIN_NAV_TEXT;
use gpsrx_samples::sim::{Scenario, Simulator};
use num_complex::Complex32;
use std::path::Path;

const FS_HZ: f64 = 2.048e6;
const LLH_DEG: [f64; 3] = [37.5665, 126.9780, 40.0];

/// The project's static Seoul scenario (12 satellites, `samples/scenarios/static-seoul-4msps.toml`)
/// at 2.048 MHz, starting 10 s later (TOW 28 mod 30: subframe 1 begins 2 s in, so subframes
/// 1-3 are decoded by about 20 s), with a receiver clock bias and drift.
fn simulator(duration_s: f64) -> Simulator {
    simulator_with(duration_s, "")
}

/// [`simulator`] with `rest` (further TOML tables, e.g. `[[outages]]`).
fn simulator_with(duration_s: f64, rest: &str) -> Simulator {
    let text = format!(
        r#"
duration_s = {duration_s}
seed = 7
nav = "builtin:brdc0010.22n"
[start]
gps_calendar = "2022-01-01 12:29:58"
[output]
format = "cf32_le"
fs_hz = {FS_HZ}
[receiver]
kind = "static"
llh_deg = [{}, {}, {}]
[clock]
bias_s = -3.0e-4
drift_s_s = 1.0e-7
{rest}
"#,
        LLH_DEG[0], LLH_DEG[1], LLH_DEG[2]
    );
    let sc = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
    Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// A receiver with (`nav`) or without the built-in ephemerides as assistance, week 2190, the
/// tropospheric model on (the scenario simulates a troposphere).
fn receiver(nav: bool) -> Receiver {
    let mut config = ReceiverConfig::default();
    config.run.week = Some(2190);
    let nav = nav.then(|| parse_rinex_nav(BUILTIN_NAV_TEXT).unwrap_or_else(|e| panic!("{e}")));
    let assistance = Assistance {
        nav,
        ..Assistance::default()
    };
    Receiver::new(&config, FS_HZ, assistance).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs the receiver on the simulator's samples with `len_s` cut out at `at_s` (simulator
/// time).
fn run_cut(sim: &Simulator, nav: bool, at_s: f64, len_s: f64) -> MemorySink {
    let mut rx = receiver(nav);
    let mut sink = MemorySink::new();
    let mut buf = Vec::new();
    let n = sim.chunk_samples() as u64;
    for chunk in 0..sim.chunk_count() {
        let first = chunk * n;
        let (t_first, t_end) = (first as f64 / FS_HZ, (first + n) as f64 / FS_HZ);
        if t_first >= at_s && t_end <= at_s + len_s {
            continue;
        }
        sim.generate_chunk(chunk, &mut buf);
        let keep: Vec<Complex32> = buf
            .iter()
            .enumerate()
            .filter(|(k, _)| {
                let t = (first + *k as u64) as f64 / FS_HZ;
                !(t >= at_s && t < at_s + len_s)
            })
            .map(|(_, s)| *s)
            .collect();
        if !keep.is_empty() {
            rx.push(&keep, &mut sink).unwrap_or_else(|e| panic!("{e}"));
        }
    }
    rx.finish(&mut sink).unwrap_or_else(|e| panic!("{e}"));
    sink
}

/// A scored fix: stream time (s), 3-D error (m), valid, 3-D 3-sigma of its stated
/// east/north/up sigmas (m, 0 when none is stated).
type Scored = (f64, f64, bool, f64);

/// Every fix after stream time `after_s`, scored against the truth.
fn scored(sink: &MemorySink, after_s: f64) -> Vec<Scored> {
    let truth = Llh::from_degrees(LLH_DEG[0], LLH_DEG[1], LLH_DEG[2]).to_ecef();
    sink.fixes
        .iter()
        .filter(|f| f.t_stream_s > after_s)
        .map(|f| {
            let e = f.fix.ecef_m;
            let d =
                ((e[0] - truth.x).powi(2) + (e[1] - truth.y).powi(2) + (e[2] - truth.z).powi(2))
                    .sqrt();
            let s3 = f.fix.sigma_enu_m.map_or(0.0, |s| {
                3.0 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
            });
            (f.t_stream_s, d, f.fix.quality != FixQuality::None, s3)
        })
        .collect()
}

/// The valid fixes more than 5 m off whose stated 3-sigma does not cover the error.
fn uncovered(fixes: &[Scored]) -> Vec<(f64, f64, f64)> {
    fixes
        .iter()
        .filter(|f| f.2 && f.1 > 5.0 && f.1 > f.3)
        .map(|f| (f.0, f.1, f.3))
        .collect()
}

fn describe(name: &str, sink: &MemorySink, at_s: f64) {
    let all = scored(sink, 0.0);
    let before: Vec<&Scored> = all.iter().filter(|f| f.2 && f.0 < at_s).collect();
    eprintln!(
        "{name}: before the cut {} valid, worst {:.1} m, {} uncovered",
        before.len(),
        before.iter().map(|f| f.1).fold(0.0, f64::max),
        uncovered(
            &all.iter()
                .filter(|f| f.0 < at_s)
                .copied()
                .collect::<Vec<_>>()
        )
        .len()
    );
    let fixes = scored(sink, at_s);
    let valid: Vec<&Scored> = fixes.iter().filter(|f| f.2).collect();
    let worst = valid.iter().map(|f| f.1).fold(0.0, f64::max);
    let back = valid.first().map(|f| f.0 - at_s);
    let events: Vec<String> = sink
        .events
        .iter()
        .filter(|e| {
            !matches!(
                e,
                ReceiverEvent::Acquired { .. }
                    | ReceiverEvent::FrameSync { .. }
                    | ReceiverEvent::EphemerisDecoded { .. }
            )
        })
        .map(|e| format!("{e:?}"))
        .collect();
    eprintln!(
        "{name}: {} fixes after the cut, {} valid, first valid {back:?} s after, worst valid {worst:.1} m; invalid: {}",
        fixes.len(),
        valid.len(),
        fixes.iter().filter(|f| !f.2).count()
    );
    eprintln!(
        "  first: {:?}",
        fixes
            .iter()
            .take(30)
            .map(|f| format!(
                "{:.1}m/{:.1}@{:.1}{}",
                f.1,
                f.3,
                f.0,
                if f.2 { "" } else { "x" }
            ))
            .collect::<Vec<_>>()
    );
    eprintln!("  uncovered after: {:?}", uncovered(&fixes));
    let bias_ms: Vec<String> = sink
        .fixes
        .iter()
        .filter(|f| f.t_stream_s > at_s && f.fix.quality != FixQuality::None)
        .take(3)
        .map(|f| format!("{:.4}", f.fix.clock_bias_m / 299_792_458.0 * 1e3))
        .collect();
    eprintln!("  clock bias of the first valid fixes after, ms: {bias_ms:?}");
    eprintln!("  events: {}", events.join("; "));
}

/// The stream times of the reported sample gaps, the lengths measured for them (ms), and the
/// receiver clock steps after the first gap (ms).
fn gap_events(sink: &MemorySink) -> (Vec<f64>, Vec<f64>, Vec<i64>) {
    let mut gaps = Vec::new();
    let mut lengths = Vec::new();
    let mut steps = Vec::new();
    for e in &sink.events {
        match e {
            ReceiverEvent::SampleGap { t_s } => gaps.push(*t_s),
            ReceiverEvent::GapMeasured { length_ms, .. } => lengths.push(*length_ms),
            ReceiverEvent::ClockStep { ms } if !gaps.is_empty() => steps.push(*ms),
            _ => {}
        }
    }
    (gaps, lengths, steps)
}

/// Runs a `len_s` cut at stream time `at_s` of a recording that goes on for `after_s` past
/// it, and checks against the truth: one gap reported where it happened and its length
/// measured to a millisecond once the time is back, the receiver clock stepped once by it;
/// the first valid fix at most `within_s`
/// after the signal returns, and valid fixes from then on; no valid fix, before or after,
/// more than 5 m off unless its stated 3-sigma covers the error.
fn assert_recovers(nav: bool, at_s: f64, len_s: f64, after_s: f64, within_s: f64) {
    let name = format!("{len_s} s cut at {at_s} s, nav {nav}");
    let sim = simulator(at_s + len_s + after_s);
    let sink = run_cut(&sim, nav, at_s, len_s);
    let (gaps, lengths, steps) = gap_events(&sink);
    assert!(
        gaps.len() == 1 && (gaps[0] - at_s).abs() < 0.05,
        "{name}: gaps reported at {gaps:?} s"
    );
    assert!(
        lengths.len() == 1 && (lengths[0] - len_s * 1e3).abs() < 1.0,
        "{name}: lengths measured {lengths:?} ms"
    );
    // The receiver time is stepped once, by the whole milliseconds lost (the clock bias stays
    // within a millisecond: the first fix need not step it again).
    assert!(
        steps.len() == 1 && (steps[0] as f64 - len_s * 1e3).abs() <= 1.0,
        "{name}: clock steps after the gap {steps:?} ms"
    );
    let all = scored(&sink, 0.0);
    let wrong = uncovered(&all);
    assert!(
        wrong.is_empty(),
        "{name}: valid fixes more than 5 m off, beyond their 3-sigma (t s, error m, 3-sigma m): {wrong:?}"
    );
    let after = scored(&sink, at_s);
    let first = after.iter().find(|f| f.2).map(|f| f.0 - at_s);
    assert!(
        first.is_some_and(|b| b <= within_s),
        "{name}: first valid fix {first:?} s after the signal returned"
    );
    // Fixes at 10 Hz from then on (a few may fail the integrity test).
    let valid = after.iter().filter(|f| f.2).count() as f64;
    let expected = (after_s - first.unwrap_or(after_s)) * 10.0;
    assert!(
        valid >= 0.9 * expected,
        "{name}: {valid} valid fixes after the gap, {expected:.0} expected"
    );
}

#[test]
fn a_five_second_cut_gives_valid_fixes_within_two_seconds_with_nav() {
    // Samples of unknown length were lost (the code of every satellite moved by more than a
    // gap of a second explains): the coarse-time solver with the navigation file's
    // ephemerides gives the time and every SV time back.
    assert_recovers(true, 10.0, 5.0, 4.0, 2.0);
}

#[test]
fn a_five_second_cut_gives_valid_fixes_within_two_seconds_with_ephemerides_decoded_before() {
    // Without a navigation file: the ephemerides decoded before the gap serve the
    // coarse-time solver (the issue's bound is 8 s, the next time of week).
    assert_recovers(false, 21.0, 5.0, 4.0, 2.0);
}

#[test]
fn a_sixty_second_cut_gives_valid_fixes_within_two_seconds_with_nav() {
    // The satellites moved 60 s along their orbits: 60 km of error at the receiver's time.
    assert_recovers(true, 10.0, 60.0, 4.0, 2.0);
}

#[test]
fn samples_cut_inside_an_outage_are_found_by_raim_and_the_time_re_established_within_two_seconds() {
    // Every signal blocked from 9 to 16 s, and 3 s of samples lost at 11 s inside the
    // blockage: the satellites come back at stream time 13 s with the SV times carried over
    // the outage 3 s (150 data bits) wrong, which the bit edges cannot show. The solutions
    // fail RAIM, every SV time is dropped, and the coarse-time solver gives the time back.
    let (at_s, len_s, back_s) = (11.0, 3.0, 13.0);
    let sim = simulator_with(20.0, "[[outages]]\nstart_s = 9.0\nend_s = 16.0\n");
    let sink = run_cut(&sim, true, at_s, len_s);
    let all = scored(&sink, 0.0);
    let wrong = uncovered(&all);
    assert!(
        wrong.is_empty(),
        "valid fixes more than 5 m off, beyond their 3-sigma (t s, error m, 3-sigma m): {wrong:?}"
    );
    let first = all.iter().find(|f| f.2 && f.0 > at_s).map(|f| f.0 - back_s);
    assert!(
        first.is_some_and(|b| (0.0..=2.0).contains(&b)),
        "first valid fix {first:?} s after the signals returned"
    );
    let (_, lengths, _) = gap_events(&sink);
    let steps: Vec<i64> = sink
        .events
        .iter()
        .filter_map(|e| match e {
            ReceiverEvent::ClockStep { ms } => Some(*ms),
            _ => None,
        })
        .collect();
    // Found after the fact (from the solutions, not the signal): the lost time is measured
    // from the clock bias of the first fix after it.
    assert!(
        lengths.len() == 1 && (lengths[0] - len_s * 1e3).abs() < 1.0,
        "lengths measured {lengths:?} ms"
    );
    assert!(
        steps.iter().any(|&s| (s as f64 - len_s * 1e3).abs() <= 1.0),
        "clock steps {steps:?} ms"
    );
}

#[test]
#[ignore]
fn measure_long_cuts() {
    let len_s: f64 = std::env::var("GPSRX_CUT_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5.0);
    let nav = std::env::var("GPSRX_NAV").map_or(true, |v| v != "0");
    let at: f64 = std::env::var("GPSRX_AT")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(if nav { 16.0 } else { 22.0 });
    let sim = simulator(at + len_s + 14.0);
    describe(
        &format!("cut {len_s} s, nav {nav}"),
        &run_cut(&sim, nav, at, len_s),
        at,
    );
}
