//! The phase-domain closed-loop simulator of these tests is the library's
//! [`gpsrx_tracking::phase_sim`] (model and timing documented there); this module re-exports it
//! and keeps only the test suite's own noise source: `rand`'s xoshiro256++ with its ziggurat
//! normal, so that the seeded noise (and so every measured number) of the tests is unchanged.

use gpsrx_tracking::phase_sim::{self, NcoStart, NoiseSource};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

pub use gpsrx_tracking::phase_sim::{
    g_to_hz_s, mean, pll_jitter_deg, std, Signal, Step, Trajectory, LAMBDA_M as LAMBDA,
};

/// Seeded, portable RNG.
pub fn rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

/// One standard normal draw.
pub fn gauss(r: &mut Xoshiro256PlusPlus) -> f64 {
    r.sample(StandardNormal)
}

/// `rand`'s generator as the simulator's noise source (bits by `random::<bool>()`, normals by
/// the ziggurat), drawn in the simulator's order.
struct RandNoise(Xoshiro256PlusPlus);

impl NoiseSource for RandNoise {
    fn data_bit(&mut self) -> bool {
        self.0.random::<bool>()
    }

    fn gauss(&mut self) -> f64 {
        gauss(&mut self.0)
    }
}

/// Runs `n` intervals of `t` seconds (see [`phase_sim::run_with`]). `f_init` is the NCO
/// frequency of interval 0 (its phase starts on the signal's). Returns the steps (the closure's
/// view) in order.
pub fn run(
    traj: &Trajectory,
    sig: Signal,
    t: f64,
    n: usize,
    f_init: f64,
    lp: impl FnMut(&Step) -> f64,
) -> Vec<Step> {
    let start = NcoStart {
        phase_cycles: traj.phase(0.0),
        freq_hz: f_init,
    };
    phase_sim::run_with(traj, sig, t, n, start, &mut RandNoise(rng(sig.seed)), lp)
}
