//! Long gaps in the sample stream (seconds to a minute cut out): the receiver time must be
//! re-established from the signal, with the ephemerides known (coarse time) or from the next
//! time of week, and no wrong fix may be flagged valid meanwhile. Scored against the
//! simulator's truth position.

use gpsrx_core::frames::Llh;
use gpsrx_receiver::output::FixQuality;
use gpsrx_receiver::pipeline::{MemorySink, ReceiverEvent};
use gpsrx_receiver::{Assistance, Receiver, ReceiverConfig};
use gpsrx_samples::sim::{Scenario, Simulator};
use num_complex::Complex32;
use std::path::Path;

const FS_HZ: f64 = 2.048e6;
const LLH_DEG: [f64; 3] = [36.3721, 127.3604, 80.0];

/// A static receiver at 2.048 MHz with a clock bias and drift, the built-in ephemerides.
fn simulator(duration_s: f64) -> Simulator {
    let text = format!(
        r#"
duration_s = {duration_s}
seed = 11
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538198.0
[output]
format = "cf32_le"
fs_hz = {FS_HZ}
[receiver]
kind = "static"
llh_deg = [{}, {}, {}]
[clock]
bias_s = 3.0e-4
drift_s_s = 4.0e-8
"#,
        LLH_DEG[0], LLH_DEG[1], LLH_DEG[2]
    );
    let sc = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
    Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

/// A receiver with (`nav`) or without the built-in ephemerides as assistance.
fn receiver(nav: bool) -> Receiver {
    if nav {
        return crate::pipeline::receiver(FS_HZ);
    }
    let mut config = ReceiverConfig::default();
    config.run.tropo = gpsrx_receiver::config::TropoModel::None;
    config.run.week = Some(2190);
    Receiver::new(&config, FS_HZ, Assistance::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs the receiver on the simulator's samples with `len_s` cut out at `at_s` (simulator
/// time).
fn run_cut(sim: &Simulator, nav: bool, at_s: f64, len_s: f64) -> MemorySink {
    let mut rx = receiver(nav);
    let mut sink = MemorySink::new();
    let mut buf = Vec::new();
    for chunk in 0..sim.chunk_count() {
        let first = chunk * sim.chunk_samples() as u64;
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
    eprintln!("  events: {}", events.join("; "));
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
