//! The experiment's fixed parameters: timing, trajectory, oscillator, INS and loop bandwidths.

/// GPS time of week of the first sample (week 2190, 2022-01-01 14:00 GPS time: 12 satellites
/// above 5 deg at Seoul, 10 of them healthy; G22 and G28 are flagged unhealthy), s.
pub const START_TOW_S: f64 = 568_800.0;
/// Sampling rate of the simulated IF (complex baseband), Hz.
pub const FS_HZ: f64 = 2.048e6;
/// Vehicle speed before the manoeuvre, m/s (an aircraft: a 10 g turn at 200 m/s turns at
/// `a / v` = 0.49 rad/s, so the line-of-sight jerk is `a^2 / v` = 48 m/s^3).
pub const SPEED_MPS: f64 = 200.0;
/// Cruise before the manoeuvre, s.
pub const LEAD_IN_S: f64 = 4.0;
/// Acceleration ramp in and out of the manoeuvre (bounded jerk), s.
pub const RAMP_S: f64 = 1.0;
/// Length of a turn segment (ramp-in included), s.
pub const TURN_S: f64 = 8.0;
/// Length of an acceleration-step segment (ramp-in included), s.
pub const STEP_S: f64 = 4.0;
/// Recording length, s.
pub const DURATION_S: f64 = 15.0;
/// Allan deviation of the receiver oscillator at 1 s (white FM): a quiet OCXO-class
/// oscillator. `oracles.md`: the oscillator jitter of a 2nd-order loop is about
/// `144 sigma_A f_L1 / Bn` = 1.1 deg at 2 Hz, comparable to the thermal jitter.
pub const ALLAN_DEVIATION_1S: f64 = 1.0e-11;
/// Nominal receiver clock drift, s/s (shifts every Doppler by `-f_L1 d` = -47 Hz).
pub const CLOCK_DRIFT_S_S: f64 = 3.0e-8;
/// Accelerometer bias magnitude of INS 1, m/s^2 (about 5 mg; INS 2 has twice it). INS 2's
/// 2nd-order steady-state error `360 B_V / (lambda omega0^2)` is up to 5.9 deg at 3 Hz and 13
/// deg at 2 Hz (the narrowest Bn): clearly visible in the mean, not lock-breaking.
pub const INS1_BIAS_MPS2: f64 = 0.05;
/// INS output rate, Hz.
pub const INS_RATE_HZ: f64 = 100.0;
/// Sampling interval of the satellites-tracked count, s.
pub const TICK_S: f64 = 0.1;
/// Bandwidth of the 2nd-order loop of the headline comparison, Hz. Seed 004 used 0.4 Hz, which
/// cannot follow the satellites' own line-of-sight acceleration (up to about 0.18 m/s^2)
/// unaided: the steady-state error `0.2809 a / Bn^2` is 1.7 cycles at 0.4 Hz, 23 deg at 2 Hz
/// (at the lock indicator's 22.8 deg threshold) and 10 deg at 3 Hz, the narrowest unaided loop
/// that holds every satellite before the manoeuvre.
pub const HEADLINE_BN_HZ: f64 = 3.0;
/// Bandwidth of the aided 1st-order loops, Hz: wide enough that INS 2's growing error
/// `theta_1(t)` stays inside the Costas discriminator's linear range to the end of the run.
pub const ORDER1_BN_HZ: f64 = 18.0;
