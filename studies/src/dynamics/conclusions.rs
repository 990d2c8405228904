//! The conclusions of `study.md` on the 10 g turn: satellites kept unaided and aided at 0.4 Hz
//! (seed 004 Figs. 12/15), the narrowest unaided loop that holds every satellite, and the
//! 1st-order aided loop. Every statement is chosen by the numbers; Table 3 is in
//! [`super::table3_md`].

use super::aiding::Aiding;
use super::headline::{always_lost_before, cn0s, Headline, Trio, TEN_G};
use super::params::HEADLINE_BN_HZ;
use super::result::CaseResult;
use super::table3_md::table3_md;
use gpsrx_dsp::constants::LAMBDA_L1_M;

/// Phase error at which a Costas loop slips, cycles.
pub(super) const COSTAS_SLIP_CYCLES: f64 = 0.25;

/// All the conclusions on the 10 g turn.
pub(super) fn conclusions_md(results: &[CaseResult]) -> String {
    let h = Headline::new(results);
    let mut s = String::new();
    for cn0 in cn0s(results).iter().rev() {
        let at = Headline::at(results, *cn0);
        for (t, order) in [(&at.order2, 2u8), (&at.order3, 3)] {
            s += &figs_md(t, order, *cn0);
        }
    }
    s += &narrowest_md(results);
    s += &table3_md(results);
    s += &order1_md(results, &h);
    s
}

/// Seed 004 Figs. 12/15 for one loop order at 0.4 Hz: unaided vs INS 1 vs INS 2.
pub(super) fn figs_md(t: &Trio<'_>, order: u8, cn0: f64) -> String {
    let (Some(u), Some(i1), Some(i2)) = (t.unaided, t.ins1, t.ins2) else {
        return String::new();
    };
    let n = u.satellites;
    let mut s = format!(
        "**10 g turn, {cn0} dB-Hz, order-{order} PLL at Bn = {HEADLINE_BN_HZ} Hz (seed 004 Figs. \
12/15).** "
    );
    if u.kept == n {
        s += &format!("Unaided, the loop kept every satellite ({n}) through the turn. ");
    } else {
        s += &format!(
            "Unaided, the loop kept {} of {n} satellites through the turn (fewest tracked {}, \
mean {:.1}; {} lock drops, {} channels lost)",
            u.kept, u.tracked_min, u.tracked_mean, u.lock_drops, u.channels_lost
        );
        if u.tracked_at_start < n {
            s += &format!(
                "; {} of them were already lost before the turn began",
                n - u.tracked_at_start
            );
            if order == 2 {
                s += &lead_in_cause(u);
            }
        } else {
            s += "; all were tracking when the turn began, so the turn dropped them";
        }
        s += ". ";
    }
    s += &format!(
        "Aided by INS 1 it kept {} of {n} (fewest {}, {} lock drops), by INS 2 {} (fewest {}, \
{} lock drops). ",
        i1.kept, i1.tracked_min, i1.lock_drops, i2.kept, i2.tracked_min, i2.lock_drops
    );
    let aided_min = i1.tracked_min.min(i2.tracked_min);
    s += &if i1.kept > u.kept && i2.kept > u.kept {
        format!(
            "Aiding kept more satellites than the unaided loop (fewest {aided_min} aided vs {} \
unaided), as in seed 004 (as few as 4 unaided, Fig. 12; at least 8 aided, Fig. 15).\n\n",
            u.tracked_min
        )
    } else {
        format!(
            "Aiding did not keep more satellites than the unaided loop here (fewest {aided_min} \
aided vs {} unaided; seed 004: as few as 4 unaided, at least 8 aided).\n\n",
            u.tracked_min
        )
    };
    s
}

/// Whether the satellites' own line-of-sight acceleration explains an unaided 2nd-order loop's
/// losses before the manoeuvre: its steady-state error `0.2809 a / Bn^2` (Kaplan 5.2.2) against
/// the Costas loop's slip at 0.25 cycle.
fn lead_in_cause(u: &CaseResult) -> String {
    let a = u.lead_in_accel_max_mps2;
    let e = 0.2809 * a / (u.case.bn_hz * u.case.bn_hz) / LAMBDA_L1_M;
    if e > COSTAS_SLIP_CYCLES {
        format!(
            ", as the satellites' own line-of-sight acceleration predicts: up to {a:.3} m/s^2 \
here, a steady-state error 0.2809 a / Bn^2 of {e:.2} cycle, past the Costas loop's \
{COSTAS_SLIP_CYCLES}"
        )
    } else {
        format!(
            ", which the satellites' own line-of-sight acceleration (up to {a:.3} m/s^2, \
{e:.2} cycle of steady-state error) does not explain"
        )
    }
}

