//! The study's fixed parameters: the lock criterion, the run lengths, the C/N0 scan and the
//! rule of thumb.

/// Length of the window over which lock is counted, s (the "30 s").
pub const WINDOW_S: f64 = 30.0;
/// Run before the window, s: the loop starts in its steady state, but the receiver's lock
/// detector needs at least 10 tests of 20 ms (0.2 s) to declare lock and, at weak signals, its
/// low-pass a running mean of up to 500 tests (`1/min_alpha`, 10 s): lock is declared once
/// that mean is precise enough, within a few seconds down to about 15 dB-Hz.
pub const PRE_ROLL_S: f64 = 10.0;
/// Fraction of the window's 1 ms epochs in which carrier lock must be reported for the C/N0 to
/// count as held.
pub const HOLD_FRACTION: f64 = 0.95;
/// Runs (noise seeds) per C/N0 of the scan: their held shares are pooled, so that one lucky or
/// unlucky run does not move a threshold.
pub const RUNS_PER_STEP: usize = 3;
/// Rule of thumb (Kaplan & Hegarty 2nd ed. sec. 5.6, oracles.md): `3 sigma + theta_e <= 45` deg
/// for a Costas PLL, i.e. `sigma + theta_e/3 <= 15` deg.
pub const RULE_LIMIT_DEG: f64 = 45.0;
/// Highest C/N0 of the measured scan, dB-Hz: a cell that loses lock here has no threshold.
pub const SCAN_TOP_DBHZ: f64 = 50.0;
/// Lowest C/N0 of the measured scan, dB-Hz.
pub const SCAN_BOTTOM_DBHZ: f64 = 5.0;
/// Step of the measured scan, dB.
pub const SCAN_STEP_DB: f64 = 0.5;
/// How far a measured threshold may lie from the theoretical one and still agree, dB.
pub const AGREE_DB: f64 = 3.0;
/// L1 carrier frequency, Hz.
pub const F_L1_HZ: f64 = 1575.42e6;
