//! The study's conclusions, computed from its results: every number and every verdict here
//! comes from the cases run.

use super::cases::{Mode, Test, AFTER_BLOCKAGE_S};
use super::measure::{Case, CaseResult};
use crate::report::{fmt, median};
use std::fmt::Write;

/// The threshold gain of vector over scalar tracking Lashley, Bevly and Hung measured
/// (PLANS 2010, 5 to 11 satellites), dB.
pub const LASHLEY_GAIN_DB: (f64, f64) = (2.4, 6.2);
/// The largest error of the first fixes after a blockage issue 29 accepts, m.
pub const BLOCKAGE_MAX_ERROR_M: f64 = 5.0;

/// The result of `mode` on `test`.
pub fn find<'a>(
    results: &'a [(Case, CaseResult)],
    test: &Test,
    mode: Mode,
) -> Option<&'a CaseResult> {
    results
        .iter()
        .find(|(c, _)| c.test == *test && c.mode == mode)
        .map(|(_, r)| r)
}

/// The threshold gain of `mode` over scalar tracking on `test`: (median gain, smallest and
/// largest per satellite), dB, over the satellites both have.
pub fn threshold_gain(
    results: &[(Case, CaseResult)],
    test: &Test,
    mode: Mode,
) -> Option<(f64, f64, f64)> {
    let scalar = find(results, test, Mode::Scalar)?;
    let other = find(results, test, mode)?;
    let per: Vec<f64> = scalar
        .thresholds_dbhz
        .iter()
        .filter_map(|(p, s)| {
            let o = other.thresholds_dbhz.iter().find(|(q, _)| q == p)?;
            Some(s - o.1)
        })
        .collect();
    if per.is_empty() {
        return None;
    }
    let med = median(
        &scalar
            .thresholds_dbhz
            .iter()
            .map(|x| x.1)
            .collect::<Vec<_>>(),
    ) - median(
        &other
            .thresholds_dbhz
            .iter()
            .map(|x| x.1)
            .collect::<Vec<_>>(),
    );
    let lo = per.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = per.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some((med, lo, hi))
}

/// Where `gain_db` falls against Lashley et al.'s range.
fn against_lashley(gain_db: f64) -> &'static str {
    if gain_db < LASHLEY_GAIN_DB.0 {
        "below"
    } else if gain_db > LASHLEY_GAIN_DB.1 {
        "above"
    } else {
        "within"
    }
}

/// The conclusions in Markdown.
pub fn conclusions_md(results: &[(Case, CaseResult)], tests: &[Test], seed: u64) -> String {
    let mut md = String::from("## Conclusions (computed from the cases above)\n\n");
    for test in tests {
        match test {
            Test::Fade { .. } => fade(&mut md, results, test),
            Test::Blockage => blockage(&mut md, results, test),
            Test::Turn { g } => turn(&mut md, results, test, *g),
        }
    }
    let _ = writeln!(
        md,
        "Measured on one noise seed ({seed}) and one simulated sky; `--seed N` runs another."
    );
    md
}

fn fade(md: &mut String, results: &[(Case, CaseResult)], test: &Test) {
    let Some(scalar) = find(results, test, Mode::Scalar) else {
        return;
    };
    let th: Vec<f64> = scalar.thresholds_dbhz.iter().map(|x| x.1).collect();
    let _ = write!(
        md,
        "- **Threshold** ({}): scalar tracking holds its {} satellites down to a median {} dB-Hz (true C/N0 at each one's last observables).",
        test.label(),
        th.len(),
        fmt(median(&th), 1)
    );
    for mode in [Mode::Vector, Mode::VectorIns, Mode::ScalarAided] {
        if let Some((gain, lo, hi)) = threshold_gain(results, test, mode) {
            let _ = write!(
                md,
                " {}: {} dB lower (per satellite {} to {} dB){}.",
                mode.label(),
                fmt(gain, 1),
                fmt(lo, 1),
                fmt(hi, 1),
                if mode.is_vector() {
                    format!(
                        ", {} Lashley, Bevly and Hung's {}-{} dB",
                        against_lashley(gain),
                        LASHLEY_GAIN_DB.0,
                        LASHLEY_GAIN_DB.1
                    )
                } else {
                    String::new()
                }
            );
        }
    }
    let tracking = gpsrx_receiver::ReceiverConfig::default().tracking;
    let _ = writeln!(
        md,
        " On a static receiver an INS has no dynamics to take out of the loops; what lowers the vector threshold is the filter's check, which lets a checked channel count as lost only below {} dB-Hz (an unchecked one below {} dB-Hz), and the narrower loops its prediction allows.",
        fmt(tracking.vector_cn0_lost_dbhz, 0),
        fmt(tracking.cn0_lost_dbhz, 0)
    );
}

