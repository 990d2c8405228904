//! The first fixes after an outage: after a common collapse of the prompt power, the
//! satellites' lock detectors declare lock again one by one over a few tenths of a second,
//! so the first epochs back hold whichever four came first: a fix with no redundancy (RAIM
//! cannot check it) from a geometry that lasts a tenth of a second (PDOP 15.6 on the
//! simulator's 4.3 g climb after 1 s of zeros, 13 m off, where the next epoch had 7
//! satellites and 1.7 m). Such a fix is not handed out as valid until one RAIM can check
//! has been made (more than [`ONSET_S`] after the collapse), or four-satellite fixes have
//! come in a row for [`SETTLE_S`] (the sky may hold only four).

/// How long four-satellite fixes in a row after an outage make them valid again, s.
pub const SETTLE_S: f64 = 0.5;
/// A checked fix this soon after the collapse ends no wait: its epoch may still hold the
/// signal from before it (the collapse is dated at its median onset), s.
pub const ONSET_S: f64 = 0.2;

/// The state after the last outage (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OutageSettle {
    /// Stream time of the collapse, s, while no checked fix has come since.
    collapse_s: Option<f64>,
    /// First and latest stream time of the current run of unchecked fixes, s.
    run: Option<(f64, f64)>,
}

impl OutageSettle {
    /// The prompt power of the tracked satellites collapsed at stream time `t_s`.
    pub fn collapse(&mut self, t_s: f64) {
        *self = Self {
            collapse_s: Some(t_s),
            run: None,
        };
    }

    /// Whether an otherwise valid fix at stream time `t_s` may be valid: `checked` when RAIM
    /// could test it (redundancy); epochs `epoch_s` apart (a longer pause restarts the run).
    pub fn admit(&mut self, t_s: f64, checked: bool, epoch_s: f64) -> bool {
        let Some(collapse_s) = self.collapse_s else {
            return true;
        };
        if t_s < collapse_s {
            return true;
        }
        if checked {
            if t_s > collapse_s + ONSET_S {
                *self = Self::default();
            }
            return true;
        }
        let from_s = match self.run {
            Some((from_s, last_s)) if t_s - last_s <= 1.5 * epoch_s => from_s,
            _ => t_s,
        };
        self.run = Some((from_s, t_s));
        if t_s - from_s >= SETTLE_S - 1e-9 {
            *self = Self::default();
            return true;
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn after_a_collapse_four_satellites_wait_for_a_checked_fix_or_half_a_second() {
        let mut s = OutageSettle::default();
        assert!(s.admit(10.0, false, 0.1), "no outage: as before");
        s.collapse(48.0);
        assert!(s.admit(47.9, false, 0.1), "an epoch before the collapse");
        assert!(s.admit(48.02, true, 0.1), "the signal from before it");
        assert!(!s.admit(48.1, false, 0.1), "four just after it");
        // The return: four satellites, then seven.
        assert!(!s.admit(49.3, false, 0.1));
        assert!(s.admit(49.4, true, 0.1), "a checked fix");
        assert!(s.admit(49.5, false, 0.1), "settled: four are valid again");
        // Another outage where only four come back: valid after 0.5 s of them in a row.
        s.collapse(60.0);
        let admitted: Vec<bool> = (0..8)
            .map(|i| s.admit(61.0 + 0.1 * i as f64, false, 0.1))
            .collect();
        assert_eq!(
            admitted,
            [false, false, false, false, false, true, true, true]
        );
        // A pause restarts the run.
        s.collapse(70.0);
        assert!(!s.admit(70.1, false, 0.1));
        assert!(!s.admit(70.2, false, 0.1));
        assert!(!s.admit(71.0, false, 0.1), "after a pause");
        for t in [71.1, 71.2, 71.3, 71.4] {
            assert!(!s.admit(t, false, 0.1), "{t}");
        }
        assert!(s.admit(71.5, false, 0.1), "0.5 s from the restart");
    }
}
