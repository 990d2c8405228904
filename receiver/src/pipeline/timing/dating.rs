//! Which GPS week labels the receiver's times before a subframe 1 gives the broadcast week.
//!
//! The signal gives the time of week within seconds of frame sync (the HOW of every subframe),
//! but the week number only with subframe 1 (every 30 s), and then modulo 1024. Until then
//! the week comes from, in order: the configuration (`--week`, `[run] week`), the approximate
//! time (`--time`, `[run] approx_time`), the recording's
//! metadata (SigMF `core:datetime`), a navigation file (the week of its first ephemeris). With
//! none of these the week is *unknown*: the system clock still resolves the 10-bit broadcast
//! week (the 1024-week era nearest today: right for recordings under 9.8 years old), but it never
//! dates an output ([`WeekReference::known`] is false: `gps_week` is left empty, the NMEA date
//! too, and `observables.rnx` waits for the decoded week).

use crate::pipeline::navigation::navdata::current_gps_week;
use gpsrx_nav::rinex_nav::NavData;
use gpsrx_nav::time::GpsTime;
use gpsrx_samples::sigmf::RecordingStart;

/// Where the reference week comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum WeekSource {
    /// `--week` / `[run] week`.
    Configured,
    /// The approximate time `--time` / `[run] approx_time`.
    ApproximateTime,
    /// The recording's metadata (the text says which key of which file).
    Recording(String),
    /// The first ephemeris of the navigation file.
    NavFile,
    /// Nothing: today's week, from the system clock, used only to resolve the 10-bit week.
    Unknown,
}

/// The week that labels receiver time until subframe 1 is decoded, and where it comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct WeekReference {
    /// The full GPS week.
    pub week: u32,
    /// Its origin.
    pub source: WeekSource,
}

impl WeekReference {
    /// The reference from the configured week, the approximate time, the recording's start
    /// and the navigation file, in that order (see the module documentation).
    pub fn resolve(
        configured: Option<u32>,
        approx_time: Option<GpsTime>,
        recording: Option<&RecordingStart>,
        nav: Option<&NavData>,
    ) -> WeekReference {
        let nav_week = nav.and_then(|n| n.ephemerides.first()).map(|e| e.toe.week);
        if let (None, Some(t)) = (configured, approx_time) {
            return WeekReference {
                week: t.week,
                source: WeekSource::ApproximateTime,
            };
        }
        match (configured, recording, nav_week) {
            (Some(week), _, _) => WeekReference {
                week,
                source: WeekSource::Configured,
            },
            (None, Some(r), _) => WeekReference {
                week: r.time.week,
                source: WeekSource::Recording(r.origin.clone()),
            },
            (None, None, Some(week)) => WeekReference {
                week,
                source: WeekSource::NavFile,
            },
            (None, None, None) => WeekReference {
                week: current_gps_week(),
                source: WeekSource::Unknown,
            },
        }
    }

    /// Whether the week may date outputs (it does not come from the system clock).
    pub fn known(&self) -> bool {
        self.source != WeekSource::Unknown
    }

    /// Logs where the week comes from: INFO when known, a WARN saying what is left out when
    /// not; a WARN when `--week` disagrees with the recording's date.
    pub fn log(&self, recording: Option<&RecordingStart>) {
        match &self.source {
            WeekSource::Configured => {
                if let Some(r) = recording.filter(|r| r.time.week != self.week) {
                    tracing::warn!(
                        "the GPS week given, {}, overrides week {} of the recording ({})",
                        self.week,
                        r.time.week,
                        r.origin
                    );
                }
                tracing::info!("GPS week {} (as given) until subframe 1 is decoded", self.week);
            }
            WeekSource::ApproximateTime => tracing::info!(
                "GPS week {} (from the approximate time given) until subframe 1 is decoded",
                self.week
            ),
            WeekSource::Recording(origin) => tracing::info!(
                "GPS week {} from {origin} until subframe 1 is decoded",
                self.week
            ),
            WeekSource::NavFile => tracing::info!(
                "GPS week {} from the navigation file until subframe 1 is decoded",
                self.week
            ),
            WeekSource::Unknown => tracing::warn!(
                "the GPS week is unknown (no recording date, GPS week or navigation data was given): the outputs carry no week or date until a subframe 1 gives it (up to 30 s after frame sync), and observables.rnx is written only once it does; give the GPS week or navigation data to date them from the start"
            ),
        }
    }
}
