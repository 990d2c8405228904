//! GPS domain basics for gpsrx: time, frames, broadcast ephemeris, RINEX navigation files,
//! atmospheric models, the EGM96 geoid and the LNAV (L1 C/A) navigation message.
//!
//! Every formula cites the IS-GPS-200 section or table it implements. Units are SI and are
//! carried in the names (`tow_s`, `clock_bias_s`, `delta_n_rad_s`).

pub mod almanac;
pub mod atmosphere;
pub mod constants;
pub mod ephemeris;
pub mod frames;
pub mod geoid;
pub mod lnav;
pub mod pvt;
pub mod rinex_nav;
pub mod time;
pub mod utc;

pub use almanac::{Almanac, AlmanacPrediction, AlmanacSet};
pub use atmosphere::{klobuchar_delay_s, saastamoinen_delay_m, KlobucharParams, UtcParams};
pub use ephemeris::{select_ephemeris, HealthPolicy, MAX_EPHEMERIS_AGE_S};
pub use ephemeris::{Ephemeris, SvState};
pub use frames::{
    azimuth_elevation, enu_rotation, light_time, rotate_for_earth_rotation, Llh, SvAtReception,
    Vector3,
};
pub use rinex_nav::{parse_rinex_nav, read_rinex_nav, NavData, RinexError};
pub use time::GpsTime;
