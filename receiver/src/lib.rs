//! The gpsrx receiver: the pipeline from IF samples to fixes, its outputs, studies, and the
//! `gpsrx` command-line tool built on them.
//!
//! - [`cli`]: command-line arguments (clap derive);
//! - [`commands`]: one module per subcommand.

pub mod cli;
pub mod commands;
pub mod fusion;
pub mod landmarks;
pub mod output;
pub mod pipeline;
pub mod study;
