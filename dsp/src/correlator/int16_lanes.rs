//! What the int16-lane kernels ([`super::avx2_i16`]: 16 samples per step, [`super::avx512_i16`]:
//! 32) share: where each sample sits in the i16 vectors, the per-call code plan and the
//! headroom shift of ci16 samples.
//!
//! **Positions.** A kernel wipes the carrier off `L` samples held in `L` i16 lanes (one
//! vector of I, one of Q). ci8 loads land in sample order. A ci16 step loads `L/2` samples
//! (one I/Q pair per 32-bit lane) into each of two vectors `a`, `b`; `vpblendw` of `a` with
//! `b << 16` (32-bit lanes) gives the I vector and of `a >> 16` with `b` the Q vector, so
//! word `2m` of 128-bit lane `k` holds `a`'s sample `4k + m` and word `2m + 1` `b`'s
//! ([`ci16_positions`]); shifts and blends, no shuffle-port instruction. The carrier and the
//! code replica are built in whatever position order the samples have.
//!
//! **Carrier lanes.** The f32 rotator runs as two sets of vectors A and B (`L/2` f32 lanes
//! each) converted to i32 and packed with `vpackssdw`, which per 128-bit lane `k` writes A's
//! lanes `4k..4k+4` then B's lanes `4k..4k+4` ([`pack_position`]); each rotator lane is seeded
//! at the sample of the position it lands on.
//!
//! **Code.** Exactly the 2^-32-chip NCO of [`super::plan`]: tap `t`'s phase is the first
//! tap's `B` plus a constant `Delta_t = W_t 2^32 + f_t`, so the lane of sample `o` reads chip
//! `floor(B / 2^32) + W_t + h + carry` with `l = f_t + o S`, `h = l >> 32` and
//! `carry = [B_lo + (l mod 2^32) >= 2^32] = [B_lo >u !l]` (unsigned; the AVX2 kernel compares
//! signed after flipping both sign bits). A `vpshufb` of the 16 code bytes at chip
//! `floor(B / 2^32) + W_t` ([`super::PackedCode`]'s byte copy) by `h + carry` (both bytes of a
//! lane) then `| 1` is the +-1 replica in i16 lanes. Needs every `h <= 14`: `L` samples within
//! 15 chips, i.e. a code step below `14 / (L - 1)` chip per sample ([`LanePlan::new`] says
//! no otherwise, and the caller runs another kernel).
//!
//! **Scale.** Wiped samples are `vpmulhrsw(x 2^sh, c)` with the carrier `c` in Q14:
//! `round(x c 2^(sh - 1))`, in units of `2^(1 - sh)` sample. ci8 samples take `sh = 8`
//! (`x 2^8` is the byte moved to the high half of its lane: no shift); ci16 samples the
//! largest `sh` with every `|I|, |Q| < 2^(15 - sh)` in the block ([`abs_shift`]: the block's
//! headroom, 0 for full-scale samples), so the rounding is at most `2^-sh` per
//! product, `2^(1 - sh) sqrt 2` per wiped sample, i.e. `2^-14.5` of the block's largest
//! sample (`2^-7 sqrt 2` for ci8). `|x 2^sh| <= 2^15` and `|c| <= 2^14 (1 + 4.1e-4)` give
//! `|w| <= 2^14.5 (1 + 4.1e-4) + 1 < 2^15`: no lane saturates.

use super::plan::{CodeNco, CODE_LEN_FIX};
use super::simd::CI16;
use super::MAX_TAPS;

/// The largest chip offset `h` a 16-byte code window allows (the carry adds one).
const MAX_OFFSET: u64 = 14;

/// The ci8 position order: sample `p` at position `p`.
pub(super) fn ci8_positions<const L: usize>() -> [usize; L] {
    super::plan::natural::<L>()
}

/// The ci16 position order (module doc): position `p = 8k + w` holds sample `4k + w / 2`
/// (`w` even) or `L/2 + 4k + w / 2` (`w` odd).
pub(super) fn ci16_positions<const L: usize>() -> [usize; L] {
    let mut o = [0usize; L];
    for (p, s) in o.iter_mut().enumerate() {
        let (k, w) = (p / 8, p % 8);
        *s = if w % 2 == 0 {
            4 * k + w / 2
        } else {
            L / 2 + 4 * k + w / 2
        };
    }
    o
}

/// The position that lane `j` of the rotator pair (A: `0..L/2`, B: `L/2..L`) lands on after
/// `vpackssdw(A, B)`.
pub(super) fn pack_position<const L: usize>(j: usize) -> usize {
    let (b, v) = if j < L / 2 { (0, j) } else { (4, j - L / 2) };
    8 * (v / 4) + b + v % 4
}

