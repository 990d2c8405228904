//! Integration tests of the sample layer and the simulator: one test binary for the crate.

mod io;
mod sim;
mod vehicle_motion;
