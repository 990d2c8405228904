//! [`Tap`]: a sink that hands everything on and keeps what vector tracking needs.

use super::tracker::Captured;
use crate::pipeline::sink::{
    ChannelRow, FixReport, NavigationEnd, ObservablesReport, Progress, ReceiverEvent, Sink,
    SinkError,
};
use gpsrx_tracking::ChannelEpoch;

/// Passes every report to `inner` and keeps the observables and fixes in `captured`.
pub struct Tap<'a> {
    /// Where the reports go.
    pub inner: &'a mut dyn Sink,
    /// What vector tracking takes ([`crate::pipeline::vector::VectorTracking::take`]).
    pub captured: &'a mut Vec<Captured>,
}

impl std::fmt::Debug for Tap<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Tap({} captured)", self.captured.len())
    }
}

impl Sink for Tap<'_> {
    fn fix(&mut self, report: &FixReport) -> Result<(), SinkError> {
        self.captured.push(Captured::fix(report));
        self.inner.fix(report)
    }

    fn observables(&mut self, report: &ObservablesReport) -> Result<(), SinkError> {
        self.captured
            .push(Captured::Observables(report.epoch.clone()));
        self.inner.observables(report)
    }

    fn channel(&mut self, row: &ChannelRow) -> Result<(), SinkError> {
        self.inner.channel(row)
    }

    fn channel_epoch(&mut self, channel: usize, epoch: &ChannelEpoch) -> Result<(), SinkError> {
        self.inner.channel_epoch(channel, epoch)
    }

    fn event(&mut self, event: &ReceiverEvent) -> Result<(), SinkError> {
        self.inner.event(event)
    }

    fn progress(&mut self, progress: &Progress) -> Result<(), SinkError> {
        self.inner.progress(progress)
    }

    fn finish(&mut self, end: &NavigationEnd) -> Result<(), SinkError> {
        self.inner.finish(end)
    }
}
