//! Moving a channel onto a signal whose code jumped.
//!
//! When the front end loses a number of samples that is not a whole number of C/A code
//! periods, the code of every satellite jumps by the same fraction of a period: each channel's
//! prompt collapses to noise while the carrier frequency it held is still right. A search at
//! that frequency finds the new code start at once; [`Channel::realign_code`] puts the replica
//! there instead of waiting a second for the loss and pulling in a new channel from scratch.

use super::Channel;
use crate::carrier_loop::CarrierLoop;
use crate::code_loop::CodeLoop;
use gpsrx_dsp::constants::{CA_CHIP_RATE_HZ, CA_CODE_LENGTH, F_L1_HZ};
use num_complex::Complex64;

/// A code realignment of a channel: what moved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CodeShift {
    /// The replica moved forward by this many samples, in `[0, period)`.
    pub shift_samples: f64,
    /// Samples per code period at the channel's code rate.
    pub period_samples: f64,
}

impl Channel {
    /// The shift (samples, in `[0, period)`) that would move the channel's code onto a signal
    /// whose C/A code period starts at the (fractional) sample index `code_start_sample`, and
    /// the period in samples.
    pub fn code_shift_to(&self, code_start_sample: f64) -> CodeShift {
        let period = CA_CODE_LENGTH as f64 * self.fs_hz / self.code_rate_chips_s;
        // Where the replica's current code period started (code phase 0).
        let own_start =
            self.next_sample as f64 - self.code_phase_chips * self.fs_hz / self.code_rate_chips_s;
        CodeShift {
            shift_samples: (code_start_sample - own_start).rem_euclid(period),
            period_samples: period,
        }
    }

    /// Moves the replica forward onto a signal whose code period starts at
    /// `code_start_sample` ([`Channel::code_shift_to`]). With `carrier = (doppler_hz,
    /// doppler_rate_hz_s, cn0_dbhz)`, the values the channel held before its prompt collapsed
    /// (the loops and the C/N0 estimate have since been fed noise), the carrier loop restarts
    /// at that Doppler (and rate, for an unaided 3rd-order loop) and the C/N0 estimate from
    /// that value; without, the loops go on (the channel kept its signal: its code moved by
    /// less than a chip). Loops integrating longer than 1 ms (the weak-signal ones) are
    /// replaced by the 1 ms ones at the Doppler they hold: longer integrations are aligned to
    /// bit edges that are no longer known (the channel switches back at a bit edge once the
    /// bits are found again, if its C/N0 is still low).
    ///
    /// The accumulated carrier phase stays a continuous function of the sample index (the NCO
    /// runs on over the skipped samples), so the carrier-phase step of the signal over the
    /// jump can be measured afterwards. The bit synchroniser starts again (the bit edges moved
    /// with the code); the lock detectors and `ms_count` carry on.
    ///
    /// Only a channel in tracking is moved; returns `None` otherwise or for a non-finite
    /// input.
    pub fn realign_code(
        &mut self,
        code_start_sample: f64,
        carrier: Option<(f64, f64, f64)>,
    ) -> Option<CodeShift> {
        if self.state != super::ChannelState::Track
            || !code_start_sample.is_finite()
            || carrier.is_some_and(|(f, _, c)| !f.is_finite() || !c.is_finite())
        {
            return None;
        }
        let ff = self.ff_applied_hz.unwrap_or(0.0);
        match carrier {
            Some((doppler_hz, rate_hz_s, cn0_dbhz)) => {
                self.restart_carrier(doppler_hz, rate_hz_s)?;
                self.cn0_dbhz = cn0_dbhz;
            }
            None if (self.carrier.t_coh_s() * 1e3).round() as usize != 1 => {
                let f = self.carrier.frequency_memory_hz() + ff;
                let rate = self.carrier.filter().rate_memory().unwrap_or(0.0);
                self.restart_carrier(f, rate)?;
            }
            None => {}
        }
        let shift = self.code_shift_to(code_start_sample);
        let rate = self.code_rate_chips_s / self.fs_hz;
        let new_start =
            self.next_sample as f64 - self.code_phase_chips / rate + shift.shift_samples;
        let next = new_start.ceil().max(0.0);
        self.carrier_phase_cycles +=
            self.carrier_freq_hz * (next - self.next_sample as f64) / self.fs_hz;
        self.next_sample = next as u64;
        self.code_phase_chips = (next - new_start) * rate;
        self.acc = [Complex64::new(0.0, 0.0); 3];
        self.acc_ms = 0;
        self.phase_fit.reset();
        self.low_cn0_count = 0;
        self.bit_sync.reset();
        self.bit_sync_origin_ms = self.ms_count;
        self.pending_bit = None;
        Some(shift)
    }

