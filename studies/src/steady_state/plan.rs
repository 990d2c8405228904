//! The loop configurations of a run and the cells planned for each.

use super::text::short;
use super::{AidParams, Aiding, Cell, Input, SteadyStateArgs, MAIN_T_COH_S};

/// The configurations `(Bn Hz, T s)` of a run: the main one first.
pub(super) fn configs(args: &SteadyStateArgs) -> Vec<(f64, f64)> {
    let mut v = vec![(args.bn_hz, MAIN_T_COH_S)];
    if !args.common.quick {
        for c in [
            (2.0, MAIN_T_COH_S),
            (18.0, MAIN_T_COH_S),
            (2.0, 0.02),
            (args.bn_hz, 0.02),
            (18.0, 0.02),
            (25.0, 0.02),
        ] {
            if !v.contains(&c) {
                v.push(c);
            }
        }
    }
    v
}

/// What was done with one (configuration, order).
pub(super) enum Planned {
    Cells(Vec<Cell>),
    NotRun(String),
}

pub(super) fn plan(bn_hz: f64, t_coh_s: f64, order: u8, aid: AidParams) -> Planned {
    let probe = Cell {
        bn_hz,
        t_coh_s,
        input: Input::Step,
        order,
        aiding: Aiding::Unaided,
        aid,
    };
    if !probe.is_stable() {
        return Planned::NotRun(format!(
            "not run: the digital loop is unstable at Bn T = {}",
            short(bn_hz * t_coh_s)
        ));
    }
    let mut cells = Vec::new();
    for input in Input::ALL {
        for aiding in Aiding::ALL {
            cells.push(Cell {
                input,
                aiding,
                ..probe
            });
        }
    }
    Planned::Cells(cells)
}

pub(super) fn is_main(args: &SteadyStateArgs, bn: f64, t: f64) -> bool {
    bn == args.bn_hz && t == MAIN_T_COH_S
}
