//! The gpsrx receiver as a library: the pipeline from IF samples to fixes, and its outputs.
//!
//! - [`pipeline`]: tracking channels, navigation data, observables, aiding;
//! - [`output`]: RINEX, NMEA, GeoJSON, KML and CSV writers;
//! - [`fusion`]: GNSS/dead-reckoning fusion after tracking (seeds 000 and 002);
//! - [`landmarks`]: landmark range observations for the solver (seed 001).

pub mod fusion;
pub mod landmarks;
pub mod output;
pub mod pipeline;
