//! `gpsrx study dr --quick`: seed 000's GPS/DR cases and seed 002's speed filter on the
//! simulated urban drive (and seed 002's hilly road), through the gpsrx command line.
//!
//! The quick run has Cases 1 and 3, Case 2 at three outage placements (60, 90 and 120 s, five
//! seconds after a satellite-set change) and the speed filter through 20-60 s gaps, one noise
//! seed. The assertions read `study.json` and check the files.

use serde_json::Value;
use std::time::Instant;

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number: {}", v[key]))
}

#[test]
fn quick_dr_study_reproduces_seeds_000_and_002() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("dr");
    let started = Instant::now();
    crate::run_study(&["dr", "--quick", "--seed", "3"], &out);
    eprintln!("quick dr study: {:.1} s", started.elapsed().as_secs_f64());
    for f in [
        "study.md",
        "study.csv",
        "study.json",
        "speed_trace.csv",
        "position_error_outage.png",
        "position_error_case1.png",
        "position_error_case3.png",
        "gyro_scale_case3.png",
        "speed_error_gaps.png",
        "speed_error_gaps_urban.png",
    ] {
        let p = out.join(f);
        let len = std::fs::metadata(&p)
            .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
            .len();
        assert!(len > 1000, "{f} is nearly empty ({len} bytes)");
    }
    let md = std::fs::read_to_string(out.join("study.md")).unwrap_or_else(|e| panic!("{e}"));
    let json: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("study.json")).unwrap_or_else(|e| panic!("{e}")),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let ctx = format!("{json:#}");

    // The drive is the urban scenario: 20-30 minutes, 12-18 km.
    let drive = &json["drive"];
    assert!(
        (1200.0..=1800.0).contains(&num(drive, "duration_s")),
        "{ctx}"
    );
    assert!(
        (12_000.0..18_000.0).contains(&num(drive, "distance_m")),
        "{ctx}"
    );

    // Case 2 (seed 000 Table 2, 74 m vs 187 m): the proposed filter's mean error over outages
    // right after a satellite-set change is at most half the conventional one's, pooled over the
    // placements, and every placement is reported.
    let ratio = num(&json, "case2_outage_error_ratio");
    assert!(ratio > 0.0 && ratio <= 0.5, "Case 2 ratio {ratio}\n{ctx}");
    let outages = json["case2_outages"]
        .as_array()
        .unwrap_or_else(|| panic!("no case2_outages\n{ctx}"));
    assert_eq!(outages.len(), 3, "{ctx}");
    let mut lengths: Vec<f64> = outages
        .iter()
        .map(|o| num(o, "outage_end_s") - num(o, "outage_start_s"))
        .collect();
    lengths.sort_by(f64::total_cmp);
    assert_eq!(lengths, vec![60.0, 90.0, 120.0], "{ctx}");
    for o in outages {
        // Each starts 5 s after its satellite-set change; the conventional filter's error grows
        // through it (tens of metres by the end), the proposed one stays near GNSS level.
        assert!(
            (num(o, "outage_start_s") - num(o, "set_change_s") - 5.0).abs() < 1e-9,
            "{ctx}"
        );
        assert!(num(o, "conventional_final_m") > 20.0, "{o}");
        assert!(
            num(o, "proposed_mean_m") < num(o, "conventional_mean_m"),
            "{o}"
        );
    }

    // Case 3 (Fig. 6b): the tilted gyro's scale factor converges to 45.045 / cos 20 deg.
    let target = 45.045 / 20f64.to_radians().cos();
    assert!((target - 47.936).abs() < 5e-4);
    let sf = num(&json, "case3_gyro_scale_final_dps_per_v");
    assert!(
        ((sf - target) / target).abs() < 0.01,
        "Sf_G {sf} vs {target}\n{ctx}"
    );
    assert!(
        (num(&json, "case3_gyro_scale_true_dps_per_v") - target).abs() < 1e-9,
        "{ctx}"
    );

    // Case 1 (Table 1): fusion beats GNSS alone and the proposed filter beats the conventional
    // one over the whole drive.
    let all1 = json["case1_sections"]
        .as_array()
        .and_then(|a| a.last())
        .unwrap_or_else(|| panic!("no case1_sections\n{ctx}"));
    assert_eq!(all1["section"], "all", "{ctx}");
    assert!(
        num(all1, "proposed_mean_m") < num(all1, "conventional_mean_m"),
        "{all1}"
    );
    assert!(
        num(all1, "proposed_mean_m") < num(all1, "gnss_mean_m"),
        "{all1}"
    );
    assert!(
        num(all1, "proposed_var_m2") < num(all1, "gnss_var_m2"),
        "{all1}"
    );

    // Speed filter (seed 002): RMS over 20-60 s gaps at most half of holding the last speed.
    let speed = num(&json, "speed_gap_rms_ratio");
    assert!(speed > 0.0 && speed <= 0.5, "speed ratio {speed}\n{ctx}");
    // The urban drive's figure is reported too (its steep short hills cost the filter more).
    assert!(num(&json, "speed_gap_rms_ratio_urban") > 0.0, "{ctx}");

    // The report carries the tables and the conclusions.
    for needle in [
        "case2_outage_error_ratio",
        "speed_gap_rms_ratio",
        "47.936",
        "| O-A |",
        "What differs from the papers",
        "position_error_outage.png",
    ] {
        assert!(md.contains(needle), "study.md lacks {needle}\n{md}");
    }
}
