//! Synthetic C/A signals for benchmarks and examples: white noise plus satellites with a known
//! code delay and Doppler (the truth a search is timed against).

use crate::ca_code::{CaCode, Prn};
use num_complex::Complex32;

/// `n` complex baseband samples at `fs_hz`: unit-variance complex white noise (SplitMix64 from
/// `seed`, Box-Muller) plus, per `(prn, delay_samples, doppler_hz)`, that PRN's C/A code
/// delayed by `delay_samples` on a carrier at `doppler_hz`, at `cn0_dbhz` (amplitude
/// `sqrt(C/N0 / fs)` against the unit noise). Chips at 1.023 MHz (no code Doppler).
pub fn noisy_ca_signal(
    n: usize,
    fs_hz: f64,
    satellites: &[(u8, f64, f64)],
    cn0_dbhz: f64,
    seed: u64,
) -> Vec<Complex32> {
    let mut state = seed;
    let mut uniform = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (((z ^ (z >> 31)) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut x: Vec<Complex32> = (0..n)
        .map(|_| {
            let r = (-uniform().ln()).sqrt();
            let t = 2.0 * std::f64::consts::PI * uniform();
            Complex32::new((r * t.cos()) as f32, (r * t.sin()) as f32)
        })
        .collect();
    let amp = (10f64.powf(cn0_dbhz / 10.0) / fs_hz).sqrt();
    for &(prn, delay, doppler_hz) in satellites {
        let Ok(prn) = Prn::new(prn) else { continue };
        let code = CaCode::new(prn);
        for (k, v) in x.iter_mut().enumerate() {
            let chip = ((k as f64 - delay) * 1.023e6 / fs_hz).rem_euclid(1023.0) as usize;
            let ph = 2.0 * std::f64::consts::PI * doppler_hz * k as f64 / fs_hz;
            let a = amp * f64::from(code.chip(chip));
            *v += Complex32::new((a * ph.cos()) as f32, (a * ph.sin()) as f32);
        }
    }
    x
}
