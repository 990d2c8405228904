//! Carrier-to-noise density (C/N0) estimators on prompt correlator outputs.
//!
//! Model: prompt `P = A d exp(j phi) + n`, `n` complex Gaussian of variance `sigma^2` per
//! component, integration time `T`; then `C/N0 = A^2 / (2 sigma^2 T)` (with unit noise,
//! `A = sqrt(2 C/N0 T)`).
//!
//! - [`NwprEstimator`]: narrow-band / wide-band power ratio (Van Dierendonck; Kaplan Sec. 5.11.1).
//!   Over a block of `M` prompts, `WBP = sum(I^2 + Q^2)`, `NBP = (sum I)^2 + (sum Q)^2`,
//!   `NP = NBP/WBP`; with `mu = mean(NP)` over `K` blocks, `E[NP] ~ (M rho + 1)/(rho + 1)`
//!   (`rho = C/N0 T`), hence `C/N0 = (mu - 1) / (T (M - mu))`. The blocks must not straddle a
//!   data-bit edge (align them with the bit synchroniser) and the residual frequency must be small
//!   against `1/(M T)`.
//! - [`M2m4Estimator`]: second and fourth moments, `M2 = E|P|^2 = A^2 + 2 sigma^2`,
//!   `M4 = E|P|^4 = A^4 + 8 A^2 sigma^2 + 8 sigma^4`, hence `A^2 = sqrt(2 M2^2 - M4)`,
//!   `2 sigma^2 = M2 - A^2` and `C/N0 = A^2/(2 sigma^2 T)`. Insensitive to data bits and carrier
//!   phase (it only uses `|P|`).
//!
//! Estimates are clamped to [`CN0_MIN_DBHZ`, `CN0_MAX_DBHZ`] when the sample moments fall outside
//! the model (noise only, or no noise at all).

use num_complex::Complex64;

/// Lower clamp of the estimates, dB-Hz ("no signal").
pub const CN0_MIN_DBHZ: f64 = 0.0;
/// Upper clamp of the estimates, dB-Hz ("no noise").
pub const CN0_MAX_DBHZ: f64 = 100.0;

fn to_dbhz(cn0_hz: f64) -> f64 {
    if cn0_hz.is_nan() || cn0_hz <= 0.0 {
        CN0_MIN_DBHZ
    } else {
        (10.0 * cn0_hz.log10()).clamp(CN0_MIN_DBHZ, CN0_MAX_DBHZ)
    }
}

/// One NWPR block: the coherent sum and the summed power of `m` prompts.
#[derive(Debug, Clone, Copy)]
struct NwprBlock {
    sum: Complex64,
    wbp: f64,
    n: u32,
}

impl NwprBlock {
    const EMPTY: Self = Self {
        sum: Complex64::new(0.0, 0.0),
        wbp: 0.0,
        n: 0,
    };

    /// Adds a prompt; returns the block's normalised power `|sum|^2 / sum |p|^2` (1 for noise,
    /// `m` for a pure carrier) when the block holds `m` prompts, and starts a new block.
    /// Non-finite prompts are skipped. A block without any power (the input was zeros: a
    /// dropout, a stalled front end) holds no signal and counts as noise (1), so the estimate
    /// falls to [`CN0_MIN_DBHZ`] instead of freezing at its last value.
    fn push(&mut self, prompt: Complex64, m: u32) -> Option<f64> {
        if !(prompt.re.is_finite() && prompt.im.is_finite()) {
            return None;
        }
        self.sum += prompt;
        self.wbp += prompt.norm_sqr();
        self.n += 1;
        if self.n < m {
            return None;
        }
        let np = if self.wbp > 0.0 {
            self.sum.norm_sqr() / self.wbp
        } else {
            1.0
        };
        *self = Self::EMPTY;
        Some(np)
    }
}

/// C/N0 (linear, Hz) from the mean normalised power `mu` of blocks of `m` prompts of `t_s`:
/// `(mu - 1) / (T (M - mu))` (Van Dierendonck's NWPR).
fn nwpr_cn0_hz(mu: f64, m: u32, t_s: f64) -> f64 {
    let m = f64::from(m);
    if mu >= m {
        f64::INFINITY
    } else {
        (mu - 1.0) / (t_s * (m - mu))
    }
}

