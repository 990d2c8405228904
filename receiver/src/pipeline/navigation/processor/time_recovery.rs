//! The receiver time across lost samples and long gaps, as navigation meets them: the SV
//! times set aside and carried over a gap once its length is known, the receiver clock stepped
//! over it, and the time re-established from the signal when it cannot be measured.

use super::{NavigationProcessor, CODE_SETTLE_AFTER_REALIGN_S, PHASE_SETTLE_AFTER_REALIGN_S};
use crate::pipeline::channels::channel_manager::Realigned;
use crate::pipeline::sink::{ReceiverEvent, Sink, SinkError};
use crate::pipeline::timing::quick_sync::QuickSync;
use gpsrx_tracking::ChannelEpoch;

impl NavigationProcessor {
    /// The channels of the satellites in `r` were moved onto a code that jumped as lost
    /// samples make it jump. The SV times are kept aside until the length is resolved from
    /// the new bit edges, the carrier-phase steps (measured once the phase loops hold again)
    /// and the code, as after a whole-millisecond gap.
    pub fn on_code_realigned(
        &mut self,
        r: &Realigned,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let t_s = r.jump_sample as f64 / self.fs_hz;
        if r.length_unknown {
            tracing::warn!(
                "{t_s:.3} s: samples lost (the code of {} satellites moved by more than any gap of up to {:.0} s explains): channels moved onto it; no fix until the receiver time is re-established",
                r.prns.len(),
                r.shortest_gap_s
            );
            self.forget_time(t_s, Vec::new(), None);
            let settled =
                r.at_sample as f64 + crate::pipeline::timing::long_gap::CODE_SETTLE_S * self.fs_hz;
            self.fixes_from_sample = self.fixes_from_sample.max(settled);
            return sink.event(&ReceiverEvent::SampleGap { t_s });
        }
        let frac_ms = (-r.fraction_of_period).rem_euclid(1.0);
        tracing::warn!(
            "{t_s:.3} s: samples lost (the code of {} satellites jumped: {frac_ms:.4} ms modulo 1 ms, at least {:.1} ms): channels moved onto it; no fix until the receiver time is re-established",
            r.prns.len(),
            r.shortest_gap_s * 1e3
        );
        self.forget_time(t_s, Vec::new(), Some(t_s + CODE_SETTLE_AFTER_REALIGN_S));
        let settle = (PHASE_SETTLE_AFTER_REALIGN_S * self.fs_hz) as u64;
        self.time
            .code_realigned(r.jump_sample, r.prns.clone(), r.at_sample + settle);
        sink.event(&ReceiverEvent::SampleGap { t_s })
    }

    /// After lost samples: every SV time is dropped (the decoders find frame sync again and the
    /// HOW gives the time), carrier smoothing restarts, and the clock of the last fix is kept
    /// to measure the gap once the time is back.
    ///
    /// With the carrier-phase steps of the gap (`steps`), the SV times are kept, to be carried
    /// over it once its length is resolved from them and the new bit edges.
    /// `code_from_s`: from when the code offsets may measure the gap (`None`: not used).
    pub(super) fn forget_time(
        &mut self,
        t_s: f64,
        steps: Vec<crate::pipeline::timing::carrier_step::PhaseStep>,
        code_from_s: Option<f64>,
    ) {
        for dec in self.decoders.values_mut() {
            dec.reset_sync();
        }
        self.time.start_gap(t_s, steps, code_from_s);
        self.builder.note_gap(t_s);
        self.prior = None;
    }

    /// A carried SV time refused at `t_s` for `prn`, `off_ms` off the bit edge: when
    /// [`crate::pipeline::timing::discontinuity::MIN_SATELLITES`] satellites are refused within 2 s by
    /// the same offset (0.1 ms), samples were lost during the outage (that offset plus a
    /// whole number of 20 ms bits): reported as a gap.
    pub(super) fn on_refused(
        &mut self,
        t_s: f64,
        prn: u8,
        off_ms: f64,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let Some((agreeing, offsets)) = self.time.note_refusal(t_s, prn, off_ms) else {
            return Ok(());
        };
        tracing::warn!(
            "{t_s:.3} s: samples lost during the outage: the SV times carried over it are {:.3} ms (modulo 20 ms) off the new bit edges of {agreeing} satellites",
            -off_ms
        );
        // The new channels' code has settled by their bit edges: the code offsets measure
        // the gap at once.
        self.forget_time(t_s, Vec::new(), Some(t_s));
        sink.event(&ReceiverEvent::SampleGap { t_s })?;
        let resolved = self.time.add_edge_offsets(offsets, t_s);
        if let Some(length_ms) = resolved {
            tracing::warn!(
                "{t_s:.3} s: the samples lost were {length_ms:.3} ms of signal (from the code of the new channels): SV times carried over the gap"
            );
            self.time.move_over_gap(length_ms);
            sink.event(&ReceiverEvent::GapMeasured { t_s, length_ms })?;
            self.lost_for_aid_ms += length_ms;
            self.step_clock_over_gap(t_s, length_ms, sink)?;
        }
        Ok(())
    }

