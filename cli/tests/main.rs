//! Integration tests of the `gpsrx` command-line tool and its commands: one test binary
//! (one link) for the crate.

mod common;

mod acquisition;
mod aided_run;
mod bad_input;
mod batch;
mod bench;
mod dating;
mod dr_run;
mod ins_simulate;
mod narrow_loops;
mod outputs;
mod run;
mod snapshot;
mod tracking;
