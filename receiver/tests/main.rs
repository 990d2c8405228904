//! Integration tests of the receiver library: the pipeline driven in memory against the
//! simulator's truth (one test binary for the crate).

mod acquisition;
mod ephemeris_file;
mod faults;
mod long_gaps;
mod pipeline;
mod plots;
mod sigmf_lo;
mod snapshot;
mod vector;
