//! The Table 3 conclusions (seed 004): INS 2 / INS 1 discriminator std at 0.4 Hz against the
//! paper's 1.09-1.17, each statement chosen by the numbers.

use super::conclusions::COSTAS_SLIP_CYCLES;
use super::headline::cn0s;
use super::params::MG_MPS2;
use super::result::CaseResult;
use super::seed_tables::{table3, table3_rows, Table3Row, PAPER_RATIO};

/// Seed 004 Table 3's discriminator std range (INS 1 and INS 2), cycles.
const PAPER_STD: (f64, f64) = (0.085, 0.101);

/// Ratios this close to 1 count as "the same".
const SAME: f64 = 0.05;

fn list(v: &[f64], digits: usize) -> String {
    v.iter()
        .map(|x| format!("{x:.digits$}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Table 3 and what it shows.
pub(super) fn table3_md(results: &[CaseResult]) -> String {
    let rows = table3_rows(results);
    if rows.is_empty() {
        return String::new();
    }
    let mut s = format!(
        "**INS 1 vs INS 2 at 0.4 Hz (seed 004 Table 3: discriminator atan(Q/I) std 0.085-0.101 \
cycle, INS 2 / INS 1 = {:.2}-{:.2}).** Pooled over the satellites tracked in the window; \
*largest offset* = the static phase offset `B / (lambda w0^2)` with the whole bias on the line \
of sight (2nd order; 3rd order: 0).\n\n{}\n",
        PAPER_RATIO.0,
        PAPER_RATIO.1,
        table3(&rows).to_markdown()
    );
    for cn0 in cn0s(results) {
        for order in [2u8, 3] {
            let at: Vec<&Table3Row<'_>> = rows
                .iter()
                .filter(|r| r.cn0_dbhz == cn0 && r.order == order)
                .collect();
            if !at.is_empty() {
                s += &row_group_md(cn0, order, &at);
            }
        }
    }
    s + "\n"
}

/// One C/N0 and order: the ratios against the paper's, how they go with the bias, the std
/// level, and the slips.
fn row_group_md(cn0: f64, order: u8, at: &[&Table3Row<'_>]) -> String {
    let ratios: Vec<f64> = at.iter().map(|r| r.disc_ratio()).collect();
    let phase: Vec<f64> = at.iter().map(|r| r.phase_ratio()).collect();
    let biases: Vec<f64> = at.iter().map(|r| r.ins1_bias_mps2 / MG_MPS2).collect();
    let inside = ratios
        .iter()
        .filter(|r| (PAPER_RATIO.0..=PAPER_RATIO.1).contains(*r))
        .count();
    let mut s = format!(
        "- {cn0} dB-Hz, order {order}: INS 2 / INS 1 discriminator std {} for INS 1 biases {} mg \
({inside} of {} within the paper's {:.2}-{:.2}); against the true phase {}. ",
        list(&ratios, 3),
        list(&biases, 1),
        ratios.len(),
        PAPER_RATIO.0,
        PAPER_RATIO.1,
        list(&phase, 3),
    );
    let finite: Vec<f64> = ratios.iter().copied().filter(|r| r.is_finite()).collect();
    if finite.is_empty() {
        return format!(
            "- {cn0} dB-Hz, order {order}: no satellite was tracked through the window with \
either INS (kept {}), so there is no ratio.\n",
            at.iter()
                .map(|r| format!("{}/{}", r.ins1.kept, r.ins2.kept))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let rising = finite.len() >= 2 && finite.windows(2).all(|w| w[1] > w[0]);
    let all_same = finite.iter().all(|r| (r - 1.0).abs() < SAME);
    let phase_same = phase
        .iter()
        .filter(|r| r.is_finite())
        .all(|r| (r - 1.0).abs() < SAME);
    s += &if all_same {
        format!("The bias does not change the std (every ratio within {SAME} of 1). ")
    } else if finite.len() < 2 {
        // One INS pair: no trend with the bias to state.
        String::new()
    } else if rising {
        "The ratio rises with the bias. ".to_string()
    } else {
        "The ratio does not rise steadily with the bias. ".to_string()
    };
    if !all_same && phase_same && finite.iter().all(|&r| r > 1.0) {
        s += "The phase error against the truth has the same std with either INS, so INS 2's \
larger discriminator std comes from the discriminator, not from the loop, consistent with \
atan(Q/I) folding more of its noise at +-90 deg about INS 2's larger static offset. ";
    }
    let d1: Vec<f64> = at
        .iter()
        .map(|r| r.ins1.disc_std_cycles)
        .filter(|d| d.is_finite())
        .collect();
    let lo = d1.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = d1.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let level = if format!("{lo:.3}") == format!("{hi:.3}") {
        format!("{lo:.3}")
    } else {
        format!("{lo:.3}-{hi:.3}")
    };
    s += &format!(
        "INS 1's discriminator std is {level} cycle ({} the paper's {:.3}-{:.3}). ",
        if lo <= PAPER_STD.1 && hi >= PAPER_STD.0 {
            "overlapping"
        } else if hi < PAPER_STD.0 {
            "below"
        } else {
            "above"
        },
        PAPER_STD.0,
        PAPER_STD.1
    );
    s += &slips_md(at);
    s + "\n"
}

/// INS runs that lost satellites in the window, against the slip limit of their static offset.
fn slips_md(at: &[&Table3Row<'_>]) -> String {
    let mut out = Vec::new();
    let mut seen: Vec<f64> = Vec::new();
    for r in at {
        for (k, c) in [(1.0, r.ins1), (2.0, r.ins2)] {
            // INS 2 of one pair and INS 1 of the next can be the same INS (same bias): once.
            let b = c.case.bias_mps2();
            if seen.contains(&b) {
                continue;
            }
            seen.push(b);
            if c.kept < c.tracked_at_start {
                let o = r.offset_bound_cycles(k);
                out.push(format!(
                    "the {:.1} mg INS lost {} of {} (largest offset {o:.3} cycle, {} the \
Costas loop's {COSTAS_SLIP_CYCLES})",
                    b / MG_MPS2,
                    c.tracked_at_start - c.kept,
                    c.tracked_at_start,
                    if o > COSTAS_SLIP_CYCLES {
                        "past"
                    } else {
                        "within"
                    }
                ));
            }
        }
    }
    if out.is_empty() {
        "Every aided run kept every satellite it tracked at the start of the turn.".into()
    } else {
        let mut s = out.join("; ") + ".";
        if let Some(first) = s.get_mut(0..1) {
            first.make_ascii_uppercase();
        }
        s
    }
}
