//! The study's fixed parameters: the lock criterion, the run lengths, the C/N0 scan and the
//! rule of thumb.

/// Length of the window over which lock is counted, s (the "30 s").
pub const WINDOW_S: f64 = 30.0;
/// Run before the window, s: the loop starts in its steady state, but the receiver's lock
/// detector needs at least 10 tests of 20 ms (0.2 s) to declare lock and its low-pass
/// (alpha 0.1 per test) about as long to settle.
pub const PRE_ROLL_S: f64 = 1.0;
/// Fraction of the window's 1 ms epochs in which carrier lock must be reported for the C/N0 to
/// count as held.
pub const HOLD_FRACTION: f64 = 0.95;
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
/// Where the data-bit edges fall inside the lock detector's 20-prompt coherent blocks, ms.
///
/// A channel's lock detector sums 20 consecutive 1 ms prompts counted from the channel's first
/// code period, not from a bit edge, so a data-bit transition can fall inside a block and
/// cancel part of its sum. With the edge `m` ms into the block, the block's expected signal
/// power is `g = 1/2 + (1/2)(1 - m/10)^2` of an aligned one (a transition in half of the
/// blocks); over a uniformly random `m` the mean is 0.668. The study uses `m = 5` (g = 0.625,
/// -2.0 dB), a typical start.
pub const BIT_EDGE_IN_LOCK_BLOCK_MS: u32 = 5;
/// Prompts per lock-detector block (the receiver's `PllLockConfig::default().coherent_sum`).
pub const LOCK_BLOCK_PROMPTS: u32 = 20;
/// L1 carrier frequency, Hz.
pub const F_L1_HZ: f64 = 1575.42e6;
