//! The navigation message: each report's data bit to its satellite's LNAV decoder (frame
//! sync, ephemerides, almanac), quick frame sync from a TLM and HOW, and the coarse-time fix
//! while no satellite's time is known.

use super::NavigationProcessor;
use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::navigation::navdata::{NavDecoder, NavEvent};
use crate::pipeline::sink::{ReceiverEvent, Sink, SinkError};
use crate::pipeline::timing::coarse_fix::CoarseRefusal;
use crate::pipeline::timing::quick_sync::TowCandidate;
use gpsrx_nav::ephemeris::HealthPolicy;
use gpsrx_tracking::{ChannelEpoch, ChannelState};

impl NavigationProcessor {
    /// Feeds the report's data bit to its satellite's decoder.
    pub(super) fn decode(
        &mut self,
        e: &ChannelEpoch,
        aiding: Option<&InsFeedForward>,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let week = self.reference_week;
        let quick = self.quick.is_some();
        let dec = self.decoders.entry(e.prn).or_insert_with(|| {
            let mut d = NavDecoder::new(e.prn, week);
            d.report_tow_candidates(quick);
            d
        });
        let mut coarse_wrong = None;
        let mut candidate = None;
        if let (Some(b), Some(ms)) = (e.bit, e.bit_start_ms) {
            let coarse_given = self
                .coarse
                .as_ref()
                .is_some_and(|c| c.given.contains(&e.prn));
            let mut mismatch = false;
            for ev in dec.push_bit(b.value, ms) {
                match ev {
                    NavEvent::TowCandidate { first_ms, tow_s } => {
                        candidate = Some(TowCandidate::new(e, first_ms, tow_s));
                    }
                    NavEvent::Subframe { tow_s, .. } if coarse_given && !mismatch => {
                        tracing::info!(
                            "G{:02}: its first HOW (TOW {tow_s} s) confirms the SV time of the coarse-time fix",
                            e.prn
                        );
                        if let Some(c) = self.coarse.as_mut() {
                            c.given.remove(&e.prn);
                        }
                    }
                    NavEvent::TowMismatch { error_ms } if coarse_given => {
                        mismatch = true;
                        coarse_wrong = Some(format!(
                            "the HOW of G{:02} differs from its SV time by {error_ms:.3} ms",
                            e.prn
                        ));
                    }
                    NavEvent::BitEdgeMismatch { offset_ms } if coarse_given => {
                        coarse_wrong = Some(format!(
                            "the first bit edge of G{:02} falls {offset_ms:+.3} ms off a 20 ms boundary of its SV time",
                            e.prn
                        ));
                    }
                    NavEvent::FrameSync { tow_s } => {
                        tracing::info!("G{:02}: frame sync, TOW {tow_s} s", e.prn);
                        sink.event(&ReceiverEvent::FrameSync {
                            prn: e.prn,
                            tow_s: f64::from(tow_s),
                        })?;
                    }
                    NavEvent::Ephemeris(eph) => {
                        tracing::info!("G{:02}: ephemeris decoded (IODE {})", e.prn, eph.iode);
                        if let Some(ff) = aiding {
                            ff.set_ephemeris(&eph);
                        }
                        sink.event(&ReceiverEvent::EphemerisDecoded {
                            prn: e.prn,
                            iode: eph.iode,
                        })?;
                    }
                    NavEvent::AlmanacPage(sf) => {
                        if let Some(w) = dec.decoded_week() {
                            self.almanac.set_reference_week(w);
                        }
                        let added = self.almanac.push(&sf);
                        if !added.is_empty() {
                            tracing::debug!("almanac of {added:?} decoded (from G{:02})", e.prn);
                        }
                    }
                    NavEvent::TowMismatch { error_ms } => {
                        tracing::warn!(
                            "G{:02}: the HOW time differs from the SV time kept by {error_ms:.3} ms (a gap in the samples?): the HOW's time is taken",
                            e.prn
                        );
                    }
                    NavEvent::BitEdgeMismatch { offset_ms } => {
                        tracing::info!(
                            "G{:02}: the bit edges found disagree with the SV time carried over the outage by {offset_ms:.3} ms (samples lost?): waiting for frame sync",
                            e.prn
                        );
                        self.time.make_rough(Some(e.prn));
                    }
                    _ => {}
                }
            }
        }
        if e.state == ChannelState::Lost {
            let reason = if e.cn0_dbhz.is_finite() && e.cn0_dbhz < self.cn0_lost_dbhz {
                format!(
                    "C/N0 estimate {:.1} dB-Hz, below the {:.0} dB-Hz loss threshold",
                    e.cn0_dbhz, self.cn0_lost_dbhz
                )
            } else {
                "no data-bit edges found (no usable signal)".to_string()
            };
            tracing::info!("G{:02}: signal lost at {:.2} s: {reason}", e.prn, e.t_rx_s);
            dec.reset_sync();
            sink.event(&ReceiverEvent::Lost {
                prn: e.prn,
                t_s: e.t_rx_s,
            })?;
        }
        if let Some(why) = coarse_wrong {
            self.drop_coarse_times(e.t_rx_s, &why, sink)?;
        }
        if let Some(c) = candidate {
            self.on_tow_candidate(c, sink)?;
        }
        Ok(())
    }

