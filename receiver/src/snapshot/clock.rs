//! The device clock of a snapshot sequence: its error against GPS time, from the time
//! corrections of the sequence's own fixes.
//!
//! A snapshot receiver tags its snapshots with a real-time clock whose error (seconds at
//! most, drifting by a few ppm) is the same for neighbouring snapshots, while one 12 ms
//! snapshot determines its time only to tens of milliseconds (the coarse time is observable
//! only through the satellites' range rates; see [`gpsrx_nav::pvt::coarse_time`]). The
//! correction that fits a snapshot is therefore taken as the median of the corrections of the
//! `fix` rows whose tags lie within [`WINDOW_S`] of it (at least [`MIN_POINTS`]), with the
//! sigma `max(1.4826 MAD / sqrt(n), MIN_SIGMA_S)`; the snapshot is then solved again with that
//! time as an observation ([`gpsrx_nav::pvt::CoarseApriori::time_sigma_s`]). The median keeps
//! a few wrong fixes from moving it; a clock drift of 20 ppm moves it by 6 ms across the
//! window at most.

/// Half-width of the window of neighbouring fixes, s of tag time.
pub const WINDOW_S: f64 = 300.0;
/// Fixes needed in the window.
pub const MIN_POINTS: usize = 5;
/// Smallest sigma given to the clock estimate, s.
pub const MIN_SIGMA_S: f64 = 1e-3;

/// Time corrections of a sequence's fixes against their tags.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SequenceClock {
    /// (tag time relative to the first tag, s; correction, s).
    points: Vec<(f64, f64)>,
}

impl SequenceClock {
    /// Adds a fix tagged `tag_s` (any common origin) whose correction was `correction_s`.
    pub fn push(&mut self, tag_s: f64, correction_s: f64) {
        if tag_s.is_finite() && correction_s.is_finite() {
            self.points.push((tag_s, correction_s));
        }
    }

    /// The correction and its sigma at tag time `tag_s`, if enough fixes are near.
    pub fn at(&self, tag_s: f64) -> Option<(f64, f64)> {
        let mut v: Vec<f64> = self
            .points
            .iter()
            .filter(|(t, _)| (t - tag_s).abs() <= WINDOW_S)
            .map(|&(_, c)| c)
            .collect();
        if v.len() < MIN_POINTS {
            return None;
        }
        let med = median(&mut v);
        let mut dev: Vec<f64> = v.iter().map(|c| (c - med).abs()).collect();
        let mad = median(&mut dev);
        let sigma = (1.4826 * mad / (v.len() as f64).sqrt()).max(MIN_SIGMA_S);
        Some((med, sigma))
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_resists_outliers_and_needs_enough_points() {
        let mut c = SequenceClock::default();
        for k in 0..4 {
            c.push(f64::from(k), 0.15 + 0.01 * f64::from(k % 2));
        }
        assert_eq!(c.at(0.0), None);
        c.push(4.0, 3.0); // a wrong fix
        c.push(5.0, 0.15);
        let (m, s) = c.at(2.0).expect("six points");
        assert!((m - 0.15).abs() < 0.006, "{m}");
        assert!((MIN_SIGMA_S..0.01).contains(&s), "{s}");
        // Far away in time: nothing near.
        assert_eq!(c.at(1000.0), None);
    }
}
