//! The conclusions follow the measured cells: built from synthetic results, one measured value
//! perturbed at a time, the sentence that states the result changes with it.

use super::conclusions::conclusions_md;
use super::{
    agrees, AidParams, Aiding, Cell, CellResult, ClosedForm, Input, SteadyStateArgs, MAIN_T_COH_S,
};
use crate::CommonStudyArgs;

fn args() -> SteadyStateArgs {
    SteadyStateArgs::new(CommonStudyArgs {
        out: "unused".into(),
        quick: true,
        seed: 1,
    })
}

/// A bounded cell whose measurement equals its closed form.
fn cell(bn_hz: f64, t_coh_s: f64, input: Input, order: u8, aiding: Aiding) -> CellResult {
    let closed = match (aiding, order) {
        (Aiding::BiasedIns, 2) => -0.000738,
        (Aiding::BandLimited, 2) if input == Input::Cubic => 0.02,
        (Aiding::BandLimited, 1) if input == Input::Parabola => 0.03,
        _ => 0.0,
    };
    CellResult {
        cell: Cell {
            bn_hz,
            t_coh_s,
            input,
            order,
            aiding,
            aid: AidParams {
                alpha_rad_s: 5.0,
                b_v_mps2: 0.05,
            },
        },
        magnitude: 1.0,
        closed: ClosedForm::Bounded(closed),
        measured: closed,
        window_ends_cycles: (closed, closed),
        window: (1.0, 2.0),
        max_abs_error_cycles: 0.03,
        agree: true,
        trace: Vec::new(),
        fit: (Vec::new(), 0.0),
    }
}

/// Every aided cell of the main table (orders 1-3, inputs step to cubic).
fn main_cells() -> Vec<CellResult> {
    let mut v = Vec::new();
    for aiding in [Aiding::Perfect, Aiding::BandLimited, Aiding::BiasedIns] {
        for input in [Input::Step, Input::Ramp, Input::Parabola, Input::Cubic] {
            for order in 1..=3u8 {
                v.push(cell(10.0, MAIN_T_COH_S, input, order, aiding));
            }
        }
    }
    v
}

fn md(results: &[CellResult]) -> String {
    let agree = results.iter().filter(|r| r.agree).count();
    conclusions_md(&args(), (results.len(), agree), &[], results)
}

/// Sets a cell's measurement, and its agreement by the study's rule.
fn measure(r: &mut CellResult, measured: f64) {
    r.measured = measured;
    r.agree = agrees(r.closed.value(), measured);
}

#[test]
fn the_bias_conclusion_needs_every_biased_cell_to_agree() {
    let mut r = main_cells();
    let s = md(&r);
    assert!(s.contains("**36 of 36 cells agree"), "{s}");
    assert!(
        s.contains(
            "order 1 4 of 4 cells agree, order 2 4 of 4 cells agree, order 3 4 of 4 cells agree"
        ),
        "{s}"
    );
    assert!(
        s.contains("aided loops need order >= 2, as seed 004 concludes"),
        "{s}"
    );
    assert!(s.contains("error is negative here (every input)"), "{s}");
    assert!(
        s.contains("order 2 -0.0007380 cycles for every input"),
        "{s}"
    );
    // One 2nd-order biased cell measured with the opposite sign.
    let i = r
        .iter()
        .position(|x| x.cell.aiding == Aiding::BiasedIns && x.cell.order == 2)
        .expect("a biased order-2 cell");
    measure(&mut r[i], 0.000738);
    let s = md(&r);
    assert!(s.contains("**35 of 36 cells agree"), "{s}");
    assert!(s.contains("order 2 3 of 4 cells agree"), "{s}");
    assert!(s.contains("does not confirm seed 004's conclusion"), "{s}");
    assert!(!s.contains("as seed 004 concludes"), "{s}");
    assert!(s.contains("changes sign with the input here"), "{s}");
    // Every one positive.
    for x in r
        .iter_mut()
        .filter(|x| x.cell.aiding == Aiding::BiasedIns && x.cell.order == 2)
    {
        measure(x, 0.000738);
    }
    assert!(md(&r).contains("is positive here (every input)"));
}

#[test]
fn perfect_aiding_is_called_error_free_only_when_its_cells_agree() {
    let mut r = main_cells();
    let s = md(&r);
    assert!(
        s.contains("Perfect aiding (closed form 0 for every order): 12 of 12 cells agree, so"),
        "{s}"
    );
    assert!(s.contains("so it leaves no error for any order"), "{s}");
    measure(&mut r[0], 0.01);
    let s = md(&r);
    assert!(
        s.contains("Perfect aiding (closed form 0 for every order): 11 of 12 cells agree"),
        "{s}"
    );
    assert!(s.contains("does *not* leave a negligible error"), "{s}");
    assert!(s.contains("largest steady error 0.01000 cycle"), "{s}");
}

#[test]
fn the_seed_differences_follow_the_band_limited_cells() {
    let mut r = main_cells();
    let s = md(&r);
    assert!(
        s.contains("this run's cell agrees (measured 0.02000, closed form 0.02000)"),
        "{s}"
    );
    let i = r
        .iter()
        .position(|x| {
            x.cell.aiding == Aiding::BandLimited
                && x.cell.order == 2
                && x.cell.input == Input::Cubic
        })
        .expect("the band-limited jerk cell");
    measure(&mut r[i], 0.03);
    let s = md(&r);
    assert!(
        s.contains("this run's cell does not agree (measured 0.03000, closed form 0.02000)"),
        "{s}"
    );
    // The cell removed: the run says so instead of claiming agreement.
    r.remove(i);
    assert!(md(&r).contains("this run's cell did not run"));
}

#[test]
fn other_configurations_are_claimed_only_when_run_and_agreeing() {
    let mut r = main_cells();
    let s = md(&r);
    assert!(s.contains("This run has only Bn T = 0.01"), "{s}");
    r.push(cell(25.0, 0.02, Input::Ramp, 2, Aiding::Unaided));
    r.push(cell(25.0, 0.02, Input::Step, 2, Aiding::Unaided));
    let s = md(&r);
    assert!(
        s.contains("Measured: all 2 cells of the other configurations (Bn T up to 0.5) agree"),
        "{s}"
    );
    let n = r.len();
    r[n - 1].agree = false;
    let s = md(&r);
    assert!(
        s.contains("only 1 of 2 cells of the other configurations"),
        "{s}"
    );
}
