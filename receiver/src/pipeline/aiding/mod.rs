//! Aiding wing: the INS-velocity Doppler feed-forward for the channels' aiding port and the
//! integrity monitor that gates it.
//!
//! - `feed_forward`: [`InsFeedForward`], the Doppler of each satellite from the INS velocity,
//!   the ephemerides and the fixes (seed 004, eq. 6);
//! - `monitor`: [`AidMonitor`], the check of that feed-forward against the tracked Doppler
//!   ([`GatedAid`] hands the aid on only while it is admitted).

mod feed_forward;
mod monitor;

pub use feed_forward::{InsFeedForward, DRIFT_SMOOTHING_S};
pub use monitor::{AidMonitor, AidPermission, AidingStats, GatedAid};
