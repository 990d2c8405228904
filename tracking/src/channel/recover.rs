//! Recovery from a loss of carrier lock in tracking (issue 25).
//!
//! A channel in [`ChannelState::Track`] whose phase-lock indicator ([`crate::lock_detector`])
//! stays out for [`ChannelConfig::relock_after_s`](super::ChannelConfig::relock_after_s)
//! has slipped: a narrow loop left a fraction of a hertz off (a Costas loop beats at twice
//! the error and its mean discriminator output nearly vanishes) does not pull itself back in.
//! The channel goes to [`ChannelState::Recover`]: **code-only tracking**. Its DLL keeps the
//! code (carrier-aided by an NCO that is off by hertz at most, 0.001 chip/s per Hz), its
//! bit synchronisation stays, its measurements are marked unlocked and never feed a fix, and
//! the carrier is pulled in again from the frequency memory (from the feed-forward alone when
//! the navigation filter of vector tracking checks the channel, `DopplerAid::checked`):
//!
//! - at a C/N0 of at least the weak pull-in's [`WeakPullInConfig::enter_dbhz`](super::WeakPullInConfig::enter_dbhz)
//!   (or without a weak pull-in) with the wide, FLL-assisted pull-in loops
//!   ([`ChannelConfig::pull_in`](super::ChannelConfig::pull_in), 1 ms; the FLL assist off
//!   after `fll_assist_s`), as after acquisition;
//! - below it with the weak pull-in: its FLL on unaligned 10 ms sums, then at the next bit
//!   edge (the bits are still synchronised) its bit-aligned 20 ms FLL-assisted PLL.
//!
//! Once the phase is locked again the usual hand-over returns it, at a bit edge, to its
//! configured loops (narrowed in stages from the phase fit if they are narrow). A channel
//! still not locked after [`ChannelConfig::recover_s`](super::ChannelConfig::recover_s) is
//! released ([`ChannelState::Lost`]): the receiver searches for the satellite again.

use super::{Channel, ChannelState};
use crate::carrier_loop::CarrierLoop;
use crate::channel::weak_pull_in::WeakStage;
use num_complex::Complex64;

/// Time without phase lock after which a channel the navigation filter checks
/// ([`crate::aiding::DopplerAid::checked`]) goes to recovery, s, when
/// [`super::ChannelConfig::relock_after_s`] is longer. Out of lock, a narrow 3rd-order loop
/// wanders on noise (a 25 dB-Hz channel: 5 Hz off within 0.6 s, 10 Hz within 1.5 s, never
/// back by itself); a checked channel's recovery starts at the feed-forward, which is right to
/// a fraction of a hertz, and locks again within about a second. Measured at 25 dB-Hz
/// (receiver test `vector_tracking_uses_satellites_below_the_scalar_loss_threshold...`).
pub const CHECKED_RELOCK_AFTER_S: f64 = 0.5;

impl Channel {
    /// Per integration interval in tracking or recovery: counts the time without phase lock
    /// (from the interval's length `dur_ms`), starts a recovery after
    /// [`super::ChannelConfig::relock_after_s`] in tracking, and releases a channel whose
    /// recovery has lasted [`super::ChannelConfig::recover_s`].
    pub(super) fn watch_carrier_lock(&mut self, dur_ms: u64) {
        match self.state {
            ChannelState::Track => {
                // The lock the channel reports: the detector's, and no fade.
                if self.pll_lock.locked() && !self.fade.faded() {
                    self.unlocked_ms = 0;
                    return;
                }
                if self.coasting_on_aid() {
                    return; // the aid holds the signal's place (`Channel::coasting_on_aid`)
                }
                self.unlocked_ms += dur_ms;
                let relock_after_s = if self.checked_aid() {
                    self.cfg.relock_after_s.min(CHECKED_RELOCK_AFTER_S)
                } else {
                    self.cfg.relock_after_s
                };
                let limit_ms = (relock_after_s * 1e3).round() as u64;
                if relock_after_s > 0.0 && self.unlocked_ms >= limit_ms {
                    self.start_recovery();
                }
            }
            // Reported as lost with the next interval (as a release from outside).
            ChannelState::Recover if self.pull_in_ms as f64 >= self.cfg.recover_s * 1e3 => {
                self.release_requested = true;
            }
            _ => {}
        }
    }

