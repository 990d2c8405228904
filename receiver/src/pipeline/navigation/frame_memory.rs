//! The data bits of the frames before, by position in the frame: the time of a bit stream whose
//! time is lost, read from the navigation message itself.
//!
//! LNAV (IS-GPS-200 20.3.2, 20.3.3) sends a 1500-bit frame every 30 s, aligned with the GPS week
//! (bit `n` of the week, `n = TOW / 20 ms`, sits at position `n mod 1500` of its frame).
//! Subframes 1-3 (positions 0-899) carry the clock and ephemeris and repeat word for word
//! from one frame to the next while the issue of data holds (hours). The telemetry word opens
//! every subframe and is the same in all of them. The hand-over word that follows carries the
//! time of week of the next subframe (20.3.3.2), 5 counts (30 s) more each frame, with its
//! last two bits solved so that its parity ends in `00` (20.3.5.2); the word before it (the
//! telemetry word) is the same every time, so from the hand-over word one frame before the
//! one sent now is computed exactly ([`FrameMemory::expected_how`]), and the word after it is
//! sent the same too. So a bit stream after lost samples, whose receiver time is known only to
//! within seconds, can be placed exactly: among the 20 ms positions the kept time allows, the
//! one whose bits equal, in one polarity, the bits sent at the same frame positions one to
//! four frames before. A stream in subframes 4-5 (pages that change from frame to frame)
//! matches on their telemetry and hand-over words only.
//!
//! A chance match needs every comparable bit to agree: with [`MIN_COMPARED`] bits and at most
//! [`MAX_ERRORS`] disagreeing, `2 (1 + N) 2^-N` per candidate, under `2e-7` over the 150
//! candidates of 3 s; a second candidate that agrees nearly as well (at most three errors: data
//! with a period, such as a reserved field) leaves the time undecided until the stream is longer.

use gpsrx_nav::lnav::{
    parity_check, parity_encode, solve_trailing_bits, PREAMBLE, SUBFRAMES_PER_WEEK,
};

/// Bits in a frame (5 subframes of 300 bits: 30 s).
pub const FRAME_BITS: u32 = 1500;
/// Bits in a GPS week (604 800 s at 50 bit/s), a whole number of frames.
pub const WEEK_BITS: u32 = 30_240_000;
/// Comparable bits a match needs.
pub const MIN_COMPARED: u32 = 32;
/// Disagreeing bits (in the better polarity) a match allows.
pub const MAX_ERRORS: u32 = 1;
/// Oldest frame compared with, in frames (2 minutes: the issue of data holds far longer).
const MAX_FRAMES_BACK: u32 = 4;

/// Whether the bit at frame position `p` is sent the same in every frame while the issue of
/// data holds: subframes 1-3 but their hand-over words, and every telemetry word.
pub fn repeats(p: u32) -> bool {
    let subframe = p / 300;
    let word = (p % 300) / 30;
    word == 0 || (subframe < 3 && word != 1)
}

/// Whether frame position `p` is in a hand-over word (word 2 of a subframe).
fn in_how(p: u32) -> bool {
    (p % 300) / 30 == 1
}

/// The last bit received at each position of the frame, with its bit number in the week.
#[derive(Debug, Clone)]
pub struct FrameMemory {
    slots: Vec<Option<(u32, u8)>>,
}

impl Default for FrameMemory {
    fn default() -> Self {
        Self {
            slots: vec![None; FRAME_BITS as usize],
        }
    }
}

impl FrameMemory {
    /// Keeps bit `raw` (0/1 as received) of bit number `n` in the week.
    pub fn record(&mut self, n: u32, raw: u8) {
        let n = n % WEEK_BITS;
        self.slots[(n % FRAME_BITS) as usize] = Some((n, raw));
    }

