//! What the receiver needs to run a round of the channels while the navigation processor
//! takes the reports of the round before (`Receiver::run`): the round's search decided ahead
//! on a copy of the scheduler, the reports handed over as a whole, and the channels' state
//! kept so that the round can be undone when the navigation's end of block asks for
//! something else (a collapse, a phase jump, another search).

use super::{ChannelManager, DueSearch, WorkTimes};
use crate::pipeline::channels::dynamics::DynamicsWatch;
use crate::pipeline::channels::ring::SampleView;
use crate::pipeline::channels::search_schedule::Visibility;
use gpsrx_dsp::Prn;
use gpsrx_tracking::{Channel, ChannelEpoch};

/// The state [`ChannelManager::work`] changes, kept to undo a round
/// ([`ChannelManager::snapshot`], [`ChannelManager::restore`]).
#[derive(Debug, Clone)]
pub struct WorkSnapshot {
    channels: Vec<Channel>,
    dynamics: DynamicsWatch,
    times: WorkTimes,
}

impl ChannelManager {
    /// The state the next [`ChannelManager::work`] changes (the channels, the dynamics watch,
    /// the work times).
    pub fn snapshot(&self) -> WorkSnapshot {
        WorkSnapshot {
            channels: self.channels.clone(),
            dynamics: self.dynamics,
            times: self.times,
        }
    }

    /// Back to `snapshot`: the round worked since is undone and its reports dropped.
    pub fn restore(&mut self, snapshot: WorkSnapshot) {
        self.channels = snapshot.channels;
        self.dynamics = snapshot.dynamics;
        self.times = snapshot.times;
        for r in &mut self.reports {
            r.clear();
        }
    }

    /// Swaps the reports of the last round with `other` (per channel; the manager's next
    /// round fills what it gets, cleared first).
    pub fn swap_reports(&mut self, other: &mut Vec<Vec<ChannelEpoch>>) {
        std::mem::swap(&mut self.reports, other);
        for r in &mut self.reports {
            r.clear();
        }
    }

    /// The reports of the last round, per channel.
    pub fn reports_mut(&mut self) -> &mut Vec<Vec<ChannelEpoch>> {
        &mut self.reports
    }

    /// [`ChannelManager::due_search`] as the channels of `snapshot` (kept before the round just
    /// worked) would make it: the search due after their round, decided on their liveness.
    pub fn due_search_before(
        &mut self,
        snapshot: &mut WorkSnapshot,
        window: SampleView<'_>,
        visibility: &dyn Fn(Prn) -> Visibility,
    ) -> Option<DueSearch> {
        std::mem::swap(&mut self.channels, &mut snapshot.channels);
        let due = self.due_search(window, visibility);
        std::mem::swap(&mut self.channels, &mut snapshot.channels);
        due
    }

    /// Whether a code realignment is waiting (its search comes before any other).
    pub fn realignment_pending(&self) -> bool {
        self.realign.is_some()
    }

    /// The search [`ChannelManager::due_search`] would make due now, with the window ending
    /// at sample `end` and holding `span` samples, decided on a copy of the scheduler (which
    /// is left as it is). `None` with a realignment pending.
    pub fn preview_due(
        &self,
        end: u64,
        span: u64,
        visibility: &dyn Fn(Prn) -> Visibility,
    ) -> Option<DueSearch> {
        if self.realign.is_some() {
            return None;
        }
        let mut schedule = self.schedule.clone()?;
        self.scheduled(&mut schedule, end, span, visibility)
    }
}

impl DueSearch {
    /// Whether `other` is the same search (samples, targets, batch; neither a realignment).
    pub fn same_as(&self, other: &DueSearch) -> bool {
        self.realign.is_none()
            && other.realign.is_none()
            && self.first == other.first
            && self.len == other.len
            && self.targets == other.targets
            && self.batch == other.batch
    }
}