    /// Tracking -> recovery: the pull-in carrier loop (normal or weak, module documentation)
    /// at the running loop's frequency memory; the code loop, the bit synchronisation and the
    /// C/N0 estimate carry on.
    fn start_recovery(&mut self) {
        if self.checked_aid() {
            // The navigation filter checks this satellite: its Doppler is the feed-forward's
            // to a fraction of a hertz, and what the loop holds beyond it is what the loop
            // wandered off on noise while out of lock (a 25 dB-Hz channel: 5 Hz within
            // 0.6 s). The pull-in starts at the feed-forward.
            self.carrier
                .shift_base_hz(-self.carrier.frequency_memory_hz());
        }
        let f = self.carrier.frequency_memory_hz();
        let weak = self
            .cfg
            .weak_pull_in
            .filter(|w| self.cn0_dbhz.is_nan() || self.cn0_dbhz < w.enter_dbhz);
        if let Some(w) = weak {
            // The frequency stage's 10 ms sums need no alignment; the stage hands over to the
            // bit-aligned phase stage at the next bit edge ([`Channel::weak_pull_in_step`]).
            self.set_weak_loops(&w.fll);
            self.weak_stage = Some(WeakStage::Frequency);
        } else {
            let Ok(carrier) = CarrierLoop::new(&self.cfg.pull_in, f) else {
                return; // validated at construction
            };
            self.carrier = carrier;
            self.weak_stage = None;
        }
        self.state = ChannelState::Recover;
        self.recoveries += 1;
        self.unlocked_ms = 0;
        self.pull_in_ms = 0;
        self.narrowing = None;
        self.rate_fit = [0.0; 5];
        self.phase_fit.reset();
        self.acc = [Complex64::new(0.0, 0.0); 3];
        self.acc_ms = 0;
    }

    /// How many times the channel lost carrier lock in tracking and went to recovery.
    pub fn recoveries(&self) -> u32 {
        self.recoveries
    }
}

#[cfg(test)]
mod tests {
    use crate::channel::{Channel, ChannelConfig, ChannelStart, ChannelState};
    use crate::config::LoopConfig;
    use crate::phase_sim::{NoiseSource, SimRng};
    use gpsrx_dsp::ca_code::{CaCode, Prn};
    use gpsrx_dsp::constants::{CA_CHIP_RATE_HZ, F_L1_HZ};
    use num_complex::{Complex32, Complex64};

    const FS: f64 = 2.048e6;
    const DOPPLER_HZ: f64 = 1234.5;

    /// PRN 7 at `cn0_dbhz` in unit complex noise (`A^2 fs / 2 = C/N0`), 50 bit/s data
    /// alternating in pairs, the carrier Doppler stepping by `step_hz` at `step_s`
    /// (phase-continuous); no signal at all from `off_s` on; from `cut.0` s on, `cut.1` s of
    /// signal lost (as when samples are dropped); from `zeros.0` s on, `zeros.1` s of samples
    /// that are 0 (a stalled front end).
    struct Signal {
        code: CaCode,
        step_s: f64,
        step_hz: f64,
        off_s: f64,
        cn0_dbhz: f64,
        rng: SimRng,
        cut: (f64, f64),
        zeros: (f64, f64),
    }

    impl Signal {
        /// PRN 7 at `cn0_dbhz`, steady: no Doppler step, cut, zeros or end.
        fn steady(cn0_dbhz: f64, seed: u64) -> Self {
            Signal {
                code: CaCode::new(Prn::new(7).expect("PRN")),
                step_s: f64::INFINITY,
                step_hz: 0.0,
                off_s: f64::INFINITY,
                cut: (f64::INFINITY, 0.0),
                zeros: (f64::INFINITY, 0.0),
                cn0_dbhz,
                rng: SimRng::new(seed),
            }
        }

