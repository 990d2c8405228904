//! `gpsrx study steady-state --quick`: every cell of the 48-cell table agrees with its closed
//! form, the report files are written, and spot checks of single cells against the closed forms
//! of `oracles.md` written out here independently of the study's own `closed_form`.
//!
//! Tolerances: the cells are noise-free and measured after the slowest closed-loop pole has
//! decayed to 1e-5 of its start, so a measured steady state matches its closed form to far better
//! than the study's 5 %; the spot checks use 1e-3 relative (a wrong omega0 constant, e.g. 0.5303
//! for 0.53, or a wrong power of omega0 would miss it by 0.06 % to orders of magnitude: the first
//! is below this tolerance and does not matter, the others fail).

use gpsrx_studies::steady_state::{
    agrees, closed_form, residual, run, simulate, AidParams, Aiding, Cell, ClosedForm, Input,
    SteadyStateArgs, ABS_TOL_CYCLES,
};
use gpsrx_studies::CommonStudyArgs;
use std::time::Instant;

/// L1 wavelength, m: c / 1575.42 MHz (`oracles.md`: 0.190294 m).
const LAMBDA_M: f64 = 299_792_458.0 / 1_575.42e6;
const BN_HZ: f64 = 10.0;
const AID: AidParams = AidParams {
    alpha_rad_s: 5.0,
    b_v_mps2: 0.05,
};

/// omega0 of the oracle table: Bn/0.25, Bn/0.53, Bn/0.7845.
fn omega0_oracle(order: u8, bn_hz: f64) -> f64 {
    bn_hz / [0.25, 0.53, 0.7845][usize::from(order) - 1]
}

fn cell(input: Input, order: u8, aiding: Aiding) -> Cell {
    Cell {
        bn_hz: BN_HZ,
        t_coh_s: 1e-3,
        input,
        order,
        aiding,
        aid: AID,
    }
}

fn rel_err(got: f64, want: f64) -> f64 {
    (got / want - 1.0).abs()
}

#[test]
fn quick_study_agrees_everywhere_and_writes_its_files() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let args = SteadyStateArgs::new(CommonStudyArgs {
        out: dir.path().to_path_buf(),
        quick: true,
        seed: 1,
    });
    let t0 = Instant::now();
    let report = run(&args, false)?;
    let written = report.write(dir.path())?;
    let elapsed = t0.elapsed().as_secs_f64();
    assert!(elapsed < 60.0, "--quick took {elapsed} s");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("study.json"))?)?;
    assert_eq!(json["cells_total"], 48);
    assert_eq!(json["cells_agree"], 48, "cells that disagree: {:#}", {
        let bad: Vec<&serde_json::Value> = json["cells"]
            .as_array()
            .map(|c| c.iter().filter(|c| c["agree"] != true).collect())
            .unwrap_or_default();
        serde_json::json!(bad)
    });
    assert_eq!(json["bn_hz"], BN_HZ);
    assert_eq!(json["t_coh_s"], 1e-3);
    assert_eq!(json["alpha_rad_s"], AID.alpha_rad_s);
    assert_eq!(json["b_v_mps2"], AID.b_v_mps2);
    assert_eq!(json["cells"].as_array().map(Vec::len), Some(48));

    let md = std::fs::read_to_string(&written.markdown)?;
    assert!(md.contains("| input | order | aiding | magnitude | closed_form | measured | agree |"));
    assert!(md.contains("48 of 48 cells agree"));
    let csv = std::fs::read_to_string(&written.csv)?;
    assert_eq!(csv.lines().count(), 49, "header + 48 rows");
    assert!(csv.lines().skip(1).all(|l| l.contains(",yes,")));
    assert!(written.plots.len() >= 3);
    for p in &written.plots {
        let png = std::fs::read(p)?;
        assert_eq!(&png[1..4], b"PNG", "{}", p.display());
        assert!(png.len() > 5000, "{} looks blank", p.display());
    }
    Ok(())
}

/// Unaided, 2nd order, constant Doppler rate a: theta_e = a/omega0^2 (oracle table), and the
/// equivalent form 0.2809 a/Bn^2.
#[test]
fn order2_parabola_settles_at_a_over_omega0_squared() -> anyhow::Result<()> {
    let r = simulate(&cell(Input::Parabola, 2, Aiding::Unaided))?;
    let want = r.magnitude / omega0_oracle(2, BN_HZ).powi(2);
    assert!((want / (0.2809 * r.magnitude / BN_HZ.powi(2)) - 1.0).abs() < 1e-3);
    assert!(rel_err(r.measured, want) < 1e-3, "{} vs {want}", r.measured);
    assert!(r.agree);
    Ok(())
}

