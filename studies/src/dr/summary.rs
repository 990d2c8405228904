//! Gathers the job results into the study's headline numbers, `study.json` and the report.

use super::cases::{JobResult, OutageStats, SectionStats};
use super::conclusions::conclusions_md;
use super::drive::Drive;
use super::fusion::FusionRun;
use super::params::{CASE3_TILT_DEG, SECTIONS};
use super::plots::{draw_plots, plot_links, write_speed_trace};
use super::speed::{GapResult, SpeedRun};
use super::tables::{intro_md, table};
use super::DrArgs;
use crate::report::StudyReport;
use gpsrx_ins_aiding::SEED000_SF_G_DPS_PER_V;
use serde_json::json;

/// Everything the report needs, sorted out of the job results.
#[derive(Debug, Clone)]
pub struct Gathered<'a> {
    /// Case 1 run and sections (whole drive last).
    pub case1: (&'a FusionRun, &'a [SectionStats]),
    /// Case 3 run and sections.
    pub case3: (&'a FusionRun, &'a [SectionStats]),
    /// Case 2 outages, in job order.
    pub outages: Vec<&'a OutageStats>,
    /// The first outage's run (for the plot).
    pub outage_run: Option<(&'a FusionRun, (f64, f64))>,
    /// Speed-filter gaps per seed on the hilly road.
    pub speed: Vec<(u64, &'a [GapResult])>,
    /// The same on the urban drive.
    pub speed_urban: Vec<(u64, &'a [GapResult])>,
    /// The first seed's speed runs (for the plots): hilly road, urban drive.
    pub speed_run: Option<&'a SpeedRun>,
    /// On the urban drive.
    pub speed_run_urban: Option<&'a SpeedRun>,
    /// Headline numbers.
    pub headline: Headline,
}

/// The three criteria and what goes with them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Headline {
    /// Pooled proposed / conventional mean error over the outages.
    pub case2_ratio: f64,
    /// Pooled mean errors over the outages, m (proposed, conventional).
    pub case2_means_m: (f64, f64),
    /// Largest single-outage ratio.
    pub case2_ratio_max: f64,
    /// Final `Sf_G` estimate of Case 3, deg/s/V.
    pub case3_sf_g: f64,
    /// Its target, `45.045 / cos(20 deg)`.
    pub case3_sf_g_true: f64,
    /// First time after which the estimate stays within 1 % of the target, s.
    pub case3_converged_s: f64,
    /// Pooled RMS speed error over all gaps of the hilly road, m/s (filter, hold).
    pub speed_rms_mps: (f64, f64),
    /// The same on the urban drive.
    pub speed_urban_rms_mps: (f64, f64),
}

/// Pooled RMS (filter, hold) over gaps, weighted by their length.
fn pooled_rms(speed: &[(u64, &[GapResult])]) -> (f64, f64) {
    let (mut f2, mut h2, mut m) = (0.0, 0.0, 0.0);
    for (_, gaps) in speed {
        for r in gaps.iter() {
            let n = r.window.1 - r.window.0;
            f2 += r.rms_filter_mps.powi(2) * n;
            h2 += r.rms_hold_mps.powi(2) * n;
            m += n;
        }
    }
    ((f2 / m).sqrt(), (h2 / m).sqrt())
}

pub(super) fn headline(g: &Gathered) -> Headline {
    let (sp, sc) = g.outages.iter().fold((0.0, 0.0), |(a, b), o| {
        (a + o.proposed.0, b + o.conventional.0)
    });
    let n = g.outages.len().max(1) as f64;
    let ratio_max = g.outages.iter().map(|o| o.ratio()).fold(f64::NAN, f64::max);
    let run3 = g.case3.0;
    let target = SEED000_SF_G_DPS_PER_V / CASE3_TILT_DEG.to_radians().cos();
    let final_sf = run3.sf_g_dps_per_v.last().copied().unwrap_or(f64::NAN);
    let outside = run3
        .sf_g_dps_per_v
        .iter()
        .rposition(|s| ((s - target) / target).abs() > 0.01);
    let converged = match outside {
        None => run3.t_s.first().copied().unwrap_or(f64::NAN),
        Some(i) if i + 1 < run3.t_s.len() => run3.t_s[i + 1],
        Some(_) => f64::NAN,
    };
    Headline {
        case2_ratio: sp / sc,
        case2_means_m: (sp / n, sc / n),
        case2_ratio_max: ratio_max,
        case3_sf_g: final_sf,
        case3_sf_g_true: target,
        case3_converged_s: converged,
        speed_rms_mps: pooled_rms(&g.speed),
        speed_urban_rms_mps: pooled_rms(&g.speed_urban),
    }
}

fn num(v: f64) -> serde_json::Value {
    if v.is_finite() {
        json!(v)
    } else {
        serde_json::Value::Null
    }
}

fn sections_json(s: &[SectionStats]) -> serde_json::Value {
    json!(s
        .iter()
        .map(|x| json!({
            "section": SECTIONS.get(x.index).map_or("all", |s| s.name),
            "t_start_s": x.span.0,
            "t_end_s": x.span.1,
            "proposed_mean_m": num(x.proposed.0),
            "proposed_var_m2": num(x.proposed.1),
            "conventional_mean_m": num(x.conventional.0),
            "conventional_var_m2": num(x.conventional.1),
            "gnss_mean_m": num(x.gnss.0),
            "gnss_var_m2": num(x.gnss.1),
        }))
        .collect::<Vec<_>>())
}

fn gather(results: &[JobResult]) -> anyhow::Result<Gathered<'_>> {
    let mut case1 = None;
    let mut case3 = None;
    let mut outages = Vec::new();
    let mut outage_run = None;
    let mut speed = Vec::new();
    let mut speed_urban = Vec::new();
    let mut speed_run = None;
    let mut speed_run_urban = None;
    for r in results {
        match r {
            JobResult::Drive {
                case: 1,
                run,
                sections,
            } => case1 = Some((run, sections.as_slice())),
            JobResult::Drive { run, sections, .. } => case3 = Some((run, sections.as_slice())),
            JobResult::Outage { stats, run } => {
                if outage_run.is_none() {
                    outage_run = Some((run, stats.window));
                }
                outages.push(stats);
            }
            JobResult::Speed {
                seed,
                hilly,
                gaps,
                run,
            } => {
                let (list, first) = if *hilly {
                    (&mut speed, &mut speed_run)
                } else {
                    (&mut speed_urban, &mut speed_run_urban)
                };
                if first.is_none() {
                    *first = Some(run);
                }
                list.push((*seed, gaps.as_slice()));
            }
        }
    }
    let (Some(case1), Some(case3)) = (case1, case3) else {
        anyhow::bail!("internal: Case 1 or Case 3 missing from the results");
    };
    let mut g = Gathered {
        case1,
        case3,
        outages,
        outage_run,
        speed,
        speed_urban,
        speed_run,
        speed_run_urban,
        headline: Headline {
            case2_ratio: f64::NAN,
            case2_means_m: (f64::NAN, f64::NAN),
            case2_ratio_max: f64::NAN,
            case3_sf_g: f64::NAN,
            case3_sf_g_true: f64::NAN,
            case3_converged_s: f64::NAN,
            speed_rms_mps: (f64::NAN, f64::NAN),
            speed_urban_rms_mps: (f64::NAN, f64::NAN),
        },
    };
    g.headline = headline(&g);
    Ok(g)
}

