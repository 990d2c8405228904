//! [`Receiver::run`]'s rounds with the navigation of one round beside the channels' next.
//!
//! Without an INS or vector tracking, a round of the channels needs from the navigation of
//! the round before only what its end of block asks for (a collapse of the prompt power, a
//! common phase jump), the search it makes due (the predicted visibility) and the channels
//! a search of that round found. So, when that round found nothing, the navigation
//! processor takes its reports on this thread while the pool works the next round (with the
//! search decided ahead, on a copy of the scheduler) and reads the block after it. Then the
//! round is checked: when the end of block gave an event, or the search due now is not the
//! one decided ahead (a fix moved a predicted Doppler window), the channels go back to the
//! state kept before the round and the round is worked again as the one-after-the-other
//! loop works it. Every output is the same as that loop's; the navigation's wall time hides
//! behind the channels' (on a 2-core machine about a fifth of a default run's).

use super::{done_span, round_aid, Receiver, ReceiverError, ReportsOut};
use crate::pipeline::channels::channel_manager::SearchOutcome;
use crate::pipeline::channels::ring::beside;
use crate::pipeline::sink::Sink;
use gpsrx_samples::SampleSource;

/// A round's samples read beside it, and what its search found.
type Worked = (usize, Option<SearchOutcome>);

impl Receiver {
    /// The rounds of [`Receiver::run`] after the cold start, to the end of `source`, without
    /// an INS or vector tracking (see the module documentation).
    pub(super) fn run_rounds_overlapped(
        &mut self,
        source: &mut dyn SampleSource,
        sink: &mut dyn Sink,
    ) -> Result<(), ReceiverError> {
        let (mut got, mut found) = self.round_reading(source)?;
        loop {
            let overlap = got > 0
                && found.is_none()
                && self.bridge.is_none()
                && !self.manager.realignment_pending();
            if overlap {
                (got, found) = self.overlapped_round(source, sink)?;
                continue;
            }
            self.timed_deliver(found, self.window.end(), sink)?;
            if got == 0 {
                return Ok(());
            }
            (got, found) = self.round_reading(source)?;
        }
    }

    /// A round of the channels (and a due search) on the samples held, the next block read
    /// beside it.
    fn round_reading(&mut self, source: &mut dyn SampleSource) -> Result<Worked, ReceiverError> {
        let view = self.window.view();
        let end = view.end();
        let (nav, t_s) = (&self.nav, end as f64 / self.fs_hz);
        let due = self
            .manager
            .due_search(view, &|p| nav.visibility(p.get(), t_s));
        let aid = round_aid(None, None, self.bridge.as_ref().map(|(b, _)| b));
        let (window, manager, block) = (&mut self.window, &mut self.manager, self.block);
        let t0 = std::time::Instant::now();
        let worked = window.fill_during(source, block, |v| manager.work(v, due, aid))?;
        self.stages.rounds_s += t0.elapsed().as_secs_f64();
        self.processed_to = Some(end);
        Ok(worked)
    }

    /// The navigation of the round whose reports wait, beside the channels' next round on
    /// the block held after it (and the read of the block after that); the next round is
    /// undone and worked again when the navigation's end of block asks for something else.
    fn overlapped_round(
        &mut self,
        source: &mut dyn SampleSource,
        sink: &mut dyn Sink,
    ) -> Result<Worked, ReceiverError> {
        let end = self.window.end();
        let t_s = end as f64 / self.fs_hz;
        // What the round's end will drop, and so the window the next search is decided on.
        let keep = self.manager.oldest_needed(end);
        let span = end - self.window.start().max(keep.min(end));
        let nav = &self.nav;
        let ahead = self
            .manager
            .preview_due(end, span, &|p| nav.visibility(p.get(), t_s));
        let mut kept = self.manager.snapshot();
        self.manager.swap_reports(&mut self.spare_reports);
        let span_done = done_span(self.first_sample, self.processed_to, self.fs_hz);
        let (window, manager, block) = (&mut self.window, &mut self.manager, self.block);
        let due = ahead.clone();
        let pool = || window.fill_during(source, block, |v| manager.work(v, due, None));
        let (nav, reports, monitor) = (&mut self.nav, &mut self.spare_reports, &mut self.monitor);
        let here = || {
            let t0 = std::time::Instant::now();
            let out = ReportsOut {
                nav: &mut *nav,
                reports,
                aiding: None,
                monitor,
                vector: None,
                span: span_done,
            };
            let event = out
                .pass(sink)
                .and_then(|()| nav.end_block(end, sink).map_err(ReceiverError::Sink));
            (event, t0.elapsed().as_secs_f64())
        };
        let t0 = std::time::Instant::now();
        let (worked, (event, nav_s)) = beside(pool, here);
        self.stages.rounds_s += t0.elapsed().as_secs_f64() - nav_s;
        self.stages.navigation_s += nav_s;
        self.stages.overlapped_rounds += 1;
        let (got, found) = worked?;
        let event = event?;
        if event.is_none() {
            // The round's end as `end_round` makes it: nothing to start, the samples no one
            // needs dropped.
            self.window.discard_before(keep);
            let (nav, view) = (&self.nav, self.window.view().until(end));
            let due = self
                .manager
                .due_search_before(&mut kept, view, &|p| nav.visibility(p.get(), t_s));
            let same = match (&ahead, &due) {
                (None, None) => true,
                (Some(a), Some(b)) => a.same_as(b),
                _ => false,
            };
            self.processed_to = Some(end);
            if same {
                return Ok((got, found));
            }
            tracing::trace!("round to {end} worked again: another search is due");
            self.stages.redone_rounds += 1;
            self.manager.restore(kept);
            let view = self.window.view().until(end);
            let found = self.manager.work(view, due, None);
            return Ok((got, found));
        }
        // The end of block asked for something: the round as the one-after-the-other loop
        // makes it, after what was asked.
        tracing::trace!("round to {end} worked again after the end of block's {event:?}");
        self.stages.redone_rounds += 1;
        self.manager.restore(kept);
        self.after_end_block(event, None, end, sink)?;
        Ok((got, self.work_until(end)))
    }
}
