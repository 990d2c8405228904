//! One epoch's solution: the ephemerides and ionosphere of the epoch, the WLS PVT with RAIM
//! (`gpsrx_nav::pvt::solve`), its integrity verdict, the fix and observables to the sink, and
//! the receiver clock kept within 0.5 ms of GPS time by whole-millisecond steps.

use super::predict::PredictionAnchor;
use super::{NavigationProcessor, FAILURES_TO_DISTRUST_TIME};
use crate::config::{IonoModel, TropoModel};
use crate::pipeline::aiding::InsFeedForward;
use crate::pipeline::navigation::fix_output::{fix_of, obs_epoch, passes_integrity};
use crate::pipeline::navigation::observables::ObservableEpoch;
use crate::pipeline::sink::FixQuality;
use crate::pipeline::sink::{FixReport, ObservablesReport, ReceiverEvent, Sink, SinkError};
use gpsrx_nav::atmosphere::KlobucharParams;
use gpsrx_nav::constants::SPEED_OF_LIGHT_MPS;
use gpsrx_nav::ephemeris::{Ephemeris, HealthPolicy};
use gpsrx_nav::pvt::{solve, Landmark, PvtOptions, PvtSolution, RaimStatus, SatMeasurement};

impl NavigationProcessor {
    /// The ionosphere parameters for the next solution: decoded, assisted, else a typical set.
    pub(super) fn iono(&mut self) -> Option<KlobucharParams> {
        if self.settings.iono != IonoModel::Klobuchar {
            return None;
        }
        let known = self
            .decoders
            .values()
            .find_map(|d| d.iono)
            .or_else(|| self.nav_assist.as_ref().and_then(|n| n.iono));
        if known.is_none() && !self.iono_fallback_said {
            tracing::info!(
                "ionosphere: typical Klobuchar coefficients until subframe 4 page 18 is decoded (no navigation data with them was given)"
            );
            self.iono_fallback_said = true;
        }
        Some(known.unwrap_or(KlobucharParams::FALLBACK))
    }

    /// The PVT options of the settings, with the ionosphere parameters known now.
    pub(super) fn pvt_options(&mut self) -> PvtOptions {
        PvtOptions {
            tropo: self.settings.tropo == TropoModel::Saastamoinen,
            elevation_mask_deg: self.settings.elevation_mask_deg,
            raim_pfa: self.settings.raim_pfa,
            iono: self.iono(),
            ..PvtOptions::default()
        }
    }

    /// The ephemeris for each satellite of the epoch: decoded, else from the navigation file.
    pub(super) fn ephemerides(&self, epoch: &ObservableEpoch) -> Vec<(u8, Ephemeris)> {
        // With `--allow-unhealthy` an unhealthy satellite's ephemeris is taken from the file too
        // (before, only its decoded one: it waited 18-30 s for subframes 1-3).
        let policy = if self.settings.allow_unhealthy {
            HealthPolicy::PreferHealthy
        } else {
            HealthPolicy::HealthyOnly
        };
        epoch
            .sats
            .iter()
            .filter_map(|s| {
                let decoded = self.decoders.get(&s.prn).and_then(|d| d.ephemeris.clone());
                decoded
                    .or_else(|| {
                        self.nav_assist
                            .as_ref()
                            .and_then(|n| n.select_with(s.prn, epoch.rx_time, policy).cloned())
                    })
                    .map(|e| (s.prn, e))
            })
            .collect()
    }

    /// The WLS solution of one epoch, if there are enough measurements.
    pub(super) fn solution(
        &mut self,
        epoch: &ObservableEpoch,
        ephs: &[(u8, Ephemeris)],
    ) -> Option<PvtSolution> {
        let meas: Vec<SatMeasurement<'_>> = epoch
            .sats
            .iter()
            .filter_map(|s| {
                let (_, eph) = ephs.iter().find(|(p, _)| *p == s.prn)?;
                (eph.sv_health == 0 || self.settings.allow_unhealthy).then_some(SatMeasurement {
                    prn: s.prn,
                    pseudorange_m: s.smoothed_pseudorange_m,
                    doppler_hz: Some(s.doppler_hz),
                    cn0_dbhz: s.cn0_dbhz,
                    tx_time: None,
                    ephemeris: eph,
                })
            })
            .collect();
        let opts = self.pvt_options();
        // Landmark observations of this epoch (receiver time within half an interval; the clock
        // bias is kept below 0.5 ms, far less than that).
        let landmarks: Vec<Landmark> = self
            .landmarks
            .iter()
            .filter(|l| (l.tow_s - epoch.rx_time.tow_s).abs() <= 0.5 / self.settings.rate_hz)
            .map(|l| l.landmark)
            .collect();
        if meas.len() + landmarks.len() < 4 || meas.is_empty() {
            tracing::trace!(
                "{} satellites with ephemeris at {:.3}",
                meas.len(),
                epoch.rx_time.tow_s
            );
            return None;
        }
        match solve(epoch.rx_time, &meas, &landmarks, &opts, self.prior.as_ref()) {
            Ok(s) => Some(s),
            Err(e) => {
                tracing::debug!("no fix at {:.3}: {e}", epoch.rx_time.tow_s);
                None
            }
        }
    }

