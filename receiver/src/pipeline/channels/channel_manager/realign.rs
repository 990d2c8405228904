//! Code realignment: when the prompt power of several satellites collapsed at once
//! ([`crate::pipeline::timing::code_jump`]: samples lost by a fraction of a code period, or tenths of a
//! second), every tracked satellite is searched at once in a narrow window around the Doppler
//! it held, and the channels whose code shifts one gap length explains are moved onto it
//! ([`gpsrx_tracking::Channel::realign_code`]).

use super::{ChannelManager, DueSearch, SearchOutcome};
use crate::pipeline::channels::ring::SampleView;
use crate::pipeline::timing::code_jump::{Collapse, CollapsedSat, RealignPlan, POWER_REPORTS};
use gpsrx_dsp::acquisition::{AcqConfig, AcquisitionEngine, SearchTarget};
use gpsrx_dsp::Prn;
use gpsrx_tracking::ChannelState;

/// Half width of the Doppler window of a code realignment search, Hz (the Doppler held before
/// the collapse is known to a few hertz).
pub const REALIGN_DOPPLER_HZ: f64 = 100.0;
/// Coherent integration (ms), non-coherent blocks and refinement periods (ms) of a code
/// realignment search: the Doppler is known to a few hertz, so 5 ms blocks (bit edges handled
/// by the engine's half-shifted pass) reach about 31 dB-Hz in 30 ms of signal.
pub(super) const REALIGN_ACQ: (u32, u32, u32) = (5, 6, 20);
/// Longest wait for the samples of a code realignment search after a collapse, s.
const REALIGN_WAIT_S: f64 = 0.3;

/// A code realignment to make: the collapse, and the first sample a search may read.
#[derive(Debug, Clone)]
pub(super) struct Realign {
    jump: u64,
    after: u64,
    satellites: Vec<CollapsedSat>,
}

/// Channels moved onto a code that jumped ([`ChannelManager::realign`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Realigned {
    /// Sample index of the collapse.
    pub jump_sample: u64,
    /// The shortest gap the code shifts allow, s.
    pub shortest_gap_s: f64,
    /// The forward shift of the first satellite moved, in code periods (`-g` modulo 1 ms).
    pub fraction_of_period: f64,
    /// The satellites moved.
    pub prns: Vec<u8>,
    /// The first sample after the move (the next code period of the channels).
    pub at_sample: u64,
    /// The code moved by more than a gap of up to `crate::pipeline::timing::code_jump::MAX_GAP_S`
    /// explains (on at least three satellites): samples of an unknown, longer length were lost,
    /// and the receiver time must be re-established from the signal.
    pub length_unknown: bool,
}

impl ChannelManager {
    /// Asks for a code realignment of the satellites of `collapse` (samples at `fs_hz`): they
    /// are searched as soon as the window holds a search's worth of samples after it.
    pub fn request_realignment(&mut self, collapse: &Collapse) {
        if self.realign_engine.is_none() {
            return;
        }
        let after = collapse.sample + (POWER_REPORTS as f64 * 1e-3 * self.fs_hz) as u64;
        self.realign = Some(Realign {
            jump: collapse.sample,
            after,
            satellites: collapse.satellites.clone(),
        });
    }

    /// The realignment search due in `window`, if its samples have come: every satellite with
    /// a live channel in tracking, around the Doppler it held (those that collapsed) or holds
    /// (a long gap moves the code of some satellites less than a chip: they did not collapse
    /// but moved too).
    pub(super) fn due_realignment(&mut self, window: SampleView<'_>) -> Option<DueSearch> {
        let r = self.realign.as_ref()?;
        let keep = self.realign_samples()? as u64;
        let now = window.end();
        if now < r.after + keep || now < window.start() + keep {
            if now > r.after + keep + (REALIGN_WAIT_S * self.fs_hz) as u64 {
                self.realign = None;
            }
            return None;
        }
        let r = self.realign.take()?;
        let t_s = now as f64 / self.fs_hz;
        let targets: Vec<SearchTarget> = self
            .channels
            .iter()
            .filter(|c| c.state() == ChannelState::Track)
            .map(|c| {
                let doppler = r
                    .satellites
                    .iter()
                    .find(|s| s.prn == c.prn().get())
                    .map_or(c.doppler_hz(), |s| s.doppler_at(t_s));
                SearchTarget::around(c.prn(), doppler, REALIGN_DOPPLER_HZ)
            })
            .collect();
        tracing::debug!(
            "code realignment search at sample {now}: {} PRN(s)",
            targets.len()
        );
        (!targets.is_empty()).then(|| DueSearch {
            first: now - keep,
            len: keep as usize,
            targets,
            batch: None,
            realign: Some(r),
        })
    }

