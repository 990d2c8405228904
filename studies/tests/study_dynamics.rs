//! `gpsrx study dynamics --quick`: seed 004's high-dynamics experiment on simulated IF.
//!
//! The quick grid is one scenario (10 g turn at 45 dB-Hz, fixed noise seed) tracked by a
//! 2nd-order PLL at 3 Hz unaided and aided by INS 1 (accelerometer bias B) and INS 2 (2B), and
//! by a 1st-order PLL at 18 Hz aided by each INS. The assertions read `study.json`.

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
        "tracked_10g.png",
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
    let n = num(t, &["satellites"]);
    assert!(n >= 8.0, "only {n} satellites simulated\n{ctx}");
    let min = |mode: &str| num(t, &[mode, "tracked_min"]);
    let kept = |mode: &str| num(t, &[mode, "kept"]);

    // Every channel was tracking when the manoeuvre began, so what follows is the manoeuvre's
    // doing, not the pull-in's.
    for mode in ["unaided", "ins1", "ins2"] {
        assert_eq!(num(t, &[mode, "tracked_at_start"]), n, "{mode}\n{ctx}");
    }
    // Seed 004 Fig. 12: unaided, the narrow 2nd-order loop loses satellites under 10 g (the
    // steady-state error 0.2809 a / Bn^2 is tens of cycles at 3 Hz): it must lose some...
    assert!(min("unaided") < n, "unaided kept every satellite\n{ctx}");
    assert!(num(t, &["unaided", "lock_drops"]) >= 1.0, "{ctx}");
    // ...while Fig. 15: aided by either INS it keeps all of them, at every 0.1 s sample.
    for mode in ["ins1", "ins2"] {
        assert_eq!(kept(mode), n, "{mode} did not keep every satellite\n{ctx}");
        assert_eq!(min(mode), n, "{mode}\n{ctx}");
        assert_eq!(num(t, &[mode, "lock_drops"]), 0.0, "{mode}\n{ctx}");
        assert!(min("unaided") < min(mode), "{ctx}");
    }
    // Table 3: the 2nd-order aided loop's phase error std does not depend on the INS bias.
    // 0.7-1.4: the tolerance (the loop is linear and both runs see the same noise, so
    // the measured ratio is 1 to a few parts in 1e3).
    let ratio = num(t, &["phase_std_ratio_ins2_ins1"]);
    assert!((0.7..1.4).contains(&ratio), "std ratio {ratio}\n{ctx}");
    // The std is at the noise level: thermal jitter (oracles.md) at 45 dB-Hz, Bn 3 Hz,
    // T = 1 ms is 0.56 deg = 0.0016 cycle, the oscillator (Allan deviation 1e-11) adds about
    // 144 sigma_A f_L1 / Bn = 0.76 deg = 0.002 cycle; 0.02 cycle (7 deg) would mean dynamics
    // leaking through the aiding.
    let std1 = num(t, &["ins1", "phase_std_cycles"]);
    assert!(
        std1 > 0.0005 && std1 < 0.02,
        "INS 1 phase std {std1}\n{ctx}"
    );
    // Its mean error is the bias's constant 360 B_V / (lambda omega0^2): within 20 % of it for
    // both INS (the digital loop's Bn is within a few % of design at Bn T = 0.003).
    for mode in ["ins1", "ins2"] {
        let m = num(t, &[mode, "mean_abs_phase_error_deg"]);
        let p = num(t, &[mode, "predicted_mean_abs_phase_error_deg"]);
        assert!((m / p - 1.0).abs() < 0.2, "{mode}: mean {m} vs {p}\n{ctx}");
    }
    // 1st-order aided loop: the error grows as 360 B_V t / (lambda omega0), twice as fast with
    // INS 2. Ratio 2 within 20 % and each growth within 20 % of the theory.
    let o1 = &t["order1"];
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
    // ... and its mean |phase error| over the manoeuvre is larger with INS 2.
    let e1 = num(o1, &["ins1", "mean_abs_phase_error_deg"]);
    let e2 = num(o1, &["ins2", "mean_abs_phase_error_deg"]);
    assert!(
        e2 > 1.3 * e1,
        "order 1: INS 1 {e1} deg, INS 2 {e2} deg\n{ctx}"
    );
    // The 2nd-order loop does not grow (its integrator absorbs the bias): at most a tenth of
    // the 1st-order loop's growth with the same INS.
    let g2 = num(t, &["ins2", "phase_error_growth_deg_s"]);
    let g1 = num(o1, &["ins2", "phase_error_growth_deg_s"]);
    assert!(
        g2 < 0.1 * g1,
        "2nd order grows {g2} deg/s vs 1st {g1}\n{ctx}"
    );
    assert!(md.contains("| 10 g turn | 45 | 2 | 3 | INS 1 |"), "{md}");
}