    /// Logs the start of a stretch of solutions whose geometry is too poor to hand out
    /// ([`RunSettings::max_pdop`]).
    pub(super) fn log_poor_geometry(&mut self, t_stream_s: f64, pdop: f64, n_sv: usize) {
        if !self.poor_geometry_logged {
            tracing::info!(
                "{t_stream_s:.2} s: PDOP {pdop:.1} with {n_sv} satellites is above the largest PDOP allowed, {}: fixes flagged invalid until the geometry improves",
                self.settings.max_pdop
            );
            self.poor_geometry_logged = true;
        }
    }

    /// Logs a change of the RAIM outcome at INFO: an exclusion (with the residuals of the
    /// rest), a fault that could not be excluded, and the return to a clean test.
    pub(super) fn log_raim(&mut self, t_stream_s: f64, sol: &PvtSolution) {
        if self.last_raim.as_ref() == Some(&sol.raim) {
            return;
        }
        let residuals = || {
            sol.residuals_m
                .iter()
                .map(|(p, r)| format!("G{p:02} {r:+.1} m"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match &sol.raim {
            RaimStatus::FaultExcluded { prn } => tracing::info!(
                "{t_stream_s:.2} s: RAIM excluded G{prn:02} (a fault in its pseudorange); residuals of the rest: {}",
                residuals()
            ),
            RaimStatus::FaultDetectedNotExcluded => tracing::info!(
                "{t_stream_s:.2} s: RAIM detected a fault it could not exclude: no valid fix (residuals {})",
                residuals()
            ),
            RaimStatus::Ok
                if matches!(
                    self.last_raim,
                    Some(RaimStatus::FaultExcluded { .. } | RaimStatus::FaultDetectedNotExcluded)
                ) =>
            {
                tracing::info!("{t_stream_s:.2} s: RAIM test passes again")
            }
            _ => {}
        }
        self.last_raim = Some(sol.raim);
    }

    /// Whether a fix that passed the integrity and geometry tests, at stream time `t_s`, may
    /// be valid when RAIM could not check it: not just after an outage (`settle`), and not
    /// with an SV time carried over an outage that no HOW has confirmed yet. Such a time is
    /// checked by the bit edges only modulo 20 ms: samples lost during the outage by a whole
    /// number of data bits do not show (a 5 s cut of a 24-32 dB-Hz recording, which no
    /// lost-sample detector saw: 4-satellite fixes 5.8 km off handed out as valid for 3 s),
    /// and without redundancy nothing else checks it: such a fix waits for the satellites'
    /// HOWs (or for RAIM).
    fn unchecked_fix_admitted(&mut self, s: &PvtSolution, t_s: f64) -> bool {
        let checked = !matches!(s.raim, RaimStatus::Unavailable);
        if !self.settle.admit(t_s, checked, 1.0 / self.settings.rate_hz) {
            tracing::debug!("{t_s:.2} s: a fix of 4 satellites just after an outage is not valid (waiting for one RAIM can check)");
            return false;
        }
        let unconfirmed = s
            .used_prns
            .iter()
            .filter(|p| self.decoders.get(p).is_some_and(|d| d.time_carried()))
            .count();
        if !checked && unconfirmed > 0 {
            tracing::debug!("{t_s:.2} s: a fix RAIM cannot check, with the SV times of {unconfirmed} satellites carried over an outage and not yet confirmed by a HOW, is not valid");
            return false;
        }
        true
    }

    /// Solves one epoch and hands its observables and fix to the sink.
    pub(super) fn solve_epoch(
        &mut self,
        epoch: ObservableEpoch,
        aiding: Option<&InsFeedForward>,
        sink: &mut dyn Sink,
    ) -> Result<(), SinkError> {
        if epoch.sample < self.fixes_from_sample {
            return Ok(());
        }
        let ephs = self.ephemerides(&epoch);
        let solution = self.solution(&epoch, &ephs);
        let max_pdop = self.settings.max_pdop;
        let integrity_ok = solution.as_ref().is_some_and(passes_integrity);
        let mut valid = integrity_ok && solution.as_ref().is_some_and(|s| s.dop.pdop <= max_pdop);
        if let Some(s) = solution.as_ref().filter(|_| valid) {
            valid = self.unchecked_fix_admitted(s, epoch.sample / self.fs_hz);
        }
        if let Some(s) = solution.as_ref().filter(|s| s.dop.pdop > max_pdop) {
            self.log_poor_geometry(epoch.sample / self.fs_hz, s.dop.pdop, s.n_sv);
        } else {
            self.poor_geometry_logged = false;
        }
        sink.observables(&ObservablesReport {
            epoch: obs_epoch(&epoch),
            fix_position_m: solution
                .as_ref()
                .filter(|_| valid)
                .map(|s| [s.pos_ecef_m.x, s.pos_ecef_m.y, s.pos_ecef_m.z]),
            week_decoded: self.decoders.values().any(|d| d.decoded_week().is_some()),
            week_known: self.week_known(),
        })?;
        let Some(sol) = solution else {
            return Ok(());
        };
        let t_stream_s = epoch.sample / self.fs_hz;
        self.log_raim(t_stream_s, &sol);
        // A poor geometry is no sign of a wrong time: only integrity failures count.
        self.failed_in_row = if integrity_ok {
            0
        } else {
            self.failed_in_row + 1
        };
        if self.failed_in_row >= 3 {
            self.drop_carried_times(t_stream_s);
        }
        if self.failed_in_row >= FAILURES_TO_DISTRUST_TIME && self.time_trusted {
            // Every solution fails after good ones: the receiver time itself may be wrong
            // (samples lost by whole data bits, which neither the carrier nor the bits show).
            tracing::warn!(
                "{t_stream_s:.2} s: {} solutions in a row fail the integrity test: the receiver time may be wrong (samples lost?); re-establishing it from the satellites' time of week",
                self.failed_in_row
            );
            self.time_trusted = false;
            self.forget_time(t_stream_s, Vec::new(), None);
            sink.event(&ReceiverEvent::SampleGap { t_s: t_stream_s })?;
        }
        if valid {
            self.time_trusted = true;
        }
        if !valid {
            // Written for the record, flagged: quality `none` in pvt.csv, GGA quality 0, absent
            // from the GeoJSON and KML tracks; it steers nothing.
            self.stats.invalid_fixes += 1;
            let mut fix = fix_of(&sol, &epoch, &ephs, self.week_known());
            fix.quality = FixQuality::None;
            return sink.fix(&FixReport {
                fix,
                solution: sol,
                t_stream_s,
            });
        }
        if let Some(gap) = self.time.take_unmeasured_gap() {
            let length = gap.length_from_bias_ms(t_stream_s, sol.clock_bias_m);
            match length {
                Some(ms) => tracing::warn!(
                    "{t_stream_s:.2} s: receiver time re-established; the samples lost at {:.3} s were {ms:.3} ms of signal",
                    gap.t_s
                ),
                None => tracing::warn!(
                    "{t_stream_s:.2} s: receiver time re-established after the samples lost at {:.3} s",
                    gap.t_s
                ),
            }
            if let Some(length_ms) = length {
                sink.event(&ReceiverEvent::GapMeasured {
                    t_s: gap.t_s,
                    length_ms,
                })?;
                self.lost_for_aid_ms += length_ms;
            }
        }
        // Keep the receiver clock within +-0.5 ms of GPS time by whole-millisecond steps.
        let bias_ms = sol.clock_bias_m / SPEED_OF_LIGHT_MPS * 1e3;
        let mut bias_after_m = sol.clock_bias_m;
        if bias_ms.abs() > 0.5 {
            let step = -bias_ms.round() as i64;
            self.builder.step_clock_ms(step);
            bias_after_m += step as f64 * 1e-3 * SPEED_OF_LIGHT_MPS;
            tracing::debug!("receiver clock stepped by {step} ms");
            sink.event(&ReceiverEvent::ClockStep { ms: step })?;
        }
        let drift_mps = sol.clock_drift_mps.unwrap_or(0.0);
        self.time
            .note_fix(t_stream_s, bias_after_m, drift_mps, sol.llh);
        if self.stats.first_fix_s.is_none() {
            tracing::info!(
                "first fix at {:.2} s: {:.7} {:.7} {:.1} m, {} satellites, PDOP {:.1}",
                t_stream_s,
                sol.llh.lat_rad.to_degrees(),
                sol.llh.lon_rad.to_degrees(),
                sol.llh.h_m,
                sol.n_sv,
                sol.dop.pdop
            );
        }
        let fix = fix_of(&sol, &epoch, &ephs, self.week_known());
        if let Some(ff) = aiding {
            ff.set_fix_from(t_stream_s, &sol);
        }
        self.stats.add(t_stream_s, &fix);
        sink.fix(&FixReport {
            fix,
            solution: sol.clone(),
            t_stream_s,
        })?;
        if passes_integrity(&sol) {
            let anchor = PredictionAnchor::new(&sol, t_stream_s, self.anchor.as_ref());
            self.anchor = Some(anchor);
            self.remember_fix(&sol, t_stream_s);
        }
        self.prior = Some(sol);
        Ok(())
    }
}
