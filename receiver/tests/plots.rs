//! The PNG plots of a run: drawn by the file sink at the end of a short simulated run, valid
//! PNGs of the documented sizes, and none when they are turned off.

use crate::pipeline::{receiver, simulator, SimSource};
use gpsrx_receiver::output::plots::{cn0, dop, skyplot, track};
use gpsrx_receiver::output::FileSink;
use std::path::Path;

/// Width and height from a PNG's IHDR chunk (PNG spec 11.2.2), after checking the signature.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(
        &bytes[..8],
        b"\x89PNG\r\n\x1a\n",
        "{}: not a PNG",
        path.display()
    );
    assert_eq!(&bytes[12..16], b"IHDR", "{}", path.display());
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

#[test]
fn a_short_run_draws_every_plot_at_its_size_and_none_when_turned_off() {
    let sim = simulator(13.0);
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let on = dir.path().join("on");
    let mut files = FileSink::create(&on, 10.0)
        .unwrap_or_else(|e| panic!("{e}"))
        .with_plots(true);
    let summary = receiver(2.048e6)
        .run(&mut SimSource::new(&sim), &mut files)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(summary.fixes > 5, "{} fixes", summary.fixes);
    for (name, size) in [
        ("track.png", track::TRACK_SIZE),
        ("skyplot.png", skyplot::SKYPLOT_SIZE),
        ("cn0.png", cn0::CN0_SIZE),
        ("dop.png", dop::DOP_SIZE),
    ] {
        let path = on.join(name);
        assert_eq!(png_size(&path), size, "{name}");
        let len = std::fs::metadata(&path).map_or(0, |m| m.len());
        assert!(len > 20_000, "{name}: {len} bytes, a blank image?");
    }
    // Turned off (the default of a bare FileSink): the text outputs, no PNG.
    let off = dir.path().join("off");
    let mut files = FileSink::create(&off, 10.0)
        .unwrap_or_else(|e| panic!("{e}"))
        .with_plots(false);
    receiver(2.048e6)
        .run(&mut SimSource::new(&sim), &mut files)
        .unwrap_or_else(|e| panic!("{e}"));
    let pngs: Vec<_> = std::fs::read_dir(&off)
        .unwrap_or_else(|e| panic!("{e}"))
        .filter_map(Result::ok)
        .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
        .collect();
    assert!(off.join("pvt.csv").exists());
    assert!(pngs.is_empty(), "{pngs:?}");
}
