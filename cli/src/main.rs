//! `gpsrx`: the command-line GPS L1 C/A receiver.

use clap::Parser;
use gpsrx_cli::cli::{Cli, Command};
use gpsrx_cli::commands;

fn main() {
    let cli = Cli::parse();
    let filter = tracing_subscriber::EnvFilter::try_from_env("GPSRX_LOG").unwrap_or_else(|_| {
        tracing_subscriber::EnvFilter::new(if cli.verbose { "debug" } else { "info" })
    });
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(false)
        .init();
    let result = match cli.command {
        Command::Simulate(args) => commands::simulate::run(&args),
        Command::Info(args) => commands::info::run(&args),
        Command::Demo(args) => commands::demo::run(&args),
        Command::Acquire(args) => commands::acquire::run(&args),
        Command::Track(args) => commands::track::run(&args),
        Command::Run(args) => commands::run::run(&args),
        Command::Config(args) => commands::config::run(&args),
        Command::Study(args) => gpsrx_studies::run(&args),
        Command::Bench(args) => commands::bench::run(&args),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
