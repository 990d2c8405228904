//! The gpsrx receiver as a library: the pipeline from IF samples to fixes, and its outputs.
//!
//! - [`config`]: [`ReceiverConfig`], the configuration (a `gpsrx.toml` file);
//! - [`pipeline`]: [`Receiver`], its channel manager and navigation processor, [`Sink`]s;
//! - [`output`]: RINEX, NMEA, GeoJSON, KML and CSV writers;
//! - [`fusion`]: GNSS/dead-reckoning fusion after tracking (seeds 000 and 002);
//! - [`landmarks`]: landmark range observations for the solver (seed 001);
//! - [`batch`]: batches of recordings from a manifest (`gpsrx batch`, the Python package);
//! - [`simulate`]: a scenario into an IF recording, its truth and the simulated sensor logs
//!   (`gpsrx simulate`, the Python package, the benchmarks);
//! - [`error_message`]: an error and its causes as one message.
//!
//! # Example: the whole receiver in memory
//!
//! Twelve seconds of a simulated static antenna are pushed into a [`Receiver`] block by block
//! (any block size gives the same result); the fixes collected by a [`MemorySink`] land on the
//! simulator's truth. [`Receiver::run`] does the same from any
//! [`gpsrx_samples::SampleSource`] (a file, a FIFO, standard input), and
//! [`output::FileSink`] writes the standard files instead.
//!
//! ```
//! use gpsrx_receiver::{Assistance, MemorySink, Receiver, ReceiverConfig};
//! use gpsrx_samples::sim::{scenario::BUILTIN_NAV_TEXT, Scenario, Simulator};
//!
//! let scenario = Scenario::from_toml(
//!     r#"
//!     duration_s = 12.0
//!     nav = "builtin:brdc0010.22n"
//!     [start]
//!     week = 2190
//!     tow_s = 538198.0
//!     [output]
//!     format = "cf32_le"
//!     fs_hz = 2.048e6
//!     [receiver]
//!     kind = "static"
//!     llh_deg = [36.3721, 127.3604, 80.0]
//!     "#,
//! )?;
//! let sim = Simulator::new(&scenario, std::path::Path::new("."))?;
//!
//! let mut config = ReceiverConfig::default();
//! config.run.tropo = gpsrx_receiver::config::TropoModel::None; // the simulator has none
//! let assistance = Assistance {
//!     nav: Some(gpsrx_nav::rinex_nav::parse_rinex_nav(BUILTIN_NAV_TEXT)?),
//!     ..Assistance::default()
//! };
//! let mut receiver = Receiver::new(&config, 2.048e6, assistance)?;
//! let mut sink = MemorySink::new();
//! let mut block = Vec::new();
//! for chunk in 0..sim.chunk_count() {
//!     sim.generate_chunk(chunk, &mut block);
//!     receiver.push(&block, &mut sink)?;
//! }
//! let summary = receiver.finish(&mut sink)?;
//!
//! assert!(summary.fixes > 0, "no fix");
//! let (_, truth) = sim.receiver_truth(0.0);
//! for f in &sink.fixes {
//!     let [x, y, z] = f.fix.ecef_m;
//!     let error_m = ((x - truth.pos_m.x).powi(2) + (y - truth.pos_m.y).powi(2)
//!         + (z - truth.pos_m.z).powi(2))
//!     .sqrt();
//!     assert!(error_m < 10.0, "fix {error_m:.1} m from the truth");
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod batch;
pub mod config;
pub mod fusion;
pub mod landmarks;
mod message;
pub mod output;
pub mod pipeline;
pub mod simulate;
pub mod snapshot;

pub use config::ReceiverConfig;
pub use message::error_message;
pub use pipeline::{Assistance, MemorySink, Receiver, ReceiverError, RunSummary, Sink};
