//! The receiver pipeline: samples in, observables, fixes and events out.
//!
//! [`Receiver`] (in `receiver`) is the whole receiver, driven by a
//! [`gpsrx_samples::SampleSource`] (`run`) or by sample blocks (`push`), writing to a [`Sink`].
//! Around it, five wings, a folder each with one public face:
//!
//! - [`channels`]: the cold start, re-acquisition, the search schedule, the sample window and
//!   the channels' work per block (and channels alone over a stream, [`channels::track`]);
//! - [`timing`]: receiver and SV time across losses of the signal, lost samples and long gaps
//!   (gap detection and length, quick frame sync, the coarse-time fix, the week's dating);
//! - [`navigation`]: LNAV decoders, observables and carrier smoothing, PVT with RAIM, fix
//!   output and clock steering ([`navigation::NavigationProcessor`]);
//! - [`aiding`]: the INS-velocity Doppler feed-forward and its integrity monitor;
//! - [`vector`]: vector tracking, the navigation filter that drives the channels through the
//!   same aiding port (`--tracking vector`);
//!
//! and what the receiver emits: [`sink`] (the [`Sink`] trait and the products [`Fix`],
//! [`ObsEpoch`], [`ChannelRow`]); `profile`: where a run's time goes, stage by stage
//! ([`StageTimes`]).

pub mod aiding;
pub mod channels;
pub mod navigation;
mod profile;
mod receiver;
pub mod sink;
#[cfg(test)]
mod test_support;
pub mod timing;
pub mod vector;

pub use channels::SearchSettings;
pub use profile::StageTimes;
pub use receiver::{
    Assistance, AssistanceError, AssistanceFiles, InsAiding, InsAidingSummary, Receiver,
    ReceiverError, RunSummary,
};
pub use sink::{
    ChannelRow, Fix, FixQuality, FixReport, MemorySink, NavigationEnd, ObsEpoch, ObservablesReport,
    Progress, ReceiverEvent, SatObs, SatView, Sink, SinkError, Tee,
};
pub use timing::{WeekReference, WeekSource};
pub use vector::VectorSummary;
