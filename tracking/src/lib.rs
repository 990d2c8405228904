//! Tracking loops for the gpsrx GPS L1 C/A receiver, with an INS Doppler aiding port.
//!
//! One receiver concept per module:
//!
//! - [`config`]: the loop configuration ([`LoopConfig`]) and its validation.
//! - [`loop_filter`]: digital PLL / FLL / FLL-assisted PLL / DLL filters (Kaplan Table 5.6,
//!   Figs. 5.20-5.21).
//! - [`loop_analysis`]: the closed digital loop (NCO timing model), its stability and noise
//!   bandwidth.
//! - [`discriminator`]: Costas / atan2 PLL, cross-dot FLL, E-L envelope and dot-product DLL
//!   discriminators.
//! - [`aiding`]: the feed-forward arithmetic of seed 004 Fig. 4 and carrier-aided code rate.
//! - [`carrier_loop`], [`code_loop`]: what a channel drives once per integration interval.
//! - [`lock_detector`]: phase lock (`cos 2 phi`) and code lock (C/N0) with hysteresis.
//! - [`cn0`]: NWPR and M2M4 C/N0 estimators.
//! - [`fade_detector`]: a sudden collapse of the prompt power (blockage, sample gap).
//! - [`bit_sync`]: histogram bit synchronisation and bit decisions.
//! - [`phase_fit`]: a least-squares quadratic fit of the tracked carrier phase (open-loop
//!   frequency and Doppler rate for a loop that is narrowed or restarted).
//! - [`phase_sim`]: a phase-domain closed-loop simulator (correlator-level prompts) for studies.
//!
//! Measured closed-loop behaviour (noise bandwidth, stability limits, dynamic and thermal errors,
//! aiding) is in `tracking/README.md` and the `closed_loop` integration test.

pub mod aiding;
pub mod bit_sync;
pub mod carrier_loop;
pub mod channel;
pub mod cn0;
pub mod code_loop;
pub mod config;
pub mod correlator_choice;
pub mod discriminator;
pub mod fade_detector;
pub mod lock_detector;
pub mod loop_analysis;
pub mod loop_filter;
pub mod phase_fit;
pub mod phase_sim;

pub use aiding::{AidSource, AidingPort, DopplerAid, TrackingMode};
pub use bit_sync::{Bit, BitSync, BitSyncConfig, BitSyncState};
pub use carrier_loop::{CarrierLoop, CarrierOutput};
pub use channel::{
    dynamic_weak_config, Channel, ChannelConfig, ChannelEpoch, ChannelStart, ChannelState,
    CodeShift, DYNAMIC_WEAK_BW_HZ, DYNAMIC_WEAK_T_COH_S,
};
pub use cn0::{M2m4Estimator, NwprEstimator};
pub use code_loop::{CodeLoop, CodeOutput};
pub use config::{ConfigError, DllDiscriminator, FllDiscriminator, LoopConfig, PllDiscriminator};
pub use correlator_choice::{CorrelatorArithmetic, CorrelatorChoice, CorrelatorIsa};
pub use lock_detector::{CodeLockDetector, Hysteresis, PllLockConfig, PllLockDetector};
pub use loop_filter::LoopFilter;