/// Unaided, 3rd order, constant jerk j: theta_e = j/omega0^3 = 0.4828 j/Bn^3.
#[test]
fn order3_cubic_settles_at_j_over_omega0_cubed() -> anyhow::Result<()> {
    let r = simulate(&cell(Input::Cubic, 3, Aiding::Unaided))?;
    let want = r.magnitude / omega0_oracle(3, BN_HZ).powi(3);
    assert!((want / (0.4828 * r.magnitude / BN_HZ.powi(3)) - 1.0).abs() < 1e-3);
    assert!(rel_err(r.measured, want) < 1e-3, "{} vs {want}", r.measured);
    Ok(())
}

/// Unaided, 1st order, constant Doppler rate a: the error grows at a/omega0 cycles/s.
#[test]
fn order1_parabola_grows_at_a_over_omega0() -> anyhow::Result<()> {
    let r = simulate(&cell(Input::Parabola, 1, Aiding::Unaided))?;
    assert!(matches!(r.closed, ClosedForm::Growing { p: 1, .. }));
    let want = r.magnitude / omega0_oracle(1, BN_HZ);
    assert!(rel_err(r.measured, want) < 1e-3, "{} vs {want}", r.measured);
    Ok(())
}

/// Biased INS, 2nd order: -(B_V/lambda)/omega0^2 cycles whatever the input; band-limited aid,
/// 1st order, constant Doppler rate: a/(alpha omega0) (`oracles.md`, seed 004 eqs. 8-16).
#[test]
fn aided_cells_match_the_seed_004_oracles() -> anyhow::Result<()> {
    let want_bias = -(AID.b_v_mps2 / LAMBDA_M) / omega0_oracle(2, BN_HZ).powi(2);
    for input in Input::ALL {
        let r = simulate(&cell(input, 2, Aiding::BiasedIns))?;
        assert!(
            rel_err(r.measured, want_bias) < 1e-3,
            "{input:?}: {} vs {want_bias}",
            r.measured
        );
    }
    let r = simulate(&cell(Input::Parabola, 1, Aiding::BandLimited))?;
    let want = r.magnitude / (AID.alpha_rad_s * omega0_oracle(1, BN_HZ));
    assert!(rel_err(r.measured, want) < 1e-3, "{} vs {want}", r.measured);
    // Perfect aid: zero for every order, far below the 0.005-cycle tolerance.
    for order in 1..=3 {
        let r = simulate(&cell(Input::Cubic, order, Aiding::Perfect))?;
        assert!(r.measured.abs() < 1e-6, "order {order}: {}", r.measured);
    }
    Ok(())
}

/// The oracle's worked example: B_V = 0.05 m/s^2 gives 3.0 deg at Bn = 3 Hz, 2nd order (negative
/// with error = signal - NCO); the closed form gives it to 0.1 deg.
#[test]
fn closed_form_reproduces_the_oracle_example() {
    let w = omega0_oracle(2, 3.0);
    let res = residual(Input::Ramp, Aiding::BiasedIns, 1.0, AID);
    let ClosedForm::Bounded(e) = closed_form(2, w, res) else {
        panic!("2nd order under an INS bias is bounded")
    };
    assert!((e * 360.0 + 3.0).abs() < 0.1, "{} deg", e * 360.0);
    // 1st order: unbounded; 3rd order: zero.
    assert!(matches!(
        closed_form(1, omega0_oracle(1, 3.0), res),
        ClosedForm::Growing { p: 1, .. }
    ));
    assert_eq!(
        closed_form(3, omega0_oracle(3, 3.0), res),
        ClosedForm::Bounded(0.0)
    );
}

/// The agreement rule can fail: a closed form off by 10 % (or a non-zero error where 0 is
/// predicted) is flagged.
#[test]
fn a_wrong_closed_form_is_flagged() -> anyhow::Result<()> {
    let r = simulate(&cell(Input::Parabola, 2, Aiding::Unaided))?;
    let c = r.closed.value();
    assert!(agrees(c, r.measured));
    assert!(!agrees(1.1 * c, r.measured));
    assert!(!agrees(0.9 * c, r.measured));
    assert!(!agrees(-c, r.measured));
    assert!(agrees(0.0, 0.9 * ABS_TOL_CYCLES));
    assert!(!agrees(0.0, 1.1 * ABS_TOL_CYCLES));
    assert!(!agrees(0.0, r.measured), "0.03 cycle is not zero");
    Ok(())
}
