//! Code realignment: when the prompt power of several satellites collapsed at once
//! ([`crate::pipeline::timing::code_jump`]: samples lost by a fraction of a code period, or tenths of a
//! second), every tracked satellite is searched at once in a narrow window around the Doppler
//! it held, and the channels whose code shifts one gap length explains are moved onto it
//! ([`gpsrx_tracking::Channel::realign_code`]).

use super::{ChannelManager, DueSearch, SearchOutcome};
use crate::pipeline::channels::ring::SampleView;
use crate::pipeline::timing::code_jump::{fit_code_gap, Collapse, CollapsedSat, POWER_REPORTS};
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
    /// The code moved by more than a gap of up to [`crate::pipeline::timing::code_jump::MAX_GAP_S`]
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

    /// Moves the channels of a realignment search onto the code found, if one gap explains
    /// the code shifts of at least three satellites ([`fit_code_gap`]); returns what moved.
    /// The channels that collapsed restart their carrier loop at the Doppler they held before;
    /// the others keep their loops.
    ///
    /// When at least three satellites are found again at a moved code that no gap up to
    /// [`crate::pipeline::timing::code_jump::MAX_GAP_S`] explains, samples of a longer, unknown length
    /// were lost ([`Realigned::length_unknown`]): every satellite found is moved onto its code,
    /// at the Doppler the search found (the Doppler held before may have drifted over the gap).
    pub fn realign(&mut self, outcome: SearchOutcome) -> Option<Realigned> {
        let r = outcome.realign?;
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
        let shifts: Vec<(u8, gpsrx_tracking::CodeShift)> = found
            .iter()
            .map(|&(i, _, s, _)| (self.channels[i].prn().get(), s))
            .collect();
        // Two samples, or a twentieth of a chip at high rates: the search's code resolution.
        let tol = (0.05 * self.fs_hz / gpsrx_dsp::constants::CA_CHIP_RATE_HZ).max(2.0);
        let fit = fit_code_gap(&shifts, self.fs_hz, tol);
        let unexplained = unexplained_moves(&shifts, fit.as_ref(), tol);
        let length_unknown =
            unexplained.len() >= crate::pipeline::timing::code_jump::MIN_SATELLITES;
        let (shortest_gap_s, prns) = match fit {
            _ if length_unknown => {
                tracing::debug!(
                    "code realignment: the code of {unexplained:?} moved by more than a gap of up to {} s explains: {shifts:?}",
                    crate::pipeline::timing::code_jump::MAX_GAP_S
                );
                let moved = shifts.iter().filter(|(_, s)| code_moved(s, tol));
                (
                    crate::pipeline::timing::code_jump::MAX_GAP_S,
                    moved.map(|(p, _)| *p).collect(),
                )
            }
            Some(gap) => (gap.shortest_s, gap.prns),
            None => {
                tracing::debug!("code realignment: no gap explains the shifts {shifts:?}");
                return None;
            }
        };
        let mut moved = Vec::new();
        let mut at_sample = 0;
        for (i, start, _, found_hz) in found {
            let ch = &mut self.channels[i];
            let prn = ch.prn().get();
            if !prns.contains(&prn) {
                continue;
            }
            let t_s = ch.next_span().0 as f64 / self.fs_hz;
            let carrier = r.satellites.iter().find(|s| s.prn == prn).map(|s| {
                let doppler = if length_unknown {
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
                shortest_gap_s,
                fraction_of_period: shift_samples,
                prns: moved,
                at_sample,
                length_unknown,
            }
        })
    }
}

/// Whether a code shift moved the code (by more than `tol_samples`, modulo its period).
fn code_moved(s: &gpsrx_tracking::CodeShift, tol_samples: f64) -> bool {
    crate::pipeline::timing::modulo::nearest_remainder(s.shift_samples, s.period_samples).abs()
        > tol_samples
}

/// The satellites whose code moved but which the fitted gap (if any) does not explain.
fn unexplained_moves(
    shifts: &[(u8, gpsrx_tracking::CodeShift)],
    fit: Option<&crate::pipeline::timing::code_jump::CodeGap>,
    tol_samples: f64,
) -> Vec<u8> {
    shifts
        .iter()
        .filter(|(p, s)| code_moved(s, tol_samples) && fit.is_none_or(|g| !g.prns.contains(p)))
        .map(|(p, _)| *p)
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use gpsrx_tracking::CodeShift;

    use crate::pipeline::timing::code_jump::shifts_after;

    #[test]
    fn code_moves_of_a_gap_longer_than_the_fit_reaches_are_left_unexplained() {
        let dopplers = [
            -3186.0, 1963.0, -1888.0, 637.0, -565.0, 2480.0, -2710.0, 1210.0,
        ];
        let unexplained = |g: f64| {
            let s = shifts_after(g, &dopplers);
            unexplained_moves(&s, fit_code_gap(&s, 2.6e6, 2.0).as_ref(), 2.0)
        };
        // Up to the fit's reach, one length explains every move.
        for g in [1.25e-3, 0.5, 0.7317] {
            assert!(unexplained(g).is_empty(), "{g} s: {:?}", unexplained(g));
        }
        // Beyond, the moves g f_D / f_L1 (26 samples for 5 s at 3 kHz) differ between satellites by
        // more than any one gap of up to a second explains (a few may agree by chance).
        for g in [5.0, 5.37, 60.0] {
            let u = unexplained(g);
            assert!(u.len() >= 6, "{g} s: {u:?}");
        }
        // Nothing moved (a blockage that ended): no gap.
        let still: Vec<(u8, CodeShift)> = shifts_after(0.0, &dopplers);
        assert!(unexplained_moves(&still, None, 2.0).is_empty());
    }
}