        fn sample(&mut self, k: u64) -> Complex32 {
            let t = k as f64 / FS;
            if (self.zeros.0..self.zeros.0 + self.zeros.1).contains(&t) {
                return Complex32::new(0.0, 0.0);
            }
            let t = if t >= self.cut.0 { t + self.cut.1 } else { t };
            let n = Complex64::new(self.rng.gauss(), self.rng.gauss());
            if t >= self.off_s {
                return Complex32::new(n.re as f32, n.im as f32);
            }
            let dt = (t - self.step_s).max(0.0);
            let cycles = DOPPLER_HZ * t + self.step_hz * dt;
            let chips = t * CA_CHIP_RATE_HZ + cycles * CA_CHIP_RATE_HZ / F_L1_HZ;
            let chip = f64::from(self.code.chip(chips.floor() as usize % 1023));
            let bit = if (chips / 20460.0).floor() as u64 % 4 < 2 {
                1.0
            } else {
                -1.0
            };
            let amp = (2.0 * 10f64.powf(0.1 * self.cn0_dbhz) / FS).sqrt();
            let v = Complex64::from_polar(amp * chip * bit, std::f64::consts::TAU * cycles) + n;
            Complex32::new(v.re as f32, v.im as f32)
        }
    }

    /// Runs `ch` to `end_s` and returns (time, state, lock, Doppler) of every report.
    fn run(ch: &mut Channel, sig: &mut Signal, end_s: f64) -> Vec<(f64, ChannelState, bool, f64)> {
        let mut out = Vec::new();
        while ch.state() != ChannelState::Lost {
            let (start, n) = ch.next_span();
            if (start + n as u64) as f64 / FS > end_s {
                break;
            }
            let x: Vec<Complex32> = (start..start + n as u64).map(|k| sig.sample(k)).collect();
            if let Some(e) = ch.process_code_period(&x) {
                if std::env::var("LOCKDBG").is_ok()
                    && ((e.t_rx_s * 10.0).round() - e.t_rx_s * 10.0).abs() < 0.011
                {
                    eprintln!(
                        "{:.2} {:?} {} rho {:.2} a {:.4} st {:.2} cn0 {:.1}",
                        e.t_rx_s,
                        e.state,
                        e.pll_lock,
                        ch.pll_lock.block_snr(),
                        ch.pll_lock.alpha(),
                        ch.pll_lock.phase_steadiness(),
                        e.cn0_dbhz
                    );
                }
                out.push((e.t_rx_s, e.state, e.pll_lock, e.doppler_hz));
            }
        }
        out
    }

    /// Longest stretch (s) of reports in tracking without phase lock.
    fn longest_unlocked_track(eps: &[(f64, ChannelState, bool, f64)]) -> f64 {
        let (mut since, mut longest) = (None, 0.0f64);
        for &(t, state, lock, _) in eps {
            if state == ChannelState::Track && !lock {
                let t0 = *since.get_or_insert(t);
                longest = longest.max(t - t0);
            } else {
                since = None;
            }
        }
        longest
    }

    fn narrow_config() -> ChannelConfig {
        let base = ChannelConfig::default();
        ChannelConfig {
            relock_after_s: 1.0,
            track: LoopConfig {
                pll_order: 3,
                pll_bw_hz: 1.0,
                ..base.track
            },
            ..base
        }
    }

    fn start() -> ChannelStart {
        ChannelStart {
            prn: Prn::new(7).expect("PRN"),
            code_start_sample: 0,
            doppler_hz: DOPPLER_HZ + 3.0,
            cn0_dbhz: 45.0,
        }
    }