    /// Samples a code realignment search reads: the search itself and a few tens of code
    /// periods for the refinement of its code phase (not the whole refinement of an
    /// acquisition: the Doppler is known).
    pub(super) fn realign_samples(&self) -> Option<usize> {
        self.realign_engine
            .as_ref()
            .map(AcquisitionEngine::samples_wanted)
    }

    /// Index of the live channel of `prn`.
    pub(super) fn live(&self, prn: Prn) -> Option<usize> {
        self.channels
            .iter()
            .position(|c| c.prn() == prn && c.state() != ChannelState::Lost)
    }

    /// The code shifts a realignment search found (`SearchOutcome::is_realignment`): per
    /// satellite with a live channel found again, how far its replica must move onto the
    /// signal. Timing judges them (`crate::pipeline::timing::code_jump::plan_realignment`);
    /// [`ChannelManager::realign`] carries out its plan. `None` for any other search.
    pub fn realignment_found(&self, outcome: SearchOutcome) -> Option<RealignSearch> {
        let realign = outcome.realign?;
        let first = outcome.first as f64;
        let found: Vec<(usize, f64, gpsrx_tracking::CodeShift, f64)> = outcome
            .results
            .iter()
            .filter(|d| d.detected)
            .filter_map(|d| {
                let i = self.live(d.prn)?;
                let start = first + d.code_phase_samples;
                Some((
                    i,
                    start,
                    self.channels[i].code_shift_to(start),
                    d.doppler_hz,
                ))
            })
            .collect();
        let shifts = found
            .iter()
            .map(|&(i, _, s, _)| (self.channels[i].prn().get(), s))
            .collect();
        Some(RealignSearch {
            realign,
            found,
            shifts,
        })
    }

    /// Moves the channels of `plan` onto the code their realignment search found; returns
    /// what moved (at least `crate::pipeline::timing::code_jump::MIN_SATELLITES`, else
    /// nothing). The channels that collapsed restart their carrier loop at the Doppler they
    /// held before (when the gap's length is unknown, at the Doppler the search found: the one
    /// held may have drifted over the gap); the others keep their loops.
    pub fn realign(&mut self, search: RealignSearch, plan: &RealignPlan) -> Option<Realigned> {
        let RealignSearch {
            realign: r,
            found,
            shifts,
        } = search;
        let mut moved = Vec::new();
        let mut at_sample = 0;
        for (i, start, _, found_hz) in found {
            let ch = &mut self.channels[i];
            let prn = ch.prn().get();
            if !plan.prns.contains(&prn) {
                continue;
            }
            let t_s = ch.next_span().0 as f64 / self.fs_hz;
            let carrier = r.satellites.iter().find(|s| s.prn == prn).map(|s| {
                let doppler = if plan.length_unknown {
                    found_hz
                } else {
                    s.doppler_at(t_s)
                };
                (doppler, s.doppler_rate_hz_s, s.cn0_dbhz)
            });
            if ch.realign_code(start, carrier).is_some() {
                moved.push(prn);
                at_sample = at_sample.max(ch.next_span().0);
            }
        }
        (moved.len() >= crate::pipeline::timing::code_jump::MIN_SATELLITES).then(|| {
            let shift_samples = shifts
                .iter()
                .find(|(p, _)| *p == moved[0])
                .map_or(0.0, |(_, s)| s.shift_samples / s.period_samples);
            Realigned {
                jump_sample: r.jump,
                shortest_gap_s: plan.shortest_gap_s,
                fraction_of_period: shift_samples,
                prns: moved,
                at_sample,
                length_unknown: plan.length_unknown,
            }
        })
    }
}

/// What a code realignment search found: the realignment asked for, and per channel found
/// again `(channel index, first sample of its code found, its code shift, Doppler found Hz)`.
#[derive(Debug)]
pub struct RealignSearch {
    realign: Realign,
    found: Vec<(usize, f64, gpsrx_tracking::CodeShift, f64)>,
    shifts: Vec<(u8, gpsrx_tracking::CodeShift)>,
}

impl RealignSearch {
    /// The code shifts found, `(PRN, shift)` per satellite found again.
    pub fn shifts(&self) -> &[(u8, gpsrx_tracking::CodeShift)] {
        &self.shifts
    }
}

/// The engine of code realignment searches at `fs_hz` with the settings `acq`.
pub(super) fn realign_engine(
    fs_hz: f64,
    acq: &AcqConfig,
) -> Result<AcquisitionEngine, gpsrx_dsp::acquisition::AcqError> {
    AcquisitionEngine::new(
        fs_hz,
        AcqConfig {
            coherent_ms: REALIGN_ACQ.0,
            noncoherent: REALIGN_ACQ.1,
            refine_ms: REALIGN_ACQ.2,
            ..acq.clone()
        },
    )
}
