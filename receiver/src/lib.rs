//! The gpsrx receiver as a library: the pipeline from IF samples to fixes, and its outputs.
//!
//! - [`config`]: [`ReceiverConfig`], the configuration (a `gpsrx.toml` file);
//! - [`pipeline`]: [`Receiver`], its channel manager and navigation processor, [`Sink`]s;
//! - [`output`]: RINEX, NMEA, GeoJSON, KML and CSV writers;
//! - [`fusion`]: GNSS/dead-reckoning fusion after tracking (seeds 000 and 002);
//! - [`landmarks`]: landmark range observations for the solver (seed 001).

pub mod config;
pub mod fusion;
pub mod landmarks;
pub mod output;
pub mod pipeline;

pub use config::ReceiverConfig;
pub use pipeline::{Assistance, MemorySink, Receiver, ReceiverError, RunSummary, Sink};
