//! Navigation wing: from channel reports to observables and fixes.
//!
//! - `processor`: [`NavigationProcessor`], per satellite an LNAV decoder, across satellites the
//!   observables, per epoch the PVT, clock steering and the aiding feedback; split by concern
//!   (`decode`: the navigation message and the coarse-time fix; `time_recovery`: the receiver
//!   time across lost samples, as navigation meets them; `solve`: the solution of an epoch and
//!   its fix; `predict`: what the last fix predicts for the acquisition scheduler);
//! - `navdata`: frame sync, subframes, ephemerides and SV time per satellite ([`NavDecoder`]);
//! - `frame_memory`: the bits of the frames before by frame position, which place a bit stream
//!   in time after lost samples;
//! - `observables`: pseudoranges, carrier phase, Doppler at common receiver epochs;
//! - `smoothing`: carrier smoothing of the pseudoranges (Hatch filter, bridged over gaps);
//! - `fix_output`: the fix, observables and integrity verdict of an epoch, fix statistics
//!   ([`FixStats`]).

pub(crate) mod fix_output;
mod frame_memory;
pub(crate) mod navdata;
pub(crate) mod observables;
mod processor;
mod smoothing;

pub use fix_output::FixStats;
pub use navdata::{NavDecoder, NavEvent};
pub use processor::{
    NavigationProcessor, APPROX_DOPPLER_HZ, BELOW_HORIZON_DEG, PENDING_FOR_S, PREDICTED_DOPPLER_HZ,
    PREDICTED_DOPPLER_RATE_HZ_S,
};
