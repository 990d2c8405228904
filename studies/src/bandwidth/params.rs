//! The study's fixed parameters: recordings, DLL, observable intervals and the checks' limits.

/// Sampling rate of the study recordings, Hz (complex; 2500 samples per code period, not a
/// multiple of the chip rate).
pub const FS_HZ: f64 = 2.5e6;
/// The satellites of every recording (all at the recording's C/N0): Dopplers +3672, -3183 and
/// +1975 Hz at the start, so that the code drifts across the sample grid at 1.3-2.4 chip/s (a
/// satellite near zero Doppler, e.g. G31 at +201 Hz, drifts at 0.13 chip/s and its code error
/// then carries the slowly varying sample-grid bias of the unfiltered correlation triangle).
pub const PRNS: [u8; 3] = [16, 25, 26];
/// DLL: order 1 (carrier-aided), this noise bandwidth, Hz.
pub const DLL_BN_HZ: f64 = 1.0;
/// Early-late spacing, chips.
pub const EL_SPACING_CHIPS: f64 = 1.0;
/// Observable interval of the receiver's Doppler (`gpsrx run` at 10 Hz), s.
pub const OBS_INTERVAL_S: f64 = 0.1;
/// The longer Doppler averaging interval also reported, s.
pub const LONG_INTERVAL_S: f64 = 1.0;
/// The thermal-noise tolerance the study checks, relative.
pub const TOLERANCE: f64 = 0.2;
/// `Bn T` up to which the formula is expected to hold within [`TOLERANCE`].
pub const BNT_LIMIT: f64 = 0.1;
/// Tracking threshold rule of thumb (oracles.md): `3 sigma <= 45` deg, so `sigma <= 15` deg.
pub const THRESHOLD_SIGMA_DEG: f64 = 15.0;
