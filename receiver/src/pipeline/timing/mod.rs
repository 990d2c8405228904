//! Timing wing: receiver time and the satellites' SV times, across losses of the signal, lost
//! samples and long gaps.
//!
//! Navigation asks one type, [`TimeKeeper`] (`keeper`): it holds the SV times, the gap
//! detectors, the clock of the last fix and the recovery from long gaps, and says what the end
//! of a block found ([`BlockEvent`]). The decision on a code realignment's shifts is made here
//! too (`code_jump::plan_realignment`); the channel manager only carries it out.
//!
//! - `sv_time`: SV times kept across losses of the signal and lost samples;
//! - `discontinuity`: lost samples found by a carrier-phase jump common to the satellites;
//! - `bit_edge`: lost samples found by the data-bit edges moving together;
//! - `code_jump`: lost samples found by a code jump (prompt power collapsing together);
//! - `carrier_step`: a satellite's carrier-phase step over lost samples;
//! - `gap_length`: the length of lost time from the bit edges and carrier-phase steps;
//! - `modulo`: remainders modulo a period (phase, data bit, code period);
//! - `long_gap`: the receiver time re-established after a gap too long to measure;
//! - `quick_sync`: frame sync from one TLM and HOW, confirmed across satellites;
//! - `predicted`: SV time from vector tracking's prediction at a channel's bit edge;
//! - `coarse_fix`: the first fix from code phases alone (approximate time and position);
//! - `dating`: which GPS week labels receiver time before subframe 1 is decoded
//!   ([`WeekReference`]).

pub(crate) mod bit_edge;
pub(crate) mod carrier_step;
pub(crate) mod coarse_fix;
pub(crate) mod code_jump;
pub(crate) mod dating;
pub(crate) mod discontinuity;
mod gap_length;
mod keeper;
pub(crate) mod long_gap;
pub(crate) mod modulo;
pub(crate) mod predicted;
pub(crate) mod quick_sync;
pub(crate) mod sv_time;

pub use dating::{WeekReference, WeekSource};
pub use discontinuity::FoundBy;
pub use keeper::{BlockEvent, TimeKeeper};
