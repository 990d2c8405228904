//! Closed-loop tests of the tracking crate: the implemented loops measured against the analytic
//! oracles of `shared/reference/oracles.md` (one integration-test binary for the crate).
//!
//! Run with `--nocapture` to see the measured tables (they are copied into `tracking/README.md`).

mod aided;
mod bandwidth;
mod costas_gain;
mod dll;
mod dynamics;
mod estimators;
mod fll;
mod sim;
mod thermal;
