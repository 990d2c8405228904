//! Aiding wing: the INS-velocity Doppler feed-forward for the channels' aiding port, the
//! integrity monitor that gates it, and without an INS the bridge over an outage from the
//! receiver's own motion.
//!
//! - `feed_forward`: [`InsFeedForward`], the Doppler of each satellite from the INS velocity,
//!   the ephemerides and the fixes (seed 004, eq. 6);
//! - `monitor`: [`AidMonitor`], the check of that feed-forward against the tracked Doppler
//!   ([`GatedAid`] hands the aid on only while it is admitted);
//! - `bridge`: [`OutageBridge`], the motion of the last fixes (a turn at a constant rate) fed
//!   forward while every signal is gone and the loops take it back.

mod bridge;
mod feed_forward;
mod monitor;

pub use bridge::{
    FixPoint, OutageBridge, TurnMotion, ARM_ACCEL_MPS2, FIT_WINDOW_S, MAX_ACCEL_CHANGE,
    MAX_BRIDGE_S, MAX_FIX_AGE_S, MIN_FIT_FIXES, MIN_TURN_SPEED_MPS, QUADRATIC_FIT_FIXES,
};
pub use feed_forward::{InsFeedForward, DRIFT_SMOOTHING_S};
pub use monitor::{AidMonitor, AidPermission, AidingStats, GatedAid};
