//! `gpsrx info`: describe a recording.

use crate::cli::InfoArgs;
use anyhow::Context;

/// Runs `gpsrx info`.
pub fn run(args: &InfoArgs) -> anyhow::Result<()> {
    let cfg = args.source.to_config()?;
    let report = gpsrx_samples::info::inspect(&cfg, args.max_samples)
        .with_context(|| format!("cannot describe {}", cfg.path.display()))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{report}");
    }
    Ok(())
}