/// The narrowest unaided loop that holds every satellite, found from the grid: per C/N0 and
/// order, over the 10 g turn, through the turn and before it.
pub(super) fn narrowest_md(results: &[CaseResult]) -> String {
    let mut parts = Vec::new();
    for cn0 in cn0s(results) {
        for order in [2u8, 3] {
            let mut unaided: Vec<&CaseResult> = results
                .iter()
                .filter(|r| {
                    r.spec.manoeuvre == TEN_G
                        && r.spec.cn0_dbhz == cn0
                        && r.case.order == order
                        && r.case.aiding == Aiding::Unaided
                })
                .collect();
            if unaided.is_empty() {
                continue;
            }
            unaided.sort_by(|a, b| a.case.bn_hz.total_cmp(&b.case.bn_hz));
            let tried: Vec<String> = unaided.iter().map(|r| r.case.bn_hz.to_string()).collect();
            // Satellites no case tracked into the manoeuvre at this C/N0 are left out.
            let always = always_lost_before(results, cn0);
            let skip = always.len();
            let left_out = if always.is_empty() {
                String::new()
            } else {
                let p: Vec<String> = always.iter().map(|p| format!("G{p:02}")).collect();
                format!(
                    ", leaving out {} (never tracked into the turn)",
                    p.join(", ")
                )
            };
            let narrowest = |held: &dyn Fn(&CaseResult) -> bool| {
                unaided
                    .iter()
                    .find(|r| held(r))
                    .map_or("none".to_string(), |r| format!("{} Hz", r.case.bn_hz))
            };
            parts.push(format!(
                "order {order} at {cn0} dB-Hz (Bn tried: {} Hz{left_out}): through the turn {}, \
before it {}",
                tried.join(", "),
                narrowest(&|r| r.kept + skip == r.satellites),
                narrowest(&|r| r.tracked_at_start + skip == r.satellites),
            ));
        }
    }
    if parts.is_empty() {
        return String::new();
    }
    format!(
        "**Narrowest unaided loop that held every satellite** (10 g turn; found from the runs): \
{}.\n\n",
        parts.join("; ")
    )
}

