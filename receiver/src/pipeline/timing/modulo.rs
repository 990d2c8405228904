//! Remainders of a measurement modulo a period, shared by the gap detectors and the gap's
//! length (a phase modulo half a cycle, a time modulo a data bit, a code shift modulo a code
//! period).

/// `x` less the nearest multiple of `period`: in [-period/2, period/2] (a phase modulo half a
/// cycle with `period = pi`, a time within a data bit with `period = 20` ms).
pub fn nearest_remainder(x: f64, period: f64) -> f64 {
    x - (x / period).round() * period
}
