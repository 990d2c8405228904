//! The state of a land vehicle as its own sensors see it (seed 000 eqs. 1-3, seed 002): the
//! truth that dead-reckoning and accelerometer models take, produced by the simulator's motion
//! tables and by the receiver from any ECEF trajectory.

/// A land vehicle at one instant, in the local level (east, north, up) frame of a start point.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VehicleState {
    /// Seconds from the start (the first IF sample).
    pub t_s: f64,
    /// East of the start point in its local level frame, m.
    pub east_m: f64,
    /// North, m.
    pub north_m: f64,
    /// Up, m.
    pub up_m: f64,
    /// Speed along the path (what an odometer measures, slopes included), m/s, `>= 0`.
    pub speed_mps: f64,
    /// Heading, rad clockwise from north (any branch; the simulator's motion tables give
    /// `(-pi, pi]`).
    pub heading_rad: f64,
    /// Yaw rate (heading rate), rad/s, positive turning right (clockwise).
    pub yaw_rate_rad_s: f64,
    /// Longitudinal acceleration (rate of change of `speed_mps`), m/s^2.
    pub a_long_mps2: f64,
    /// Road slope `atan(grade)`, rad, positive nose up.
    pub pitch_rad: f64,
}