    /// A 3rd-order 1 Hz loop hit by a 5 Hz Doppler step (4 cycles of phase against its
    /// `w0` = 1.27 rad/s) slips and stays off; the channel goes to recovery after 1 s without
    /// lock (`relock_after_s` = 1 s here), the FLL-assisted pull-in finds the new frequency,
    /// and it tracks locked again at the new Doppler. It is never in tracking without lock
    /// for more than about `relock_after_s`.
    #[test]
    fn a_slipped_narrow_loop_is_pulled_in_again() {
        let mut sig = Signal {
            step_s: 4.0,
            step_hz: 5.0,
            ..Signal::steady(45.0, 11)
        };
        let mut ch = Channel::new(&start(), FS, &narrow_config()).expect("channel");
        let eps = run(&mut ch, &mut sig, 9.0);
        let at = |t0: f64| eps.iter().find(|e| e.0 >= t0).copied().expect("report");
        let before = at(3.9);
        assert_eq!(
            (before.1, before.2),
            (ChannelState::Track, true),
            "{before:?}"
        );
        assert!(
            eps.iter().any(|e| e.1 == ChannelState::Recover),
            "never recovered"
        );
        assert_eq!(ch.recoveries(), 1);
        let longest = longest_unlocked_track(&eps);
        assert!(longest < 1.1, "{longest:.2} s in tracking without lock");
        let end = eps.last().copied().expect("report");
        assert_eq!((end.1, end.2), (ChannelState::Track, true), "{end:?}");
        assert!((end.3 - (DOPPLER_HZ + 5.0)).abs() < 0.5, "{end:?}");
    }

    /// The same at 31 dB-Hz (loops without the weak-signal switch, so the 1 Hz loop at 1 ms
    /// tracks it): the recovery takes the weak pull-in (an FLL on 10 ms sums, then at a bit
    /// edge the bit-aligned 20 ms PLL) and hands back to the configured loops.
    #[test]
    fn a_weak_channel_recovers_through_the_weak_pull_in() {
        let mut sig = Signal {
            step_s: 6.0,
            step_hz: 5.0,
            ..Signal::steady(31.0, 23)
        };
        let cfg = ChannelConfig {
            weak_track: None,
            ..narrow_config()
        };
        let start = ChannelStart {
            cn0_dbhz: 31.0,
            ..start()
        };
        let mut ch = Channel::new(&start, FS, &cfg).expect("channel");
        let eps = run(&mut ch, &mut sig, 16.0);
        let before = eps
            .iter()
            .rev()
            .find(|e| e.0 < 6.0)
            .copied()
            .expect("report");
        assert_eq!(
            (before.1, before.2),
            (ChannelState::Track, true),
            "{before:?}"
        );
        // The weak pull-in's 20 ms sums report in recovery.
        assert!(
            eps.iter().any(|e| e.1 == ChannelState::Recover && e.2),
            "never locked in recovery"
        );
        // Measured: before the hand-over waited for the phase fit, the 1 Hz loop slipped again
        // 0.5 s after each of three recoveries.
        assert_eq!(ch.recoveries(), 1);
        assert!(longest_unlocked_track(&eps) < 1.1);
        let end = eps.last().copied().expect("report");
        assert_eq!((end.1, end.2), (ChannelState::Track, true), "{end:?}");
        // The loop's NCO frequency over the last second (one 1 ms report of a 1 Hz loop at
        // 31 dB-Hz is off by a few tenths of a hertz).
        let last: Vec<f64> = eps
            .iter()
            .filter(|e| e.0 > end.0 - 1.0)
            .map(|e| e.3)
            .collect();
        let mean = last.iter().sum::<f64>() / last.len().max(1) as f64;
        assert!(
            (mean - (DOPPLER_HZ + 5.0)).abs() < 0.2,
            "{mean} Hz, end {end:?}"
        );
    }

    /// Without the signal (and with the C/N0 loss switched off) the recovery cannot lock:
    /// the channel is released `recover_s` after it started, and reports `Lost`.
    #[test]
    fn a_channel_that_cannot_recover_is_released() {
        let mut sig = Signal {
            off_s: 2.0,
            ..Signal::steady(45.0, 5)
        };
        let cfg = ChannelConfig {
            cn0_lost_dbhz: -100.0,
            relock_after_s: 1.0,
            ..ChannelConfig::default()
        };
        let mut ch = Channel::new(&start(), FS, &cfg).expect("channel");
        let eps = run(&mut ch, &mut sig, 12.0);
        let first_recover = eps
            .iter()
            .find(|e| e.1 == ChannelState::Recover)
            .map(|e| e.0)
            .expect("a recovery");
        // The lock indicator of a wide loop on noise reads high for a while (the fade
        // detector, not this test, marks such reports unlocked): out within 1.5 s, then 1 s.
        assert!((3.0..4.5).contains(&first_recover), "{first_recover}");
        let lost = eps.last().copied().expect("report");
        assert_eq!(lost.1, ChannelState::Lost, "{lost:?}");
        assert!(
            (lost.0 - first_recover - cfg.recover_s).abs() < 0.1,
            "released at {:.2} s, recovery from {first_recover:.2} s",
            lost.0
        );
        assert!(longest_unlocked_track(&eps) < 1.1);
    }