    /// The bit sent at bit number `n` as the frames before sent it, where it repeats and was
    /// received one to [`MAX_FRAMES_BACK`] frames before.
    pub fn expected(&self, n: u32) -> Option<u8> {
        let n = n % WEEK_BITS;
        let p = n % FRAME_BITS;
        if !repeats(p) {
            return None;
        }
        let (n_mem, raw) = self.slots[p as usize]?;
        let back = (n + WEEK_BITS - n_mem) % WEEK_BITS;
        (FRAME_BITS..=MAX_FRAMES_BACK * FRAME_BITS)
            .contains(&back)
            .then_some(raw)
    }

    /// The bits (0/1 as received, D1 in bit 29) of the hand-over word of subframe `s` of the
    /// week (its first bit is number `300 s + 30`), computed from the telemetry and hand-over
    /// words of the same subframe one to [`MAX_FRAMES_BACK`] frames before: their polarity
    /// from the preamble, the source bits from the parity (20.3.5.2, which must pass), the
    /// time-of-week count advanced by 5 a frame, the two solved bits and the parity again.
    pub fn expected_how(&self, s: u32) -> Option<u32> {
        let word = |first: u32| -> Option<(u32, u32)> {
            let mut w = 0u32;
            let mut n0 = None;
            for i in 0..30 {
                let (n, b) = self.slots[((first + i) % FRAME_BITS) as usize]?;
                let n_first = n.checked_sub(i)?;
                if *n0.get_or_insert(n_first) != n_first {
                    return None;
                }
                w = (w << 1) | u32::from(b);
            }
            Some((n0?, w))
        };
        let first = (s * 300) % WEEK_BITS;
        let (n_tlm, tlm) = word(first)?;
        let (n_how, how) = word(first + 30)?;
        let back = (first + WEEK_BITS - n_tlm) % WEEK_BITS;
        if n_how != n_tlm + 30
            || !back.is_multiple_of(FRAME_BITS)
            || !(FRAME_BITS..=MAX_FRAMES_BACK * FRAME_BITS).contains(&back)
        {
            return None;
        }
        // The preamble (IS-GPS-200 20.3.3.1) in either polarity.
        let invert = match tlm >> 22 {
            p if p == PREAMBLE => false,
            p if p == (!PREAMBLE & 0xFF) => true,
            _ => return None,
        };
        let flip = |w: u32| if invert { w ^ 0x3FFF_FFFF } else { w };
        let tlm = flip(tlm);
        let (d29, d30) = (tlm & 0b10 != 0, tlm & 0b1 != 0);
        let data = parity_check(flip(how), d29, d30)?;
        let tow = ((data >> 7) + 5 * (back / FRAME_BITS)) % SUBFRAMES_PER_WEEK;
        let data = solve_trailing_bits((tow << 7) | (data & 0x7F), d29, d30);
        Some(flip(parity_encode(data, d29, d30)))
    }

