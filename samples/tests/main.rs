//! Integration tests of the sample layer and the simulator: one test binary for the crate.

mod held_ci16;
mod io;
mod sim;
mod vehicle_motion;