    /// A steady signal at `cn0_dbhz` (noise seed `seed`) that loses 31 ms of samples at 3 s:
    /// its data-bit edges move by 11 ms.
    fn cut_at_3_s(cn0_dbhz: f64, seed: u64) -> Signal {
        Signal {
            cut: (3.0, 0.031),
            ..Signal::steady(cn0_dbhz, seed)
        }
    }

    /// One second of zeros at 3 s under a 36 dB-Hz satellite (between the weak-signal
    /// thresholds, 32 and 35 dB-Hz, on its 1 ms loops): the C/N0 estimates sink with the power
    /// and the channel coasts through on its weak-signal loops; `dynamics` tells it the
    /// receiver is manoeuvring. Returns the reports of 3.95-5.0 s and the channel.
    fn one_second_of_zeros(dynamics: bool) -> (Vec<(f64, ChannelState, bool, f64)>, Channel) {
        let mut sig = Signal {
            zeros: (3.0, 1.0),
            ..Signal::steady(36.0, 41)
        };
        let mut ch = Channel::new(&start(), FS, &ChannelConfig::default()).expect("channel");
        ch.set_dynamics(dynamics);
        let _ = run(&mut ch, &mut sig, 2.95);
        assert!(!ch.weak_loops(), "weak before the outage");
        let _ = run(&mut ch, &mut sig, 3.95);
        assert!(ch.weak_loops(), "not coasting on the weak loops");
        (run(&mut ch, &mut sig, 5.0), ch)
    }

    /// When the signal comes back the channel takes back its 1 ms loops at once, not once its
    /// C/N0 estimate, which still averages the zeros, has climbed over the weak-signal
    /// threshold and its hysteresis (0.5-0.8 s later), and holds the phase within 0.3 s.
    /// Under unaided dynamics it keeps its weak loops (its NCO did not follow the motion
    /// through the outage).
    #[test]
    fn after_an_outage_a_channel_takes_back_the_loops_it_had() {
        let (eps, ch) = one_second_of_zeros(false);
        let back = eps
            .iter()
            .find(|e| e.0 >= 4.1)
            .expect("reports after the outage");
        assert!(!ch.weak_loops(), "on the weak loops at the end");
        assert!(eps.iter().all(|e| e.1 == ChannelState::Track), "lost");
        assert!(
            eps.iter().filter(|e| e.0 >= 4.3).all(|e| e.2),
            "not locked 0.3 s after the outage"
        );
        // Each report is one interval: 1 ms intervals from 0.1 s after the return.
        assert!(
            longest_interval_ms(&eps, back.0) < 1.5,
            "longer intervals after 4.1 s"
        );
        // (Under dynamics the weak loops are the widened ones, 10 ms, once the signal is back.)
        let (eps, _) = one_second_of_zeros(true);
        assert!(
            longest_interval_ms(&eps, 4.1) > 5.0,
            "unaided under dynamics: taken back"
        );
    }

