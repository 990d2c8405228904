//! GPS system time as (full week number, time of week), IS-GPS-200 20.3.3.3.1.1 (week number)
//! and 20.3.3.2 (time of week). GPS time is continuous: it has no leap seconds and its epoch,
//! week 0 TOW 0, is 1980-01-06 00:00:00 (midnight between 5 and 6 January 1980, UTC at that time).

use crate::constants::{SECONDS_PER_DAY, SECONDS_PER_WEEK};

/// Days from 1970-01-01 to the GPS epoch 1980-01-06.
const GPS_EPOCH_DAYS_FROM_UNIX: i64 = 3657;

/// A GPS time: full week number (not modulo 1024) and seconds of week.
///
/// Values built with [`GpsTime::new`] always have `tow_s` in `[0, 604800)`, except before the
/// GPS epoch, where `week` saturates at 0 and `tow_s` is negative.
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, serde::Serialize, serde::Deserialize)]
pub struct GpsTime {
    /// Full GPS week number counted from 1980-01-06 (not modulo 1024).
    pub week: u32,
    /// Time of week, seconds since Saturday/Sunday midnight of `week`.
    pub tow_s: f64,
}

impl GpsTime {
    /// Builds a time, normalising `tow_s` into `[0, 604800)` by moving whole weeks into `week`.
    ///
    /// A non-finite `tow_s` is kept as is (the week is not touched). Times before the GPS
    /// epoch keep `week = 0` and a negative `tow_s`; weeks beyond `u32::MAX` saturate.
    pub fn new(week: u32, tow_s: f64) -> GpsTime {
        if !tow_s.is_finite() {
            return GpsTime { week, tow_s };
        }
        let mut weeks = (tow_s / SECONDS_PER_WEEK).floor();
        let mut tow = tow_s - weeks * SECONDS_PER_WEEK;
        if tow >= SECONDS_PER_WEEK {
            // Rounding of a tiny negative tow can land exactly on the week length.
            tow -= SECONDS_PER_WEEK;
            weeks += 1.0;
        }
        let full_week = f64::from(week) + weeks;
        if full_week < 0.0 {
            GpsTime {
                week: 0,
                tow_s: tow + full_week * SECONDS_PER_WEEK,
            }
        } else if full_week > f64::from(u32::MAX) {
            GpsTime {
                week: u32::MAX,
                tow_s: tow,
            }
        } else {
            GpsTime {
                // Exact: full_week is an integer-valued f64 within u32 range.
                week: full_week as u32,
                tow_s: tow,
            }
        }
    }

    /// This time plus `dt_s` seconds (negative to go back), renormalised.
    pub fn add_seconds(self, dt_s: f64) -> GpsTime {
        GpsTime::new(self.week, self.tow_s + dt_s)
    }

    /// `self - earlier` in seconds. Whole weeks are differenced as integers first, so the result
    /// keeps the sub-microsecond precision of the TOWs across week crossovers.
    pub fn diff_s(self, earlier: GpsTime) -> f64 {
        let dweek = i64::from(self.week) - i64::from(earlier.week);
        dweek as f64 * SECONDS_PER_WEEK + (self.tow_s - earlier.tow_s)
    }

    /// A difference of two times of week (s, e.g. a receive TOW minus a transmit TOW) whose
    /// week is not known, folded into +-half a week: across a week crossover `0.07 - 604799.93`
    /// is the 0.14 s it means.
    pub fn fold_tow_difference_s(d_s: f64) -> f64 {
        d_s - (d_s / SECONDS_PER_WEEK).round() * SECONDS_PER_WEEK
    }

