//! Channels wing: the satellites searched for and tracked, block by block.
//!
//! - `channel_manager`: [`ChannelManager`], the cold start, re-acquisition, the channels' work
//!   per block, and the realignment of channels whose code jumped over lost samples;
//! - `search_schedule`: which satellites are searched when, within a CPU budget
//!   ([`SearchBudget`], [`Visibility`]);
//! - `visibility`: elevation and Doppler of a satellite predicted from an ephemeris
//!   ([`predict_satellite`]);
//! - `dynamics`: whether the receiver is under dynamics, from its strong channels' loops (the
//!   weak channels then widen theirs);
//! - `ring`: the window of recent samples addressed by absolute index;
//! - `tracker`: channels alone over a stream, without navigation ([`track`], loop studies).

pub(crate) mod channel_manager;
mod dynamics;
pub(crate) mod ring;
pub(crate) mod search_schedule;
mod tracker;
pub(crate) mod visibility;

pub use channel_manager::{ChannelManager, RealignSearch, Realigned, SearchSettings};
pub use search_schedule::{
    cost_s, fixed_cost_s, level_config, SearchBudget, Visibility, BURST_S, DEFAULT_PER_SIGNAL_S,
    DEFER_DEEP_FROM_TRACKED, LEVELS,
};
pub use tracker::{track, AidSource};
pub use visibility::{predict as predict_satellite, SatPrediction};
