//! The report's introduction: how the study ran.

use super::{
    RunInfo, DLL_BN_HZ, EL_SPACING_CHIPS, FS_HZ, LONG_INTERVAL_S, MAX_SETTLE_S, OBS_INTERVAL_S,
    SETTLE_FRACTION,
};
use gpsrx_dsp::constants::F_L1_HZ;
use std::fmt::Write as _;

pub(super) fn intro(info: &RunInfo) -> String {
    let (aided, quick) = (info.aided, info.quick);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Simulated static receiver (Seoul, {}), clock without noise (Allan deviation 0): the \
         loops see thermal noise only. Real oscillators add the Allan term (oracles.md: about \
         `144 sigma_A f_L1 / Bn` deg for a 2nd-order loop, `160 sigma_A f_L1 / Bn` for a 3rd; \
         {:.1} deg at 3 Hz for sigma_A = 1e-10), which grows as Bn shrinks and is not in this \
         table.\n",
        if quick { "`--quick` grid" } else { "full grid" },
        144.0 * 1e-10 * F_L1_HZ / 3.0
    );
    let _ = writeln!(
        s,
        "- {} recordings, {:.0} s in all (complex floats at {:.1} MHz, no quantisation), each \
         with G16, G25 and G26 at one C/N0; every satellite tracked by one channel per (order, \
         Bn, T) cell over the same samples, started from truth. {}\n\
         - Channel: Costas `atan(Q/I)` PLL of the cell's order and Bn (no FLL); the pull-in loop \
         is a PLL of the same Bn at T = 1 ms (order 2 for the 3rd-order cells: a 3rd-order loop \
         pulling in from a random carrier phase overshoots past +-90 deg and can slip), and the \
         cell's loop and T start at a bit edge after bit synchronisation; DLL 1st order, carrier-aided, Bn = {DLL_BN_HZ} Hz, normalised \
         early-minus-late envelope with d = {EL_SPACING_CHIPS} chip.\n\
         - Measured over at least {:.0} s (`window / Bn` for Bn < 1 Hz) after each cell's \
         settling time `settle_s` from the hand-over to \
         tracking (1 s plus the time the cell's linearised loop takes to bring a start-up \
         transient down to {SETTLE_FRACTION:e} of its size: about 8 time constants of its \
         slowest mode, longer for the lightly damped 3rd-order loop: the conclusions give the \
         values; at most {MAX_SETTLE_S} s), per integration interval against the simulator's truth, \
         pooled over the three satellites: `phase_jitter_deg` = \
         std of the replica (NCO) carrier phase minus the true carrier phase (offset and Costas \
         half cycle removed){}; `doppler_std_hz` = NCO frequency held over each interval minus \
         the true mean Doppler; `pr_rate_std_mps` = carrier-phase change over {OBS_INTERVAL_S} s \
         (the receiver's 10 Hz observable Doppler) minus the true one, times lambda; \
         `pr_rate_1s_std_mps` the same over {LONG_INTERVAL_S} s; `code_std_chips` = replica minus \
         true code phase.\n\
         - `phase_jitter_formula_deg`: oracles.md Costas formula; `ratio` = measured / formula; \
         `phase_jitter_loop_deg`: the implemented digital loop (its realised noise bandwidth) \
         with the atan discriminator's own slope `1 - exp(-C/N0 T)` and noise at the prompt SNR. \
         `doppler_theory_hz`, `pr_rate_theory_mps`, `pr_rate_1s_theory_mps`: the same \
         linearised digital loop's impulse responses (there is no standard closed form; module \
         docs of `receiver/src/study/bandwidth/mod.rs`); at high C/N0 T they reduce to the loop \
         driven by the formula's discriminator noise. \
         A `-` in the theory columns: the linearised loop is unstable at that discriminator \
         slope. `code_formula_chips`: the oracle \
         early-minus-late *power* formula; `code_envelope_chips`: the normalised envelope \
         discriminator the channel uses, in the same linearised loop.\n\
         - `locked`: every channel reached tracking, was never released, had no half-cycle slip \
         (0.1 s block means of the phase error against truth stay on one branch) and kept the \
         code within half a chip; statistics use only channels that held lock, and a cell with \
         any loss of lock is reported, not averaged in. `within_20pct`: |ratio - 1| <= 0.2 \
         (n.a. when not locked). Tracking threshold: formula `3 sigma <= 45` deg. `epochs`: \
         measured intervals per channel.\n",
        info.recordings,
        info.recorded_s,
        FS_HZ / 1e6,
        if aided {
            "The true Doppler (and its rate) is fed forward (a perfect INS, seed 004 eq. 7), so \
             the satellites' own LOS dynamics do not load the loops."
        } else {
            "Unaided (`--unaided`): the satellites' own LOS acceleration loads the loops \
             (steady-state error a/omega0^2 for order 2)."
        },
        info.window_s,
        if aided {
            ""
        } else {
            " and a least-squares straight line (the slowly varying dynamic error)"
        },
    );
    s
}