    /// Converts a calendar date and time *in the GPS time scale* (no leap seconds applied) into
    /// week and TOW. Out-of-range fields roll over arithmetically (month 13 is January of the
    /// next year, day 0 is the last day of the previous month, hour 24 is the next day).
    pub fn from_calendar(
        year: i32,
        month: u32,
        day: u32,
        hour: u32,
        min: u32,
        sec: f64,
    ) -> GpsTime {
        // Normalise the month into 1..=12 so the civil-date formula applies.
        let m0 = i64::from(month) - 1;
        let y = i64::from(year) + m0.div_euclid(12);
        let m = m0.rem_euclid(12) + 1;
        let days = days_from_civil(y, m, 1) + i64::from(day) - 1 - GPS_EPOCH_DAYS_FROM_UNIX;
        let week = days.div_euclid(7);
        let dow = days.rem_euclid(7);
        let tow_s =
            dow as f64 * SECONDS_PER_DAY + f64::from(hour) * 3600.0 + f64::from(min) * 60.0 + sec;
        if week < 0 {
            GpsTime::new(0, tow_s + week as f64 * SECONDS_PER_WEEK)
        } else {
            GpsTime::new(u32::try_from(week).unwrap_or(u32::MAX), tow_s)
        }
    }

    /// Converts to a calendar date and time in the GPS time scale:
    /// `(year, month, day, hour, minute, second)`.
    pub fn to_calendar(self) -> (i32, u32, u32, u32, u32, f64) {
        let day_in_week = (self.tow_s / SECONDS_PER_DAY).floor();
        let sod = self.tow_s - day_in_week * SECONDS_PER_DAY;
        let days = i64::from(self.week) * 7 + day_in_week as i64 + GPS_EPOCH_DAYS_FROM_UNIX;
        let (y, m, d) = civil_from_days(days);
        let hour = (sod / 3600.0).floor();
        let min = ((sod - hour * 3600.0) / 60.0).floor();
        let sec = sod - hour * 3600.0 - min * 60.0;
        (
            i32::try_from(y).unwrap_or(i32::MAX),
            m as u32,
            d as u32,
            hour as u32,
            min as u32,
            sec,
        )
    }

    /// Resolves a week number transmitted modulo 1024 (IS-GPS-200 20.3.3.3.1.1, 10-bit WN) to
    /// the full week nearest to `reference_week` (e.g. a build date or the receiver's clock).
    /// Valid while the true week is within +-512 weeks of the reference. Never returns a
    /// negative week: near week 0 the smallest non-negative candidate is returned.
    pub fn resolve_week_10bit(week_mod_1024: u32, reference_week: u32) -> u32 {
        resolve_week_modulo(week_mod_1024, reference_week, 1024)
    }
}

/// Full week congruent to `week_mod` modulo `modulus` that is nearest to `reference_week`
/// (ties go to the later week). Used for the 10-bit WN and the 8-bit WN_t / WN_LSF of
/// IS-GPS-200 20.3.3.5.2.4.
pub fn resolve_week_modulo(week_mod: u32, reference_week: u32, modulus: u32) -> u32 {
    let modulus = i64::from(modulus.max(1));
    let reference = i64::from(reference_week);
    let w = i64::from(week_mod).rem_euclid(modulus);
    let base = reference - reference.rem_euclid(modulus) + w;
    let candidates = [base - modulus, base, base + modulus];
    let mut best = base;
    let mut best_dist = i64::MAX;
    for c in candidates {
        if c < 0 {
            continue;
        }
        let dist = (c - reference).abs();
        if dist < best_dist || (dist == best_dist && c > best) {
            best = c;
            best_dist = dist;
        }
    }
    u32::try_from(best).unwrap_or(u32::MAX)
}

/// Days since 1970-01-01 of a proleptic-Gregorian date (month 1..=12). Standard era-based
/// civil-calendar arithmetic (400-year cycles of 146097 days, years starting in March).
fn days_from_civil(year: i64, month: i64, day: i64) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400; // [0, 399]
    let mp = (month + 9) % 12; // March = 0
    let doy = (153 * mp + 2) / 5 + day - 1; // [0, 365]
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy; // [0, 146096]
    era * 146_097 + doe - 719_468
}

/// Inverse of [`days_from_civil`]: (year, month 1..=12, day 1..=31).
fn civil_from_days(days: i64) -> (i64, i64, i64) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn civil_days_known_values() {
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(1980, 1, 6), GPS_EPOCH_DAYS_FROM_UNIX);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
    }
}