    /// A satellite at 30 dB-Hz under 1.2 s of zeros: its C/N0 estimates sink for as long
    /// (5 of them below 25 dB-Hz, with the code lock out, release a channel). Unaided it is
    /// released in the outage; with a feed-forward that holds its Doppler (an INS, or the
    /// receiver's outage bridge) it coasts through, is not released for the estimates that
    /// still average the zeros after the return, and tracks locked again.
    #[test]
    fn a_channel_coasting_on_a_feed_forward_is_not_released_for_the_outage() {
        let run_aided = |aided: bool| {
            let mut sig = Signal {
                zeros: (3.0, 1.2),
                ..Signal::steady(30.0, 7)
            };
            let mut ch = Channel::new(&start(), FS, &ChannelConfig::default()).expect("channel");
            let mut last = None;
            while ch.state() != ChannelState::Lost {
                let (first, n) = ch.next_span();
                let t = first as f64 / FS;
                if t > 7.0 {
                    break;
                }
                let aid = crate::DopplerAid {
                    doppler_hz: DOPPLER_HZ,
                    doppler_rate_hz_s: 0.0,
                    coast: false,
                    checked: false,
                    source: crate::AidSource::Ins,
                };
                ch.set_aid((aided && t > 2.9).then_some(aid), t);
                let x: Vec<Complex32> = (first..first + n as u64).map(|k| sig.sample(k)).collect();
                if let Some(e) = ch.process_code_period(&x) {
                    last = Some((e.t_rx_s, e.state, e.pll_lock));
                }
            }
            last.expect("reports")
        };
        let (t, state, _) = run_aided(false);
        assert_eq!(
            state,
            ChannelState::Lost,
            "unaided: still tracking at {t:.2} s"
        );
        assert!(t < 5.0, "unaided: released only at {t:.2} s");
        let (t, state, locked) = run_aided(true);
        assert!(
            state == ChannelState::Track && locked && t > 6.9,
            "aided: {state:?}, lock {locked} at {t:.2} s"
        );
    }

    /// The longest interval between two reports from `from_s` on, ms.
    fn longest_interval_ms(eps: &[(f64, ChannelState, bool, f64)], from_s: f64) -> f64 {
        let after: Vec<f64> = eps.iter().filter(|e| e.0 >= from_s).map(|e| e.0).collect();
        after
            .windows(2)
            .map(|w| (w[1] - w[0]) * 1e3)
            .fold(0.0f64, f64::max)
    }

    /// A satellite at 34 dB-Hz, 2 dB over the weak-signal threshold: the C/N0 estimates
    /// between lost samples and their detection straddle the moved bits and fall below it, so
    /// the channel starts narrowing to its weak-signal loops (20 ms, 6 Hz) at the next old bit
    /// edge. The restart of the bit synchronisation that follows puts it back on its 1 ms loops
    /// and must end that narrowing too (it used to go on at the first new edge: a 37 dB-Hz
    /// satellite on 6 Hz loops in a 10 g turn, lost seconds later). From the restart on every
    /// interval is 1 ms, and the C/N0 stands at the level before the gap.
    #[test]
    fn a_bit_sync_restart_ends_a_narrowing_begun_on_the_moved_bits() {
        let mut sig = cut_at_3_s(34.0, 5);
        let mut ch = Channel::new(&start(), FS, &ChannelConfig::default()).expect("channel");
        let _ = run(&mut ch, &mut sig, 2.95);
        assert!(!ch.weak_loops() && !ch.narrowing(), "weak before the gap");
        // Found late: the estimates of 0.15 s read the moved bits.
        let _ = run(&mut ch, &mut sig, 3.15);
        ch.restart_bit_sync();
        assert!(ch.cn0_dbhz() > 32.5, "C/N0 {:.1} dB-Hz", ch.cn0_dbhz());
        let mut longest_ms = 0.0f64;
        while ch.next_span().0 as f64 / FS < 5.0 {
            let (start, n) = ch.next_span();
            let x: Vec<Complex32> = (start..start + n as u64).map(|k| sig.sample(k)).collect();
            if let Some(e) = ch.process_code_period(&x) {
                longest_ms = longest_ms.max(e.t_coh_s * 1e3);
            }
        }
        assert!(
            longest_ms < 1.5,
            "integrations of {longest_ms} ms after the restart"
        );
    }

