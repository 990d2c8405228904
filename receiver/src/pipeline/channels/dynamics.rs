//! Whether the receiver is under dynamics, from the carrier loops of its strong channels.
//!
//! A static receiver sees line-of-sight Doppler rates below about 1 Hz/s (the satellites' own
//! motion); a car 5-15 Hz/s (1-3 m/s^2); the onset of a 10 g turn 500 Hz/s within a
//! second. The 1 ms 3rd-order loops of the strong channels (18 Hz) follow such an onset within
//! tens of milliseconds, the weak channels' narrow loops (6 Hz, 20 ms) do not: they slip in the
//! first tenth of a second of the jerk. So the strong channels watch for the weak ones: when two
//! of them see more than [`ENTER_HZ_S`], every weak channel widens its loops
//! ([`gpsrx_tracking::dynamic_weak_config`]) at its next bit edge, until all have stayed below
//! [`LEAVE_HZ_S`] for [`CALM_S`].

/// Line-of-sight Doppler rate that puts the receiver under dynamics, Hz/s (1.5 m/s^2).
pub const ENTER_HZ_S: f64 = 8.0;
/// Rate below which the dynamics may end, Hz/s.
pub const LEAVE_HZ_S: f64 = 4.0;
/// How long every rate must stay below [`LEAVE_HZ_S`] before the dynamics end, s.
pub const CALM_S: f64 = 2.0;

/// The receiver's dynamics state, with hysteresis.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DynamicsWatch {
    on: bool,
    /// Stream time from which every rate has been below [`LEAVE_HZ_S`], s.
    calm_since_s: Option<f64>,
}

impl DynamicsWatch {
    /// Takes the line-of-sight Doppler rate (Hz/s, magnitude) the strong channels follow at
    /// stream time `t_s` (`None`: no strong channel to tell); returns whether the
    /// receiver is under dynamics. Without a strong channel the state holds.
    pub fn update(&mut self, t_s: f64, max_rate_hz_s: Option<f64>) -> bool {
        let Some(rate) = max_rate_hz_s.filter(|r| r.is_finite()) else {
            return self.on;
        };
        if rate > ENTER_HZ_S {
            if !self.on {
                tracing::debug!("{t_s:.2} s: a strong channel follows {rate:.0} Hz/s: the weak channels widen their loops for dynamics");
            }
            self.on = true;
            self.calm_since_s = None;
        } else if rate < LEAVE_HZ_S {
            let since = *self.calm_since_s.get_or_insert(t_s);
            if self.on && t_s - since >= CALM_S {
                tracing::debug!(
                    "{t_s:.2} s: dynamics over: the weak channels narrow their loops again"
                );
                self.on = false;
            }
        } else {
            self.calm_since_s = None;
        }
        self.on
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_onset_turns_it_on_at_once_and_only_a_calm_of_two_seconds_off() {
        let mut w = DynamicsWatch::default();
        // Static: satellites' own rates (< 1 Hz/s), a car pulling away (7 Hz/s).
        assert!(!w.update(0.0, Some(0.8)));
        assert!(!w.update(0.1, Some(7.0)));
        // The onset of a turn.
        assert!(w.update(0.2, Some(25.0)));
        // Between the thresholds, and no strong channel: it holds.
        assert!(w.update(1.0, Some(6.0)));
        assert!(w.update(1.1, None));
        // Calm from 2.0 s: still on at 3.9 s, off at 4.0 s.
        assert!(w.update(2.0, Some(3.0)));
        assert!(w.update(3.9, Some(3.0)));
        assert!(!w.update(4.0, Some(3.0)));
        // A rate between the thresholds restarts the calm.
        assert!(w.update(5.0, Some(30.0)));
        assert!(w.update(5.5, Some(3.0)));
        assert!(w.update(6.0, Some(6.0)));
        assert!(w.update(7.6, Some(3.0)));
        assert!(!w.update(9.6, Some(3.0)));
        // A non-finite rate is no information.
        assert!(!w.update(10.0, Some(f64::NAN)));
    }
}
