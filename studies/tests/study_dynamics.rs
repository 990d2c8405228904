//! `gpsrx study dynamics --quick`: seed 004's high-dynamics experiment on simulated IF.
//!
//! The quick grid is one scenario (10 g turn at 45 dB-Hz, fixed noise seed, 13 s lead-in for
//! the channels to narrow in stages to 0.4 Hz) tracked by 2nd- and 3rd-order PLLs at 0.4 Hz
//! (seed 004's bandwidth) unaided and aided by INS 1 (accelerometer bias 1 mg) and INS 2
//! (2 mg), and by a 1st-order PLL at 18 Hz aided by each INS (5 and 10 mg). The assertions
//! read `study.json`.

use serde_json::Value;
use std::time::Instant;

fn num(v: &Value, path: &[&str]) -> f64 {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    x.as_f64()
        .unwrap_or_else(|| panic!("{} is not a number: {x}", path.join(".")))
}

#[test]
fn quick_dynamics_study_reproduces_seed_004() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("dyn");
    let started = Instant::now();
    crate::run_study(&["dynamics", "--quick", "--seed", "4"], &out);
    eprintln!(
        "quick dynamics study: {:.1} s",
        started.elapsed().as_secs_f64()
    );
    for f in [
        "study.md",
        "study.csv",
        "study.json",
        "tracked_10g_45dbhz.png",
        "phase_std_vs_g.png",
        "min_tracked_vs_g.png",
    ] {
        let p = out.join(f);
        let len = std::fs::metadata(&p)
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
            .len();
        assert!(len > 100, "{f} is nearly empty ({len} bytes)");
    }
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("study.json")).unwrap_or_else(|e| panic!("{e}")),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let md = std::fs::read_to_string(out.join("study.md")).unwrap_or_else(|e| panic!("{e}"));
    let t = &json["ten_g"];
    let ctx = format!("{t:#}\n{md}");
    assert_eq!(num(t, &["bn_hz"]), 0.4, "{ctx}");
    let n = num(t, &["satellites"]);
    assert!(n >= 8.0, "only {n} satellites simulated\n{ctx}");
    let o2 = &t["order2"];
    let o3 = &t["order3"];

    // Seed 004 Fig. 12: unaided, the 0.4 Hz loops lose satellites. The 3rd-order one was
    // tracking every satellite when the turn began (the satellites' own acceleration does not
    // stress it), so its losses are the turn's doing.
    assert_eq!(num(o3, &["unaided", "tracked_at_start"]), n, "{ctx}");
    for o in [o2, o3] {
        assert!(
            num(o, &["unaided", "tracked_min"]) < n,
            "unaided kept all\n{ctx}"
        );
    }
    assert!(num(o3, &["unaided", "lock_drops"]) >= 1.0, "{ctx}");
    // ...while Fig. 15: aided by either INS, both orders keep every satellite through the
    // turn, at every 0.1 s sample (the channels narrowed to 0.4 Hz in the lead-in the way the
    // receiver's do).
    for o in [o2, o3] {
        for mode in ["ins1", "ins2"] {
            assert_eq!(num(o, &[mode, "tracked_at_start"]), n, "{mode}\n{ctx}");
            assert_eq!(num(o, &[mode, "kept"]), n, "{mode} lost some\n{ctx}");
            assert_eq!(num(o, &[mode, "tracked_min"]), n, "{mode}\n{ctx}");
        }
    }
    // Table 3 at 45 dB-Hz: the loop is linear there (static offsets of at most 0.09 and 0.18
    // cycle, noise 0.02 cycle), so the phase error std against the truth is the same with
    // either INS; 0.9-1.1 (both runs see the same noise, so the ratio is 1 to a few parts in
    // 1e3).
    for o in [o2, o3] {
        let ratio = num(o, &["phase_std_ratio_ins2_ins1"]);
        assert!((0.9..1.1).contains(&ratio), "std ratio {ratio}\n{ctx}");
    }
    // The std is at the noise level: thermal jitter at 45 dB-Hz, Bn 0.4 Hz, T = 1 ms is
    // 0.2 deg, the oscillator (sigma_y 1.1e-11 at 1 s) about 144 sigma_A f_L1 / Bn = 5.7 deg =
    // 0.016 cycle; 0.05 cycle (18 deg) would mean dynamics leaking through the aiding.
    let std1 = num(o2, &["ins1", "phase_std_cycles"]);
    assert!(std1 > 0.001 && std1 < 0.05, "INS 1 phase std {std1}\n{ctx}");
    // The 2nd-order loop's mean error is the bias's constant 360 B_V / (lambda omega0^2): within
    // 20 % of it for both INS.
    for mode in ["ins1", "ins2"] {
        let m = num(o2, &[mode, "mean_abs_phase_error_deg"]);
        let p = num(o2, &[mode, "predicted_mean_abs_phase_error_deg"]);
        assert!((m / p - 1.0).abs() < 0.2, "{mode}: mean {m} vs {p}\n{ctx}");
    }
    let table3 = json["table3"]
        .as_array()
        .unwrap_or_else(|| panic!("no table3\n{ctx}"));
    assert_eq!(table3.len(), 2, "{ctx}");
    // 1st-order aided loop: the error grows as 360 B_V t / (lambda omega0), twice as fast with
    // INS 2. Ratio 2 within 20 % and each growth within 20 % of the theory.
    let o1 = &t["order1"]["cases"];
    let g = num(o1, &["growth_ratio_ins2_ins1"]);
    assert!((1.6..2.4).contains(&g), "1st-order growth ratio {g}\n{ctx}");
    for mode in ["ins1", "ins2"] {
        let m = num(o1, &[mode, "phase_error_growth_deg_s"]);
        let p = num(o1, &[mode, "predicted_phase_error_growth_deg_s"]);
        assert!(
            (m / p - 1.0).abs() < 0.2,
            "order 1 {mode}: {m} vs {p}\n{ctx}"
        );
    }
    assert!(
        md.contains("| 10 g turn | 45 | 13 | 2 | 0.4 | INS 1 | 1.0 |"),
        "{md}"
    );
    assert!(md.contains("Table 3"), "{md}");
}
