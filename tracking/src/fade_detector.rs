//! Fade detector: a sudden collapse of the prompt power (a blocked signal, a tunnel entry, a
//! gap in the samples) flagged within 40-60 ms.
//!
//! The C/N0 estimate averages over its window (0.2 s by default) and the PLL lock indicator
//! `cos 2 phi` stays high for about a second on pure noise (the loop steers the noise into the
//! in-phase arm), so neither notices a blockage at once, and the measurements of that second
//! are noise. This detector compares the prompt power of each 20 ms block,
//! `W = sum |P_k|^2` (non-coherent: data bits do not matter), with its running mean `W_bar`
//! over the blocks with signal:
//!
//! - faded when `W < W_bar / 4` in two consecutive blocks;
//! - recovered when `W > W_bar / 2`.
//!
//! With signal power `A^2` and noise `sigma^2` per prompt, `E[W] = M (A^2 + sigma^2)`, so a
//! blockage divides `W` by `1 + C/N0 T`: 33 at 45 dB-Hz, 4.2 at 35 dB-Hz (detected), 2 at
//! 30 dB-Hz (not detected: there the C/N0 test takes over). On a steady signal `W` has a
//! relative spread of about `sqrt((1 + 2 C/N0 T) / M) / (1 + C/N0 T)` (0.19 at 30 dB-Hz), so
//! two blocks in a row below a quarter of the mean do not happen. A fade that lasts
//! [`REBASE_BLOCKS`] takes the new level as the reference (a front-end gain change, not a
//! blockage); the C/N0 test releases a channel that has really lost its signal. A level of no
//! power at all (zeros from a dropout or a stalled front end) is never taken as a reference:
//! it stays a fade. Nor is a fade rebased while the caller holds the reference
//! ([`FadeDetector::hold_reference`]: vector tracking predicts the signal through a blockage,
//! whose noise is a steady level too).

use num_complex::Complex64;

/// Prompts per block.
const BLOCK_PROMPTS: u32 = 20;
/// Running-mean length of the block power, blocks (0.5 s of 1 ms prompts).
const MEAN_BLOCKS: u32 = 25;
/// A block below this fraction of the mean counts towards a fade.
const FADE_RATIO: f64 = 0.25;
/// Consecutive low blocks that confirm a fade.
const CONFIRM_BLOCKS: u32 = 2;
/// A block above this fraction of the mean ends a fade.
const RECOVER_RATIO: f64 = 0.5;
/// Blocks of fade after which the faded level becomes the reference (1 s).
pub const REBASE_BLOCKS: u32 = 50;

/// Flags a sudden loss of prompt power (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct FadeDetector {
    sum: f64,
    n: u32,
    mean: f64,
    blocks: u32,
    low: u32,
    faded_blocks: u32,
    faded: bool,
    hold: bool,
}

impl FadeDetector {
    /// A detector with no history.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets the history (e.g. when the channel restarts).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Whether the signal has faded.
    pub fn faded(&self) -> bool {
        self.faded
    }

    /// While `on`, a fade is not taken as a new level however long it lasts: it ends only when
    /// the power comes back (the caller knows the signal is gone, not the gain changed).
    pub fn hold_reference(&mut self, on: bool) {
        self.hold = on;
    }

    /// Feeds one prompt (any fixed integration time; 1 ms in a channel). Non-finite prompts
    /// are skipped.
    pub fn push(&mut self, prompt: Complex64) {
        let p2 = prompt.norm_sqr();
        if !p2.is_finite() {
            return;
        }
        self.sum += p2;
        self.n += 1;
        if self.n < BLOCK_PROMPTS {
            return;
        }
        let w = self.sum;
        (self.sum, self.n) = (0.0, 0);
        self.block(w);
    }

