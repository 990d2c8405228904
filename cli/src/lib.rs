//! The `gpsrx` command-line tool: argument parsing ([`cli`]) and one thin module per
//! subcommand ([`commands`]) over the receiver library (`gpsrx-receiver`) and the studies
//! (`gpsrx-studies`).

pub mod cli;
pub mod commands;
pub mod exit;