/// The sample each rotator lane (A then B) must hold for `positions`.
pub(super) fn rotator_order<const L: usize>(positions: &[usize; L]) -> [usize; L] {
    let mut o = [0usize; L];
    for (j, s) in o.iter_mut().enumerate() {
        *s = positions[pack_position::<L>(j)];
    }
    o
}

/// The per-call code constants of every tap (module doc): per compare lane the threshold
/// `!l ^ flip`, per position the duplicated offset `h * 0x0101`, and the whole-chip offset
/// `W_t`.
pub(super) struct LanePlan<const L: usize> {
    pub thr: [[u32; L]; MAX_TAPS],
    pub hi_dup: [[i16; L]; MAX_TAPS],
    pub whole: [usize; MAX_TAPS],
}

impl<const L: usize> LanePlan<L> {
    /// An all-zero plan, to be [`LanePlan::fill`]ed.
    pub(super) const ZERO: Self = Self {
        thr: [[0; L]; MAX_TAPS],
        hi_dup: [[0; L]; MAX_TAPS],
        whole: [0; MAX_TAPS],
    };

    /// Writes the plan for the taps of `nco` (`n_taps`) in place, compare lane `j` serving the
    /// sample at position `cmp_position(j)` of `positions` (`cmp_position` a permutation of
    /// `0..L`); thresholds XORed with `flip`.
    /// `false` if some lane lies 16 or more chips past its tap's window (the plan is then
    /// unusable). Only the first `n_taps` taps are written: a kernel of `n_taps` taps reads no
    /// other, so a plan kept from call to call (see `Plan32::with` and `Plan16::with`) is neither
    /// zeroed nor moved per call (1.5 KB at 32 lanes: with the zeroing and the move of a plan
    /// returned by value, 4-5 % of a 4 MHz run's CPU time).
    pub(super) fn fill(
        &mut self,
        nco: &CodeNco,
        n_taps: usize,
        positions: &[usize; L],
        cmp_position: impl Fn(usize) -> usize,
        flip: u32,
    ) -> bool {
        // `o S` per position and per compare lane (below 32 * 1023 * 2^32 < 2^47: no
        // overflow). `cmp_position` is a permutation, so the offsets written per position
        // below are those of the compare lanes serving them: two contiguous loops, no scatter.
        let mut pos_s = [0u64; L];
        for (s, &o) in pos_s.iter_mut().zip(positions) {
            *s = o as u64 * nco.step;
        }
        let mut o_s = [0u64; L];
        for (j, s) in o_s.iter_mut().enumerate() {
            *s = pos_s[cmp_position(j)];
        }
        // The last sample of a step is the furthest from its window.
        let last = (L as u64 - 1) * nco.step;
        let b0 = nco.phases[0];
        for t in 0..n_taps.min(MAX_TAPS) {
            let delta = (nco.phases[t] + CODE_LEN_FIX - b0) % CODE_LEN_FIX;
            self.whole[t] = (delta >> 32) as usize;
            let frac = delta & 0xFFFF_FFFF;
            if (frac + last) >> 32 > MAX_OFFSET {
                return false;
            }
            for (thr, &s) in self.thr[t].iter_mut().zip(&o_s) {
                *thr = !((frac + s) as u32) ^ flip;
            }
            for (hi, &s) in self.hi_dup[t].iter_mut().zip(&pos_s) {
                *hi = (((frac + s) >> 32) as u16 * 0x0101) as i16;
            }
        }
        true
    }
}

/// The exact headroom of a ci16 block: the largest `sh <= 15` with every `v 2^sh` an i16,
/// i.e. the redundant sign bits common to every I and Q ([`abs_shift`] is at most one short).
#[cfg(test)]
fn ci16_shift(x: &[[i16; 2]]) -> u32 {
    let mut acc = 0u16;
    for s in x {
        for &v in s {
            acc |= (v ^ (v >> 15)) as u16;
        }
    }
    // acc <= 0x7FFF: at least one leading zero.
    (acc.leading_zeros() - 1).min(15)
}

/// The code plan of an `L`-lane int16 kernel and the lane order of its samples, kept per
/// thread by the kernel ([`super::avx2_i16::Plan16`], [`super::avx512_i16::Plan32`]).
pub(super) struct KernelPlan<const L: usize> {
    pub code: LanePlan<L>,
    /// The sample each rotator lane (A then B) is seeded at.
    pub rotator: [usize; L],
    /// The sample format `rotator` is for (`u8::MAX`: none yet).
    format: u8,
}

impl<const L: usize> KernelPlan<L> {
    /// An all-zero plan, to be filled.
    pub(super) const ZERO: Self = Self {
        code: LanePlan::ZERO,
        rotator: [0; L],
        format: u8::MAX,
    };

