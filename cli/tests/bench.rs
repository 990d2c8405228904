//! `gpsrx bench --quick --json`: the report's shape and sanity (no timing assertions: the
//! numbers depend on the machine and its load).

use gpsrx_dsp::correlator::Correlator;
use serde_json::Value;
use std::process::Command;

/// A field that must be a positive finite number.
fn positive(v: &Value, what: &str) -> f64 {
    let x = v
        .as_f64()
        .unwrap_or_else(|| panic!("{what}: not a number: {v}"));
    assert!(x.is_finite() && x > 0.0, "{what} = {x}");
    x
}

#[test]
fn quick_bench_reports_every_kernel_acquisition_and_end_to_end() {
    let out = Command::new(env!("CARGO_BIN_EXE_gpsrx"))
        .args(["bench", "--quick", "--json"])
        .output()
        .unwrap_or_else(|e| panic!("cannot run gpsrx: {e}"));
    assert!(
        out.status.success(),
        "gpsrx bench failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    });

    // Correlators: the full grid of this CPU's kernels x formats x tap counts, once each.
    let rows = v["correlators"]
        .as_array()
        .unwrap_or_else(|| panic!("no correlators array"));
    let kernels = Correlator::available();
    assert_eq!(
        rows.len(),
        kernels.len() * 6 * 3,
        "one row per kernel, format, taps"
    );
    for k in &kernels {
        for format in ["ci8", "ci16", "cf32", "cu8", "ri8", "ri16"] {
            for taps in [1u64, 3, 5] {
                let hits: Vec<&Value> = rows
                    .iter()
                    .filter(|r| {
                        r["kernel"] == k.name().as_str()
                            && r["format"] == format
                            && r["taps"].as_u64() == Some(taps)
                    })
                    .collect();
                assert_eq!(hits.len(), 1, "{} {format} {taps} taps", k.name());
                let r = hits[0];
                positive(
                    &r["msps_per_core"],
                    &format!("{} {format} {taps}", k.name()),
                );
                // isa and arithmetic spell the kernel's name; `runs` names the kernel that ran.
                let isa = r["isa"].as_str().unwrap_or_default();
                let arith = r["arithmetic"].as_str().unwrap_or_default();
                assert_eq!(format!("{isa}/{arith}"), k.name());
                assert_eq!(r["runs"].as_str(), Some(k.kernel_for(format, 4e6).as_str()));
            }
        }
    }
    // auto: one choice per format, a row of the grid, the kernel the library resolves.
    let auto = v["auto"]
        .as_array()
        .unwrap_or_else(|| panic!("no auto array"));
    assert_eq!(auto.len(), 6);
    let resolver = Correlator::best_up_to(
        gpsrx_dsp::correlator::Isa::Avx512,
        gpsrx_dsp::correlator::Arithmetic::Auto,
    );
    for (a, format) in auto
        .iter()
        .zip(["ci8", "ci16", "cf32", "cu8", "ri8", "ri16"])
    {
        assert_eq!(a["format"], format);
        let k = resolver.resolved_for(format, 4e6);
        assert_eq!(a["kernel"].as_str(), Some(k.name().as_str()));
        assert_eq!(a["runs"].as_str(), Some(k.kernel_for(format, 4e6).as_str()));
        assert!(
            rows.iter().any(|r| r["kernel"] == a["kernel"]
                && r["format"] == format
                && r["runs"] == a["runs"]),
            "auto's {format} kernel {a} is not a row"
        );
    }
    // cu8, ri8 and ri16 are held as ci16: auto runs on them what it runs on ci16 (the int16
    // kernel wherever the CPU has AVX2).
    for format in ["cu8", "ri8", "ri16"] {
        let a = auto.iter().find(|a| a["format"] == format);
        let c = auto.iter().find(|a| a["format"] == "ci16");
        assert_eq!(a.map(|a| &a["runs"]), c.map(|c| &c["runs"]), "{format}");
    }
    positive(&v["reference_msps_per_core"], "reference correlator");
    // The CPU and its instruction sets come with the figures.
    assert!(!v["cpu"].as_str().unwrap_or_default().is_empty());
    for f in ["avx2", "fma", "avx512f", "avx512bw"] {
        assert!(v["cpu_features"][f].is_boolean(), "cpu_features.{f}");
    }
    assert_eq!(v["correlator_ceiling"], "auto");
    assert!(v["end_to_end"]["correlator"].is_string());

    // Acquisition: a positive time, the median of the runs, and the simulated satellites found.
    let acq_ms = positive(&v["acquisition_ms"], "acquisition_ms");
    let runs: Vec<f64> = v["acquisition"]["runs_ms"]
        .as_array()
        .unwrap_or_else(|| panic!("no runs_ms"))
        .iter()
        .map(|r| positive(r, "acquisition run"))
        .collect();
    assert_eq!(runs.len(), 3, "--quick times 3 searches");
    let mut sorted = runs.clone();
    sorted.sort_by(f64::total_cmp);
    assert_eq!(
        acq_ms, sorted[1],
        "acquisition_ms is the median of {runs:?}"
    );
    assert_eq!(v["acquisition"]["prns"], 32);

    // End to end: the requested 1 s processed, the factor consistent with the wall time, every
    // simulated satellite acquired and tracked, memory within the 200 MB budget.
    let e = &v["end_to_end"];
    let duration = positive(&e["duration_s"], "duration_s");
    assert!((duration - 1.0).abs() < 1e-6, "processed {duration} s");
    let wall = positive(&e["wall_s"], "wall_s");
    let rtf = positive(&v["realtime_factor"], "realtime_factor");
    assert!(
        (rtf - duration / wall).abs() <= 1e-9 * rtf.max(1.0),
        "realtime_factor {rtf} vs {duration} s / {wall} s"
    );
    assert_eq!(e["realtime_factor"], v["realtime_factor"]);
    let simulated = e["satellites_simulated"].as_u64().unwrap_or(0);
    assert!(simulated >= 4, "{simulated} satellites simulated");
    assert_eq!(e["satellites_tracked"].as_u64(), Some(simulated));
    assert_eq!(v["acquisition"]["detected"].as_u64(), Some(simulated));
    if !e["peak_rss_mb"].is_null() {
        let mb = positive(&e["peak_rss_mb"], "peak_rss_mb");
        if e["peak_rss_reset"] == true {
            assert!(mb < 200.0, "peak RSS {mb} MB");
        }
    }
}

#[test]
fn correlator_ceiling_limits_the_kernels_and_bad_names_are_refused() {
    // --correlator avx2: no AVX-512 row even on an AVX-512 machine (the figure an AVX2-only
    // CPU would give); --correlators-only: no simulation, acquisition or end-to-end.
    let out = Command::new(env!("CARGO_BIN_EXE_gpsrx"))
        .args([
            "bench",
            "--quick",
            "--json",
            "--correlators-only",
            "--correlator",
            "avx2",
        ])
        .output()
        .unwrap_or_else(|e| panic!("cannot run gpsrx: {e}"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}"));
    let rows = v["correlators"]
        .as_array()
        .unwrap_or_else(|| panic!("no correlators array"));
    let expected = Correlator::available()
        .iter()
        .filter(|k| k.isa() != gpsrx_dsp::correlator::Isa::Avx512)
        .count();
    assert_eq!(rows.len(), expected * 6 * 3);
    assert!(rows.iter().all(|r| r["isa"] != "avx512"));
    // Under the avx2 ceiling auto takes AVX2 kernels (or scalar on a CPU without them).
    let auto = v["auto"]
        .as_array()
        .unwrap_or_else(|| panic!("no auto array"));
    assert!(auto.iter().all(|a| !a["kernel"]
        .as_str()
        .unwrap_or("avx512")
        .starts_with("avx512")));
    assert_eq!(v["correlator_ceiling"], "avx2");
    assert!(v["acquisition"].is_null() && v["end_to_end"].is_null());

    let out = Command::new(env!("CARGO_BIN_EXE_gpsrx"))
        .args(["bench", "--correlators-only", "--correlator", "sse4"])
        .output()
        .unwrap_or_else(|e| panic!("cannot run gpsrx: {e}"));
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("auto, avx512, avx2, scalar"), "{err}");
}