    /// A TLM and HOW found while unsynchronised: frame sync on it (and on the waiting
    /// candidates it agrees with) once another satellite confirms its time
    /// ([`crate::pipeline::timing::quick_sync`]).
    pub(super) fn on_tow_candidate(
        &mut self,
        c: TowCandidate,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let known: Vec<(u8, u64, f64)> = self
            .decoders
            .iter()
            .filter(|(_, d)| d.synced())
            .filter_map(|(&p, _)| self.time.last_known(p).map(|(k, sv)| (p, k, sv)))
            .collect();
        let Some(quick) = self.quick.as_mut() else {
            return Ok(());
        };
        let confirmed = quick.offer(c, &known, self.fs_hz);
        // Times read from HOWs that two satellites agree on, against SV times carried over an
        // outage (checked by the bit edges modulo 20 ms only): a carried time that disagrees
        // counts whole data bits of samples lost unseen; every carried time is dropped.
        let wrong_carried = confirmed.first().is_some_and(|c| {
            known.iter().any(|&(p, k, sv)| {
                self.decoders.get(&p).is_some_and(NavDecoder::time_carried)
                    && !c.agrees(k, sv, self.fs_hz)
            })
        });
        if wrong_carried {
            self.drop_carried_times(c.sample as f64 / self.fs_hz);
        }
        let by: Vec<String> = confirmed.iter().map(|c| format!("G{:02}", c.prn)).collect();
        for c in &confirmed {
            let synced = self
                .decoders
                .get_mut(&c.prn)
                .is_some_and(|d| d.sync_at(c.first_ms, c.tow_s));
            if synced {
                tracing::info!(
                    "G{:02}: frame sync, TOW {} s (TLM and HOW; times agree: {})",
                    c.prn,
                    c.tow_s,
                    if by.len() > 1 {
                        by.join(" ")
                    } else {
                        "with the satellites synchronised".to_string()
                    }
                );
                sink.event(&ReceiverEvent::FrameSync {
                    prn: c.prn,
                    tow_s: f64::from(c.tow_s),
                })?;
            }
        }
        Ok(())
    }

    /// Feeds the report to the coarse-time fix while no satellite's time is known, and hands
    /// its SV times to the decoders once it succeeds.
    pub(super) fn coarse_step(
        &mut self,
        e: &ChannelEpoch,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        if self.coarse.as_ref().is_none_or(|c| c.done) {
            return Ok(());
        }
        if self.decoders.values().any(NavDecoder::synced) {
            tracing::debug!("coarse time: a satellite's time is known already, no coarse-time fix");
            if let Some(c) = self.coarse.as_mut() {
                c.done = true;
            }
            return Ok(());
        }
        let opts = self.pvt_options();
        let (decoders, nav) = (&self.decoders, self.nav_assist.as_ref());
        let Some(cf) = self.coarse.as_mut() else {
            return Ok(());
        };
        cf.observe(e);
        let allow_unhealthy = self.settings.allow_unhealthy;
        let policy = if allow_unhealthy {
            HealthPolicy::PreferHealthy
        } else {
            HealthPolicy::HealthyOnly
        };
        // Decoded (after a long gap without a navigation file), else from the file.
        let ephemeris = |prn: u8, t| {
            decoders
                .get(&prn)
                .and_then(|d| d.ephemeris.clone())
                .filter(|eph| eph.sv_health == 0 || allow_unhealthy)
                .or_else(|| nav?.select_with(prn, t, policy).cloned())
        };
        match cf.attempt(&ephemeris, &opts) {
            Ok(out) => {
                self.step_clock_to_coarse_time(&out, sink)?;
                for t in &out.sv_times {
                    if let Some(d) = self.decoders.get_mut(&t.prn) {
                        d.carry_time(t.ms_count, t.sv_tow_s);
                    }
                }
                // A report covers up to 20 ms: later epochs have every channel's observables.
                let from = (out.t_s + 0.025) * self.fs_hz;
                self.fixes_from_sample = self.fixes_from_sample.max(from);
                tracing::info!(
                    "coarse-time fix at {:.2} s: {} satellites, time corrected by {:+.3} s, {:.1} km from the approximate position ({}): SV times set, fixes follow",
                    out.t_s,
                    out.sv_times.len(),
                    out.time_correction_s,
                    out.position_shift_m * 1e-3,
                    out.check
                );
                sink.event(&ReceiverEvent::CoarseTime {
                    t_s: out.t_s,
                    satellites: out.sv_times.len(),
                    time_correction_s: out.time_correction_s,
                })?;
            }
            Err(CoarseRefusal::Waiting) => {}
            Err(CoarseRefusal::Refused(why)) => {
                if self.coarse_warned {
                    tracing::debug!("{:.2} s: no coarse-time fix: {why}", e.t_rx_s);
                } else {
                    tracing::warn!(
                        "{:.2} s: no coarse-time fix: {why}; trying again as satellites come, else the first fix waits for frame sync",
                        e.t_rx_s
                    );
                    self.coarse_warned = true;
                }
            }
        }
        Ok(())
    }

    /// The SV times of the coarse-time fix disagree with the signal (`why`): every one not yet
    /// confirmed by a HOW is dropped (frame sync gives the time).
    pub(super) fn drop_coarse_times(
        &mut self,
        t_s: f64,
        why: &str,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        let Some(c) = self.coarse.as_mut() else {
            return Ok(());
        };
        let given = std::mem::take(&mut c.given);
        tracing::warn!(
            "{t_s:.2} s: {why}: the SV times of the coarse-time fix are dropped, waiting for frame sync"
        );
        for p in given {
            if let Some(d) = self.decoders.get_mut(&p) {
                if d.time_carried() {
                    d.reset_sync();
                }
            }
            self.time.make_rough(Some(p));
        }
        self.builder.restart();
        self.prior = None;
        // The coarse time was wrong, and so were the fixes from it.
        self.anchor = None;
        self.recent_fixes.clear();
        sink.event(&ReceiverEvent::CoarseTimeDropped { t_s })
    }
}
