//! LNAV word parity: the (32,26) extended Hamming code of IS-GPS-200 20.3.5.2, Table 20-XIV.
//!
//! A transmitted 30-bit word is D1..D30 (D1 first on air, stored here as bit 29 of a `u32`).
//! The 24 source data bits d1..d24 are sent as D_i = d_i XOR D30* (the last bit of the
//! previous word), and D25..D30 are parity bits computed from the *source* bits and the
//! previous word's D29*, D30*.

/// Source-bit indices (1-based, d1..d24) entering each parity bit D25..D30 (Table 20-XIV).
const PARITY_TERMS: [&[u8]; 6] = [
    &[1, 2, 3, 5, 6, 10, 11, 12, 13, 14, 17, 18, 20, 23],
    &[2, 3, 4, 6, 7, 11, 12, 13, 14, 15, 18, 19, 21, 24],
    &[1, 3, 4, 5, 7, 8, 12, 13, 14, 15, 16, 19, 20, 22],
    &[2, 4, 5, 6, 8, 9, 13, 14, 15, 16, 17, 20, 21, 23],
    &[1, 3, 5, 6, 7, 9, 10, 14, 15, 16, 17, 18, 21, 22, 24],
    &[3, 5, 6, 8, 9, 10, 11, 13, 15, 19, 22, 23, 24],
];

/// Whether parity bit D25+k starts from D29* (true) or D30* (false) (Table 20-XIV).
const USES_D29: [bool; 6] = [true, false, true, false, false, true];

/// 24-bit masks (d1 = bit 23) built from [`PARITY_TERMS`] at compile time.
const PARITY_MASKS: [u32; 6] = {
    let mut masks = [0u32; 6];
    let mut k = 0;
    while k < 6 {
        let terms = PARITY_TERMS[k];
        let mut j = 0;
        while j < terms.len() {
            masks[k] |= 1 << (24 - terms[j] as u32);
            j += 1;
        }
        k += 1;
    }
    masks
};

/// The six parity bits D25..D30 (D25 in bit 5) of 24 source data bits.
pub fn parity_bits(data24: u32, d29_prev: bool, d30_prev: bool) -> u32 {
    let data = data24 & 0x00FF_FFFF;
    let mut parity = 0;
    for k in 0..6 {
        let seed = if USES_D29[k] { d29_prev } else { d30_prev };
        let bit = ((data & PARITY_MASKS[k]).count_ones() & 1) ^ u32::from(seed);
        parity |= bit << (5 - k);
    }
    parity
}

/// Encodes 24 source data bits into the transmitted 30-bit word (D1 in bit 29): data
/// complemented when `d30_prev` (D30*) is 1, followed by the Table 20-XIV parity.
pub fn parity_encode(data24: u32, d29_prev: bool, d30_prev: bool) -> u32 {
    let data = data24 & 0x00FF_FFFF;
    let sent = if d30_prev { data ^ 0x00FF_FFFF } else { data };
    (sent << 6) | parity_bits(data, d29_prev, d30_prev)
}

/// Checks a received 30-bit word (D1 in bit 29) given the previous word's D29*, D30*.
/// Returns the 24 source data bits (complement undone), or `None` if the parity fails.
pub fn parity_check(word30: u32, d29_prev: bool, d30_prev: bool) -> Option<u32> {
    let word = word30 & 0x3FFF_FFFF;
    let sent = word >> 6;
    let data = if d30_prev { sent ^ 0x00FF_FFFF } else { sent };
    (parity_bits(data, d29_prev, d30_prev) == (word & 0x3F)).then_some(data)
}

/// D29 and D30 (the last two bits) of a transmitted word.
pub fn last_two_bits(word30: u32) -> (bool, bool) {
    (word30 & 0b10 != 0, word30 & 0b1 != 0)
}

/// Chooses the two non-information bits d23, d24 of a word (HOW and word 10, IS-GPS-200
/// 20.3.5.2) so that the transmitted D29 = D30 = 0. Always possible: d24 enters D29 and D30,
/// d23 only D30.
pub fn solve_trailing_bits(data24: u32, d29_prev: bool, d30_prev: bool) -> u32 {
    let base = data24 & 0x00FF_FFFC;
    for t in 0..4 {
        let candidate = base | t;
        if parity_bits(candidate, d29_prev, d30_prev) & 0b11 == 0 {
            return candidate;
        }
    }
    base // unreachable by the argument above; kept total for safety
}