    /// The bit number of the first of `bits` (consecutive bits, 0/1 as received), among the
    /// candidates `first..=last` (bit numbers, may exceed a week), found by matching them
    /// against the frames before (module documentation): `None` while no candidate matches
    /// or more than one does.
    pub fn place(&self, bits: &[u8], first: i64, last: i64) -> Option<u32> {
        let mut found = None;
        // The hand-over words computed so far: (subframe of the week, word).
        let mut hows: Vec<(u32, Option<u32>)> = Vec::new();
        let mut how_bit = |n: u32| -> Option<u8> {
            let s = n / 300;
            let w = match hows.iter().find(|h| h.0 == s) {
                Some(h) => h.1,
                None => {
                    let w = self.expected_how(s);
                    hows.push((s, w));
                    w
                }
            }?;
            Some(((w >> (29 - (n % 300 - 30))) & 1) as u8)
        };
        for c in first..=last {
            let c = c.rem_euclid(i64::from(WEEK_BITS)) as u32;
            let (mut compared, mut agree) = (0u32, 0u32);
            for (j, &b) in bits.iter().enumerate() {
                let n = (c + j as u32) % WEEK_BITS;
                let e = if in_how(n % FRAME_BITS) {
                    how_bit(n)
                } else {
                    self.expected(n)
                };
                if let Some(e) = e {
                    compared += 1;
                    agree += u32::from(e == b);
                }
            }
            let errors = agree.min(compared - agree);
            if compared >= MIN_COMPARED && errors <= MAX_ERRORS {
                if found.is_some() {
                    return None;
                }
                found = Some(c);
            } else if compared >= MIN_COMPARED && errors <= 3 * MAX_ERRORS {
                // Another candidate agrees almost as well: the data repeats; wait.
                return None;
            }
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A memory of one frame of random bits starting at bit number `n0` (a frame boundary), and
    /// the same frame sent again one frame later (hand-over words and subframes 4-5 new).
    fn frames(seed: u64, n0: u32) -> (FrameMemory, Vec<u8>) {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let first: Vec<u8> = (0..FRAME_BITS).map(|_| rng.random_range(0..2)).collect();
        let mut mem = FrameMemory::default();
        for (j, &b) in first.iter().enumerate() {
            mem.record(n0 + j as u32, b);
        }
        let second = first
            .iter()
            .enumerate()
            .map(|(p, &b)| {
                if repeats(p as u32) {
                    b
                } else {
                    rng.random_range(0..2)
                }
            })
            .collect();
        (mem, second)
    }

    #[test]
    fn the_positions_that_repeat_are_subframes_1_to_3_and_every_tlm() {
        assert!(repeats(0) && repeats(29) && !repeats(30) && !repeats(59) && repeats(60));
        assert!(repeats(899) && repeats(900) && !repeats(930) && !repeats(1499));
        assert_eq!((0..FRAME_BITS).filter(|&p| repeats(p)).count(), 810 + 60);
    }

    #[test]
    fn a_stream_is_placed_at_its_bit_number_in_either_polarity_with_a_bit_error() {
        let n0 = 17_941 * FRAME_BITS; // TOW 538 230 s
        let (mem, next) = frames(7, n0);
        // 80 bits from position 620 of the next frame (subframe 3: 50 of them repeat), true
        // number n.
        let n = n0 + FRAME_BITS + 620;
        let mut bits: Vec<u8> = next[620..700].to_vec();
        bits[5] ^= 1;
        let (lo, hi) = (i64::from(n) - 150, i64::from(n) + 150);
        assert_eq!(mem.place(&bits, lo, hi), Some(n));
        let inverted: Vec<u8> = bits.iter().map(|b| b ^ 1).collect();
        assert_eq!(mem.place(&inverted, lo, hi), Some(n));
        // Too few bits compared, or the true number outside the candidates: no time.
        assert_eq!(mem.place(&bits[..20], lo, hi), None);
        assert_eq!(mem.place(&bits, i64::from(n) + 1, hi), None);
        // Three bit errors: no match rather than a wrong one.
        bits[9] ^= 1;
        bits[40] ^= 1;
        assert_eq!(mem.place(&bits, lo, hi), None);
    }

    #[test]
    fn subframes_4_and_5_past_their_tlm_and_how_are_not_compared() {
        let n0 = 3 * FRAME_BITS;
        let (mem, next) = frames(11, n0);
        // Bits of subframe 4 beyond its TLM and HOW: nothing to compare, no time.
        let n = n0 + FRAME_BITS + 940;
        assert_eq!(
            mem.place(&next[940..1100], i64::from(n) - 50, i64::from(n) + 50),
            None
        );
        // A memory older than four frames is not used.
        let old = n0 + 6 * FRAME_BITS + 620;
        assert_eq!(
            mem.place(&next[620..700], i64::from(old) - 50, i64::from(old) + 50),
            None
        );
    }

    #[test]
    fn data_that_repeats_with_a_period_leaves_the_time_undecided() {
        let n0 = 20 * FRAME_BITS;
        let mut mem = FrameMemory::default();
        // Subframe 1, words 4-6 as alternating bits (a reserved field).
        for p in 90..180u32 {
            mem.record(n0 + p, (p % 2) as u8);
        }
        let bits: Vec<u8> = (100..160u32).map(|p| (p % 2) as u8).collect();
        let n = n0 + FRAME_BITS + 100;
        assert_eq!(mem.place(&bits, i64::from(n) - 10, i64::from(n) + 10), None);
    }
}