    /// Samples lost by 31 ms move the data-bit edges by 11 ms: the channel forgets them
    /// ([`Channel::restart_bit_sync`]) and finds them again. Until then its C/N0 and lock
    /// blocks would straddle data-bit transitions: the C/N0 held at its last estimate keeps a
    /// 38 dB-Hz satellite off the weak-signal loops (20 ms at 6 Hz, which would not hold a
    /// 10 g turn), and it tracks locked on its 1 ms loops after the new edges.
    #[test]
    fn a_bit_sync_restart_keeps_the_c_n0_and_the_loops() {
        let mut sig = cut_at_3_s(38.0, 11);
        let mut ch = Channel::new(&start(), FS, &ChannelConfig::default()).expect("channel");
        let eps = run(&mut ch, &mut sig, 2.95);
        assert!(eps
            .last()
            .is_some_and(|e| e.1 == ChannelState::Track && e.2));
        assert!((ch.cn0_dbhz() - 38.0).abs() < 1.5, "{}", ch.cn0_dbhz());
        // The receiver finds the gap a little after it.
        let _ = run(&mut ch, &mut sig, 3.04);
        ch.restart_bit_sync();
        let mut lowest = f64::INFINITY;
        let mut weak = false;
        while ch.next_span().0 as f64 / FS < 5.0 {
            let before = ch.next_span().0;
            let _ = run(&mut ch, &mut sig, (before as f64 / FS) + 0.02);
            lowest = lowest.min(ch.cn0_dbhz());
            weak |= ch.weak_loops();
        }
        assert!(
            !weak,
            "the restart put the channel on its weak-signal loops"
        );
        assert!(lowest > 33.0, "C/N0 fell to {lowest:.1} dB-Hz");
        let eps = run(&mut ch, &mut sig, 6.0);
        assert!(eps.iter().all(|e| e.1 == ChannelState::Track));
        assert!(
            eps.iter().filter(|e| e.0 > 5.5).all(|e| e.2),
            "not locked again"
        );
    }

    /// A 30 dB-Hz satellite on its weak loops (6 Hz, 20 ms): told the receiver is under
    /// dynamics it takes the widened weak loops (15 Hz, 10 ms) at its next bit edges and keeps
    /// its lock; told they are over, it narrows back to the weak loops. Its own rate is not
    /// read as the receiver's (weak loops), a strong channel's is, once settled.
    #[test]
    fn a_weak_channel_widens_its_loops_under_dynamics_and_narrows_after() {
        let mut sig = Signal::steady(30.0, 29);
        let weak_start = ChannelStart {
            cn0_dbhz: 30.0,
            ..start()
        };
        let mut ch = Channel::new(&weak_start, FS, &ChannelConfig::default()).expect("channel");
        let eps = run(&mut ch, &mut sig, 6.0);
        assert!(
            ch.weak_loops() && !ch.dynamic_weak_loops(),
            "not on the weak loops"
        );
        assert!(eps
            .last()
            .is_some_and(|e| e.1 == ChannelState::Track && e.2));
        assert_eq!(ch.los_rate_hz_s(), None, "a weak channel's rate was read");
        ch.set_dynamics(true);
        let eps = run(&mut ch, &mut sig, 7.0);
        assert!(ch.dynamic_weak_loops(), "not widened");
        assert!(eps.iter().filter(|e| e.0 > 6.1).all(|e| e.2), "lock lost");
        ch.set_dynamics(false);
        let _ = run(&mut ch, &mut sig, 9.0);
        assert!(
            ch.weak_loops() && !ch.dynamic_weak_loops(),
            "not narrowed back"
        );
        // A 40 dB-Hz channel on its 1 ms loops: its rate (a static signal: near 0) is read
        // once it has tracked for 2 s.
        let mut strong_sig = Signal::steady(40.0, 31);
        let mut strong = Channel::new(&start(), FS, &ChannelConfig::default()).expect("channel");
        let _ = run(&mut strong, &mut strong_sig, 1.5);
        assert_eq!(strong.los_rate_hz_s(), None, "read before it settled");
        let _ = run(&mut strong, &mut strong_sig, 4.0);
        let rate = strong.los_rate_hz_s().expect("rate of a strong channel");
        assert!(rate.abs() < 2.0, "{rate} Hz/s on a static signal");
    }