/// Narrow-band / wide-band power ratio C/N0 estimator.
#[derive(Debug, Clone)]
pub struct NwprEstimator {
    m: u32,
    k: u32,
    t_s: f64,
    block: NwprBlock,
    np_sum: f64,
    blocks: u32,
    last_dbhz: Option<f64>,
}

impl NwprEstimator {
    /// An estimator on prompts of `t_s` seconds each, `m` (>= 2) prompts per block and `k` (>= 1)
    /// blocks per estimate; e.g. `m = 20, k = 50` gives one estimate per second from 1 ms prompts.
    /// Values outside those ranges are raised to them; a non-positive `t_s` is replaced by 1 ms.
    pub fn new(t_s: f64, m: u32, k: u32) -> Self {
        Self {
            m: m.max(2),
            k: k.max(1),
            t_s: if t_s.is_finite() && t_s > 0.0 {
                t_s
            } else {
                1e-3
            },
            block: NwprBlock::EMPTY,
            np_sum: 0.0,
            blocks: 0,
            last_dbhz: None,
        }
    }

    /// Restarts the current block (call at a bit edge to align blocks with the data bits).
    pub fn align_block(&mut self) {
        self.block = NwprBlock::EMPTY;
    }

    /// Feeds one prompt; returns a new estimate (dB-Hz) when `k` blocks are complete.
    /// Non-finite prompts are skipped.
    pub fn push(&mut self, prompt: Complex64) -> Option<f64> {
        let np = self.block.push(prompt, self.m)?;
        self.np_sum += np;
        self.blocks += 1;
        if self.blocks < self.k {
            return None;
        }
        let mu = self.np_sum / f64::from(self.blocks);
        self.np_sum = 0.0;
        self.blocks = 0;
        let db = to_dbhz(nwpr_cn0_hz(mu, self.m, self.t_s));
        self.last_dbhz = Some(db);
        Some(db)
    }

    /// The latest estimate, dB-Hz.
    pub fn last_dbhz(&self) -> Option<f64> {
        self.last_dbhz
    }
}

/// Moments (M2M4) C/N0 estimator.
#[derive(Debug, Clone)]
pub struct M2m4Estimator {
    n: u32,
    t_s: f64,
    m2: f64,
    m4: f64,
    count: u32,
    last_dbhz: Option<f64>,
}

impl M2m4Estimator {
    /// An estimator on prompts of `t_s` seconds, one estimate per `n` (>= 2) prompts.
    pub fn new(t_s: f64, n: u32) -> Self {
        Self {
            n: n.max(2),
            t_s: if t_s.is_finite() && t_s > 0.0 {
                t_s
            } else {
                1e-3
            },
            m2: 0.0,
            m4: 0.0,
            count: 0,
            last_dbhz: None,
        }
    }

    /// Feeds one prompt; returns a new estimate (dB-Hz) every `n` prompts. Non-finite prompts are
    /// skipped.
    pub fn push(&mut self, prompt: Complex64) -> Option<f64> {
        if !(prompt.re.is_finite() && prompt.im.is_finite()) {
            return None;
        }
        let p2 = prompt.norm_sqr();
        self.m2 += p2;
        self.m4 += p2 * p2;
        self.count += 1;
        if self.count < self.n {
            return None;
        }
        let n = f64::from(self.count);
        let (m2, m4) = (self.m2 / n, self.m4 / n);
        (self.m2, self.m4, self.count) = (0.0, 0.0, 0);
        let a2 = (2.0 * m2 * m2 - m4).max(0.0).sqrt();
        let noise = m2 - a2;
        let cn0 = if m2 <= 0.0 {
            0.0
        } else if noise <= 0.0 {
            f64::INFINITY
        } else {
            a2 / (noise * self.t_s)
        };
        let db = to_dbhz(cn0);
        self.last_dbhz = Some(db);
        Some(db)
    }

