//! `gpsrx`: the command-line GPS L1 C/A receiver.
//!
//! Exit status (see [`gpsrx_cli::exit`]): 0 done (also when standard output is closed early, as
//! by `| head`), 1 an error (one line on standard error), 2 `gpsrx run` or `gpsrx demo` made
//! no valid fix; `gpsrx batch`: 1 when every entry failed.

use clap::Parser;
use gpsrx_cli::cli::{Cli, Command};
use gpsrx_cli::commands;
use gpsrx_cli::exit::{error_message, is_broken_pipe, Completion};
use std::io::{IsTerminal, Write};
use std::process::ExitCode;

fn main() -> ExitCode {
    return_large_blocks_to_the_system();
    main_thread_in_the_pool();
    let cli = Cli::parse();
    // A study runs the receiver on tens of cases: their progress lines would bury its table.
    let quiet = matches!(cli.command, Command::Study(_));
    let filter = tracing_subscriber::EnvFilter::try_from_env("GPSRX_LOG").unwrap_or_else(|_| {
        tracing_subscriber::EnvFilter::new(match (cli.verbose, quiet) {
            (true, _) => "debug",
            (false, true) => "warn",
            (false, false) => "info",
        })
    });
    // No colour codes in a log file or a pipe (nor with NO_COLOR set).
    let ansi = std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none();
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(false)
        .with_ansi(ansi)
        .init();
    let done = |r: anyhow::Result<()>| r.map(|()| Completion::Done);
    let result = match cli.command {
        Command::Simulate(args) => done(commands::simulate::run(&args)),
        Command::Info(args) => done(commands::info::run(&args)),
        Command::Demo(args) => commands::demo::run(&args),
        Command::Acquire(args) => done(commands::acquire::run(&args)),
        Command::Snapshot(args) => done(commands::snapshot::run(&args)),
        Command::Track(args) => done(commands::track::run(&args)),
        Command::Run(args) => commands::run::run(&args),
        Command::Batch(args) => commands::batch::run(&args),
        Command::Config(args) => done(commands::config::run(&args)),
        Command::Study(args) => done(gpsrx_studies::run(&args)),
        Command::Bench(args) => done(commands::bench::run(&args)),
    };
    match result {
        Ok(c) => ExitCode::from(c.exit_status()),
        // `gpsrx ... | head`: the reader has what it wanted.
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            // If standard error is gone too there is no one left to tell.
            let _ = writeln!(std::io::stderr(), "error: {}", error_message(&e));
            ExitCode::FAILURE
        }
    }
}

/// The rayon pool takes the main thread as one of its threads (one spawned thread fewer:
/// the default pool size, one per core, counts it). The main thread calls the rounds of
/// `gpsrx run` (channels beside a search, `rayon::join`) and runs the navigation between them;
/// as one of the pool's threads it works on its own rounds instead of waking the pool and
/// sleeping until the pool wakes it again, and one thread fewer spins idle between rounds
/// (measured: 60 s of 4 MHz ci8 with the defaults, process CPU 2.91 -> 2.79 s, medians of 5
/// interleaved runs, outputs identical).
/// If the pool cannot be made so (it exists already, or a thread cannot be spawned), rayon
/// makes its default pool when it is first used, as without this.
fn main_thread_in_the_pool() {
    let _ = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .build_global();
}

/// Large blocks (1 MiB and more: the block spectra and grids of a search, the sample window)
/// are mapped and unmapped on their own, so memory a search frees goes back to the system
/// between searches. glibc's default raises its mapping threshold to the size of each large
/// block freed (up to 32 MiB) and keeps the next ones in its per-thread heaps: the 10 ms x 50
/// search's 32 MB of spectra then stayed resident for the whole run (measured: 60 s of 4 MHz
/// ci8, peak resident memory 121 MB with the default, 77 MB with this).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn return_large_blocks_to_the_system() {
    // SAFETY: mallopt only sets an allocator parameter; called first thing in `main`.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
    }
}

/// Other platforms' allocators are left as they are.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn return_large_blocks_to_the_system() {}