/// The aided 1st-order loop: growth with the bias against theory, and against a 2nd-order loop
/// aided by the same INS.
fn order1_md(results: &[CaseResult], h: &Headline<'_>) -> String {
    let (Some(a), Some(b)) = (h.order1.ins1, h.order1.ins2) else {
        return String::new();
    };
    let gr = h.order1.ratio(|r| r.growth_abs_deg_s);
    let mut s = format!(
        "**1st-order aided loop (Bn = {bn} Hz, {cn0} dB-Hz).** Its error grows at {g1:.3} deg/s \
with INS 1 and {g2:.3} deg/s with INS 2 (ratio {gr:.2}; theory 360 B_V / (lambda omega0): \
{tg1:.3} and {tg2:.3} deg/s, ratio 2); mean |phase error| over the manoeuvre {e1:.2} and {e2:.2} \
deg (theory {t1:.2} and {t2:.2} deg); satellites kept {k1} and {k2} of {n}, lock drops {l1} and \
{l2}. ",
        bn = a.case.bn_hz,
        cn0 = h.cn0_dbhz,
        g1 = a.growth_abs_deg_s,
        g2 = b.growth_abs_deg_s,
        tg1 = a.predicted_growth_deg_s,
        tg2 = b.predicted_growth_deg_s,
        e1 = a.disc_mean_abs_deg,
        e2 = b.disc_mean_abs_deg,
        t1 = a.predicted_mean_abs_deg,
        t2 = b.predicted_mean_abs_deg,
        k1 = a.kept,
        k2 = b.kept,
        n = a.satellites,
        l1 = a.lock_drops,
        l2 = b.lock_drops,
    );
    let within = |m: f64, p: f64| (m / p - 1.0).abs() < 0.2;
    s += if (1.6..2.4).contains(&gr)
        && within(a.growth_abs_deg_s, a.predicted_growth_deg_s)
        && within(b.growth_abs_deg_s, b.predicted_growth_deg_s)
    {
        "The growth follows the theory within 20 % and doubles with the bias: the bias is a \
Doppler ramp (seed 004 Table 1 gives the 1st-order entry as a constant). "
    } else {
        "The growth does not follow the theory within 20 % or does not double with the bias. "
    };
    // A 2nd-order loop aided by INS 2 over the same scenario (the same bias if there is one).
    let second = results
        .iter()
        .filter(|r| {
            r.spec == b.spec
                && r.case.order == 2
                && r.case.aiding == Aiding::Ins2
                && r.growth_abs_deg_s.is_finite()
        })
        .min_by(|x, y| {
            let d = |r: &CaseResult| (r.case.ins1_bias_mps2 - b.case.ins1_bias_mps2).abs();
            d(x).total_cmp(&d(y))
        });
    if let Some(r) = second {
        let bias_mg = r.case.bias_mps2() / super::params::MG_MPS2;
        s += &if r.growth_abs_deg_s < 0.1 * b.growth_abs_deg_s {
            format!(
                "A 2nd-order loop aided by an INS 2 of {bias_mg:.1} mg (Bn {} Hz) grows at only \
{:.3} deg/s: an aided loop needs order >= 2, seed 004's conclusion.",
                r.case.bn_hz, r.growth_abs_deg_s
            )
        } else {
            format!(
                "A 2nd-order loop aided by an INS 2 of {bias_mg:.1} mg (Bn {} Hz) grows at {:.3} \
deg/s, not less than a tenth of the 1st-order loop's.",
                r.case.bn_hz, r.growth_abs_deg_s
            )
        };
    }
    s + "\n\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::grid::{Case, ScenarioSpec};
    use crate::dynamics::params::MG_MPS2;
    use crate::dynamics::result::test_result;

    const N: usize = 10;

    fn spec() -> ScenarioSpec {
        ScenarioSpec {
            manoeuvre: TEN_G,
            cn0_dbhz: 45.0,
            lead_in_s: 13.0,
        }
    }

    /// Orders 2 and 3 at 0.4 Hz (unaided, INS 1 and INS 2 of 1 mg) and unaided at 3 Hz, every
    /// satellite kept, INS 2's discriminator std `ratio` times INS 1's.
    fn results(ratio: f64) -> Vec<CaseResult> {
        let mut out = Vec::new();
        for order in [2u8, 3] {
            for (aiding, std) in [
                (Aiding::Unaided, 0.1),
                (Aiding::Ins1, 0.09),
                (Aiding::Ins2, 0.09 * ratio),
            ] {
                let case = Case {
                    order,
                    bn_hz: HEADLINE_BN_HZ,
                    aiding,
                    ins1_bias_mps2: if aiding == Aiding::Unaided {
                        0.0
                    } else {
                        MG_MPS2
                    },
                };
                out.push(test_result(spec(), case, N, std));
            }
            let wide = Case {
                order,
                bn_hz: 3.0,
                aiding: Aiding::Unaided,
                ins1_bias_mps2: 0.0,
            };
            out.push(test_result(spec(), wide, N, 0.02));
        }
        out
    }

    /// Makes the unaided 2nd-order 0.4 Hz loop lose `lost` satellites in the turn.
    fn lose(results: &mut [CaseResult], lost: usize) {
        for r in results.iter_mut().filter(|r| {
            r.case.order == 2 && r.case.bn_hz == HEADLINE_BN_HZ && r.case.aiding == Aiding::Unaided
        }) {
            r.kept = N - lost;
            r.tracked_min = N - lost;
            r.lock_drops = lost as u32;
        }
    }

    #[test]
    fn the_satellite_conclusions_follow_the_numbers() {
        let mut r = results(1.0);
        let md = conclusions_md(&r);
        assert!(
            md.contains("Unaided, the loop kept every satellite (10)"),
            "{md}"
        );
        assert!(
            md.contains("order 2 at 45 dB-Hz (Bn tried: 0.4, 3 Hz): through the turn 0.4 Hz"),
            "{md}"
        );
        assert!(md.contains("did not keep more satellites"), "{md}");
        lose(&mut r, 6);
        let md = conclusions_md(&r);
        assert!(
            md.contains("Unaided, the loop kept 4 of 10 satellites"),
            "{md}"
        );
        assert!(md.contains("so the turn dropped them"), "{md}");
        assert!(
            md.contains("through the turn 3 Hz, before it 0.4 Hz"),
            "{md}"
        );
        assert!(
            md.contains("Aiding kept more satellites than the unaided loop"),
            "{md}"
        );
        // Lost before the turn: the satellites' own acceleration (0.1 m/s^2: 0.92 cycle at
        // 0.4 Hz) explains it.
        for x in r.iter_mut().filter(|x| x.case.order == 2 && x.kept < N) {
            x.tracked_at_start = 7;
        }
        let md = conclusions_md(&r);
        assert!(
            md.contains("3 of them were already lost before the turn began, as the"),
            "{md}"
        );
        assert!(md.contains("before it 3 Hz"), "{md}");
    }

    #[test]
    fn the_table3_conclusions_follow_the_numbers() {
        let md = conclusions_md(&results(1.0));
        assert!(md.contains("(0 of 1 within the paper's 1.09-1.17)"), "{md}");
        assert!(md.contains("The bias does not change the std"), "{md}");
        assert!(md.contains("overlapping the paper's"), "{md}");
        let md = conclusions_md(&results(1.12));
        assert!(md.contains("INS 2 / INS 1 discriminator std 1.120"), "{md}");
        assert!(md.contains("(1 of 1 within the paper's 1.09-1.17)"), "{md}");
        assert!(!md.contains("The bias does not change the std"), "{md}");
        // One INS pair: no trend with the bias is claimed.
        assert!(!md.contains("rise"), "{md}");
        // Equal phase std against the truth: the discriminator is the cause.
        assert!(
            md.contains("comes from the discriminator, not from the loop"),
            "{md}"
        );
        let md = conclusions_md(&results(1.3));
        assert!(md.contains("(0 of 1 within the paper's"), "{md}");
        // Nothing tracked in the window: no ratio, no claim about the bias.
        let mut r = results(1.0);
        for x in r.iter_mut().filter(|x| x.case.aiding != Aiding::Unaided) {
            x.disc_std_cycles = f64::NAN;
            x.phase_std_cycles = f64::NAN;
            x.kept = 0;
        }
        let md = conclusions_md(&r);
        assert!(
            md.contains("no satellite was tracked through the window"),
            "{md}"
        );
        assert!(!md.contains("The bias does not change the std"), "{md}");
    }

    #[test]
    fn a_satellite_no_case_tracked_is_left_out_of_the_narrowest_loop() {
        let mut r = results(1.0);
        for x in r.iter_mut() {
            x.lost_before_prns = vec![1];
            x.tracked_at_start = N - 1;
            x.kept = N - 1;
        }
        let md = conclusions_md(&r);
        assert!(
            md.contains("leaving out G01 (never tracked into the turn)): through the turn 0.4 Hz"),
            "{md}"
        );
    }

    /// The aided 1st-order loops (INS 1 and INS 2) growing at `g1` and `g2` deg/s against the
    /// theory's 0.1 and 0.2 deg/s, and a 2nd-order loop aided by INS 2 growing at `g_o2`.
    fn order1_results(g1: f64, g2: f64, g_o2: f64) -> Vec<CaseResult> {
        use crate::dynamics::params::ORDER1_BN_HZ;
        let mut out = Vec::new();
        for (order, aiding, g, p) in [
            (1u8, Aiding::Ins1, g1, 0.1),
            (1, Aiding::Ins2, g2, 0.2),
            (2, Aiding::Ins2, g_o2, 0.0),
        ] {
            let case = Case {
                order,
                bn_hz: ORDER1_BN_HZ,
                aiding,
                ins1_bias_mps2: 0.05,
            };
            let mut r = test_result(spec(), case, N, 0.09);
            r.growth_abs_deg_s = g;
            r.predicted_growth_deg_s = p;
            r.disc_mean_abs_deg = 1.0;
            r.predicted_mean_abs_deg = 1.0;
            out.push(r);
        }
        out
    }

    #[test]
    fn the_order1_conclusions_follow_the_growth() {
        let md = conclusions_md(&order1_results(0.1, 0.2, 0.001));
        assert!(md.contains("(ratio 2.00; theory"), "{md}");
        assert!(
            md.contains("The growth follows the theory within 20 %"),
            "{md}"
        );
        assert!(
            md.contains("grows at only 0.001 deg/s: an aided loop needs order >= 2"),
            "{md}"
        );
        // INS 2's growth no longer double INS 1's; the 2nd-order loop grows as fast.
        let md = conclusions_md(&order1_results(0.1, 0.12, 0.1));
        assert!(md.contains("(ratio 1.20;"), "{md}");
        assert!(
            md.contains("does not follow the theory within 20 %"),
            "{md}"
        );
        assert!(
            md.contains("not less than a tenth of the 1st-order loop's"),
            "{md}"
        );
    }
}
