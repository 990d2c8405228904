//! The conclusions follow the measured numbers: built from synthetic results (no drive is
//! simulated), one measured input perturbed at a time, the sentences change with it.

use super::cases::{OutageStats, SectionStats};
use super::conclusions::conclusions_md;
use super::fusion::FusionRun;
use super::params::SECTIONS;
use super::speed::GapResult;
use super::summary::{headline, Gathered, Headline};
use gpsrx_ins_aiding::SEED000_SF_G_DPS_PER_V;

fn section(index: usize, proposed: f64, conventional: f64, gnss: f64) -> SectionStats {
    SectionStats {
        index,
        span: (0.0, 100.0),
        proposed: (proposed, 2.0),
        conventional: (conventional, 4.0),
        gnss: (gnss, 8.0),
    }
}

fn outage(proposed: f64, conventional: f64) -> OutageStats {
    OutageStats {
        seed: 1,
        placement: 0,
        change_s: 400.0,
        window: (405.0, 465.0),
        proposed: (proposed, 1.0),
        conventional: (conventional, 10.0),
        final_m: (proposed, conventional),
    }
}

fn gap(filter: f64, hold: f64) -> GapResult {
    GapResult {
        window: (100.0, 140.0),
        rms_filter_mps: filter,
        rms_hold_mps: hold,
        climb_m: 5.0,
        speed_change_mps: -3.0,
    }
}

/// A Case 3 run whose gyro scale estimate reaches the tilted truth at `t_conv` s (from 1 %
/// off before it), over 0-1700 s.
fn case3_run(t_conv: f64) -> FusionRun {
    let target = SEED000_SF_G_DPS_PER_V / 20f64.to_radians().cos();
    let t_s: Vec<f64> = (0..=1700).map(f64::from).collect();
    let sf = t_s
        .iter()
        .map(|&t| if t < t_conv { 0.95 * target } else { target })
        .collect();
    FusionRun {
        t_s,
        sf_g_dps_per_v: sf,
        ..FusionRun::default()
    }
}

struct Inputs {
    case1: Vec<SectionStats>,
    case3: Vec<SectionStats>,
    run3: FusionRun,
    outages: Vec<OutageStats>,
    hilly: Vec<GapResult>,
    urban: Vec<GapResult>,
}

impl Inputs {
    fn new() -> Self {
        let whole = SECTIONS.len();
        Self {
            case1: vec![section(0, 3.0, 4.0, 5.0), section(whole, 3.4, 4.6, 5.3)],
            case3: vec![section(whole, 3.5, 5.0, 5.3)],
            run3: case3_run(40.0),
            outages: vec![outage(5.0, 50.0), outage(5.0, 40.0)],
            hilly: vec![gap(2.0, 6.0)],
            urban: vec![gap(4.7, 6.7), gap(20.0, 8.0)],
        }
    }

    fn md(&self) -> String {
        let empty = Headline {
            case2_ratio: f64::NAN,
            case2_means_m: (f64::NAN, f64::NAN),
            case2_ratio_max: f64::NAN,
            case3_sf_g: f64::NAN,
            case3_sf_g_true: f64::NAN,
            case3_converged_s: f64::NAN,
            speed_rms_mps: (f64::NAN, f64::NAN),
            speed_urban_rms_mps: (f64::NAN, f64::NAN),
        };
        let mut g = Gathered {
            case1: (&self.run3, &self.case1),
            case3: (&self.run3, &self.case3),
            outages: self.outages.iter().collect(),
            outage_run: None,
            speed: vec![(1, self.hilly.as_slice())],
            speed_urban: vec![(1, self.urban.as_slice())],
            speed_run: None,
            speed_run_urban: None,
            headline: empty,
        };
        g.headline = headline(&g);
        conclusions_md(&g)
    }
}

#[test]
fn the_outage_ratio_is_compared_with_the_paper_by_its_value() {
    let mut x = Inputs::new();
    let md = x.md();
    // 10 m over 90 m: 0.111, below the paper's 0.40.
    assert!(md.contains("**case2_outage_error_ratio = 0.111**"), "{md}");
    assert!(
        md.contains("(single outages 0.100-0.125, median 0.113), below the paper's 0.40"),
        "{md}"
    );
    assert!(
        md.contains("its outage ratio is 0.111 (below the paper's 0.40)"),
        "{md}"
    );
    assert!(md.contains("cheaper in outages"), "{md}");
    // The conventional filter no worse than the proposed one: above the paper's.
    x.outages = vec![outage(30.0, 40.0), outage(30.0, 50.0)];
    let md = x.md();
    assert!(md.contains("= 0.667**"), "{md}");
    assert!(md.contains("above the paper's 0.40"), "{md}");
    assert!(!md.contains("cheaper in outages"), "{md}");
}

#[test]
fn the_calibration_time_is_measured_not_quoted() {
    let mut x = Inputs::new();
    let md = x.md();
    assert!(
        md.contains("within 1 % from t = 40 s on (earlier than the paper's"),
        "{md}"
    );
    assert!(md.contains("faster to calibrate"), "{md}");
    x.run3 = case3_run(1200.0);
    let md = x.md();
    assert!(md.contains("from t = 1200 s on (not earlier than"), "{md}");
    assert!(!md.contains("faster to calibrate"), "{md}");
    // Never converged: said so, no time claimed.
    x.run3 = case3_run(2000.0);
    let md = x.md();
    assert!(md.contains("never staying within 1 %"), "{md}");
    assert!(md.contains("never stays within 1 %"), "{md}");
}

#[test]
fn case1_and_the_speed_filter_follow_the_numbers() {
    let mut x = Inputs::new();
    let md = x.md();
    assert!(md.contains("(74 %: the proposed filter is better"), "{md}");
    assert!(
        md.contains("(GNSS 8.0 m^2, below it): so fusion smooths"),
        "{md}"
    );
    assert!(
        md.contains("ratio = 0.333**, the filter is better than holding"),
        "{md}"
    );
    // The urban drive's worst gap is found from the gaps, not quoted.
    assert!(
        md.contains("cost the filter 20.00 m/s RMS against 8.00 m/s holding"),
        "{md}"
    );
    assert!(
        md.contains("the paper's whole-drive mean errors are"),
        "{md}"
    );
    // Proposed worse than conventional, variance above GNSS, filter worse than holding.
    x.case1[1] = SectionStats {
        proposed: (5.0, 9.0),
        ..section(SECTIONS.len(), 5.0, 4.6, 5.3)
    };
    x.hilly = vec![gap(7.0, 6.0)];
    x.urban.pop();
    let md = x.md();
    assert!(md.contains("the proposed filter is not better"), "{md}");
    assert!(md.contains("above it): so fusion does not smooth"), "{md}");
    assert!(md.contains("the filter is not better than holding"), "{md}");
    assert!(md.contains("cost the filter 4.70 m/s RMS"), "{md}");
}