    /// Solutions keep failing the integrity test while SV times carried over an outage are in
    /// use: samples may have been lost during the outage by a whole number of data bits, which
    /// the bit edges cannot show. The carried times are dropped (frame sync gives the time).
    pub(super) fn drop_carried_times(&mut self, t_s: f64) {
        let carried: Vec<u8> = self
            .decoders
            .iter()
            .filter(|(_, d)| d.time_carried())
            .map(|(p, _)| *p)
            .collect();
        if carried.is_empty() {
            return;
        }
        if let Some(c) = self.coarse.as_mut() {
            c.given.clear();
        }
        tracing::warn!(
            "{t_s:.2} s: the solutions fail the integrity test with the SV times carried over the outage of {} satellites (samples lost during it?): every SV time dropped (they all count the samples), re-establishing the time from the signal",
            carried.len()
        );
        for d in self.decoders.values_mut() {
            d.reset_sync();
        }
        self.time.make_rough(None);
        self.builder.restart();
        self.failed_in_row = 0;
        self.time.ensure_gap(t_s);
    }

    /// Once the length of the gap being recovered from cannot be measured: the time comes
    /// back from the coarse-time solver or the next time of week ([`LongGapRecovery::begin`]).
    pub(super) fn start_long_gap(&mut self) {
        let with_eph = self.decoders.values().filter(|d| d.ephemeris.is_some());
        let eph = self.nav_assist.is_some()
            || with_eph.count() >= crate::pipeline::timing::coarse_fix::MIN_SATELLITES;
        let origin = self.builder.rx_time_origin();
        let Some(start) = self.time.begin_long_gap(origin, eph) else {
            return;
        };
        self.coarse = start.coarse.or(self.coarse.take());
        if start.quick_sync {
            self.quick.get_or_insert_with(QuickSync::default);
        }
        for d in self.decoders.values_mut() {
            d.report_tow_candidates(self.quick.is_some());
        }
    }

    /// After a coarse-time fix while a long gap is recovered from: the receiver clock stepped
    /// by the whole milliseconds of the time lost ([`LongGapRecovery::clock_step_ms`]).
    pub(super) fn step_clock_to_coarse_time(
        &mut self,
        out: &crate::pipeline::timing::coarse_fix::CoarseOutcome,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let origin = self.builder.rx_time_origin();
        let Some(step) = self.time.coarse_clock_step_ms(out, origin) else {
            return Ok(());
        };
        self.builder.step_clock_ms(step);
        self.time.note_clock_step(step);
        tracing::info!("receiver clock stepped by {step} ms to the coarse time");
        sink.event(&ReceiverEvent::ClockStep { ms: step })
    }

    /// Once the length of the samples lost at stream time `t_s` is known: the carrier smoothing
    /// may be bridged over them, and the receiver time (which counts samples) is late by it; it is stepped forward by the whole milliseconds (the fraction is a clock
    /// bias the solution takes up), so that the first fix after a long gap does not start
    /// from a bias of tenths of a second (pseudoranges would come out negative).
    pub(super) fn step_clock_over_gap(
        &mut self,
        t_s: f64,
        length_ms: f64,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        self.builder.set_gap_length(t_s, length_ms * 1e-3);
        let step = length_ms.round() as i64;
        if step == 0 {
            return Ok(());
        }
        self.builder.step_clock_ms(step);
        self.time.note_clock_step(step);
        // The clock of the last fix, on the stepped time scale.
        self.time.step_last_clock(step);
        tracing::info!("receiver clock stepped by {step} ms over the lost samples");
        sink.event(&ReceiverEvent::ClockStep { ms: step })
    }

    /// While the receiver time is re-established after lost samples, the first satellite
    /// whose time comes from its navigation message puts the receiver clock back near GPS time
    /// by a whole-millisecond step, as at the start (its pseudorange near 75 ms): lost samples
    /// of a second leave the receiver time a second late, which the least squares cannot take
    /// up as a clock bias from a cold start.
    pub(super) fn realign_clock(
        &mut self,
        e: &ChannelEpoch,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let (Some(_), Some(t0)) = (self.time.gap(), self.builder.rx_time_origin()) else {
            return Ok(());
        };
        let Some(dec) = self.decoders.get(&e.prn) else {
            return Ok(());
        };
        if dec.time_carried() || !e.pll_lock {
            return Ok(());
        }
        let Some(sv) = dec.sv_tow_s(e.ms_count, e.code_phase_chips) else {
            return Ok(());
        };
        let tau = gpsrx_nav::time::GpsTime::fold_tow_difference_s(t0.tow_s + e.t_rx_s - sv);
        if (0.06..=0.095).contains(&tau) {
            return Ok(());
        }
        let step = -((tau - 0.075) * 1e3).round() as i64;
        self.time.note_clock_step(step);
        self.builder.step_clock_ms(step);
        tracing::info!("receiver clock stepped by {step} ms to re-establish the time");
        sink.event(&ReceiverEvent::ClockStep { ms: step })
    }
}