    /// A channel the navigation filter checks (`DopplerAid::checked`, the aid at the signal's
    /// Doppler) whose signal goes: it goes to recovery 0.5 s after its lock
    /// ([`super::CHECKED_RELOCK_AFTER_S`]), not after `relock_after_s` (2 s), and its pull-in
    /// starts at the feed-forward, not where its loop wandered on the noise. Unchecked, the
    /// same aid changes neither.
    #[test]
    fn a_checked_channel_out_of_lock_recovers_soon_at_the_feed_forward() {
        let aid = |checked| crate::aiding::DopplerAid {
            doppler_hz: DOPPLER_HZ,
            doppler_rate_hz_s: 0.0,
            coast: false,
            checked,
            source: crate::aiding::AidSource::Vector,
        };
        let run_with = |checked: bool| {
            let mut sig = Signal {
                off_s: 3.0,
                ..Signal::steady(40.0, 5)
            };
            let mut ch = Channel::new(&start(), FS, &ChannelConfig::default()).expect("channel");
            ch.set_aid(Some(aid(checked)), 0.0);
            let eps = run(&mut ch, &mut sig, 5.5);
            let unlocked = eps
                .iter()
                .find(|e| e.0 > 3.0 && e.1 == ChannelState::Track && !e.2)
                .copied()
                .expect("lock lost");
            // The report that starts the recovery carries the slipped loop's frequency; the
            // next one the pull-in's first.
            let recovery = eps
                .iter()
                .filter(|e| e.1 == ChannelState::Recover)
                .nth(1)
                .copied();
            (unlocked, recovery)
        };
        let (unlocked, recovery) = run_with(true);
        let recovery = recovery.expect("no recovery");
        assert!(
            recovery.0 - unlocked.0 <= 0.6,
            "lock lost at {:.2} s, recovery at {:.2} s",
            unlocked.0,
            recovery.0
        );
        assert!(
            (recovery.3 - DOPPLER_HZ).abs() < 1.0,
            "recovery starts at {:.2} Hz, the aid is at {DOPPLER_HZ} Hz",
            recovery.3
        );
        let (unlocked, recovery) = run_with(false);
        if let Some(r) = recovery {
            assert!(
                r.0 - unlocked.0 >= 1.9,
                "unchecked: lock lost at {:.2} s, recovery at {:.2} s",
                unlocked.0,
                r.0
            );
        }
    }

    /// A vector aid's step (a filter update) reaches the NCO over about
    /// [`crate::channel::VECTOR_AID_BLEND_S`], not at once; an INS aid's at once.
    #[test]
    fn a_vector_aid_step_fades_in_and_an_ins_one_does_not() {
        let feedforward = |source: crate::aiding::AidSource| {
            let mut sig = Signal::steady(45.0, 9);
            let mut ch = Channel::new(&start(), FS, &ChannelConfig::default()).expect("channel");
            let mut out = Vec::new();
            loop {
                let (first, n) = ch.next_span();
                let t = first as f64 / FS;
                if t > 2.6 {
                    break;
                }
                // The aid steps by 0.5 Hz at 2 s (as at a filter update).
                let doppler_hz = DOPPLER_HZ + if t >= 2.0 { 0.5 } else { 0.0 };
                let aid = crate::aiding::DopplerAid {
                    doppler_hz,
                    doppler_rate_hz_s: 0.0,
                    coast: false,
                    checked: true,
                    source,
                };
                ch.set_aid(Some(aid), t);
                let x: Vec<Complex32> = (first..first + n as u64).map(|k| sig.sample(k)).collect();
                // The aid reaches the NCO from the interval after the one it came in.
                if let Some((e, f)) = ch
                    .process_code_period(&x)
                    .and_then(|e| Some((e.t_rx_s, e.feedforward_hz?)))
                {
                    out.push((e, f));
                }
            }
            let at = |t0: f64| out.iter().find(|e| e.0 >= t0).expect("report").1;
            (at(2.01), at(2.1), at(2.5))
        };
        let (first, t_01, t_05) = feedforward(crate::aiding::AidSource::Vector);
        assert!(
            (first - DOPPLER_HZ).abs() < 0.1,
            "vector, 10 ms after: {first}"
        );
        assert!(
            (t_01 - DOPPLER_HZ - 0.5 * (1.0 - (-1.0f64).exp())).abs() < 0.1,
            "vector, 0.1 s after: {t_01}"
        );
        assert!(
            (t_05 - DOPPLER_HZ - 0.5).abs() < 0.02,
            "vector, 0.5 s after: {t_05}"
        );
        let (first, _, _) = feedforward(crate::aiding::AidSource::Ins);
        assert!(
            (first - DOPPLER_HZ - 0.5).abs() < 1e-9,
            "INS, 10 ms after: {first}"
        );
    }
}