/// Builds the report and draws the plots into `--out`.
pub(super) fn build_report(
    args: &DrArgs,
    drive: &Drive,
    hilly: &Drive,
    results: &[JobResult],
    elapsed_s: f64,
) -> anyhow::Result<StudyReport> {
    let g = gather(results)?;
    let h = g.headline;
    let plots = draw_plots(&args.common.out, &g)?;
    write_speed_trace(&args.common.out, &g, hilly)?;
    let summary = json!({
        "study": "dr",
        "quick": args.common.quick,
        "seed": args.common.seed,
        "elapsed_s": elapsed_s,
        "drive": {
            "description": drive.description,
            "duration_s": drive.duration_s,
            "distance_m": drive.distance_m(),
        },
        "case2_outage_error_ratio": num(h.case2_ratio),
        "case2_mean_error_proposed_m": num(h.case2_means_m.0),
        "case2_mean_error_conventional_m": num(h.case2_means_m.1),
        "case2_outage_error_ratio_max": num(h.case2_ratio_max),
        "case2_outages": g.outages.iter().map(|o| json!({
            "seed": o.seed,
            "placement": o.placement,
            "set_change_s": o.change_s,
            "outage_start_s": o.window.0,
            "outage_end_s": o.window.1,
            "proposed_mean_m": num(o.proposed.0),
            "proposed_var_m2": num(o.proposed.1),
            "conventional_mean_m": num(o.conventional.0),
            "conventional_var_m2": num(o.conventional.1),
            "proposed_final_m": num(o.final_m.0),
            "conventional_final_m": num(o.final_m.1),
            "ratio": num(o.ratio()),
        })).collect::<Vec<_>>(),
        "case3_gyro_scale_final_dps_per_v": num(h.case3_sf_g),
        "case3_gyro_scale_true_dps_per_v": h.case3_sf_g_true,
        "case3_gyro_scale_error_percent": num(100.0 * (h.case3_sf_g / h.case3_sf_g_true - 1.0)),
        "case3_within_1_percent_from_s": num(h.case3_converged_s),
        "speed_gap_rms_ratio": num(h.speed_rms_mps.0 / h.speed_rms_mps.1),
        "speed_gap_rms_filter_mps": num(h.speed_rms_mps.0),
        "speed_gap_rms_hold_mps": num(h.speed_rms_mps.1),
        "speed_road": {
            "description": hilly.description,
            "duration_s": hilly.duration_s,
            "distance_m": hilly.distance_m(),
        },
        "speed_gap_rms_ratio_urban": num(h.speed_urban_rms_mps.0 / h.speed_urban_rms_mps.1),
        "speed_gap_rms_filter_urban_mps": num(h.speed_urban_rms_mps.0),
        "speed_gap_rms_hold_urban_mps": num(h.speed_urban_rms_mps.1),
        "speed_gaps": g.speed.iter().map(|x| (x, "hilly")).chain(g.speed_urban.iter().map(|x| (x, "urban"))).flat_map(|((seed, gaps), road)| gaps.iter().map(move |r| json!({
            "road": road,
            "seed": seed,
            "start_s": r.window.0,
            "end_s": r.window.1,
            "rms_filter_mps": num(r.rms_filter_mps),
            "rms_hold_mps": num(r.rms_hold_mps),
            "climb_m": num(r.climb_m),
            "speed_change_mps": num(r.speed_change_mps),
        }))).collect::<Vec<_>>(),
        "case1_sections": sections_json(g.case1.1),
        "case3_sections": sections_json(g.case3.1),
    });
    Ok(StudyReport {
        title: "GPS/DR integration with carrier velocity and the GPS/accelerometer speed filter \
                (seeds 000 and 002)"
            .into(),
        intro_md: intro_md(args, drive, hilly),
        table: table(args.common.seed, &g),
        conclusions_md: conclusions_md(&g) + &plot_links(&plots),
        summary,
        plots: Vec::new(),
    })
}