    /// The latest estimate, dB-Hz.
    pub fn last_dbhz(&self) -> Option<f64> {
        self.last_dbhz
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_free_and_empty_inputs_clamp() {
        let mut e = NwprEstimator::new(1e-3, 20, 1);
        let mut out = None;
        for _ in 0..20 {
            out = e.push(Complex64::new(1.0, 1.0));
        }
        assert_eq!(out, Some(CN0_MAX_DBHZ));
        let mut m = M2m4Estimator::new(1e-3, 4);
        let mut out = None;
        for _ in 0..4 {
            out = m.push(Complex64::new(0.0, 0.0));
        }
        assert_eq!(out, Some(CN0_MIN_DBHZ));
        assert_eq!(m.push(Complex64::new(f64::NAN, 0.0)), None);
    }

    #[test]
    fn zero_prompts_drive_the_estimate_down_instead_of_freezing_it() {
        // A strong carrier, then zeros (a dropout): the running estimate must fall to the
        // minimum within its window, never stay at the carrier's value.
        let mut e = SmoothedNwpr::new(1e-3, 20, 10, 1);
        let mut last = None;
        for k in 0..400 {
            let p = Complex64::new(if (k / 20) % 2 == 0 { 1.0 } else { -1.0 }, 0.0);
            last = e.push(p).or(last);
        }
        assert!(last.is_some_and(|db| db > 50.0), "{last:?}");
        let mut after = Vec::new();
        for _ in 0..20 * 100 {
            if let Some(db) = e.push(Complex64::new(0.0, 0.0)) {
                after.push(db);
            }
        }
        assert_eq!(after.len(), 100, "an estimate per block of zeros");
        assert!(after.windows(2).all(|w| w[1] <= w[0]), "{after:?}");
        // Below a 25 dB-Hz loss threshold within 0.4 s, at the minimum within 2 s.
        assert!(after[19] < 25.0, "{after:?}");
        assert_eq!(after.last().copied(), Some(CN0_MIN_DBHZ));
        let mut n = NwprEstimator::new(1e-3, 20, 5);
        let mut out = None;
        for _ in 0..100 {
            out = n.push(Complex64::new(0.0, 0.0)).or(out);
        }
        assert_eq!(out, Some(CN0_MIN_DBHZ));
    }
}

/// NWPR with a running mean of the block power ratio: after the first `min_blocks` blocks it
/// gives an estimate at the end of every block, from the mean of all blocks so far (up to
/// `window_blocks`), then from an exponentially weighted mean with that time constant. Same
/// estimator as [`NwprEstimator`] (`C/N0 = (mu - 1) / (T (M - mu))`, Van Dierendonck), but
/// usable within a fraction of a second of bit synchronisation. Feed it only block-aligned
/// prompts (call [`SmoothedNwpr::align_block`] at bit edges).
#[derive(Debug, Clone)]
pub struct SmoothedNwpr {
    m: u32,
    t_s: f64,
    window_blocks: u32,
    min_blocks: u32,
    block: NwprBlock,
    mu: f64,
    blocks: u32,
}

impl SmoothedNwpr {
    /// `m` prompts of `t_s` per block (>= 2), averaging over `window_blocks` (>= 1) blocks and
    /// estimating from `min_blocks` on (clamped to 1..=window).
    pub fn new(t_s: f64, m: u32, window_blocks: u32, min_blocks: u32) -> Self {
        let window_blocks = window_blocks.max(1);
        Self {
            m: m.max(2),
            t_s: if t_s.is_finite() && t_s > 0.0 {
                t_s
            } else {
                1e-3
            },
            window_blocks,
            min_blocks: min_blocks.clamp(1, window_blocks),
            block: NwprBlock::EMPTY,
            mu: 0.0,
            blocks: 0,
        }
    }

    /// Forgets everything (e.g. after a loss of lock or at bit synchronisation).
    pub fn reset(&mut self) {
        *self = Self::new(self.t_s, self.m, self.window_blocks, self.min_blocks);
    }

    /// Restarts the current block (call at a bit edge).
    pub fn align_block(&mut self) {
        self.block = NwprBlock::EMPTY;
    }

    /// Blocks averaged so far.
    pub fn blocks(&self) -> u32 {
        self.blocks
    }

    /// Feeds one prompt; returns an estimate (dB-Hz) when a block completes and enough blocks
    /// are in. Non-finite prompts are skipped.
    pub fn push(&mut self, prompt: Complex64) -> Option<f64> {
        let np = self.block.push(prompt, self.m)?;
        self.blocks = self.blocks.saturating_add(1);
        let alpha = 1.0 / f64::from(self.blocks.min(self.window_blocks));
        self.mu += alpha * (np - self.mu);
        if self.blocks < self.min_blocks {
            return None;
        }
        Some(to_dbhz(nwpr_cn0_hz(self.mu, self.m, self.t_s)))
    }
}
