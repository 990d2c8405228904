//! Study grids case by case: the cases of a study listed and run one at a time, for batches
//! that spread them over processes or machines (the Python package's `gpsrx.batch`, one Dask
//! task per case or chunk of cases). A case run alone gives the row the whole study computes
//! for it (the cases are deterministic and independent).
//!
//! Studies with a grid: `steady-state` (48 cells with `quick`, 7 (Bn, T) groups without).

use crate::steady_state::{self, Cell, SteadyStateArgs};
use crate::CommonStudyArgs;
use serde_json::{json, Map, Value};

/// The studies that can be run case by case.
pub const GRID_STUDIES: [&str; 1] = ["steady-state"];

/// The cells of a study (`quick`: its `--quick` grid).
fn steady_state_cells(quick: bool) -> anyhow::Result<Vec<Cell>> {
    let args = SteadyStateArgs::new(CommonStudyArgs {
        out: std::path::PathBuf::new(),
        quick,
        seed: 1,
    });
    Ok(steady_state::cells(&args)?.1)
}

fn unknown(study: &str) -> anyhow::Error {
    anyhow::anyhow!(
        "study `{study}` has no case grid: use one of {}",
        GRID_STUDIES.join(", ")
    )
}

/// The cases of `study`, each described by its parameters (one row per case, `case` its
/// index).
pub fn cases(study: &str, quick: bool) -> anyhow::Result<Vec<Map<String, Value>>> {
    match study {
        "steady-state" => Ok(steady_state_cells(quick)?
            .iter()
            .enumerate()
            .map(|(i, c)| describe(i, c))
            .collect()),
        _ => Err(unknown(study)),
    }
}

/// Runs case `index` of `study`: its parameters and its results as one row.
pub fn run_case(study: &str, quick: bool, index: usize) -> anyhow::Result<Map<String, Value>> {
    match study {
        "steady-state" => {
            let cells = steady_state_cells(quick)?;
            let cell = cells.get(index).ok_or_else(|| {
                anyhow::anyhow!(
                    "steady-state case {index}: the grid has {} cases (0 to {})",
                    cells.len(),
                    cells.len().saturating_sub(1)
                )
            })?;
            let r = steady_state::simulate(cell)?;
            let mut row = describe(index, cell);
            row.insert("magnitude".into(), json!(r.magnitude));
            row.insert("closed_form".into(), json!(r.closed.value()));
            row.insert("measured".into(), json!(r.measured));
            row.insert("agree".into(), json!(r.agree));
            row.insert("max_abs_error_cycles".into(), json!(r.max_abs_error_cycles));
            Ok(row)
        }
        _ => Err(unknown(study)),
    }
}

fn describe(index: usize, c: &Cell) -> Map<String, Value> {
    let mut row = Map::new();
    row.insert("study".into(), json!("steady-state"));
    row.insert("case".into(), json!(index));
    row.insert("order".into(), json!(c.order));
    row.insert("bn_hz".into(), json!(c.bn_hz));
    row.insert("t_coh_s".into(), json!(c.t_coh_s));
    row.insert("input".into(), json!(c.input.name()));
    row.insert("aiding".into(), json!(c.aiding.name()));
    row
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_case_run_alone_matches_the_closed_form_as_in_the_study() {
        let cases = cases("steady-state", true).expect("grid");
        assert_eq!(cases.len(), 48, "the quick grid's 48 cells");
        // A ramp into a 2nd-order loop: the error settles at 0 (seed 004 Table 1).
        let i = cases
            .iter()
            .position(|c| c["input"] == "ramp" && c["order"] == 2 && c["aiding"] == "unaided")
            .expect("a ramp cell");
        let row = run_case("steady-state", true, i).expect("runs");
        assert_eq!(row["closed_form"], json!(0.0));
        assert_eq!(row["agree"], json!(true), "{row:?}");
        let e = run_case("steady-state", true, 48).expect_err("out of range");
        assert!(e.to_string().contains("48 cases"), "{e}");
        assert!(cases_err("bandwidth").contains("steady-state"));
    }

    fn cases_err(study: &str) -> String {
        cases(study, true).expect_err("no grid").to_string()
    }
}
