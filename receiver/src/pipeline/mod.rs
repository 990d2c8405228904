//! The receiver pipeline: samples in, observables, fixes and events out.
//!
//! - [`Receiver`] (in [`receiver`]): the whole receiver, driven by a [`gpsrx_samples::SampleSource`]
//!   (`run`) or by sample blocks (`push`), writing to a [`Sink`];
//! - [`channel_manager`]: the cold start, re-acquisition, and the channels' work per block;
//! - [`navigation`]: LNAV decoders, observables, PVT, clock steering and aiding feedback;
//! - [`fix_output`]: the fix, observables and integrity verdict of an epoch, fix statistics;
//! - [`sink`]: what the receiver emits ([`Sink`], [`MemorySink`]);
//! - [`aiding`]: the INS-velocity Doppler feed-forward for the channels' aiding port;
//! - [`aid_monitor`]: the integrity check of that feed-forward against the tracked Doppler;
//! - [`ring`]: the window of recent samples addressed by absolute index;
//! - [`coarse_fix`]: the first fix from code phases alone (approximate time and position);
//! - [`dating`]: which GPS week labels receiver time before subframe 1 is decoded;
//! - [`navdata`]: frame sync, subframes, ephemerides and SV time per satellite;
//! - [`bit_edge`]: lost samples found by the data-bit edges moving together;
//! - [`discontinuity`]: lost samples found by a carrier-phase jump common to the satellites;
//! - [`code_jump`]: lost samples found by a code jump (prompt power collapsing together);
//! - [`carrier_step`]: a satellite's carrier-phase step over lost samples;
//! - [`gap_length`]: the length of lost time from the bit edges and carrier-phase steps;
//! - `long_gap`: the receiver time re-established after a gap too long to measure;
//! - [`quick_sync`]: frame sync from one TLM and HOW, confirmed across satellites;
//! - [`sv_time`]: SV times kept across losses of the signal and lost samples;
//! - [`observables`]: pseudoranges, carrier phase, Doppler at common receiver epochs;
//! - [`tracker`]: channels alone over a stream (loop studies);
//! - [`profile`]: where a run's time goes, stage by stage.

pub mod aid_monitor;
pub mod aiding;
pub mod bit_edge;
pub mod carrier_step;
pub mod channel_manager;
pub mod coarse_fix;
pub mod code_jump;
pub mod dating;
pub mod discontinuity;
pub mod fix_output;
pub mod gap_length;
pub(crate) mod long_gap;
pub mod navdata;
pub mod navigation;
pub mod observables;
pub mod profile;
pub mod quick_sync;
pub mod receiver;
pub mod ring;
pub mod search_schedule;
pub mod sink;
pub mod smoothing;
pub mod sv_time;
#[cfg(test)]
mod test_support;
pub mod tracker;
pub mod visibility;

pub use channel_manager::SearchSettings;
pub use dating::{WeekReference, WeekSource};
pub use profile::StageTimes;
pub use receiver::{
    Assistance, AssistanceError, AssistanceFiles, InsAiding, InsAidingSummary, Receiver,
    ReceiverError, RunSummary,
};
pub use sink::{
    FixReport, MemorySink, NavigationEnd, ObservablesReport, Progress, ReceiverEvent, Sink,
    SinkError, Tee,
};
