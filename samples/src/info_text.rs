//! The human-readable table of an [`InfoReport`] (`gpsrx info` without `--json`).

use std::fmt;

use crate::info::{ComponentStats, Histogram, InfoReport};

/// Width of the longest bar in histograms and spectra.
const BAR_WIDTH: f64 = 40.0;
/// A histogram with more rows than this is shown merged into this many rows.
const MAX_ROWS: usize = 32;

/// `1234567` → `1,234,567`.
fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::with_capacity(s.len() + s.len() / 3);
    for (k, ch) in s.chars().enumerate() {
        if k > 0 && (s.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(ch);
    }
    out
}

fn bar(share: f64) -> String {
    "#".repeat((share * BAR_WIDTH).round().clamp(0.0, BAR_WIDTH) as usize)
}

fn percent(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), |x| format!("{:.3}%", 100.0 * x))
}

/// Rows (label, count) of a histogram, merged to at most [`MAX_ROWS`].
fn rows(h: &Histogram) -> Vec<(String, u64)> {
    match h {
        Histogram::Values { values, counts } if values.len() <= MAX_ROWS => values
            .iter()
            .zip(counts)
            .map(|(v, c)| (format!("{v}"), *c))
            .collect(),
        Histogram::Values { values, counts } => {
            let per = values.len().div_ceil(MAX_ROWS);
            values
                .chunks(per)
                .zip(counts.chunks(per))
                .map(|(v, c)| {
                    (
                        format!("{}..{}", v[0], v[v.len() - 1]),
                        c.iter().sum::<u64>(),
                    )
                })
                .collect()
        }
        Histogram::Binned { lo, hi, counts } => {
            let w = (hi - lo) / counts.len().max(1) as f64;
            counts
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    let a = lo + w * k as f64;
                    (format!("{:.4}..{:.4}", a, a + w), *c)
                })
                .collect()
        }
    }
}

fn write_histogram(f: &mut fmt::Formatter<'_>, name: &str, c: &ComponentStats) -> fmt::Result {
    let rows = rows(&c.histogram);
    let total: u64 = rows.iter().map(|r| r.1).sum::<u64>().max(1);
    let max = rows.iter().map(|r| r.1).max().unwrap_or(0).max(1);
    writeln!(f, "histogram of {name}:")?;
    for (label, count) in rows {
        writeln!(
            f,
            "  {label:>22} {:>14} {:>7.3}% {}",
            thousands(count),
            100.0 * count as f64 / total as f64,
            bar(count as f64 / max as f64)
        )?;
    }
    Ok(())
}

impl fmt::Display for InfoReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "file        {}", self.path.display())?;
        if let Some(m) = &self.meta_path {
            writeln!(f, "metadata    {}", m.display())?;
            writeln!(f, "data        {}", self.data_path.display())?;
        }
        writeln!(
            f,
            "format      {} ({}), fs {:.6} MHz, IF {} Hz, Q inverted: {}",
            self.format,
            if self.complex { "complex I/Q" } else { "real" },
            self.fs_hz / 1e6,
            self.if_hz,
            if self.invert_q { "yes" } else { "no" }
        )?;
        writeln!(
            f,
            "size        {} bytes = {} samples = {:.6} s",
            thousands(self.size_bytes),
            thousands(self.n_samples),
            self.duration_s
        )?;
        writeln!(
            f,
            "analysed    {} samples from sample {} ({:.6} s)",
            thousands(self.analysed_samples),
            thousands(self.analysed_from_sample),
            self.analysed_from_sample as f64 / self.fs_hz
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "{:<10} {:>12} {:>12} {:>12} {:>12} {:>10}",
            "component", "mean", "std", "min", "max", "at extreme"
        )?;
        let mut comps = vec![(if self.complex { "I" } else { "real" }, &self.i)];
        if let Some(q) = &self.q {
            comps.push(("Q", q));
        }
        for (name, c) in &comps {
            writeln!(
                f,
                "{:<10} {:>12.4} {:>12.4} {:>12.4} {:>12.4} {:>10}",
                name,
                c.mean,
                c.std,
                c.min,
                c.max,
                percent(c.clip_fraction)
            )?;
        }
        if let Some(r) = self.iq_correlation {
            writeln!(f, "I/Q correlation {r:.4}")?;
        }
        writeln!(
            f,
            "at extreme codes overall {}",
            percent(self.clip_fraction)
        )?;
        for (name, c) in &comps {
            writeln!(f)?;
            write_histogram(f, name, c)?;
        }
        if let Some(s) = &self.spectrum {
            writeln!(f)?;
            writeln!(
                f,
                "spectrum of the stored samples ({}-point FFT, Hann window, {} blocks averaged; dB relative to the mean):",
                s.fft_size,
                thousands(s.blocks)
            )?;
            let top = s.bands.iter().map(|b| b.power_db).fold(f64::MIN, f64::max);
            for (k, b) in s.bands.iter().enumerate() {
                // Bars span the 20 dB below the strongest band.
                let share = ((b.power_db - top + 20.0) / 20.0).clamp(0.0, 1.0);
                writeln!(
                    f,
                    "  {:>9.4} .. {:>9.4} MHz {:>7.2} dB {}{}",
                    b.f_lo_hz / 1e6,
                    b.f_hi_hz / 1e6,
                    b.power_db,
                    bar(share),
                    if k == s.peak_band { "  <- peak" } else { "" }
                )?;
            }
            writeln!(
                f,
                "flatness {:.3} (1 = white), DC {:+.1} dB, strongest bin {:.4} MHz at {:+.1} dB (both over the median bin)",
                s.flatness,
                s.dc_spike_db,
                s.peak_bin_hz / 1e6,
                s.peak_bin_over_median_db
            )?;
        }
        if !self.notes.is_empty() {
            writeln!(f)?;
            writeln!(f, "notes:")?;
            for n in &self.notes {
                writeln!(f, "  - {n}")?;
            }
        }
        if !self.warnings.is_empty() {
            writeln!(f)?;
            writeln!(f, "warnings:")?;
            for w in &self.warnings {
                writeln!(f, "  - {w}")?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn thousands_separators() {
        assert_eq!(super::thousands(0), "0");
        assert_eq!(super::thousands(999), "999");
        assert_eq!(super::thousands(2_000_000), "2,000,000");
        assert_eq!(super::thousands(12_345), "12,345");
    }
}
