//! Helpers of the pipeline's unit tests.

use gpsrx_tracking::{ChannelEpoch, ChannelState};
use num_complex::Complex64;

/// A 1 ms report in tracking and phase lock at 2.048 MHz: code period `k` of PRN `prn`, its
/// `prompt`, an NCO at `doppler_hz` whose accumulated phase is `carrier_cycles`, C/N0
/// `cn0_dbhz`.
pub fn report(
    prn: u8,
    k: u64,
    prompt: Complex64,
    doppler_hz: f64,
    carrier_cycles: f64,
    cn0_dbhz: f64,
) -> ChannelEpoch {
    let t = k as f64 * 1e-3;
    ChannelEpoch {
        prn,
        state: ChannelState::Track,
        sample_index: k * 2048,
        t_rx_s: t,
        code_phase_chips: 0.0,
        code_rate_chips_s: 1.023e6,
        carrier_phase_cycles: carrier_cycles,
        doppler_hz,
        cn0_dbhz,
        cn0_lost_dbhz: 25.0,
        pll_lock: true,
        pll_lock_metric: 0.9,
        code_lock: true,
        prompt,
        early: prompt,
        late: prompt,
        phase_error_cycles: 0.0,
        freq_error_hz: 0.0,
        code_error_chips: 0.0,
        t_coh_s: 1e-3,
        feedforward_hz: None,
        coasting: false,
        ms_count: k,
        bit_edge: false,
        bit: None,
        bit_start_ms: None,
    }
}

/// Deterministic uniform numbers (xorshift) and standard normals (Box-Muller), for tests that
/// need noise without a dependency on the random-number crates' streams.
pub struct Noise(pub u64);

impl Noise {
    /// Uniform in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        (-2.0 * self.uniform().ln()).sqrt() * (std::f64::consts::TAU * self.uniform()).cos()
    }
}