    /// The 1 ms loops again (the aided ones while aided, else the normal ones), the carrier
    /// loop at `doppler_hz` (and `rate_hz_s`), the C/N0 estimator restarted; `None` (nothing
    /// changed) when the configured loops do not integrate 1 ms.
    pub(super) fn restart_carrier(&mut self, doppler_hz: f64, rate_hz_s: f64) -> Option<()> {
        let was_weak = self.weak;
        self.weak = false;
        let which = self.wanted_loops();
        self.weak = was_weak;
        let loops = self.loop_config(which);
        if (loops.t_coh_s * 1e3).round() as usize != 1 {
            return None;
        }
        let ff = self.ff_applied_hz.unwrap_or(0.0);
        let mut carrier = CarrierLoop::new(&loops, doppler_hz - ff).ok()?;
        if self.ff_applied_hz.is_none() && rate_hz_s.is_finite() {
            carrier.preset_doppler_rate(rate_hz_s);
        }
        let code_loop = CodeLoop::new(&loops).ok()?;
        self.carrier = carrier;
        self.carrier_freq_hz = doppler_hz;
        self.code_rate_chips_s = CA_CHIP_RATE_HZ * (1.0 + doppler_hz / F_L1_HZ);
        if self.loops != which {
            self.code_loop = code_loop;
            let d = loops.el_spacing_chips;
            self.taps = [d / 2.0, 0.0, -d / 2.0];
            self.loops = which;
        }
        self.weak = false;
        // A narrowing under way aims at the loops left behind (the weak ones, switched to a
        // moment before on a C/N0 the moved bits had already lowered): it ends here, or it
        // would narrow the 1 ms loops to the weak-signal ones at the first new bit edge.
        self.narrowing = None;
        self.cn0.reset();
        self.cn0_started = false;
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::channel::{ChannelConfig, ChannelStart, ChannelState};
    use gpsrx_dsp::ca_code::{CaCode, Prn};
    use num_complex::Complex32;

    const FS: f64 = 2.048e6;
    const DOPPLER_HZ: f64 = 1234.5;

    /// A noise-free signal: C/A code of PRN 7 with its code Doppler, 50 bit/s data
    /// (alternating in pairs so bit edges are found), carrier at `DOPPLER_HZ`; the sample at
    /// index `k` carries the signal of time `k / fs + lost_s` from `gap_at` on.
    struct Signal {
        code: CaCode,
        gap_at: u64,
        lost_s: f64,
    }

    impl Signal {
        fn sample(&self, k: u64) -> Complex32 {
            let t = k as f64 / FS + if k >= self.gap_at { self.lost_s } else { 0.0 };
            let chips = t * CA_CHIP_RATE_HZ * (1.0 + DOPPLER_HZ / F_L1_HZ);
            let chip = f64::from(self.code.chip(chips.floor() as usize % 1023));
            let bit = if (t / 0.02).floor() as u64 % 4 < 2 {
                1.0
            } else {
                -1.0
            };
            let phase = std::f64::consts::TAU * DOPPLER_HZ * t;
            let v = num_complex::Complex64::from_polar(chip * bit, phase);
            Complex32::new(v.re as f32, v.im as f32)
        }
    }

    /// Runs `ch` over the signal up to sample `end`; returns the last report's prompt power
    /// relative to a perfectly aligned 1 ms prompt.
    fn run(ch: &mut Channel, sig: &Signal, end: u64) -> f64 {
        let mut power = 0.0;
        loop {
            let (start, n) = ch.next_span();
            if start + n as u64 > end || ch.state() == ChannelState::Lost {
                return power;
            }
            let x: Vec<Complex32> = (start..start + n as u64).map(|k| sig.sample(k)).collect();
            if let Some(e) = ch.process_code_period(&x) {
                power = e.prompt.norm() / (FS * 1e-3);
            }
        }
    }

    #[test]
    fn a_channel_moved_onto_a_code_that_jumped_tracks_it_at_once() {
        // 1.25 ms lost at 0.8 s: the code moves by a quarter of a period.
        let gap_at = (0.8 * FS) as u64;
        let sig = Signal {
            code: CaCode::new(Prn::new(7).expect("PRN")),
            gap_at,
            lost_s: 1.25e-3,
        };
        let start = ChannelStart {
            prn: Prn::new(7).expect("PRN"),
            code_start_sample: 0,
            doppler_hz: DOPPLER_HZ + 3.0,
            cn0_dbhz: 45.0,
        };
        let mut ch = Channel::new(&start, FS, &ChannelConfig::default()).expect("channel");
        assert!(run(&mut ch, &sig, gap_at) > 0.9, "tracking before the gap");
        assert_eq!(ch.state(), ChannelState::Track);
        let phase_before =
            ch.carrier_phase_cycles - ch.next_sample as f64 / FS * ch.carrier_freq_hz;
        // The prompt collapses after the gap.
        assert!(
            run(&mut ch, &sig, gap_at + (0.02 * FS) as u64) < 0.2,
            "collapsed"
        );
        // The signal's code periods now start where time 1.25 ms later started: a code
        // start of the signal after the gap is at sample k with k / fs + 1.25 ms a whole
        // number of (Doppler-shifted) periods.
        let period_s = 1e-3 / (1.0 + DOPPLER_HZ / F_L1_HZ);
        let t_after = (gap_at as f64 / FS + 1.25e-3) / period_s;
        let k_start = (t_after.ceil() * period_s - 1.25e-3) * FS;
        let shift = ch
            .realign_code(k_start, Some((DOPPLER_HZ, 0.0, 45.0)))
            .expect("moved");
        // A quarter of a period back is three quarters forward (modulo one period).
        let want = 0.75 * shift.period_samples;
        let moved = (shift.shift_samples - want).abs();
        assert!(
            moved < 1.0,
            "shift {} samples, want {want}",
            shift.shift_samples
        );
        // The NCO phase is a continuous function of the sample index over the move.
        let phase_after = ch.carrier_phase_cycles - ch.next_sample as f64 / FS * ch.carrier_freq_hz;
        assert!(
            (phase_after - phase_before).abs() < 0.05,
            "{phase_before} {phase_after}"
        );
        // 50 ms later the prompt has its full power again.
        let p = run(&mut ch, &sig, gap_at + (0.07 * FS) as u64);
        assert!(p > 0.9, "prompt power {p} after the move");
        assert_eq!(ch.state(), ChannelState::Track);
    }
}