fn blockage(md: &mut String, results: &[(Case, CaseResult)], test: &Test) {
    let _ = write!(md, "- **{}** of every satellite:", test.label());
    for mode in Mode::ALL {
        let Some(r) = find(results, test, mode) else {
            continue;
        };
        let back = r
            .back_s
            .map_or(format!("no valid fix within {AFTER_BLOCKAGE_S} s"), |b| {
                format!("first valid fix {} s after the return", fmt(b, 2))
            });
        let err = r.max_error_after_m.map_or(String::new(), |e| {
            format!(
                ", 3-D error of the fixes in the {AFTER_BLOCKAGE_S} s after it at most {} m ({} the {BLOCKAGE_MAX_ERROR_M} m of issue 29)",
                fmt(e, 1),
                if e <= BLOCKAGE_MAX_ERROR_M { "within" } else { "over" }
            )
        });
        let _ = write!(
            md,
            " {}: {back}{err}, {} channel(s) released;",
            mode.label(),
            r.lost.len()
        );
    }
    md.pop();
    md.push_str(".\n");
}

fn turn(md: &mut String, results: &[(Case, CaseResult)], test: &Test, g: f64) {
    let _ = write!(
        md,
        "- **A {g:.0} g turn** (250 m/s; the INS biased 1 mg): satellites locked through it of those locked before:"
    );
    let mut all = Vec::new();
    for mode in Mode::ALL {
        let Some(r) = find(results, test, mode) else {
            continue;
        };
        let (kept, of) = (r.locked_through.len(), r.locked_before.len());
        all.push((mode, kept, of));
        let _ = write!(md, " {} {kept} of {of};", mode.label());
    }
    md.pop();
    md.push('.');
    let kept_by = |mode| all.iter().find(|a| a.0 == mode).map(|a| a.1);
    if let (Some(v), Some(s)) = (kept_by(Mode::Vector), kept_by(Mode::Scalar)) {
        if v < s {
            let _ = write!(
                md,
                " Vector tracking alone keeps fewer than scalar tracking: its prediction has no acceleration, so it hands the channels back at the onset, and the weak ones, on its narrow loops until then, fall out."
            );
        }
    }
    if let Some(&(_, kept, of)) = all.iter().find(|a| a.0 == Mode::VectorIns) {
        let _ = write!(
            md,
            " Vector + INS {}.",
            if kept == of && of > 0 {
                "kept every satellite".to_string()
            } else {
                format!("lost {} satellite(s)", of - kept)
            }
        );
    }
    md.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fade_case(mode: Mode, th: &[(u8, f64)]) -> (Case, CaseResult) {
        (
            Case {
                test: Test::Fade {
                    db_per_s: -1.0,
                    end_s: 26.0,
                },
                mode,
            },
            CaseResult {
                thresholds_dbhz: th.to_vec(),
                ..CaseResult::default()
            },
        )
    }

    #[test]
    fn the_threshold_gain_and_its_verdict_follow_the_numbers() {
        let test = Test::Fade {
            db_per_s: -1.0,
            end_s: 26.0,
        };
        let results = vec![
            fade_case(Mode::Scalar, &[(1, 25.0), (2, 25.4), (3, 24.8)]),
            fade_case(Mode::Vector, &[(1, 22.0), (2, 21.0), (3, 23.8)]),
        ];
        let (gain, lo, hi) =
            threshold_gain(&results, &test, Mode::Vector).unwrap_or_else(|| panic!("no gain"));
        assert!((gain - 3.0).abs() < 1e-9, "{gain}");
        assert!(
            (lo - 1.0).abs() < 1e-9 && (hi - 4.4).abs() < 1e-9,
            "{lo} {hi}"
        );
        let md = conclusions_md(&results, &[test], 1);
        assert!(md.contains("vector: 3.0 dB lower"), "{md}");
        assert!(md.contains("within Lashley"), "{md}");
        // A smaller gain is called what it is.
        let small = vec![
            fade_case(Mode::Scalar, &[(1, 25.0)]),
            fade_case(Mode::Vector, &[(1, 24.0)]),
        ];
        let md = conclusions_md(&small, &[test], 1);
        assert!(
            md.contains("1.0 dB lower") && md.contains("below Lashley"),
            "{md}"
        );
    }

    #[test]
    fn a_turn_verdict_counts_the_satellites() {
        let test = Test::Turn { g: 10.0 };
        let case = |mode, through: &[u8]| {
            (
                Case { test, mode },
                CaseResult {
                    locked_before: vec![1, 2, 3],
                    locked_through: through.to_vec(),
                    ..CaseResult::default()
                },
            )
        };
        let md = conclusions_md(
            &[case(Mode::Vector, &[1]), case(Mode::VectorIns, &[1, 2, 3])],
            &[test],
            1,
        );
        assert!(
            md.contains("vector 1 of 3") && md.contains("kept every satellite"),
            "{md}"
        );
        assert!(!md.contains("fewer than scalar"), "{md}");
        let md = conclusions_md(
            &[case(Mode::Scalar, &[1, 2, 3]), case(Mode::Vector, &[1])],
            &[test],
            1,
        );
        assert!(md.contains("keeps fewer than scalar"), "{md}");
        let md = conclusions_md(&[case(Mode::VectorIns, &[1, 2])], &[test], 1);
        assert!(md.contains("lost 1 satellite"), "{md}");
    }

    #[test]
    fn the_median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median(&[1.0, 3.0, 2.0, 10.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
