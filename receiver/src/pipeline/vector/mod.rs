//! Vector wing: the navigation filter drives the channels (`--tracking vector`, issue 29, first
//! part: a VDFLL-style carrier feed-forward).
//!
//! - `ekf`: [`NavFilter`], the 8-state extended Kalman filter (position, velocity, clock bias
//!   and drift; white-noise acceleration, a TCXO clock model) with its innovation test;
//! - `noise`: each channel's measurement noise from its C/N0 (DLL and FLL thermal noise);
//! - `measure`: the filter's rows from an epoch of pseudoranges and Dopplers;
//! - `feed`: the filter's Doppler prediction for every satellite through the aiding port
//!   ([`VectorPort`]);
//! - `dynamics`: the acceleration test that keeps the filter's feed-forward, 0.2-0.3 s ahead
//!   of its last measurement, off the channels while the receiver accelerates hard;
//! - `vouch`: the channels whose code agrees with the prediction before the filter measures
//!   them (they keep the lower loss threshold until it does);
//! - `take_in`: satellites above the horizon that no channel tracks, started where the
//!   prediction puts their signals (no search);
//! - `tracker`: [`VectorTracking`], the handover scalar to vector and back, fed with what the
//!   navigation processor emits ([`Captured`], taken by [`Tap`]).
//!
//! Not in this part: the code NCO driven from the predicted range (the code loop stays
//! carrier-aided), long coherent integration with data-bit wipe-off, INS error states (with
//! `--ins` the INS's motion drives the prediction, its velocity error a random walk), the
//! filter at the discriminator rate.

mod dynamics;
pub mod ekf;
pub mod feed;
pub mod measure;
pub mod noise;
pub mod take_in;
mod tap;
mod tracker;
pub mod vouch;

pub use ekf::{ClockModel, FilterParams, NavFilter, Row, RowKind, UpdateOutcome};
pub use feed::{Snapshot, VectorPort};
pub use tap::Tap;
pub use tracker::{Captured, VectorSummary, VectorTracking};

#[cfg(test)]
mod tests;
