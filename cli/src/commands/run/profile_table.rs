//! `gpsrx run --profile`: where the run's time went, stage by stage
//! ([`gpsrx_receiver::pipeline::StageTimes`]), with the process's CPU time and peak resident
//! memory.

use gpsrx_receiver::pipeline::StageTimes;
use std::io::Write;

/// CPU time (user + system, every thread) and peak resident memory (MB) of this process so
/// far, where the platform tells them.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn process_usage() -> Option<(f64, f64)> {
    // SAFETY: getrusage writes into the zeroed struct it is given and reads nothing else.
    let usage = unsafe {
        let mut u: libc::rusage = std::mem::zeroed();
        (libc::getrusage(libc::RUSAGE_SELF, &mut u) == 0).then_some(u)
    }?;
    let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    // ru_maxrss is in KiB on Linux.
    let peak_mb = usage.ru_maxrss as f64 * 1024.0 / 1e6;
    Some((secs(usage.ru_utime) + secs(usage.ru_stime), peak_mb))
}

/// Other platforms: not measured.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn process_usage() -> Option<(f64, f64)> {
    None
}

/// Writes the profile of a run of `duration_s` of signal that took `wall_s`; `usage` as
/// [`process_usage`] returns it.
pub fn write_profile(
    out: &mut dyn Write,
    p: &StageTimes,
    duration_s: f64,
    wall_s: f64,
    usage: Option<(f64, f64)>,
) -> std::io::Result<()> {
    let pct = |s: f64| 100.0 * s / wall_s.max(1e-9);
    match usage {
        Some((cpu_s, peak_mb)) => writeln!(
            out,
            "profile: {duration_s:.1} s of signal in {wall_s:.2} s wall ({:.1}x real time), process CPU {cpu_s:.2} s ({:.2} cores), peak memory {peak_mb:.1} MB",
            duration_s / wall_s.max(1e-9),
            cpu_s / wall_s.max(1e-9)
        )?,
        None => writeln!(
            out,
            "profile: {duration_s:.1} s of signal in {wall_s:.2} s wall ({:.1}x real time)",
            duration_s / wall_s.max(1e-9)
        )?,
    }
    writeln!(out, "  {:<58} {:>8} {:>10}", "stage", "wall s", "% of wall")?;
    let row = |out: &mut dyn Write, label: &str, s: f64| {
        writeln!(out, "  {label:<58} {s:8.3} {:9.1} %", pct(s))
    };
    row(out, "cold start (search of every PRN)", p.cold_start_s)?;
    row(
        out,
        "parallel rounds (channels | search, side by side)",
        p.rounds_s,
    )?;
    row(out, "  - channels: correlators and loops", p.tracking_s)?;
    row(
        out,
        &format!("  - background search ({} searches)", p.searches),
        p.search_s,
    )?;
    row(out, "navigation (observables, fixes, rows)", p.navigation_s)?;
    writeln!(
        out,
        "    - beside the next round in {} rounds ({} worked again)",
        p.overlapped_rounds, p.redone_rounds
    )?;
    row(out, "  - reading the next block, beside it", p.read_s)?;
    row(out, "outputs at the end (plots, files)", p.finish_s)?;
    row(
        out,
        "other (setup: files, FFT plans, replicas)",
        (wall_s - p.accounted_s()).max(0.0),
    )?;
    writeln!(
        out,
        "  (parts run side by side: each is timed from its start to its end on its own thread)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_gives_every_stage_with_its_share_of_the_wall_time() {
        let p = StageTimes {
            cold_start_s: 0.05,
            rounds_s: 1.5,
            tracking_s: 1.1,
            search_s: 0.6,
            searches: 4,
            read_s: 0.1,
            navigation_s: 0.3,
            finish_s: 0.05,
            overlapped_rounds: 1490,
            redone_rounds: 3,
        };
        let mut out = Vec::new();
        write_profile(&mut out, &p, 60.0, 2.0, Some((3.0, 44.5))).unwrap_or_else(|e| panic!("{e}"));
        let text = String::from_utf8(out).unwrap_or_else(|e| panic!("{e}"));
        assert!(text.contains("in 2.00 s wall (30.0x real time), process CPU 3.00 s (1.50 cores), peak memory 44.5 MB"), "{text}");
        let line = |key: &str| {
            text.lines()
                .find(|l| l.contains(key))
                .unwrap_or_else(|| panic!("no {key} in {text}"))
                .to_string()
        };
        assert!(
            line("parallel rounds").ends_with("1.500      75.0 %"),
            "{text}"
        );
        assert!(line("4 searches").ends_with("0.600      30.0 %"), "{text}");
        assert!(line("navigation").ends_with("0.300      15.0 %"), "{text}");
        assert!(
            line("beside the next round").ends_with("in 1490 rounds (3 worked again)"),
            "{text}"
        );
        // 2.0 - (0.05 + 1.5 + 0.3 + 0.05) s of setup.
        assert!(line("other").ends_with("0.100       5.0 %"), "{text}");
    }

    #[test]
    fn this_process_has_used_some_cpu_and_memory() {
        if let Some((cpu_s, peak_mb)) = process_usage() {
            assert!(cpu_s > 0.0 && peak_mb > 1.0, "{cpu_s} s, {peak_mb} MB");
        }
    }
}
