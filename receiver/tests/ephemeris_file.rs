//! `ephemeris.rnx` of a run: the "transmission time of message" (RINEX 3.04 Table A6,
//! broadcast orbit 7, first field) is when the ephemeris's subframe 1 was sent.

use crate::pipeline::{receiver, simulator, SimSource};
use gpsrx_receiver::output::FileSink;

/// The first field of broadcast orbit 7 of each record: (PRN, value).
fn transmission_times(text: &str) -> Vec<(u8, f64)> {
    let body = text.split("END OF HEADER").nth(1).unwrap_or_default();
    let lines: Vec<&str> = body.lines().filter(|l| !l.trim().is_empty()).collect();
    lines
        .chunks(8)
        .map(|rec| {
            let prn = rec[0][1..3].trim().parse().unwrap_or(0);
            // 4X, then D19.12 fields.
            let field = rec[7][4..23].trim().replace('D', "E");
            (prn, field.parse().unwrap_or(f64::NAN))
        })
        .collect()
}

#[test]
fn the_transmission_time_is_the_start_of_subframe_1() {
    // The simulation starts at TOW 538198 s: subframe 1 of the frame starting at 538200 s
    // (frames start at multiples of 30 s, IS-GPS-200 20.3.2) completes the ephemeris with
    // subframes 2 and 3 by 538218 s.
    let sim = simulator(23.0);
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let mut files = FileSink::create(dir.path(), 10.0).unwrap_or_else(|e| panic!("{e}"));
    receiver(2.048e6)
        .run(&mut SimSource::new(&sim), &mut files)
        .unwrap_or_else(|e| panic!("{e}"));
    let text =
        std::fs::read_to_string(dir.path().join("ephemeris.rnx")).unwrap_or_else(|e| panic!("{e}"));
    let times = transmission_times(&text);
    assert!(times.len() >= 6, "{} ephemerides in\n{text}", times.len());
    for (prn, t) in times {
        assert_eq!(t, 538_200.0, "G{prn:02}");
    }
    // The D19.12 form of the field.
    assert!(text.contains("    0.538200000000D+06"), "{text}");
}

#[test]
fn observables_whose_time_goes_back_are_left_out_of_rinex_and_the_run_goes_on() {
    // Two captures joined out of order: the receiver's time goes back by 40 s. RINEX holds
    // increasing time only, so those epochs are left out; before, the run stopped with an error.
    use gpsrx_nav::time::GpsTime;
    use gpsrx_receiver::output::{ObsEpoch, SatObs};
    use gpsrx_receiver::pipeline::{NavigationEnd, ObservablesReport, Sink};
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let mut files = FileSink::create(dir.path(), 10.0).unwrap_or_else(|e| panic!("{e}"));
    let report = |tow_s: f64| ObservablesReport {
        epoch: ObsEpoch {
            time: GpsTime::new(2190, tow_s),
            clock_offset_s: None,
            sats: vec![SatObs {
                prn: 5,
                pseudorange_m: Some(2.2e7),
                ..SatObs::default()
            }],
        },
        fix_position_m: Some([-3.05e6, 4.04e6, 3.87e6]),
        week_decoded: true,
        week_known: true,
    };
    for tow in [538_240.0, 538_240.1, 538_200.0, 538_200.1, 538_240.2] {
        files
            .observables(&report(tow))
            .unwrap_or_else(|e| panic!("TOW {tow}: {e}"));
    }
    files
        .finish(&NavigationEnd::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(dir.path().join("observables.rnx"))
        .unwrap_or_else(|e| panic!("{e}"));
    let epochs: Vec<&str> = text.lines().filter(|l| l.starts_with("> ")).collect();
    assert_eq!(epochs.len(), 3, "{text}");
    assert!(epochs[2].contains(" 30 40.2000000"), "{:?}", epochs[2]);
}
