//! GPS L1 C/A codes: Gold codes from the G1 and G2 shift registers (IS-GPS-200 section 3.3.2.3,
//! Table 3-Ia).
//!
//! `G1 = 1 + x^3 + x^10`, `G2 = 1 + x^2 + x^3 + x^6 + x^8 + x^9 + x^10`, both started from all
//! ones. The code of satellite `i` is `G1(t) xor G2(t - delay_i)`, with the G2 delays of
//! Table 3-Ia. Logic 0 is transmitted as +1 and logic 1 as -1.

use crate::constants::CA_CODE_LENGTH;
pub use gpsrx_core::prn::{Prn, PrnError};
use std::fmt;

/// G2 delays in chips for PRN 1..=32 (IS-GPS-200 Table 3-Ia, "Code Delay Chips" for C/A).
pub const G2_DELAY_CHIPS: [usize; 32] = [
    5, 6, 7, 8, 17, 18, 139, 140, 141, 251, 252, 254, 255, 256, 257, 258, 469, 470, 471, 472, 473,
    474, 509, 512, 513, 514, 515, 516, 859, 860, 861, 862,
];

/// One C/A code period as chips of +1/-1 (logic 0 -> +1, logic 1 -> -1).
#[derive(Clone, PartialEq, Eq)]
pub struct CaCode {
    prn: Prn,
    chips: [i8; CA_CODE_LENGTH],
}

impl fmt::Debug for CaCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "CaCode({}, first 10 chips octal {:04o})",
            self.prn,
            self.first_10_chips_octal()
        )
    }
}

/// Runs a 10-stage linear feedback shift register from all ones for one code period and returns
/// its output (stage 10) as bits. `taps` are the 1-based stages fed back (the polynomial's terms).
fn lfsr_sequence(taps: &[usize]) -> [u8; CA_CODE_LENGTH] {
    let mut reg = [1u8; 10];
    let mut out = [0u8; CA_CODE_LENGTH];
    for o in out.iter_mut() {
        *o = reg[9];
        let fb = taps.iter().fold(0u8, |acc, &t| acc ^ reg[t - 1]);
        reg.copy_within(0..9, 1);
        reg[0] = fb;
    }
    out
}

impl CaCode {
    /// Generates the C/A code of `prn` (IS-GPS-200 3.3.2.3).
    pub fn new(prn: Prn) -> Self {
        let g1 = lfsr_sequence(&[3, 10]);
        let g2 = lfsr_sequence(&[2, 3, 6, 8, 9, 10]);
        let delay = G2_DELAY_CHIPS[prn.index()];
        let mut chips = [0i8; CA_CODE_LENGTH];
        for (i, c) in chips.iter_mut().enumerate() {
            let bit = g1[i] ^ g2[(i + CA_CODE_LENGTH - delay) % CA_CODE_LENGTH];
            *c = 1 - 2 * bit as i8;
        }
        Self { prn, chips }
    }

    /// The PRN this code belongs to.
    pub fn prn(&self) -> Prn {
        self.prn
    }

    /// The 1023 chips as +1/-1.
    pub fn chips(&self) -> &[i8; CA_CODE_LENGTH] {
        &self.chips
    }

    /// Chip `i` modulo the code length.
    #[inline]
    pub fn chip(&self, i: usize) -> i8 {
        self.chips[i % CA_CODE_LENGTH]
    }

    /// The first 10 chips read as logic bits (1 for a -1 chip), as IS-GPS-200 Table 3-Ia prints
    /// them in octal: the first chip is the most significant bit.
    pub fn first_10_chips_octal(&self) -> u16 {
        self.chips[..10]
            .iter()
            .fold(0u16, |acc, &c| (acc << 1) | u16::from(c < 0))
    }

    /// Samples the code at `fs_hz` starting at code phase `code_phase_chips`, advancing
    /// `chip_rate_hz / fs_hz` chips per sample: `out[k] = c(floor(phase0 + k * rate / fs))`.
    pub fn sample(&self, fs_hz: f64, chip_rate_hz: f64, code_phase_chips: f64, out: &mut [i8]) {
        let step = chip_rate_hz / fs_hz;
        let n = CA_CODE_LENGTH as f64;
        for (k, o) in out.iter_mut().enumerate() {
            let phase = (code_phase_chips + k as f64 * step).rem_euclid(n);
            *o = self.chips[(phase as usize).min(CA_CODE_LENGTH - 1)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// First 10 chips of the C/A code in octal, IS-GPS-200 Table 3-Ia, PRN 1..=32.
    const TABLE_3_IA_FIRST_10_OCTAL: [u16; 32] = [
        0o1440, 0o1620, 0o1710, 0o1744, 0o1133, 0o1455, 0o1131, 0o1454, 0o1626, 0o1504, 0o1642,
        0o1750, 0o1764, 0o1772, 0o1775, 0o1776, 0o1156, 0o1467, 0o1633, 0o1715, 0o1746, 0o1763,
        0o1063, 0o1706, 0o1743, 0o1761, 0o1770, 0o1774, 0o1127, 0o1453, 0o1625, 0o1712,
    ];

    #[test]
    fn first_ten_chips_match_is_gps_200_table_3_ia_for_all_32_prns() {
        for prn in Prn::all() {
            let code = CaCode::new(prn);
            assert_eq!(
                code.first_10_chips_octal(),
                TABLE_3_IA_FIRST_10_OCTAL[prn.index()],
                "{prn}"
            );
        }
    }

    #[test]
    fn gold_code_correlation_is_three_valued() {
        // Gold codes of degree 10: cross- and off-peak autocorrelation take only the values
        // -1, -65, 63 (Gold 1967); the code is balanced (512 ones, 511 zeros -> sum -1).
        let codes: Vec<CaCode> = Prn::all().map(CaCode::new).collect();
        for a in &codes {
            let sum: i32 = a.chips().iter().map(|&c| i32::from(c)).sum();
            assert_eq!(sum, -1);
        }
        for (i, a) in codes.iter().enumerate().take(6) {
            for b in codes.iter().skip(i) {
                for lag in 0..CA_CODE_LENGTH {
                    if std::ptr::eq(a, b) && lag == 0 {
                        continue;
                    }
                    let r: i32 = (0..CA_CODE_LENGTH)
                        .map(|k| i32::from(a.chip(k)) * i32::from(b.chip(k + lag)))
                        .sum();
                    assert!(
                        r == -1 || r == -65 || r == 63,
                        "{} {} lag {lag}: {r}",
                        a.prn(),
                        b.prn()
                    );
                }
            }
        }
    }

    #[test]
    fn sampling_at_chip_rate_reproduces_chips() {
        let code = CaCode::new(Prn::new(3).unwrap_or_else(|e| panic!("{e}")));
        let mut out = vec![0i8; 2046];
        code.sample(1.023e6, 1.023e6, 0.0, &mut out);
        for (k, &c) in out.iter().enumerate() {
            assert_eq!(c, code.chip(k));
        }
    }
}
