//! `gpsrx study vector` (issue 29): scalar, INS-aided, vector and vector + INS tracking on the
//! quick grid (a 1 dB/s fade, a 3 s blockage, a 10 g turn), against what vector tracking is
//! for: a lower threshold, fixes back at once after a blockage, satellites held in a turn
//! with an INS; and the report's files.

use gpsrx_studies::vector::cases::{tests, Mode, Test};
use gpsrx_studies::vector::conclusions::{find, threshold_gain};
use gpsrx_studies::vector::{measure_all, report};

#[test]
fn vector_tracking_lowers_the_threshold_refixes_at_once_and_holds_a_turn_with_an_ins() {
    let tests = tests(true);
    let results = measure_all(&tests, 1, false).unwrap_or_else(|e| panic!("{e:#}"));
    let fade = tests
        .iter()
        .find(|t| matches!(t, Test::Fade { .. }))
        .unwrap_or_else(|| panic!("no fade"));
    let (gain, lo, _) =
        threshold_gain(&results, fade, Mode::Vector).unwrap_or_else(|| panic!("no gain"));
    eprintln!("vector threshold gain {gain:.1} dB (per satellite from {lo:.1})");
    assert!(gain >= 2.5 && lo > 0.0, "gain {gain}, smallest {lo}");
    let r = |test: &Test, mode| find(&results, test, mode).unwrap_or_else(|| panic!("{mode:?}"));
    let (scalar, vector) = (
        r(&Test::Blockage, Mode::Scalar),
        r(&Test::Blockage, Mode::Vector),
    );
    eprintln!("blockage: scalar {scalar:?}\nvector {vector:?}");
    let back = |x: &gpsrx_studies::vector::measure::CaseResult| x.back_s.unwrap_or(f64::INFINITY);
    assert!(back(vector) <= 0.5 && back(vector) < back(scalar));
    assert!(
        vector.max_error_after_m.is_some_and(|e| e <= 5.0),
        "{vector:?}"
    );
    assert!(vector.lost.is_empty() && !scalar.lost.is_empty());
    // The INS is good: its monitor never rejects it (under vector tracking the channels'
    // feed-forward is the filter's, with the whole clock drift: it once read that as INS error).
    for (case, r) in &results {
        assert_eq!(r.ins_rejections.unwrap_or(0), 0, "{case:?}");
    }
    let turn = Test::Turn { g: 10.0 };
    let with_ins = r(&turn, Mode::VectorIns);
    assert!(
        with_ins.locked_before.len() >= 7 && with_ins.locked_through == with_ins.locked_before,
        "{with_ins:?}"
    );
    // The report: its table has every case, its conclusions the numbers measured.
    let rep = report(&results, &tests, 1);
    assert_eq!(rep.table.rows.len(), tests.len() * Mode::ALL.len());
    assert!(
        rep.conclusions_md
            .contains(&format!("vector: {gain:.1} dB lower")),
        "{}",
        rep.conclusions_md
    );
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    rep.write(dir.path()).unwrap_or_else(|e| panic!("{e:#}"));
    for f in [
        "study.md",
        "study.csv",
        "study.json",
        "threshold.png",
        "blockage.png",
        "turns.png",
    ] {
        assert!(dir.path().join(f).exists(), "{f} missing");
    }
}
