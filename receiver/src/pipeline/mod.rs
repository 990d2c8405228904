//! The receiver pipeline: samples in, observables, fixes and events out.
//!
//! - [`Receiver`] (in [`receiver`]): the whole receiver, driven by a [`gpsrx_samples::SampleSource`]
//!   (`run`) or by sample blocks (`push`), writing to a [`Sink`];
//! - [`channel_manager`]: the cold start, re-acquisition, and the channels' work per block;
//! - [`navigation`]: LNAV decoders, observables, PVT, clock steering and aiding feedback;
//! - [`sink`]: what the receiver emits ([`Sink`], [`MemorySink`]);
//! - [`aiding`]: the INS-velocity Doppler feed-forward for the channels' aiding port;
//! - [`ring`]: the window of recent samples addressed by absolute index;
//! - [`dating`]: which GPS week labels receiver time before subframe 1 is decoded;
//! - [`navdata`]: frame sync, subframes, ephemerides and SV time per satellite;
//! - [`observables`]: pseudoranges, carrier phase, Doppler at common receiver epochs;
//! - [`tracker`]: channels alone over a stream (loop studies).

pub mod aiding;
pub mod channel_manager;
pub mod dating;
pub mod navdata;
pub mod navigation;
pub mod observables;
pub mod receiver;
pub mod ring;
pub mod sink;
pub mod tracker;

pub use channel_manager::SearchSettings;
pub use dating::{WeekReference, WeekSource};
pub use receiver::{
    Assistance, AssistanceError, AssistanceFiles, InsAiding, Receiver, ReceiverError, RunSummary,
};
pub use sink::{
    FixReport, MemorySink, NavigationEnd, ObservablesReport, Progress, ReceiverEvent, Sink,
    SinkError, Tee,
};
