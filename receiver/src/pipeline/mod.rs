//! The receiver pipeline: samples from a source, shared by all channels, block by block.
//!
//! - [`aiding`]: the INS-velocity Doppler feed-forward for the channels' aiding port;
//! - [`ring`]: the window of recent samples addressed by absolute index;
//! - [`navdata`]: frame sync, subframes, ephemerides and SV time per satellite;
//! - [`observables`]: pseudoranges, carrier phase, Doppler at common receiver epochs;
//! - [`tracker`]: drives the tracking channels over the window, in parallel.

pub mod aiding;
pub mod navdata;
pub mod observables;
pub mod ring;
pub mod tracker;