    /// Writes the plan in place for the taps of `nco` (`n_taps`) on samples of format `F`
    /// (ci8 or ci16), compare lane `j` serving position `cmp_position(j)` with thresholds
    /// XORed with `flip` ([`LanePlan::fill`]); the rotator order is recomputed only when the
    /// format changes. `false` if the plan cannot be made.
    pub(super) fn fill<const F: u8>(
        &mut self,
        nco: &CodeNco,
        n_taps: usize,
        cmp_position: impl Fn(usize) -> usize,
        flip: u32,
    ) -> bool {
        let positions = if F == CI16 {
            ci16_positions::<L>()
        } else {
            ci8_positions::<L>()
        };
        if self.format != F {
            self.rotator = rotator_order(&positions);
            self.format = F;
        }
        self.code.fill(nco, n_taps, &positions, cmp_position, flip)
    }
}

/// The headroom shift of a ci16 block from the OR of its `|v|` (`vpabsw`, |-32768| read as
/// 32768): the largest `sh <= 15` with `|v| < 2^(15 - sh)` for all `v`, so every `v 2^sh` is
/// an i16 (one bit short of the most that fits only when the block's largest magnitude is a
/// negative power of two).
#[inline]
pub(super) fn abs_shift(or_abs: u16) -> u32 {
    or_abs.leading_zeros().saturating_sub(1).min(15)
}

/// The unit of the wiped samples for shift `sh`, in sample units: `2^(1 - sh)`.
pub(super) fn w_unit(sh: u32) -> f64 {
    2f64.powi(1 - sh as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_and_packing_are_permutations_as_documented() {
        // AVX2 (16) and AVX-512 (32): the ci16 order interleaves the two loads, vpackssdw
        // places A then B per 128-bit lane, and each is a permutation.
        assert_eq!(
            ci16_positions::<16>(),
            [0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15]
        );
        assert_eq!(&ci16_positions::<32>()[8..12], &[4, 20, 5, 21]);
        let p16: Vec<usize> = (0..16).map(pack_position::<16>).collect();
        assert_eq!(p16, [0, 1, 2, 3, 8, 9, 10, 11, 4, 5, 6, 7, 12, 13, 14, 15]);
        let p32: Vec<usize> = (0..32).map(pack_position::<32>).collect();
        assert_eq!(&p32[..8], &[0, 1, 2, 3, 8, 9, 10, 11]);
        assert_eq!(&p32[16..20], &[4, 5, 6, 7]);
        fn is_permutation(v: &[usize]) -> bool {
            let mut s = v.to_vec();
            s.sort_unstable();
            s.iter().enumerate().all(|(i, &x)| i == x)
        }
        assert!(is_permutation(&p32) && is_permutation(&ci16_positions::<32>()));
        let r = rotator_order::<32>(&ci16_positions::<32>());
        assert!(is_permutation(&r));
        // Rotator lane j lands on position pack_position(j): it must be seeded at that
        // position's sample.
        for (j, &s) in r.iter().enumerate() {
            assert_eq!(ci16_positions::<32>()[pack_position::<32>(j)], s);
        }
    }

    #[test]
    fn abs_shift_is_one_short_only_at_negative_powers_of_two() {
        for v in i16::MIN..=i16::MAX {
            let exact = ci16_shift(&[[v, 0]]);
            let from_abs = abs_shift(v.unsigned_abs());
            let neg_pow2 = v < 0 && v.unsigned_abs().is_power_of_two();
            assert_eq!(from_abs + u32::from(neg_pow2 && exact > 0), exact, "{v}");
        }
    }

    #[test]
    fn ci16_shift_is_the_largest_that_fits_every_component() {
        for (x, sh) in [
            (vec![[0i16, 0]], 15),
            (vec![[-1, 0]], 15),
            (vec![[1, 0]], 14),
            (vec![[127, -128]], 8),
            (vec![[128, 3]], 7),
            (vec![[0, -32768]], 0),
            (vec![[32767, 0]], 0),
            (vec![[16383, -16384]], 1),
            (vec![[5, 6], [-300, 2]], 6),
        ] {
            let s = ci16_shift(&x);
            assert_eq!(s, sh, "{x:?}");
            for v in x.iter().flatten() {
                // v 2^sh fits an i16, v 2^(sh+1) does not for some v (unless sh = 15).
                assert!(i16::try_from(i32::from(*v) << s).is_ok(), "{v} << {s}");
            }
            if s < 15 {
                assert!(x
                    .iter()
                    .flatten()
                    .any(|v| i16::try_from(i32::from(*v) << (s + 1)).is_err()));
            }
        }
    }
}
