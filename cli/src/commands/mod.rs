//! One module per `gpsrx` subcommand.

pub mod acquire;
pub mod batch;
pub mod bench;
pub mod config;
pub mod demo;
pub mod info;
pub mod run;
pub mod simulate;
pub mod snapshot;
pub mod source;
pub mod track;

/// The working directory of a command with `--keep DIR`: that directory, or a temporary one
/// removed when the returned guard drops (keep the guard alive while the files are used).
pub(crate) fn work_dir(
    keep: Option<&std::path::Path>,
) -> anyhow::Result<(std::path::PathBuf, Option<tempfile::TempDir>)> {
    use anyhow::Context;
    match keep {
        Some(d) => Ok((d.to_path_buf(), None)),
        None => {
            let tmp = tempfile::tempdir().context("cannot create a temporary directory")?;
            Ok((tmp.path().to_path_buf(), Some(tmp)))
        }
    }
}