    fn block(&mut self, w: f64) {
        if self.blocks == 0 {
            self.mean = w;
            self.blocks = 1;
            return;
        }
        if self.faded {
            self.faded_blocks += 1;
            if w > RECOVER_RATIO * self.mean {
                self.faded = false;
                self.faded_blocks = 0;
                self.low = 0;
            } else if self.faded_blocks >= REBASE_BLOCKS && w > 0.0 && !self.hold {
                // A lasting new level: take it as the reference.
                self.faded = false;
                self.faded_blocks = 0;
                self.low = 0;
                self.mean = w;
                self.blocks = 1;
            }
            return;
        }
        if w < FADE_RATIO * self.mean {
            self.low += 1;
            if self.low >= CONFIRM_BLOCKS {
                self.faded = true;
                self.faded_blocks = 0;
            }
            // Low blocks do not pull the reference down.
            return;
        }
        self.low = 0;
        self.blocks = (self.blocks + 1).min(MEAN_BLOCKS);
        self.mean += (w - self.mean) / f64::from(self.blocks);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// 1 ms prompts of a signal at `cn0_dbhz` (amplitude 0 when `on` is false) in unit noise:
    /// `A^2 / sigma^2 = C/N0 T` per prompt, data bits flipping every 20 ms at random.
    struct Prompts {
        rng: Xoshiro256PlusPlus,
        noise: Normal<f64>,
        k: u64,
        bit: f64,
    }

    impl Prompts {
        fn new(seed: u64) -> Self {
            Self {
                rng: Xoshiro256PlusPlus::seed_from_u64(seed),
                noise: Normal::new(0.0, std::f64::consts::FRAC_1_SQRT_2)
                    .unwrap_or_else(|e| panic!("{e}")),
                k: 0,
                bit: 1.0,
            }
        }

        fn next(&mut self, cn0_dbhz: f64, on: bool) -> Complex64 {
            if self.k.is_multiple_of(20) && self.noise.sample(&mut self.rng) < 0.0 {
                self.bit = -self.bit;
            }
            self.k += 1;
            let a = if on {
                (10f64.powf(cn0_dbhz / 10.0) * 1e-3).sqrt()
            } else {
                0.0
            };
            Complex64::new(
                self.bit * a + self.noise.sample(&mut self.rng),
                self.noise.sample(&mut self.rng),
            )
        }
    }

    /// Milliseconds from the signal's disappearance to the fade flag, or None.
    fn latency_ms(cn0_dbhz: f64, seed: u64) -> Option<u32> {
        let mut p = Prompts::new(seed);
        let mut d = FadeDetector::new();
        for _ in 0..2000 {
            d.push(p.next(cn0_dbhz, true));
            assert!(!d.faded(), "false fade at {cn0_dbhz} dB-Hz");
        }
        (1..=500).find(|_| {
            d.push(p.next(cn0_dbhz, false));
            d.faded()
        })
    }

    #[test]
    fn a_blocked_strong_signal_is_flagged_within_60_ms() {
        for (cn0, seed) in [(45.0, 1), (40.0, 2), (37.0, 3)] {
            let ms = latency_ms(cn0, seed);
            assert!(ms.is_some_and(|ms| ms <= 60), "{cn0} dB-Hz: {ms:?} ms");
        }
    }

    #[test]
    fn steady_signals_never_fade() {
        // 10 minutes at each level: no false alarm (the spread argument of the module doc).
        for (cn0, seed) in [(45.0, 11), (30.0, 12), (25.0, 13)] {
            let mut p = Prompts::new(seed);
            let mut d = FadeDetector::new();
            for k in 0..600_000 {
                d.push(p.next(cn0, true));
                assert!(!d.faded(), "false fade at {cn0} dB-Hz after {k} ms");
            }
        }
    }

    #[test]
    fn the_signal_coming_back_ends_the_fade_and_a_lasting_new_level_is_accepted() {
        let mut p = Prompts::new(21);
        let mut d = FadeDetector::new();
        for _ in 0..1000 {
            d.push(p.next(45.0, true));
        }
        for _ in 0..200 {
            d.push(p.next(45.0, false));
        }
        assert!(d.faded());
        // Back within two blocks.
        for _ in 0..40 {
            d.push(p.next(45.0, true));
        }
        assert!(!d.faded());
        // A fade that lasts: after REBASE_BLOCKS the noise level is the new reference, and
        // stays unflagged.
        let ms = 20 * (REBASE_BLOCKS as usize + 5);
        for _ in 0..ms {
            d.push(p.next(45.0, false));
        }
        assert!(!d.faded());
        for _ in 0..2000 {
            d.push(p.next(45.0, false));
            assert!(!d.faded());
        }
    }

    #[test]
    fn a_held_reference_keeps_a_long_blockage_a_fade_until_the_signal_returns() {
        let mut p = Prompts::new(22);
        let mut d = FadeDetector::new();
        for _ in 0..1000 {
            d.push(p.next(40.0, true));
        }
        d.hold_reference(true);
        // Three times the rebase time of noise alone: still a fade.
        for k in 0..3 * 20 * REBASE_BLOCKS {
            d.push(p.next(40.0, false));
            assert!(d.faded() || k < 60, "not faded {k} ms into the blockage");
        }
        // The signal back: the fade ends within two blocks.
        let back_ms = (1..=100).find(|_| {
            d.push(p.next(40.0, true));
            !d.faded()
        });
        assert!(back_ms.is_some_and(|ms| ms <= 40), "{back_ms:?}");
        // Released: a lasting new level is taken again.
        d.hold_reference(false);
        for _ in 0..20 * (REBASE_BLOCKS + 5) {
            d.push(p.next(40.0, false));
        }
        assert!(!d.faded());
    }

    #[test]
    fn non_finite_prompts_are_ignored() {
        let mut d = FadeDetector::new();
        for _ in 0..100 {
            d.push(Complex64::new(f64::NAN, 1.0));
        }
        assert!(!d.faded());
        assert_eq!(d.blocks, 0);
    }

    #[test]
    fn zeros_stay_a_fade_and_never_become_the_reference() {
        let mut d = FadeDetector::new();
        for k in 0..1000 {
            d.push(Complex64::new(if k % 40 < 20 { 30.0 } else { -30.0 }, 0.0));
        }
        assert!(!d.faded());
        // Ten seconds of zeros: faded at once, and still faded (no rebase to a level of 0).
        for _ in 0..10_000 {
            d.push(Complex64::new(0.0, 0.0));
        }
        assert!(d.faded());
        // The signal comes back: the fade ends.
        for _ in 0..100 {
            d.push(Complex64::new(30.0, 0.0));
        }
        assert!(!d.faded());
    }
}
