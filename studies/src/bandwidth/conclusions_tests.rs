//! The conclusions follow the measured numbers: each test builds them from synthetic cell
//! results, perturbs one measured input and checks that the sentence changes with it.

use super::conclusions::conclusions;
use super::doppler_code_md::code_error;
use super::phase_md::{beyond_bnt_limit, formula_region, low_snr_failure};
use super::table_two_abs::{absolute_md, AbsoluteRow};
use super::table_two_md::table_two;
use super::{Cell, CellMeasured, CellResult, CellStatus, CellTheory, RunInfo, TableTwoRatio};

/// A locked cell (3 channels) whose phase jitter is `ratio` x the formula's 5 deg and
/// `ratio / loop_ratio` x the linearised loop's.
fn cell(cn0_dbhz: f64, bn_hz: f64, t_ms: u32, ratio: f64, loop_ratio: f64) -> CellResult {
    CellResult {
        cell: Cell {
            cn0_dbhz,
            order: 2,
            bn_hz,
            t_ms,
        },
        status: CellStatus::Run,
        theory: CellTheory {
            phase_formula_deg: 5.0,
            phase_loop_deg: 5.0 * loop_ratio,
            bn_realised_ratio: 1.8,
            phase_digital_ratio: loop_ratio,
            doppler_hz: 0.1,
            pr_rate_mps: 0.01,
            pr_rate_1s_mps: 0.001,
            code_formula_chips: 0.01,
            code_envelope_chips: 0.01,
            atan_slope: 1.0,
            linear_stable: true,
            settle_s: 1.0 + 6.3 / bn_hz,
        },
        measured: CellMeasured {
            channels: 3,
            locked: 3,
            phase_deg: 5.0 * ratio,
            doppler_hz: 0.1,
            pr_rate_mps: 0.01,
            pr_rate_1s_mps: 0.001,
            code_chips: 0.01,
            epochs: 24_000,
            ..CellMeasured::default()
        },
        duration_s: 40.0,
    }
}

#[test]
fn beyond_bn_t_states_the_measured_departure_and_whether_the_loop_predicts_it() {
    // 10 Hz at 20 ms: Bn T = 0.2, measured 1.45 x the formula, the loop predicts 1.47.
    let mut r = vec![cell(45.0, 10.0, 20, 1.45, 1.47)];
    let md = beyond_bnt_limit(&r);
    assert!(md.contains("here Bn T = 0.20"), "{md}");
    assert!(md.contains("is 45-45 % above the formula"), "{md}");
    assert!(md.contains(", within 20 % of what the linearised"), "{md}");
    assert!(md.contains("1.80-1.80 x the design value"), "{md}");
    // Measured below the formula: the sentence says so, and the loop no longer predicts it.
    r[0].measured.phase_deg = 5.0 * 0.8;
    let md = beyond_bnt_limit(&r);
    assert!(md.contains("is 20-20 % below the formula"), "{md}");
    assert!(
        md.contains("not within 20 % of what the linearised"),
        "{md}"
    );
    // The cell lost lock: nothing is claimed.
    r[0].measured.locked = 2;
    assert!(beyond_bnt_limit(&r).is_empty());
}

#[test]
fn the_formula_region_counts_follow_the_cells() {
    let mut r = vec![
        cell(45.0, 1.0, 1, 1.05, 1.0),
        cell(45.0, 4.0, 1, 0.95, 1.0),
        cell(35.0, 10.0, 1, 1.30, 1.0),
    ];
    let md = formula_region(&r);
    assert!(
        md.contains("3 cells, 3 held lock, 2 of those within 20 %"),
        "{md}"
    );
    assert!(md.contains("measured / formula 0.95-1.30"), "{md}");
    assert!(md.contains("Beyond 20 %: 35/2/10/1 at 1.30"), "{md}");
    // Remove the outlier: every cell within 20 %, the range shrinks.
    r.pop();
    let md = formula_region(&r);
    assert!(
        md.contains("2 cells, 2 held lock, 2 of those within 20 %"),
        "{md}"
    );
    assert!(md.contains("measured / formula 0.95-1.05"), "{md}");
    assert!(!md.contains("Beyond 20 %"), "{md}");
    // A cell that lost lock is listed, not averaged in.
    r[1].measured.locked = 1;
    r[1].measured.lost = 2;
    let md = formula_region(&r);
    assert!(md.contains("2 cells, 1 held lock, 1 of those"), "{md}");
    assert!(md.contains("Lost lock or slipped: 45/2/4/1"), "{md}");
}

#[test]
fn the_low_snr_verdict_follows_lock_and_the_formula() {
    // 30 dB-Hz at 1 ms (C/N0 T = 1), Bn 1 Hz: inside the formula region.
    let mut r = vec![cell(30.0, 1.0, 1, 1.1, 1.0)];
    assert!(r[0].in_formula_region());
    let md = low_snr_failure(&r);
    assert!(md.contains("the rule of thumb held here"), "{md}");
    assert!(md.contains("g = 0.63"), "{md}");
    r[0].measured.locked = 0;
    let md = low_snr_failure(&r);
    assert!(md.contains("1 of 1 cells at C/N0 T < 3"), "{md}");
    assert!(md.contains("optimistic at this prompt SNR"), "{md}");
    // Held lock but 40 % above the formula: also a failure of the formula.
    r[0].measured.locked = 3;
    r[0].measured.phase_deg = 5.0 * 1.4;
    assert!(low_snr_failure(&r).contains("optimistic"));
    // No low-SNR cell ran: no paragraph.
    assert!(low_snr_failure(&[cell(45.0, 1.0, 1, 1.0, 1.0)]).is_empty());
}

