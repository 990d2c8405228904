//! `gpsrx info`: describe a recording.

use crate::cli::InfoArgs;
use anyhow::Context;
use std::io::Write;

/// Runs `gpsrx info`.
pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let cfg = args.source.to_config()?;
    let report = gpsrx_samples::info::inspect(&cfg, args.max_samples)
        .with_context(|| format!("cannot describe {}", cfg.path.display()))?;
    let mut out = crate::exit::stdout();
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&report)?)?;
    } else {
        write!(out, "{report}")?;
    }
    out.flush()?;
    Ok(())
}
