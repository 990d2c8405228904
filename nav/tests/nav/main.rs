//! gpsrx-nav integration tests (one test binary, as the workspace prefers). Each module checks
//! one concept against independent truth: published values, RTKLIB 2.4.3 / pymap3d fixtures
//! (see ../data/README.md) or closed-form identities.

mod almanac_tests;
mod atmosphere_tests;
mod coarse_time_tests;
mod common;
mod ephemeris_tests;
mod frames_tests;
mod landmark_tests;
mod lnav_rtklib_tests;
mod lnav_tests;
mod pvt_tests;
mod rinex_tests;
mod time_tests;
