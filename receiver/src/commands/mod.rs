//! One module per `gpsrx` subcommand.

pub mod acquire;
pub mod bench;
pub mod config;
pub mod demo;
pub mod info;
pub mod run;
pub mod simulate;
pub mod track;