#[test]
fn the_code_formula_over_or_understates_as_measured() {
    // 25 dB-Hz at 1 ms: C/N0 T = 0.32 < 10. The power formula is 3 x the measured std.
    let mut r = vec![cell(25.0, 1.0, 1, 1.0, 1.0), cell(45.0, 1.0, 1, 1.0, 1.0)];
    r[0].theory.code_formula_chips = 0.03;
    let md = code_error(&r);
    assert!(
        md.contains("overstates the channel's code noise, by up to 3.0 x (25/2/1/1)"),
        "{md}"
    );
    r[0].measured.code_chips = 0.06;
    let md = code_error(&r);
    assert!(md.contains("understates"), "{md}");
    assert!(md.contains("by up to 0.5 x"), "{md}");
    // Without the low cell there is no claim about it.
    let md = code_error(&r[1..]);
    assert!(md.contains("No locked cell below C/N0 T = 10"), "{md}");
    assert!(!md.contains("overstates"), "{md}");
}

fn ratio(nco: f64, obs_0p1s: f64, obs_1s: f64) -> TableTwoRatio {
    TableTwoRatio {
        cn0_dbhz: 45.0,
        order: 2,
        t_ms: 1,
        nco_measured: nco,
        nco_theory: 4.0,
        obs_0p1s_measured: obs_0p1s,
        obs_0p1s_theory: 4.0,
        obs_1s_measured: obs_1s,
        obs_1s_theory: 2.0,
    }
}

#[test]
fn the_table_two_reading_follows_the_measured_ratios() {
    let md = table_two(&[ratio(4.0, 4.0, 2.0)]);
    assert!(md.contains("measured 2.00-2.00, above the paper's"), "{md}");
    assert!(md.contains("larger than over 1 s"), "{md}");
    assert!(
        md.contains("Closest to the paper's 1.65-1.81: the 1 s"),
        "{md}"
    );
    assert!(md.contains("even that ratio is above the paper's"), "{md}");
    // A 1 s ratio inside the paper's range, and a 0.1 s ratio below the 1 s one.
    let md = table_two(&[ratio(4.0, 1.5, 1.7)]);
    assert!(
        md.contains("measured 1.70-1.70, overlapping the paper's"),
        "{md}"
    );
    assert!(md.contains("smaller than over 1 s"), "{md}");
    assert!(!md.contains("even that ratio is above"), "{md}");
    // The NCO ratio closest to the paper's: the reading names it.
    let md = table_two(&[ratio(1.75, 4.0, 2.5)]);
    assert!(
        md.contains("Closest to the paper's 1.65-1.81: the NCO frequency"),
        "{md}"
    );
}

fn abs_row(bn1: f64, bn4: f64) -> AbsoluteRow {
    AbsoluteRow {
        oscillator: "TCXO",
        adev_1s: 1e-10,
        cn0_dbhz: 45.0,
        bn1_1s_mps: bn1,
        bn4_1s_mps: bn4,
        bn1_0p1s_mps: bn1,
        bn4_0p1s_mps: bn4,
    }
}

#[test]
fn the_absolute_table_two_follows_the_rows() {
    let md = absolute_md(&[abs_row(0.0161, 0.0062)]);
    assert!(md.contains("from 1 Hz to 4 Hz (0.39)"), "{md}");
    assert!(md.contains("the 1 s error falls"), "{md}");
    assert!(
        md.contains("Within seed 004's ranges (1 s Doppler): none"),
        "{md}"
    );
    assert!(md.contains("the paper's 1 Hz value is 2 x this"), "{md}");
    // No channel held lock at 1 Hz (NaN): said so, no trend and no scale claimed.
    let md = absolute_md(&[abs_row(f64::NAN, 0.0095)]);
    assert!(
        md.contains("no 1 s error at Bn 1 Hz (no channel held lock), so no trend"),
        "{md}"
    );
    assert!(!md.contains("NaN x"), "{md}");
    let md = absolute_md(&[abs_row(0.035, 0.06)]);
    assert!(md.contains("the 1 s error grows"), "{md}");
    assert!(
        md.contains("Within seed 004's ranges (1 s Doppler): TCXO at 45"),
        "{md}"
    );
}

#[test]
fn the_conclusions_count_the_run() {
    let info = RunInfo {
        window_s: 12.0,
        aided: true,
        quick: true,
        seed: 1,
        recordings: 2,
        recorded_s: 80.0,
        wall_s: 3.0,
    };
    let r = vec![cell(45.0, 1.0, 1, 1.0, 1.0), cell(45.0, 4.0, 1, 1.0, 1.0)];
    let md = conclusions(&r, &[], &info);
    assert!(md.contains("2 cells, 2 held lock, 2 of those"), "{md}");
    assert!(md.contains("Run: 2 recordings, 80 s"), "{md}");
    // Nothing about cells the grid does not have.
    assert!(!md.contains("Beyond Bn T"), "{md}");
    assert!(!md.contains("Low prompt SNR"), "{md}");
}
