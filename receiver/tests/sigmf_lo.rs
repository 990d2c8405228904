//! A SigMF capture from a front end tuned off L1 (`captures[0].core:frequency` != 1575.42 MHz,
//! no `gpsrx:if_hz`): the carrier sits at `L1 - core:frequency` in the samples, and the
//! receiver, told nothing else, finds the satellites at their true Doppler.

use crate::pipeline::receiver;
use gpsrx_receiver::pipeline::{MemorySink, ReceiverEvent};
use gpsrx_samples::sim::{Scenario, Simulator};
use gpsrx_samples::{open_source, resolve::resolve, SampleError, SourceConfig};
use std::path::Path;

const LO_OFFSET_HZ: f64 = 250e3;

/// 3 s of a static antenna in Daejeon, ci8 at 2.048 MHz, L1 at +250 kHz in the samples.
fn offset_lo_recording(dir: &Path) -> (Simulator, std::path::PathBuf) {
    let text = format!(
        r#"
duration_s = 3.0
seed = 11
nav = "builtin:brdc0010.22n"
[start]
week = 2190
tow_s = 538198.0
[output]
format = "ci8"
fs_hz = 2.048e6
if_hz = {LO_OFFSET_HZ}
[receiver]
kind = "static"
llh_deg = [36.3721, 127.3604, 80.0]
"#
    );
    let sc = Scenario::from_toml(&text).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulator::new(&sc, Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let report = sim.run(dir, &|_| {}).unwrap_or_else(|e| panic!("{e}"));
    // Leave only the SigMF core field: drop gpsrx:if_hz, keep core:frequency = L1 - 250 kHz.
    let meta_path = report.data_path.with_extension("sigmf-meta");
    let text = std::fs::read_to_string(&meta_path).unwrap_or_else(|e| panic!("{e}"));
    let mut meta: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}"));
    let global = meta["global"]
        .as_object_mut()
        .unwrap_or_else(|| panic!("no global object in {text}"));
    assert!(global.remove("gpsrx:if_hz").is_some(), "{text}");
    let f = meta["captures"][0]["core:frequency"].as_f64();
    assert_eq!(f, Some(1575.42e6 - LO_OFFSET_HZ));
    std::fs::write(&meta_path, meta.to_string()).unwrap_or_else(|e| panic!("{e}"));
    (sim, report.data_path)
}

#[test]
fn an_offset_lo_from_core_frequency_is_the_if_and_satellites_are_at_their_doppler() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (sim, data_path) = offset_lo_recording(dir.path());
    let cfg = SourceConfig::new(data_path.clone());
    let resolved = resolve(&cfg).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(resolved.if_hz, LO_OFFSET_HZ);
    // A conflicting --if is refused, naming both values; an agreeing one is fine.
    let conflict = resolve(&SourceConfig {
        if_hz: 100e3,
        ..cfg.clone()
    });
    match conflict {
        Err(e @ SampleError::IfConflict { .. }) => {
            let text = e.to_string();
            assert!(text.contains("100000") && text.contains("250000"), "{text}");
            assert!(text.contains("core:frequency"), "{text}");
        }
        other => panic!("expected an IF conflict, got {other:?}"),
    }
    assert!(resolve(&SourceConfig {
        if_hz: LO_OFFSET_HZ,
        ..cfg.clone()
    })
    .is_ok());

    let mut src = open_source(&cfg).unwrap_or_else(|e| panic!("{e}"));
    let mut sink = MemorySink::new();
    receiver(2.048e6)
        .run(src.as_mut(), &mut sink)
        .unwrap_or_else(|e| panic!("{e}"));
    let found: Vec<(u8, f64, f64)> = sink
        .events
        .iter()
        .filter_map(|e| match e {
            ReceiverEvent::Acquired {
                prn,
                t_s,
                doppler_hz,
                ..
            } => Some((*prn, *t_s, *doppler_hz)),
            _ => None,
        })
        .collect();
    assert!(found.len() >= 6, "{} satellites acquired", found.len());
    for (prn, t_s, doppler_hz) in found {
        let sat = sim
            .satellites
            .iter()
            .find(|s| u8::from(s.prn) == prn)
            .unwrap_or_else(|| panic!("G{prn:02}: not simulated (a false acquisition)"));
        // Truth: the rate of the simulated carrier phase over the 10 ms search.
        let t = t_s + 5e-3;
        let (a, _) = sim.observe(sat, t - 0.5e-3);
        let (b, _) = sim.observe(sat, t + 0.5e-3);
        let truth_hz = (b.carrier_cycles - a.carrier_cycles) / 1e-3;
        assert!(
            (doppler_hz - truth_hz).abs() < 100.0,
            "G{prn:02}: Doppler {doppler_hz:.0} Hz, truth {truth_hz:.0} Hz"
        );
    }
}
